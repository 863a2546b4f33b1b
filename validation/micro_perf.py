#!/usr/bin/env python3
"""Micro-solver performance on the five original patterns (`docs/micro-solver.md`): Newton steps and wall time per
solve, cold (from the reference state) and warm-started from the neighbouring strain of a chain, and where the
time goes. Uses only the `hylc solve --json` timing output.

usage: validation/micro_perf.py [path/to/hylc] [extra hylc solve options ...] > table.md
"""
import json
import os
import statistics
import subprocess
import sys

HYLC = sys.argv[1] if len(sys.argv) > 1 else "target/release/hylc"
EXTRA = sys.argv[2:]
SHARED = os.environ.get("HYLC_SHARED", "../shared")
PATTERNS = ["basket", "satin", "slip_stitch_honeycomb", "stockinette", "cartridge_belt_rib"]
# neighbouring strains with the spacing of a default 150-sample 1D range of the original grid (s_x, s_y in
# [-0.2, 1]: ~0.006 near zero; s_a in [-0.7, 0.7]: up to ~0.02), and a bending chain in steps of 5/m
CHAINS = {
    "s_x 0→0.06": [f"{0.006 * k:.4f},0,0" for k in range(11)],
    "s_a 0→0.2": [f"0,{0.02 * k:.4f},0" for k in range(11)],
    "II00 0→50/m": [f"0,0,0,{5.0 * k:.1f},0" for k in range(11)],
}


def run(pattern, strains, cold):
    args = [HYLC, "solve", f"{SHARED}/data/hylc2020/patterns/{pattern}.pyp", "--json"]
    for z in strains:
        args += ["--z", z]
    if cold:
        args.append("--cold")
    args += EXTRA
    out = subprocess.run(args, capture_output=True, text=True)
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def main():
    if not os.path.isdir(f"{SHARED}/data/hylc2020/patterns"):
        print(f"SKIPPED: {SHARED}/data/hylc2020/patterns not found (set HYLC_SHARED)")
        return
    print("| pattern | chain | warm steps (median / max) | warm time per solve (ms, mean) | cold steps (median / max) "
          "| cold time per solve (ms, mean) | converged | time share warm: assembly / contact / factorisation / "
          "line search |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    all_warm, all_cold = [], []
    for p in PATTERNS:
        for name, chain in CHAINS.items():
            warm = run(p, chain, cold=False)[1:]  # the first solve of a chain is cold
            cold = run(p, chain[1:], cold=True)
            ok = sum(r["status"] == "Converged" for r in warm + cold)
            ws = [r["steps"] for r in warm]
            cs = [r["steps"] for r in cold]
            all_warm += ws
            all_cold += cs
            wt = sum(r["time"] for r in warm) / len(warm) * 1e3
            ct = sum(r["time"] for r in cold) / len(cold) * 1e3
            tot = {k: sum(r["timings"][k] for r in warm) for k in ["assembly", "contact", "factorization", "line_search"]}
            s = sum(r["time"] for r in warm)
            share = " / ".join(f"{100 * tot[k] / s:.0f} %" for k in ["assembly", "contact", "factorization", "line_search"])
            print(f"| {p} | {name} | {statistics.median(ws):g} / {max(ws)} | {wt:.1f} | {statistics.median(cs):g} / "
                  f"{max(cs)} | {ct:.1f} | {ok}/{len(warm) + len(cold)} | {share} |")


    print()
    print(f"all chains: warm median {statistics.median(all_warm):g} steps over {len(all_warm)} solves, "
          f"cold median {statistics.median(all_cold):g} over {len(all_cold)}")


if __name__ == "__main__":
    main()
