"""Micro solves from Python against the records the library's sampler writes (the path of `hylc sample`), batches
against single calls, derivatives against finite differences, and the GIL released during a solve."""

import json
import threading

import numpy as np
import pytest

import hylc

STRAINS = [[0.01, 0.0, 0.0], [0.0, 0.05, 0.02], [0.03, 0.0, 0.01, 0.0, 20.0]]


def one_ray_plan(component, lo, hi, n):
    """A plan of one 1D range: `n` samples of strain `component` in [lo, hi], none of the others."""
    ranges = {k: [-1e-3, 1e-3] for k in ("s_x", "s_a", "s_y", "II00", "II11")}
    ranges[component] = [lo, hi]
    return {"ranges": ranges, "count_1d": n, "count_2d": 0, "pairs": [],
            "counts_1d": [n if k == component else 0 for k in ("s_x", "s_a", "s_y", "II00", "II11")]}


def records(path):
    return [json.loads(line) for line in open(path)]


def stress_as_record(s):
    return [None if np.isnan(v) else v for v in s.stress()]


@pytest.fixture(scope="module")
def plain():
    return hylc.MicroProblem("plain")


def test_solve_equals_the_sampler_cold(plain, tmp_path):
    # every sample solved from the reference state, as `hylc sample --cold` does
    out = tmp_path / "cold.jsonl"
    hylc.sample("plain", out, one_ray_plan("s_a", -0.1, 0.1, 4), cold=True)
    rs = records(out)
    assert len(rs) == 4
    for r in rs:
        s = plain.solve(r["z"])
        assert s.status == r["status"]
        assert s.steps == r["steps"]
        assert s.psi == r["psi"]  # bitwise: the records keep shortest round-trip floats
        assert stress_as_record(s) == r["stress"]


def test_design_rule_equals_the_sampler_no_inertia(tmp_path):
    design = hylc.MicroProblem("plain", inertia=False)
    out = tmp_path / "design.jsonl"
    hylc.sample("plain", out, one_ray_plan("s_x", -0.05, 0.1, 3), cold=True, inertia=False)
    for r in records(out):
        s = design.solve(r["z"])
        assert (s.status, s.steps, s.psi) == (r["status"], r["steps"], r["psi"])


def test_chain_equals_the_sampler_without_predictor(plain, tmp_path):
    # a 1D range is two rays solved outward from the sample nearest zero, each warm-started from the previous
    plan = one_ray_plan("s_x", -0.02, 0.06, 7)
    out = tmp_path / "chain.jsonl"
    hylc.sample("plain", out, plan, predictor="none")
    by_z = {r["z"][0]: r for r in records(out)}
    xs = hylc.plan_samples(plan)["z"][:7, 0]
    start = int(np.argmin(np.abs(xs)))
    ray = xs[start:]
    z = np.zeros((len(ray), 5))
    z[:, 0] = ray
    batch = plain.solve_batch(z, chain=True)
    assert list(batch["psi"]) == [by_z[x]["psi"] for x in ray]
    assert list(batch["steps"]) == [by_z[x]["steps"] for x in ray]


def test_batch_equals_single_calls(plain):
    z = np.array([[0.01, 0.0, 0.0], [0.0, 0.05, 0.02], [0.02, 0.01, 0.0]])
    batch = plain.solve_batch(z)
    assert batch["psi"].shape == (3,)
    assert batch["stress"].shape == (3, 5)
    assert batch["positions"].shape == (3, 40, 3)
    for i, row in enumerate(z):
        s = plain.solve(row)
        assert batch["status"][i] == s.status
        assert batch["psi"][i] == s.psi
        np.testing.assert_array_equal(batch["stress"][i], s.stress())
        np.testing.assert_array_equal(batch["positions"][i], s.positions)


def test_warm_start_reaches_the_same_equilibrium(plain):
    a = plain.solve([0.02, 0.0, 0.0])
    b = plain.solve([0.025, 0.0, 0.0], start=a)
    c = plain.solve([0.025, 0.0, 0.0])
    assert b.converged and c.converged
    assert b.psi == pytest.approx(c.psi, rel=1e-8)


def test_stress_against_finite_differences(plain):
    z = np.array([0.02, 0.01, 0.01])
    s = plain.solve(z)
    h = 1e-5
    for k in range(3):
        dz = np.zeros(3)
        dz[k] = h
        up = plain.solve(z + dz, start=s).psi
        down = plain.solve(z - dz, start=s).psi
        fd = (up - down) / (2 * h)
        assert s.stress()[k] == pytest.approx(fd, rel=1e-4, abs=1e-4)


