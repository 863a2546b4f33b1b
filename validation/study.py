#!/usr/bin/env python3
"""The speed/accuracy study (`docs/results.md`, "Speed and accuracy (`validation/study.py`)"): for each knob users turn,
the wall time and the error against a high-accuracy reference run of the same quantity, as Markdown tables.

Knobs: micro solver tolerance, contact quadrature order, warm vs cold start, sampling density, knot counts (micro
and fitting, on the generated stockinette of `hylc run`; knot counts also on the original basket when its samples
from validation/fit_originals.sh are present), PSD projection vs regularisation, macro mesh resolution and macro
step size (`stretch-x` with the original basket1 material when ../shared is present, else the embedded default).
Times are the CLI's own timing output. Work files go to validation/study/ (not committed); finished sample runs
are reused. Writes validation/study.json and prints the tables.

usage: cargo build --release && python3 validation/study.py [path/to/hylc] > validation/study.md   (~25 min)
"""
import json
import os
import subprocess
import sys
import time

HYLC = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "target/release/hylc")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORK = os.path.join(ROOT, "validation", "study")
SHARED = os.environ.get("HYLC_SHARED", os.path.join(ROOT, "..", "shared"))
BASKET1 = os.path.join(SHARED, "data/hylc2020/materials/basket1.json")
MATERIAL = BASKET1 if os.path.exists(BASKET1) else "default"
os.makedirs(WORK, exist_ok=True)
results = {}


def sh(args, check=True):
    t = time.time()
    out = subprocess.run([HYLC] + [str(a) for a in args], capture_output=True, text=True)
    if check and out.returncode not in (0, 3):
        sys.exit(f"hylc {' '.join(map(str, args))} failed:\n{out.stderr}")
    return out.stdout, time.time() - t


def rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def table(title, header, rows):
    print(f"\n**{title}**\n")
    print("| " + " | ".join(header) + " |")
    print("| " + " | ".join("---" for _ in header) + " |")
    for r in rows:
        print("| " + " | ".join(str(c) for c in r) + " |")


# ---------------------------------------------------------------- the micro problem: the run's stockinette
ref = os.path.join(WORK, "stockinette_ref.pyp")
if not os.path.exists(ref):
    sh(["generate", "stockinette", "--out", os.path.join(WORK, "stockinette.pyp")])
    sh(["reference", os.path.join(WORK, "stockinette.pyp"), "--out", ref, "--construction", "knitted"])
STRAINS = ["0.1,0,0", "0,0.3,0", "0,0,0.2", "0.2,0.2,-0.1", "-0.2,0,0", "0,0,0,50,0", "0,0,0,0,-50"]


def solve(extra):
    args = ["solve", ref, "--json", "--cold"] + extra
    for z in STRAINS:
        args += ["--z", z]
    out, _ = sh(args)
    return [json.loads(l) for l in out.splitlines() if l.startswith("{")]


def compare(rows, refrows):
    e_psi = max(rel(r["psi"], q["psi"]) for r, q in zip(rows, refrows))
    e_s = 0.0
    for r, q in zip(rows, refrows):
        # components without a stress (∂Ψ̄/∂II is undefined where the other curvature is exactly 0) are skipped
        keys = [k for k in sorted(q["stress"]) if q["stress"][k] is not None and r["stress"][k] is not None]
        a = [r["stress"][k] for k in keys]
        b = [q["stress"][k] for k in keys]
        num = sum((x - y) ** 2 for x, y in zip(a, b)) ** 0.5
        den = sum(y * y for y in b) ** 0.5
        e_s = max(e_s, num / den)
    return e_psi, e_s, sum(r["time"] for r in rows), sum(r["steps"] for r in rows)


# 1. micro solver tolerance
reference = solve(["--tolerance", "1e-12"])
rows, res = [], []
for tol in ["1e-4", "1e-6", "1e-8", "1e-10"]:
    e_psi, e_s, t, steps = compare(solve(["--tolerance", tol]), reference)
    res.append({"tolerance": tol, "psi_err": e_psi, "stress_err": e_s, "time": t, "steps": steps})
    rows.append([tol + (" (default)" if tol == "1e-8" else ""), f"{t:.2f} s", steps, f"{e_psi:.1e}", f"{e_s:.1e}"])
t_ref = sum(r["time"] for r in reference)
results["tolerance"] = res
table(f"Micro solver tolerance (7 cold solves of the generated stockinette; reference: tolerance 1e-12, {t_ref:.2f} s)",
      ["tolerance", "time", "Newton steps", "max rel. error Ψ̄", "max rel. error ∂Ψ̄/∂z"], rows)

# 2. contact quadrature order
reference = solve(["--quadrature", "16"])
rows, res = [], []
for q in [1, 2, 4, 8]:
    e_psi, e_s, t, steps = compare(solve(["--quadrature", str(q)]), reference)
    res.append({"quadrature": q, "psi_err": e_psi, "stress_err": e_s, "time": t, "steps": steps})
    rows.append([str(q) + (" (default)" if q == 4 else ""), f"{t:.2f} s", steps, f"{e_psi:.1e}", f"{e_s:.1e}"])
