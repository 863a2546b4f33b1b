"""Patterns and the reference state from Python against the command line's stored files; cloth scenes against the
files the same call writes; bad input raises."""

import json
from pathlib import Path

import numpy as np
import pytest

import hylc

DATA = Path(__file__).resolve().parent / "data"


def test_generate_equals_the_cli(tmp_path):
    for kind, n in [("plain", None), ("twill", 3), ("stockinette", None)]:
        p = hylc.generate(kind, n=n)
        p.save(tmp_path / f"{kind}.py.pyp")
        assert (tmp_path / f"{kind}.py.pyp").read_bytes() == (DATA / f"{kind}.pyp").read_bytes()


def test_load_save_and_summary(tmp_path):
    p = hylc.generate("plain")
    path = tmp_path / "plain.pyp"
    p.save(path)
    q = hylc.read_pyp(path)
    np.testing.assert_array_equal(q.positions, p.positions)
    assert q.periods == p.periods and q.radius == p.radius
    s = q.summary()
    # `hylc pattern plain.pyp`: 40 vertices in 4 yarns of 10, 2 edges crossing each side, rest length 4.357118e-2 m
    assert s["vertices"] == 40 and [y["vertices"] for y in s["yarns"]] == [10] * 4
    assert (s["crossing_x"], s["crossing_y"]) == (2, 2)
    assert f"{s['total_rest_length']:.6e}" == "4.357118e-02"
    assert len(p) == 40 and p.positions.shape == (40, 3)
    assert sorted(v for y in p.yarns() for v in y) == list(range(40))
    r = hylc.load_pattern(str(path))
    np.testing.assert_array_equal(r.positions, p.positions)


def test_reference_state_equals_the_cli(tmp_path, expected):
    q, report = hylc.reference_state("plain")
    q.save(tmp_path / "py.pyp")
    assert (tmp_path / "py.pyp").read_bytes() == (DATA / "plain.reference.pyp").read_bytes()
    assert report["psi"] == pytest.approx(expected["reference_plain"]["psi"], rel=1e-12)
    assert report["periods_out"] == pytest.approx(expected["reference_plain"]["periods_out"], rel=1e-12)


def test_pattern_errors_have_the_cli_messages(tmp_path, expected):
    with pytest.raises(FileNotFoundError, match="missing.pyp"):
        hylc.load_pattern("missing.pyp")
    with pytest.raises(hylc.PatternError) as e:
        hylc.generate("jersey")
    assert f"error: {e.value}" == expected["generate_jersey_error"]
    bad = tmp_path / "bad.pyp"
    bad.write_text("*not a pattern\n")
    with pytest.raises(hylc.PatternError) as e:
        hylc.read_pyp(bad)
    assert f"error: {e.value}" == expected["bad_pyp_error"].replace("{path}", str(bad))
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


def _log(folder):
    return [json.loads(line) for line in (folder / "log.jsonl").read_text().splitlines()]


def test_simulate_equals_its_log(tmp_path):
    out = tmp_path / "run"
    r = hylc.simulate("stretch-x", duration=0.05, out=out)
    log = _log(out)
    assert len(r["step"]) == len(log) == r["summary"]["steps"]
    for key in ["time", "newton", "residual", "energy_elastic", "energy_kinetic", "energy_gravity", "rejected",
                "error_estimate"]:
        np.testing.assert_array_equal(r[key], [e[key] for e in log])
    np.testing.assert_array_equal(r["strain_max"], [e["strain_max"] for e in log])
    for name, forces in r["handle_forces"].items():
        expected = [dict(map(tuple, [(h[0], h[1]) for h in e["handle_forces"]]))[name] for e in log]
        np.testing.assert_array_equal(forces, expected)
    assert r["positions"].shape == (r["summary"]["vertices"], 3)
    assert r["triangles"].shape == (r["summary"]["triangles"], 3) and r["triangles"].dtype == np.int64
    assert r["triangles"].max() < r["summary"]["vertices"]
    np.testing.assert_allclose(r["positions"], _obj_vertices(out / f"frame_{len(log):04d}.obj"), rtol=0, atol=1e-12)
    # without `out` the run is the same
    again = hylc.simulate("stretch-x", duration=0.05)
    np.testing.assert_array_equal(again["positions"], r["positions"])


