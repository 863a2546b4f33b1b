"""Materials from Python against the CLI, (N, 6) batches against single calls, derivatives against finite
differences, fitting against `hylc fit`."""

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


def test_values_equal_the_cli(cli_json):
    m = hylc.Material.default()
    z = strains(5)
    args = ["material", "default", "--json"]
    for row in z:
        args += ["--z", ",".join(repr(float(v)) for v in row)]
    records = cli_json(*args)
    psi, grad, hess = m.eval(z)
    for i, r in enumerate(records):
        assert psi[i] == r["psi"]
        assert list(grad[i]) == r["grad"]
        assert hess[i].tolist() == r["hess"]


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


def test_save_and_load_round_trip(tmp_path, cli):
    m = hylc.Material.default()
    path = tmp_path / "m.json"
    m.save(path)
    cli("material", "default", "--write", tmp_path / "cli.json")
    assert json.loads(path.read_text()) == json.loads((tmp_path / "cli.json").read_text())
    back = hylc.Material.load(path)
    z = strains(10)
    np.testing.assert_array_equal(back.psi(z), m.psi(z))


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


def test_bad_material_file_raises_material_error(tmp_path, cli):
    path = tmp_path / "bad.json"
    path.write_text('{"density": 0.2}')
    with pytest.raises(hylc.MaterialError) as e:
        hylc.Material.load(path)
    err = cli("material", path, "--z", "0,0,0,0,0,0", check=False).stderr.strip()
    assert err == f"error: {e.value}"


def test_fit_equals_the_cli(quick_samples, tmp_path, cli):
    material, report = hylc.fit(quick_samples, out=tmp_path / "py.material.json", report=tmp_path / "py.fit.json")
    cli("fit", quick_samples, "--out", tmp_path / "cli.material.json", "--report", tmp_path / "cli.fit.json", "--no-plots")
    assert (tmp_path / "py.material.json").read_text() == (tmp_path / "cli.material.json").read_text()
    assert report["samples"] == json.loads((tmp_path / "cli.fit.json").read_text())["samples"]
    z = strains(10)
    np.testing.assert_array_equal(material.psi(z), hylc.Material.load(tmp_path / "cli.material.json").psi(z))
    with pytest.raises(FileNotFoundError, match="samples: missing.jsonl"):
        hylc.fit("missing.jsonl")


def test_fit_presets_equal_the_cli_and_bad_names_raise(quick_samples, tmp_path, cli):
    hylc.fit(quick_samples, out=tmp_path / "py.material.json", report=tmp_path / "py.fit.json", preset="design")
    cli("fit", quick_samples, "--preset", "design", "--out", tmp_path / "cli.material.json", "--report",
        tmp_path / "cli.fit.json", "--no-plots")
    assert (tmp_path / "py.material.json").read_text() == (tmp_path / "cli.material.json").read_text()
    meta = json.loads((tmp_path / "py.material.json").read_text())["meta"]
    assert meta["fit options"]["bandwidth_factor"] == 2.0 and meta["fit options"]["compression_residual"] is False
    with pytest.raises(ValueError, match="unknown fit preset `fast`"):
        hylc.fit(quick_samples, preset="fast")