results["quadrature"] = res
table("Contact quadrature order (same solves; reference: 16 Gauss points per segment)",
      ["points per segment", "time", "Newton steps", "max rel. error Ψ̄", "max rel. error ∂Ψ̄/∂z"], rows)

# 3. warm vs cold start: the five 1D ranges of the quick plan (150 samples)
plan1d = os.path.join(WORK, "plan_1d.json")
out, _ = sh(["plan", "--write", plan1d, "--reduced"])
p = json.load(open(plan1d))
p.update({"count_1d": 30, "count_2d": 0, "pairs": []})
json.dump(p, open(plan1d, "w"), indent=1)
runs = {}
for mode in ["warm", "cold", "tight"]:
    f = os.path.join(WORK, f"ranges_{mode}.jsonl")
    extra = {"warm": [], "cold": ["--cold"], "tight": ["--cold", "--tolerance", "1e-12"]}[mode]
    sh(["sample", ref, "--out", f, "--plan", plan1d] + extra)
    recs = [json.loads(l) for l in open(f)]
    runs[mode] = {r["index"]: r for r in recs}
rows, res = [], []
for mode in ["warm", "cold"]:
    d = [rel(runs[mode][i]["psi"], runs["tight"][i]["psi"]) for i in runs["tight"]
         if runs[mode][i]["psi"] is not None and runs["tight"][i]["psi"] is not None]
    t = sum(r["time"] for r in runs[mode].values())
    ok = sum(r["status"] == "Converged" for r in runs[mode].values())
    res.append({"mode": mode, "time": t, "converged": ok, "max_psi_err": max(d)})
    rows.append([mode, f"{t:.1f} s", f"{ok} / {len(runs[mode])}", f"{max(d):.1e}",
                 f"{sorted(d)[len(d) // 2]:.1e}"])
results["warm_cold"] = res
table("Warm vs cold start (the quick plan's five 1D ranges, 150 samples, generated stockinette; reference: cold "
      "starts at tolerance 1e-12; time = summed solve time)",
      ["start", "solve time", "converged", "max rel. difference Ψ̄", "median"], rows)

# 4. sampling density: quick (474) vs reduced (1 050) on the 27-point held-out grid of `hylc run`
hold = os.path.join(WORK, "holdout.jsonl")
hplan = os.path.join(WORK, "holdout_plan.json")
g = {"s_x": [-0.1, 1 / 6, 0.5], "s_a": [-0.35, 0.0, 0.35], "s_y": [-0.1, 1 / 6, 0.5]}
p = json.load(open(plan1d))
p.update({"count_1d": 0, "count_2d": 0, "pairs": [], "grid": g})
json.dump(p, open(hplan, "w"), indent=1)
sh(["sample", ref, "--out", hold, "--plan", hplan])
rows, res = [], []
for plan in ["quick", "reduced"]:
    f = os.path.join(WORK, f"{plan}.jsonl")
    _, t = sh(["sample", ref, "--out", f, "--plan", plan])
    n = sum(1 for _ in open(f))
    out, _ = sh(["fit", f, "--no-plots", "--preset", "design", "--holdout", hold])
    rep = json.load(open(f.replace(".jsonl", ".fit.json")))
    h = rep["holdout"]
    st = sum(json.loads(l)["time"] for l in open(f))
    res.append({"plan": plan, "samples": n, "solve_time": st, "holdout_rms": h["rms_rel"], "holdout_max": h["max_rel"],
                "all_rms": rep["all"]["rms_rel"]})
    rows.append([plan, n, f"{st:.0f} s", f"{100 * h['rms_rel']:.1f} %", f"{100 * h['max_rel']:.1f} %",
                 f"{100 * rep['all']['rms_rel']:.1f} %"])
results["density"] = res
table("Sampling density (generated stockinette; error of the fitted ψ against the 27 held-out in-plane solves, which "
      "are the reference; summed solve time)",
      ["plan", "samples", "solve time", "held-out error (normwise)", "held-out max", "error on the fitted samples"],
      rows)

# 5. knot counts (FIT1D N_c, FIT2D knots per axis): on the reduced stockinette samples, and on basket if present
sets = [("generated stockinette, reduced plan", os.path.join(WORK, "reduced.jsonl"), hold)]
basket = os.path.join(ROOT, "validation/fit/basket.jsonl")
if os.path.exists(basket):
    sets.append(("original basket, validation plan (held out: the 9×9×9 grid)", basket, basket))
