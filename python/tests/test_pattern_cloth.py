"""Patterns, the reference state and cloth scenes from Python against the CLI; bad input raises."""

import json

import numpy as np
import pytest

import hylc


def test_generate_equals_the_cli(tmp_path, cli):
    for kind, extra in [("plain", []), ("twill", ["--n", "3"]), ("stockinette", [])]:
        cli("generate", kind, *extra, "--out", tmp_path / f"{kind}.cli.pyp")
        n = int(extra[1]) if extra else None
        p = hylc.generate(kind, n=n)
        p.save(tmp_path / f"{kind}.py.pyp")
        assert (tmp_path / f"{kind}.py.pyp").read_bytes() == (tmp_path / f"{kind}.cli.pyp").read_bytes()


def test_load_save_and_summary(tmp_path, cli):
    p = hylc.generate("plain")
    path = tmp_path / "plain.pyp"
    p.save(path)
    q = hylc.read_pyp(path)
    np.testing.assert_array_equal(q.positions, p.positions)
    assert q.periods == p.periods and q.radius == p.radius
    s = q.summary()
    text = cli("pattern", path).stdout
    assert f"vertices: {s['vertices']} " in text
    assert f"yarns: {len(s['yarns'])}" in text
    assert len(p) == 40 and p.positions.shape == (40, 3)
    assert sorted(v for y in p.yarns() for v in y) == list(range(40))
    r = hylc.load_pattern(str(path))
    np.testing.assert_array_equal(r.positions, p.positions)


def test_reference_state_equals_the_cli(tmp_path, cli):
    cli("reference", "plain", "--out", tmp_path / "cli.pyp", "--json", tmp_path / "cli.json")
    q, report = hylc.reference_state("plain")
    q.save(tmp_path / "py.pyp")
    assert (tmp_path / "py.pyp").read_bytes() == (tmp_path / "cli.pyp").read_bytes()
    expected = json.loads((tmp_path / "cli.json").read_text())
    assert report["psi"] == expected["psi"]
    assert report["periods_out"] == expected["periods_out"]


def test_pattern_errors_have_the_cli_messages(tmp_path, cli):
    with pytest.raises(FileNotFoundError, match="missing.pyp"):
        hylc.load_pattern("missing.pyp")
    with pytest.raises(hylc.PatternError) as e:
        hylc.generate("jersey")
    err = cli("generate", "jersey", check=False).stderr.strip()
    assert err == f"error: {e.value}"
    bad = tmp_path / "bad.pyp"
    bad.write_text("*not a pattern\n")
    with pytest.raises(hylc.PatternError) as e:
        hylc.read_pyp(bad)
    err = cli("pattern", bad, check=False).stderr.strip()
    assert err == f"error: {e.value}"
    with pytest.raises(ValueError, match="construction"):
        hylc.reference_state("plain", construction="crochet")
    with pytest.raises(ValueError, match="pass --construction"):
        hylc.reference_state(_saved_plain(tmp_path))
    with pytest.raises(ValueError, match="pattern: expected a Pattern"):
        hylc.MicroProblem(42)


def _saved_plain(tmp_path):
    path = tmp_path / "plain.pyp"
    hylc.generate("plain").save(path)
    return str(path)


def test_simulate_equals_the_cli_log(tmp_path, cli):
    out = tmp_path / "cli"
    cli("simulate", "stretch-x", "--duration", "0.05", "--out", out, "--quiet")
    log = [json.loads(line) for line in (out / "log.jsonl").read_text().splitlines()]
    r = hylc.simulate("stretch-x", duration=0.05)
    assert len(r["step"]) == len(log) == r["summary"]["steps"]
    for key in ["time", "newton", "residual", "energy_elastic", "energy_kinetic", "energy_gravity", "rejected",
                "error_estimate"]:
        np.testing.assert_allclose(r[key], [e[key] for e in log], rtol=1e-9, atol=1e-300)
    np.testing.assert_allclose(r["strain_max"], [e["strain_max"] for e in log], rtol=1e-9, atol=1e-15)
    for name, forces in r["handle_forces"].items():
        expected = [dict(map(tuple, [(h[0], h[1]) for h in e["handle_forces"]]))[name] for e in log]
        np.testing.assert_allclose(forces, expected, rtol=1e-8, atol=1e-12)
    assert r["positions"].shape == (r["summary"]["vertices"], 3)
    assert r["triangles"].shape == (r["summary"]["triangles"], 3) and r["triangles"].dtype == np.int64
    assert r["triangles"].max() < r["summary"]["vertices"]


