#!/usr/bin/env python3
"""The README tables of validation item 3d from the fit reports that `validation/fit_originals.sh` writes
(validation/fit/<pattern>.fit.json): our fitted 1D curves f0 + f_k against the original materials (relative RMS
over the original's sampled range, raw and with one common stiffness factor per pattern), and the fitted model
against our own solves (the fitted samples and the held-out 9x9x9 in-plane grid).

usage: validation/fit_table.py [validation/fit] > tables.md
"""
import json
import os
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
