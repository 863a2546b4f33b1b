"""Materials from Python against the command line's stored values, (N, 6) batches against single calls, derivatives
against finite differences, fitting against the files it writes and its presets."""

import json

import numpy as np
import pytest

import hylc


def strains(n, seed=1):
    rng = np.random.default_rng(seed)
    z = np.zeros((n, 6))
    z[:, 0] = rng.uniform(-0.2, 0.5, n)
    z[:, 1] = rng.uniform(-0.3, 0.3, n)
    z[:, 2] = rng.uniform(-0.2, 0.5, n)
    z[:, 3:] = rng.uniform(-50, 50, (n, 3))
    return z


def test_values_equal_the_cli(expected):
    m = hylc.Material.default()
    e = expected["material_default"]
    z = strains(5)
    np.testing.assert_array_equal(z, e["z"])
    psi, grad, hess = m.eval(z)
    np.testing.assert_allclose(psi, e["psi"], rtol=1e-13, atol=0)
    np.testing.assert_allclose(grad, e["grad"], rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(hess, e["hess"], rtol=1e-12, atol=1e-300)


def test_batch_equals_single_calls():
    m = hylc.Material.default()
    z = strains(50)
    psi, grad, hess = m.psi(z), m.gradient(z), m.hessian(z)
    assert psi.shape == (50,) and grad.shape == (50, 6) and hess.shape == (50, 6, 6)
    for i in range(len(z)):
        assert m.psi(z[i]) == psi[i]
        np.testing.assert_array_equal(m.gradient(z[i]), grad[i])
        np.testing.assert_array_equal(m.hessian(z[i]), hess[i])
    p2, g2, h2 = m.eval(z)
    np.testing.assert_array_equal(p2, psi)
    np.testing.assert_array_equal(g2, grad)
    np.testing.assert_array_equal(h2, hess)


def test_gradient_and_hessian_against_finite_differences():
    m = hylc.Material.default()
    z = strains(20, seed=2)
    grad, hess = m.gradient(z), m.hessian(z)
    scale = np.array([1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4])
    for k in range(6):
        dz = np.zeros(6)
        dz[k] = scale[k]
        fd = (m.psi(z + dz) - m.psi(z - dz)) / (2 * scale[k])
        np.testing.assert_allclose(grad[:, k], fd, rtol=1e-5, atol=1e-6)
        fd2 = (m.gradient(z + dz) - m.gradient(z - dz)) / (2 * scale[k])
        np.testing.assert_allclose(hess[:, :, k], fd2, rtol=1e-4, atol=1e-4)


def test_save_and_load_round_trip(tmp_path, expected):
    m = hylc.Material.default()
    path = tmp_path / "m.json"
    m.save(path)
    saved = json.loads(path.read_text())
    assert sorted(saved) == expected["material_default"]["keys"]
    assert saved["density"] == expected["material_default"]["density"]
    back = hylc.Material.load(path)
    back.save(tmp_path / "again.json")
    assert (tmp_path / "again.json").read_text() == path.read_text()
    z = strains(10)
    np.testing.assert_array_equal(back.psi(z), m.psi(z))
    np.testing.assert_allclose(back.psi(strains(5)), expected["material_default"]["psi"], rtol=1e-13)


def test_bad_input_raises():
    m = hylc.Material.default()
    with pytest.raises(ValueError, match=r"z: expected shape \(N, 6\), got \[4, 5\]"):
        m.psi(np.zeros((4, 5)))
    with pytest.raises(ValueError, match="z: expected a float64 array, got dtype float32"):
        m.gradient(np.zeros((4, 6), dtype=np.float32))
    z = np.zeros((3, 6))
    z[2, 4] = np.nan
    with pytest.raises(ValueError, match="z: row 2, column 4 is NaN"):
        m.hessian(z)
    with pytest.raises(ValueError, match="z: strain #2: s_y = 1000000000 is outside"):
        m.psi(np.array([[0.0] * 6, [0, 0, 1e9, 0, 0, 0]]))
    with pytest.raises(FileNotFoundError, match="no-such-material.json"):
        hylc.Material.load("no-such-material.json")
    with pytest.raises(ValueError, match="z: not an array of numbers"):
        m.psi("strain")


def test_bad_material_file_raises_material_error(tmp_path, expected):
    path = tmp_path / "bad.json"
    path.write_text('{"density": 0.2}')
    with pytest.raises(hylc.MaterialError) as e:
        hylc.Material.load(path)
    assert f"error: {e.value}" == expected["bad_material_error"].replace("{path}", str(path))


def test_fit_equals_its_files_and_is_deterministic(quick_samples, tmp_path):
    material, report = hylc.fit(quick_samples, out=tmp_path / "a.material.json", report=tmp_path / "a.fit.json")
    hylc.fit(quick_samples, out=tmp_path / "b.material.json", report=tmp_path / "b.fit.json")
    a = json.loads((tmp_path / "a.material.json").read_text())
    b = json.loads((tmp_path / "b.material.json").read_text())
    a["meta"].pop("samples", None), b["meta"].pop("samples", None)
    assert a == b
    stored = json.loads((tmp_path / "a.fit.json").read_text())
    assert report["samples"] == stored["samples"]
    # the fit read the sidecar hylc.sample wrote: the pattern, the plan and the yarn
    assert a["meta"]["pattern"] == "plain" and a["meta"]["yarn"] == hylc.yarn_defaults()
    z = strains(10)
    np.testing.assert_array_equal(material.psi(z), hylc.Material.load(tmp_path / "a.material.json").psi(z))
    with pytest.raises(FileNotFoundError, match="samples: missing.jsonl"):
        hylc.fit("missing.jsonl")


def test_fit_presets_and_bad_names_raise(quick_samples, tmp_path):
    hylc.fit(quick_samples, out=tmp_path / "design.material.json", report=tmp_path / "design.fit.json",
             preset="design")
    hylc.fit(quick_samples, out=tmp_path / "covering.material.json", report=tmp_path / "covering.fit.json")
    meta = json.loads((tmp_path / "design.material.json").read_text())["meta"]
    assert meta["fit options"]["bandwidth_factor"] == 2.0 and meta["fit options"]["compression_residual"] is False
    covering = json.loads((tmp_path / "covering.material.json").read_text())["meta"]
    assert covering["fit options"] != meta["fit options"]
    with pytest.raises(ValueError, match="unknown fit preset `fast`"):
        hylc.fit(quick_samples, preset="fast")