def test_simulate_bad_input_raises(tmp_path):
    with pytest.raises(FileNotFoundError, match="scene: missing.json"):
        hylc.simulate("missing.json")
    with pytest.raises(hylc.SimulationError, match="not a built-in scene"):
        hylc.simulate("no-such-scene")
    with pytest.raises(ValueError, match="--dt"):
        hylc.simulate("stretch-x", dt=-1.0)
    with pytest.raises(ValueError, match="time_tol: expected a positive length"):
        hylc.simulate("stretch-x", time_tol="sometimes")
    with pytest.raises(ValueError, match="time_tol"):
        hylc.simulate("stretch-x", time_tol=0.0)


def test_simulate_time_tol_off_is_one_step_per_frame():
    off = hylc.simulate("stretch-x", duration=0.05, time_tol="off")
    tight = hylc.simulate("stretch-x", duration=0.05, time_tol=1e-6)
    assert off["substeps"].max() == 1
    assert tight["substeps"].sum() > off["substeps"].sum()


def test_import_exposes_the_api():
    assert issubclass(hylc.PatternError, hylc.Error)
    assert issubclass(hylc.InternalError, hylc.Error)
    assert hylc.__version__
    for name in hylc.__all__:
        assert getattr(hylc, name) is not None
    assert "numpy arrays" in hylc.__doc__ or "(N, 6)" in hylc.__doc__
    assert hylc.MicroProblem.solve.__doc__ and hylc.Material.psi.__doc__


def test_a_panic_becomes_an_internal_error():
    from hylc import _hylc

    with pytest.raises(hylc.InternalError, match="internal error: a panic raised on purpose"):
        _hylc._panic_at_the_boundary()
    # the interpreter goes on
    assert hylc.Material.default().psi([0.0] * 6) == hylc.Material.default().psi(np.zeros(6))


def _quasi_static_stretch(tmp_path, cli):
    """`stretch-x` made quasi-static and coarse (three load steps), written as a scene file."""
    s = json.loads(cli("simulate", "stretch-x", "--print").stdout)
    s.update(quasi_static=True, duration=0.15, dt=0.05, drag=0.0)
    s["mesh"]["rectangle"]["edge"] = 0.3 / 12
    f = tmp_path / "stretch.json"
    f.write_text(json.dumps(s))
    return str(f)


def _obj_vertices(path):
    return np.array([[float(t) for t in line.split()[1:4]] for line in open(path) if line.startswith("v ")])


