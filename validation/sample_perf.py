#!/usr/bin/env python3
"""Sampling performance (`docs/results.md`, "Sampling cost"): wall time of the reduced plan (1 050 samples) on each
original pattern, warm-started (continuation + secant predictor) and cold (`--cold`), the Newton steps, convergence, and
the warm-versus-cold difference of Psi-bar (hysteresis: both converged, different equilibria). Uses the `hylc sample`
sample files and its own timing line; resumable (a rerun skips finished samples but then reports only the new part's
time, so delete validation/sample_perf/ for a fresh measurement).

usage: validation/sample_perf.py [path/to/hylc] [pattern ...] > table.md
"""
import json
import os
import re
import subprocess
import sys
import time

HYLC = sys.argv[1] if len(sys.argv) > 1 else "target/release/hylc"
SHARED = os.environ.get("HYLC_SHARED", "../shared")
PATTERNS = sys.argv[2:] or ["basket", "satin", "slip_stitch_honeycomb", "stockinette", "cartridge_belt_rib"]
OUT = "validation/sample_perf"
if not os.path.isdir(f"{SHARED}/data/hylc2020"):
    print(f"skipped: {SHARED}/data/hylc2020 not found (set HYLC_SHARED)")
    sys.exit(0)
os.makedirs(OUT, exist_ok=True)


def run(pattern, cold):
    out = f"{OUT}/{pattern}_{'cold' if cold else 'warm'}.jsonl"
    args = [HYLC, "sample", f"{SHARED}/data/hylc2020/patterns/{pattern}.pyp", "--plan", "reduced", "--out", out]
    if cold:
        args.append("--cold")
    t0 = time.time()
    p = subprocess.run(args, capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode not in (0, 3):
        sys.exit(f"{' '.join(args)}: exit {p.returncode}\n{p.stderr}")
    m = re.search(r"([0-9.]+) s\s*$", p.stdout.strip())
    records = {}
    with open(out) as f:
        for line in f:
            r = json.loads(line)
            records[r["index"]] = r
    return (float(m.group(1)) if m else wall), records


print("| pattern | start | wall time | converged | Newton steps (total) |")
print("| --- | --- | --- | --- | --- |")
hyst = []
for pat in PATTERNS:
    res = {}
    for cold in (False, True):
        t, rec = run(pat, cold)
        res[cold] = rec
        conv = sum(1 for r in rec.values() if r["psi"] is not None)
        steps = sum(r["steps"] for r in rec.values())
        print(f"| {pat} | {'cold' if cold else 'warm'} | {t:.1f} s | {conv} / {len(rec)} | {steps} |", flush=True)
    both = [(i, res[False][i], res[True][i]) for i in res[False] if i in res[True]
            and res[False][i]["psi"] is not None and res[True][i]["psi"] is not None]
    diffs = [(abs(w["psi"] - c["psi"]) / max(abs(c["psi"]), 1e-300), w, c) for i, w, c in both]
    n_diff = sum(1 for d in diffs if d[0] > 1e-6)
    worst = max(diffs, key=lambda d: abs(d[1]["psi"] - d[2]["psi"])) if diffs else None
    hyst.append((pat, len(both), n_diff, worst))

print()
print("| pattern | both converged | warm ≠ cold (> 1e-6 relative) | largest difference: z | warm Ψ̄ | cold Ψ̄ |")
print("| --- | --- | --- | --- | --- | --- |")
for pat, n, nd, w in hyst:
    if w is None:
        print(f"| {pat} | {n} | {nd} | – | – | – |")
    else:
        z = ", ".join(f"{v:.3g}" for v in w[1]["z"])
        print(f"| {pat} | {n} | {nd} | ({z}) | {w[1]['psi']:.4g} | {w[2]['psi']:.4g} |")