res = []
for name, f, h in sets:
    rows = []
    for k1, k2 in [(7, 5), (11, 9), (15, 13), (21, 17)]:
        tmp = os.path.join(WORK, f"knots_{k1}_{k2}.jsonl")
        if os.path.lexists(tmp):
            os.remove(tmp)
        os.symlink(f, tmp)
        meta = f.replace(".jsonl", ".meta.json")
        tmeta = tmp.replace(".jsonl", ".meta.json")
        if os.path.lexists(tmeta):
            os.remove(tmeta)
        os.symlink(meta, tmeta)
        t0 = time.time()
        sh(["fit", tmp, "--no-plots", "--preset", "design", "--holdout", h, "--knots-1d", k1, "--knots-2d", k2])
        t = time.time() - t0
        rep = json.load(open(tmp.replace(".jsonl", ".fit.json")))
        r1 = max(t["fit_rms_rel"] for t in rep["terms1d"])
        res.append({"set": name, "knots_1d": k1, "knots_2d": k2, "holdout_rms": rep["holdout"]["rms_rel"],
                    "holdout_max": rep["holdout"]["max_rel"], "worst_1d": r1, "time": t})
        rows.append([f"{k1} / {k2}" + (" (default)" if k1 == 11 else ""), f"{t:.2f} s", f"{100 * r1:.2f} %",
                     f"{100 * rep['holdout']['rms_rel']:.2f} %", f"{100 * rep['holdout']['max_rel']:.2f} %"])
    table(f"Knot counts ({name}; the held-out solves are the reference; time = the whole `hylc fit`)",
          ["knots 1D / 2D per axis", "fit time", "worst 1D term error", "held-out error", "held-out max"], rows)
results["knots"] = res


# ---------------------------------------------------------------- the macro scale: stretch-x
def simulate(tag, extra):
    out_dir = os.path.join(WORK, "sim_" + tag)
    out, t = sh(["simulate", "stretch-x", "--material", MATERIAL, "--quiet", "--out", out_dir] + extra)
    log = [json.loads(l) for l in open(os.path.join(out_dir, "log.jsonl"))]
    last = log[-1]
    fx = abs(last["handle_forces"][1][1][0])
    return {"wall": sum(r["wall"] for r in log), "newton": sum(r["newton"] for r in log),
            "unconverged": sum(not r["converged"] for r in log), "force": fx}


mat_name = "basket1" if MATERIAL != "default" else "the default material"
# 6. PSD projection vs regularisation (edge 1 cm)
ref6 = simulate("psd_ref", ["--edge", "0.01", "--psd", "full", "--dt", 1 / 240])
rows, res = [], []
for psd in ["full", "psi", "none"]:
    r = simulate("psd_" + psd, ["--edge", "0.01", "--psd", psd])
    e = rel(r["force"], ref6["force"])
    res.append(dict(r, psd=psd, force_err=e))
    rows.append([psd + (" (default of the built-ins)" if psd == "psi" else ""), f"{r['wall']:.1f} s", r["newton"],
                 r["unconverged"], f"{r['force']:.4f} N", f"{e:.1e}"])
results["psd"] = res
table(f"PSD projection vs regularisation (`stretch-x`, {mat_name}, 1 cm edges, 1 s at 1/60 s; reference: `full` at "
      f"1/240 s, handle force {ref6['force']:.4f} N)",
      ["Hessian", "wall", "Newton iterations", "steps not converged", "handle force at 1 s", "rel. error"], rows)

# 7. macro mesh resolution
edges = [0.03, 0.02, 0.015, 0.01, 0.0075]
ref7 = simulate("edge_ref", ["--edge", "0.005"])
rows, res = [], []
for e in edges:
    r = simulate(f"edge_{e}", ["--edge", e])
    err = rel(r["force"], ref7["force"])
    res.append(dict(r, edge=e, force_err=err))
    rows.append([f"{100 * e:g} cm", f"{r['wall']:.1f} s", r["newton"], f"{r['force']:.4f} N", f"{err:.1e}"])
results["mesh"] = res
table(f"Macro mesh resolution (`stretch-x`, {mat_name}, PSD `psi`, 1/60 s; reference: 0.5 cm edges, "
      f"{ref7['wall']:.0f} s, handle force {ref7['force']:.4f} N)",
      ["edge", "wall", "Newton iterations", "handle force at 1 s", "rel. error"], rows)

# 8. macro step size
ref8 = simulate("dt_ref", ["--edge", "0.01", "--dt", 1 / 480])
rows, res = [], []
for n in [30, 60, 120, 240]:
    r = simulate(f"dt_{n}", ["--edge", "0.01", "--dt", 1 / n])
    err = rel(r["force"], ref8["force"])
    res.append(dict(r, steps_per_second=n, force_err=err))
    rows.append([f"1/{n} s" + (" (default)" if n == 60 else ""), f"{r['wall']:.1f} s", r["newton"], r["unconverged"],
                 f"{r['force']:.4f} N", f"{err:.1e}"])
results["dt"] = res
table(f"Macro step size (`stretch-x`, {mat_name}, 1 cm edges, PSD `psi`; reference: 1/480 s, handle force "
      f"{ref8['force']:.4f} N)",
      ["step", "wall", "Newton iterations", "steps not converged", "handle force at 1 s", "rel. error"], rows)

json.dump(results, open(os.path.join(ROOT, "validation", "study.json"), "w"), indent=1)
