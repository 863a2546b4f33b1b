#!/usr/bin/env python3
"""The README tables of validation item 3d from the fit reports that `validation/fit_originals.sh` writes
(validation/fit/<pattern>.fit.json): our fitted 1D curves f0 + f_k against the original materials (relative RMS
over the original's sampled range, raw and with one common stiffness factor per pattern), and the fitted model
against our own solves (the fitted samples and the held-out 9x9x9 in-plane grid), and the held-out error by region
(when the sample files are in validation/fit; `HYLC` names the binary, default target/release/hylc).

usage: validation/fit_table.py [validation/fit] > tables.md
"""
import json
import math
import os
import subprocess
import sys

DIR = sys.argv[1] if len(sys.argv) > 1 else "validation/fit"
PATTERNS = ["basket", "satin", "slip_stitch_honeycomb", "stockinette", "cartridge_belt_rib"]
reports = {}
for p in PATTERNS:
    # the full validation plan, else the 1D-only one (PLAN=_1d)
    for f in (os.path.join(DIR, p + ".fit.json"), os.path.join(DIR, p + "_1d.fit.json")):
        if os.path.exists(f):
            reports[p] = json.load(open(f))
            break

print("| pattern | f0 + f_k raw: s_x, s_a, s_y, II00, II11 | common factor c | c × (f0 + f_k): s_x, s_a, s_y, II00, II11 | f_k alone (raw) |")
print("| --- | --- | --- | --- | --- |")
for p, r in reports.items():
    c = r.get("compare_1d")
    if not c:
        continue
    raw = ", ".join(f"{x['fit_rms_rel']:.2f}" for x in c["ranges"])
    sc = ", ".join(f"{x['scaled_fit_rms_rel']:.3f}" for x in c["ranges"])
    fk = ", ".join(f"{x['term_rms_rel']:.2f}" for x in c["ranges"])
    print(f"| {p} | {raw} | {c['common_scale']:.4f} | {sc} | {fk} |")
print()
print("| pattern | samples (converged) | f0 (J/m²) | 1D terms: model RMS | in-plane 2D terms: model RMS | all fitted: RMS / max | held-out 9×9×9 grid: RMS / max (converged) |")
print("| --- | --- | --- | --- | --- | --- | --- |")
for p, r in reports.items():
    t1 = ", ".join(f"{t['model']['rms_rel']:.1e}" for t in r["terms1d"])
    t2 = ", ".join(f"{t['model']['rms_rel']:.1e}" for t in r["terms2d"]) or "–"
    h = r.get("holdout") or {}
    hs = f"{h['rms_rel']:.3f} / {h['max_rel']:.3f} ({h['n_samples']})" if h else "–"
    print(f"| {p} | {r['samples']} ({r['converged']}) | {r['constant']:.4g} | {t1} | {t2} | "
          f"{r['all']['rms_rel']:.3f} / {r['all']['max_rel']:.3f} | {hs} |")

# The held-out error by region: the fitted material (`hylc material --z-file --json`) against the held-out samples
# (the plan's `grid`, after its 1D ranges and 2D pairs), normwise relative RMS. Needs the sample files in fit/,
# which are not committed (rerun fit_originals.sh).
HYLC = os.environ.get("HYLC", "target/release/hylc")
REGIONS = [
    ("held-out, all", lambda z: True),
    ("with s_x or s_y < 0", lambda z: z[0] < 0 or z[2] < 0),
    ("without compression", lambda z: z[0] >= 0 and z[2] >= 0),
    ("inside the 1D ranges (s_x, s_y ≤ 0.78)", lambda z: max(z[0], z[2]) <= 0.78),
]


def holdout_by_region(pattern):
    samples = os.path.join(DIR, pattern + ".jsonl")
    material = os.path.join(DIR, pattern + ".material.json")
    plan_file = os.path.join(os.path.dirname(os.path.abspath(DIR)), "plans", pattern + ".json")
    if not all(os.path.exists(f) for f in (samples, material, plan_file)) or not os.path.exists(HYLC):
        return None
    plan = json.load(open(plan_file))
    n_fitted = len(plan["ranges"]) * plan["count_1d"] + len(plan["pairs"]) * plan["count_2d"] ** 2
    held = [r for r in map(json.loads, open(samples)) if r["index"] >= n_fitted and r["psi"] is not None]
    if not held:
        return None
    zs = "".join(f"{z[0]},{z[1]},{z[2]},{z[3]},0,{z[4]}\n" for z in (r["z"] for r in held))
    out = subprocess.run([HYLC, "material", material, "--z-file", "/dev/stdin", "--json"], input=zs,
                         capture_output=True, text=True, check=True).stdout
    psi = [json.loads(line)["psi"] for line in out.splitlines() if line.startswith("{")]
    assert len(psi) == len(held), f"{pattern}: {len(psi)} model values for {len(held)} samples"
    cells = []
    for _, inside in REGIONS:
        sel = [(r["psi"], p) for r, p in zip(held, psi) if inside(r["z"])]
        err = math.sqrt(sum((p - s) ** 2 for s, p in sel) / max(sum(s * s for s, _ in sel), 1e-300))
        cells.append(f"{err:.3f} ({len(sel)})" if sel else "–")
    return cells


rows = [(p, holdout_by_region(p)) for p in reports]
rows = [(p, c) for p, c in rows if c]
if rows:
    print()
    print("| pattern | " + " | ".join(name for name, _ in REGIONS) + " |")
    print("| --- " * (len(REGIONS) + 1) + "|")
    for p, c in rows:
        print(f"| {p} | " + " | ".join(c) + " |")