def test_a_scene_dict_equals_its_file(tmp_path):
    scene = hylc.load_scene("stretch-x")
    assert scene["name"] == "stretch-x" and scene["material"] == "default"
    scene.update(duration=0.05)
    path = tmp_path / "stretch.json"
    path.write_text(json.dumps(scene))
    assert hylc.load_scene(path) == scene == hylc.load_scene(scene)
    from_file, from_dict = hylc.simulate(str(path)), hylc.simulate(scene)
    for key in ["time", "residual", "energy_elastic", "positions"]:
        np.testing.assert_array_equal(from_dict[key], from_file[key])
    # the built-in with the same override is the same scene
    np.testing.assert_array_equal(hylc.simulate("stretch-x", duration=0.05)["positions"], from_dict["positions"])
    with pytest.raises(hylc.SimulationError, match=r"scene \(a dict\)"):
        hylc.simulate(dict(scene, dt="soon"))
    with pytest.raises(ValueError, match="scene: expected"):
        hylc.simulate(42)


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


def _quasi_static_stretch(tmp_path):
    """`stretch-x` made quasi-static and coarse (three load steps), written as a scene file."""
    s = hylc.load_scene("stretch-x")
    s.update(quasi_static=True, duration=0.15, dt=0.05, drag=0.0)
    s["mesh"]["rectangle"]["edge"] = 0.3 / 12
    f = tmp_path / "stretch.json"
    f.write_text(json.dumps(s))
    return str(f)


def _obj_vertices(path):
    return np.array([[float(t) for t in line.split()[1:4]] for line in open(path) if line.startswith("v ")])


def test_gradient_equals_its_file_and_the_vjp_equals_a_target(tmp_path):
    scene = _quasi_static_stretch(tmp_path)
    g = hylc.gradient(scene, observable="handle-force:right:x", out=tmp_path / "py")
    expected = json.loads((tmp_path / "py" / "gradient.json").read_text())
    assert g["value"] == pytest.approx(expected["value"], rel=1e-12)
    assert g["scene"]["stiffness"] == pytest.approx(expected["scene"]["stiffness"], rel=1e-10)
    assert g["held"]["right"]["keyframes"].shape == (2, 3)
    np.testing.assert_allclose(g["held"]["right"]["keyframes"], expected["held"]["right"]["keyframes"], rtol=1e-10)
    p = g["material"]["coeffs"]["1D"][0]["p"]
    assert isinstance(p, np.ndarray) and np.abs(p).max() > 0
    # a scene dict gives the same gradient
    from_dict = hylc.gradient(json.loads(open(scene).read()), observable="handle-force:right:x")
    assert from_dict["value"] == g["value"]
    np.testing.assert_array_equal(from_dict["material"]["coeffs"]["1D"][0]["p"], p)
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
    # damping under option (b) is followed; under the 18×18 projection it is refused
    (tmp_path / "damped_psi.json").write_text(json.dumps(damped))
    assert np.isfinite(hylc.gradient(str(tmp_path / "damped_psi.json"), observable="energy")["value"])
    damped["psd"] = "full"
    (tmp_path / "damped.json").write_text(json.dumps(damped))
    with pytest.raises(ValueError, match="damping"):
        hylc.gradient(str(tmp_path / "damped.json"), observable="energy")


def test_yarn_chain_equals_its_file(tmp_path, quick_samples):
    material = tmp_path / "plain.material.json"
    hylc.fit(quick_samples, out=material, report=tmp_path / "plain.fit.json")
    scene = _quasi_static_stretch(tmp_path)
    g = hylc.gradient(scene, observable="energy", material=str(material), samples=quick_samples, out=tmp_path / "py")
    expected = json.loads((tmp_path / "py" / "gradient.json").read_text())["yarn"]
    assert list(g["yarn"]) == ["young", "shear", "bend_twist_factor", "contact_stiffness", "contact_radius_factor",
                               "radius"]
    for k, v in expected.items():
        assert g["yarn"][k] == v
    assert any(v != 0 for v in expected.values())
    assert g["yarn_chain"]["reference_state"] == "held fixed"
    with pytest.raises(ValueError, match="yarn needs samples"):
        hylc.gradient(scene, observable="energy", material=str(material), yarn={"young": 1e6})


def test_vtu_series_reads_back_with_meshio(tmp_path):
    meshio = pytest.importorskip("meshio")
    import xml.etree.ElementTree as ET

    out = tmp_path / "vtu"
    hylc.simulate("stretch-x", edge=0.025, duration=0.05, vtu=True, out=out)
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
