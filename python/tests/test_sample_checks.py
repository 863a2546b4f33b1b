"""Sampling plans and sample files (`hylc plan`, `hylc sample`), the derivative harness (`hylc check-derivatives`),
progress callbacks and Ctrl-C on the long calls."""

import _thread
import json
import threading
import time

import numpy as np
import pytest

import hylc


def tiny_plan():
    """Three samples per 1D range and a 2×2 grid of (s_x, s_y): 19 samples."""
    p = hylc.plan("default")
    p.update(count_1d=3, count_2d=2, pairs=[["s_x", "s_y"]])
    return p


def records(path):
    return [json.loads(line) for line in open(path)]


def without_time(rs):
    return sorted((dict(r, time=None) for r in rs), key=lambda r: r["index"])


def test_plan_sizes_and_hashes(tmp_path):
    # the sizes and hashes `hylc plan --write` prints
    for name, n, h in [("default", 23250, "328a85eae1502e7f"), ("reduced", 1050, "04730ff06cda9d64"),
                       ("quick", 474, "889db784207f1d9a"), ("holdout", 729, "7cc9d6cf32db7d0c")]:
        p = hylc.plan(name)
        s = hylc.plan_samples(name)
        assert s["hash"] == h and s["z"].shape == (n, 5) and len(s["ids"]) == n
        assert s["ids"][7] == f"{h}-7"
        grid = np.prod([len(a) for a in p["grid"].values()]) if "grid" in p else 0
        assert n == 5 * p["count_1d"] + len(p["pairs"]) * p["count_2d"] ** 2 + grid
    assert hylc.plan() == hylc.plan("default")
    hylc.plan("quick", write=tmp_path / "quick.json")
    assert json.loads((tmp_path / "quick.json").read_text()) == hylc.plan("quick")
    assert hylc.plan(tmp_path / "quick.json") == hylc.plan(hylc.plan("quick")) == hylc.plan("quick")
    assert hylc.plan_samples(tmp_path / "quick.json")["hash"] == "889db784207f1d9a"
    s = hylc.plan_samples(tiny_plan())
    assert s["z"].shape == (19, 5) and s["chains"] == 6
    with pytest.raises(ValueError, match="not a plan"):
        hylc.plan("tiny")
    with pytest.raises(hylc.SampleError, match="count_1d"):
        hylc.plan(dict(tiny_plan(), count_1d=-1))
    with pytest.raises(hylc.SampleError, match="plan field"):
        hylc.plan_samples(dict(tiny_plan(), bogus=1))


def test_sample_a_tiny_plan_and_resume(tmp_path):
    plan = tiny_plan()
    whole = tmp_path / "whole.jsonl"
    s = hylc.sample("plain", whole, plan)
    assert (s["selected"], s["written"], s["converged"], s["already_done"]) == (19, 19, 19, 0)
    assert s["plan_hash"] == hylc.plan_samples(plan)["hash"]
    rs = records(whole)
    assert sorted(r["id"] for r in rs) == sorted(hylc.plan_samples(plan)["ids"])
    meta = json.loads((tmp_path / "whole.meta.json").read_text())
    assert meta["pattern"] == "plain" and meta["plan"] == plan
    # stopped after 5 records and resumed: the same records as the uninterrupted run
    part = tmp_path / "part.jsonl"
    assert hylc.sample("plain", part, plan, limit=5)["written"] == 5
    again = hylc.sample("plain", part, plan)
    assert (again["already_done"], again["written"]) == (5, 14)
    assert without_time(records(part)) == without_time(rs)
    # a finished file: nothing to do
    assert hylc.sample("plain", part, plan)["written"] == 0
    # shards split the chains
    a = hylc.sample("plain", tmp_path / "a.jsonl", plan, shard="0/2")
    b = hylc.sample("plain", tmp_path / "b.jsonl", plan, shard=(1, 2))
    assert a["written"] + b["written"] == 19