def test_gradient_equals_the_cli_and_the_vjp_equals_a_target(tmp_path, cli):
    scene = _quasi_static_stretch(tmp_path, cli)
    cli("gradient", scene, "--observable", "handle-force:right:x", "--out", tmp_path / "cli", "--quiet")
    expected = json.loads((tmp_path / "cli" / "gradient.json").read_text())
    g = hylc.gradient(scene, observable="handle-force:right:x", out=tmp_path / "py")
    assert g["value"] == pytest.approx(expected["value"], rel=1e-12)
    assert g["scene"]["stiffness"] == pytest.approx(expected["scene"]["stiffness"], rel=1e-10)
    assert g["held"]["right"]["keyframes"].shape == (2, 3)
    np.testing.assert_allclose(g["held"]["right"]["keyframes"], expected["held"]["right"]["keyframes"], rtol=1e-10)
    p = g["material"]["coeffs"]["1D"][0]["p"]
    assert isinstance(p, np.ndarray) and np.abs(p).max() > 0
    # the vector–Jacobian product with w = x* − x̂ is the gradient of the target ½|x − x̂|² at x*
    x_hat = _obj_vertices(tmp_path / "py" / "frame_0000.obj")
    x_star = _obj_vertices(tmp_path / "py" / "frame_0003.obj")
    target = hylc.gradient(scene, observable=f"target:{tmp_path / 'py' / 'frame_0000.obj'}")
    vjp = hylc.gradient(scene, cotangent=x_star - x_hat)
    for key in ["stiffness", "bending_scale", "mass"]:
        assert vjp["scene"][key] == pytest.approx(target["scene"][key], rel=1e-6, abs=1e-12)
    np.testing.assert_allclose(vjp["held"]["left"]["translation"], target["held"]["left"]["translation"], rtol=1e-6)
    with pytest.raises(ValueError, match="exactly one"):
        hylc.gradient(scene)
    with pytest.raises(ValueError, match="cotangent"):
        hylc.gradient(scene, cotangent=np.zeros((3, 3)))
    damped = json.loads(open(scene).read())
    damped.update(quasi_static=False, damping=0.01, dt=1 / 60, duration=1 / 60)
    (tmp_path / "damped.json").write_text(json.dumps(damped))
    with pytest.raises(ValueError, match="damping"):
        hylc.gradient(str(tmp_path / "damped.json"), observable="energy")


def test_yarn_chain_equals_the_cli(tmp_path, cli, quick_samples):
    material = tmp_path / "plain.material.json"
    cli("fit", quick_samples, "--out", material, "--no-plots")
    scene = _quasi_static_stretch(tmp_path, cli)
    cli("gradient", scene, "--observable", "energy", "--material", material, "--samples", quick_samples,
        "--out", tmp_path / "cli", "--quiet")
    expected = json.loads((tmp_path / "cli" / "gradient.json").read_text())["yarn"]
    g = hylc.gradient(scene, observable="energy", material=str(material), samples=quick_samples)
    assert list(g["yarn"]) == ["young", "shear", "bend_twist_factor", "contact_stiffness", "contact_radius_factor",
                               "radius"]
    for k, v in expected.items():
        assert g["yarn"][k] == pytest.approx(v, rel=1e-12, abs=1e-300)
    assert g["yarn_chain"]["reference_state"] == "held fixed"
    with pytest.raises(ValueError, match="yarn needs samples"):
        hylc.gradient(scene, observable="energy", material=str(material), yarn={"young": 1e6})


def test_vtu_series_reads_back_with_meshio(tmp_path, cli):
    meshio = pytest.importorskip("meshio")
    import xml.etree.ElementTree as ET

    out = tmp_path / "vtu"
    cli("simulate", "stretch-x", "--edge", "0.025", "--duration", "0.05", "--format", "vtu", "--out", out, "--quiet")
    sets = ET.parse(out / "frames.pvd").getroot().find("Collection").findall("DataSet")
    times = [float(d.get("timestep")) for d in sets]
    assert len(sets) == 4 and times == sorted(times) and times[0] == 0.0
    log = [json.loads(line) for line in (out / "log.jsonl").read_text().splitlines()]
    np.testing.assert_allclose(times[1:], [e["time"] for e in log], rtol=1e-12)
    for d in sets:
        m = meshio.read(out / d.get("file"))
        tri = m.cells_dict["triangle"]
        assert np.asarray(m.cell_data["psi"][0]).reshape(len(tri), -1).shape == (len(tri), 1)
        assert m.cell_data["strain"][0].shape == (len(tri), 6)
        assert m.point_data["velocity"].shape == (len(m.points), 3)
        obj = _obj_vertices(out / d.get("file").replace(".vtu", ".obj"))
        np.testing.assert_allclose(m.points, obj, rtol=0, atol=1e-12)
    # the last frame moves: the pulled handles have a velocity
    assert np.abs(m.point_data["velocity"]).max() > 1e-4