def test_sensitivities_against_finite_differences_and_the_sampler(tmp_path):
    pattern = hylc.generate("plain")
    z = [0.02, 0.0, 0.01]
    yarn = hylc.yarn_defaults()
    d = hylc.MicroProblem(pattern, yarn).sensitivities(z)
    assert d["dpsi_dtheta"].shape == (6,)
    assert d["d2psi_dz2"].shape == (4, 4)
    assert d["dy_dz"].shape == (4, 160)
    assert d["dy_dtheta"].shape == (6, 160)
    # ∂Ψ̄/∂θ for the bending factor and the contact stiffness: central differences of re-solved Ψ̄
    for name in ["bend_twist_factor", "contact_stiffness"]:
        k = hylc.PARAMETERS.index(name)
        rel = 1e-4
        values = []
        for sign in (1, -1):
            y = dict(yarn)
            y[name] = yarn[name] * (1 + sign * rel)
            values.append(hylc.MicroProblem(pattern, y).solve(z).psi)
        fd = (values[0] - values[1]) / (2 * rel * yarn[name])
        assert d["dpsi_dtheta"][k] == pytest.approx(fd, rel=1e-3)
    # d²Ψ̄/dz² against differences of the stress
    p = hylc.MicroProblem(pattern)
    base = p.solve(z)
    h = 1e-5
    for col, name in enumerate(d["components"][:3]):
        dz = np.zeros(3)
        dz[col] = h
        ds = (p.solve(np.add(z, dz), start=base).stress() - p.solve(np.subtract(z, dz), start=base).stress()) / (2 * h)
        np.testing.assert_allclose(d["d2psi_dz2"][:3, col], ds[:3], rtol=1e-3, atol=1e-2)
    # the sampler's records keep the same ∂Ψ̄/∂θ (`hylc sample --sensitivities`)
    out = tmp_path / "sens.jsonl"
    plan = one_ray_plan("s_x", 0.0, 0.02, 2)
    hylc.sample(pattern, out, plan, cold=True, sensitivities=True)
    for r in records(out):
        d = hylc.MicroProblem(pattern).sensitivities(r["z"])
        assert d["psi"] == r["psi"]
        np.testing.assert_allclose([r["dpsi_dtheta"][k] for k in hylc.PARAMETERS], d["dpsi_dtheta"], rtol=1e-12)


def test_not_converged_raises_for_sensitivities():
    p = hylc.MicroProblem("plain", max_steps=1)
    s = p.solve([0.3, 0.0, 0.0])
    assert not s.converged and s.psi is None
    with pytest.raises(hylc.MicroError, match="need an equilibrium"):
        s.parameter_derivatives()


def test_bad_strains_raise_value_errors(plain):
    with pytest.raises(ValueError, match="z: expected shape"):
        plain.solve([0.1, 0.0])
    with pytest.raises(ValueError, match="z: row 0, column 1 is NaN"):
        plain.solve([0.1, float("nan"), 0.0])
    with pytest.raises(ValueError, match="z: expected a float64 array, got dtype int64"):
        plain.solve_batch(np.zeros((2, 3), dtype=np.int64))
    with pytest.raises(ValueError, match="z: expected one strain"):
        plain.solve(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="s_x"):
        plain.solve([-2.0, 0.0, 0.0])


def test_bad_yarn_raises():
    with pytest.raises(ValueError, match="young"):
        hylc.MicroProblem("plain", yarn={"young": -1.0})
    with pytest.raises(ValueError, match="unknown field `bogus`"):
        hylc.MicroProblem("plain", yarn={"bogus": 1.0})
    with pytest.raises(FileNotFoundError, match="yarn: no-such-yarn.json"):
        hylc.MicroProblem("plain", yarn="no-such-yarn.json")
    with pytest.raises(ValueError, match="quadrature"):
        hylc.MicroProblem("plain", quadrature=0)


def test_yarn_round_trip(tmp_path, expected):
    y = hylc.yarn_defaults()
    path = tmp_path / "yarn.json"
    hylc.save_yarn(y, path)
    assert path.read_text() == expected["yarn_defaults_text"]  # `hylc yarn`
    y["contact_stiffness"] = 50.0
    hylc.save_yarn(y, path)
    assert hylc.load_yarn(path) == y
    # the text-valued key of the bending-discretisation variant
    assert y["bending"] == "tan"
    y["bending"] = "sin"
    hylc.save_yarn(y, path)
    assert hylc.load_yarn(path)["bending"] == "sin"
    with pytest.raises(ValueError, match="cos"):
        hylc.save_yarn(dict(y, bending="cos"), path)


def test_the_gil_is_released_during_a_batch():
    p = hylc.MicroProblem("stockinette")
    z = np.array([[0.1 * k, 0.0, 0.0] for k in range(4)])
    done = threading.Event()

    def work():
        p.solve_batch(z)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        done.wait(0.001)
    t.join()
    # with the GIL held for the whole batch this loop could not run while it solved
    assert ticks > 20