def test_sample_bad_input_raises(tmp_path):
    out = tmp_path / "s.jsonl"
    with pytest.raises(ValueError, match="starts: expected one of warm, warm\\+cold, all"):
        hylc.sample("plain", out, tiny_plan(), starts="both")
    with pytest.raises(ValueError, match="shard"):
        hylc.sample("plain", out, tiny_plan(), shard="3/2")
    with pytest.raises(hylc.SampleError, match="warm\\+cold"):
        hylc.sample("plain", out, tiny_plan(), cold=True, starts="warm+cold")
    with pytest.raises(TypeError, match="progress"):
        hylc.sample("plain", out, tiny_plan(), progress=3)
    hylc.sample("plain", out, tiny_plan(), limit=1)
    with pytest.raises(hylc.SampleError, match="another problem"):
        hylc.sample("twill", out, tiny_plan())


def test_sample_progress_is_called(tmp_path):
    calls = []
    s = hylc.sample("plain", tmp_path / "s.jsonl", tiny_plan(), progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (19, 19) == (s["written"], s["selected"])
    assert all(t == 19 for _, t in calls) and [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert threading.current_thread() is threading.main_thread()


def test_an_exception_in_the_callback_stops_the_sampling(tmp_path):
    out = tmp_path / "s.jsonl"
    seen = []

    def stop(done, total):
        seen.append(done)
        if done >= 1:
            raise KeyboardInterrupt

    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        hylc.sample("plain", out, "quick", progress=stop)
    assert time.monotonic() - t0 < 5
    written = len(records(out))
    assert 1 <= written < 474
    # the file is whole: a later run resumes from it
    s = hylc.sample("plain", out, "quick", limit=3)
    assert s["already_done"] == written and s["written"] == 3


def test_ctrl_c_stops_the_sampling_within_a_second(tmp_path):
    out = tmp_path / "s.jsonl"
    timer = threading.Timer(0.5, _thread.interrupt_main)
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        hylc.sample("plain", out, "default")
    elapsed = time.monotonic() - t0
    timer.join()
    assert elapsed < 1.5
    assert 0 < len(records(out)) < 23250


def test_simulate_progress_and_interrupt(tmp_path):
    calls = []
    r = hylc.simulate("stretch-x", duration=0.05, progress=lambda d, t: calls.append((d, t)))
    assert calls[-1] == (3, 3) == (len(r["step"]), r["summary"]["steps"])
    out = tmp_path / "run"

    def stop(done, total):
        if done >= 1:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        hylc.simulate("stretch-x", duration=10.0, out=out, progress=stop)
    # stopped after a few of the 600 steps; the log written so far is complete
    log = (out / "log.jsonl").read_text().splitlines()
    assert 1 <= len(log) < 600 and all(json.loads(line)["step"] for line in log)


def test_check_derivatives_passes_and_is_reproducible():
    calls = []
    rows = hylc.check_derivatives(cases=20, seed=3, filter="psi[default]", progress=lambda d, t: calls.append((d, t)))
    assert [r["name"] for r in rows] == ["psi[default]"] and calls[-1] == (1, 1)
    r = rows[0]
    assert r["passed"] and r["cases"] == 20 and r["failures"] == 0 and 0 < r["worst_ratio"] <= 1
    assert len(r["worst_input"]) == 6
    assert hylc.check_derivatives(cases=20, seed=3, filter="psi[default]") == rows
    other = hylc.check_derivatives(cases=20, seed=4, filter="psi[default]")[0]
    assert other["worst_input"] != r["worst_input"]
    several = hylc.check_derivatives(cases=3, filter="rod-")
    assert len(several) >= 2 and all(x["passed"] for x in several)
    with pytest.raises(ValueError, match="no registered function matches"):
        hylc.check_derivatives(cases=1, filter="no-such-function")
    with pytest.raises(ValueError, match="cases"):
        hylc.check_derivatives(cases=0)
