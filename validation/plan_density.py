#!/usr/bin/env python3
"""How the cost per sample of a warm-started chain depends on the plan's density (the
projected time of the default plan). The default plan has 150 samples per 1D range and 50 × 50 grids, the reduced
plan 30 and 10 × 10; earlier projections scaled the reduced plan's CPU time by the sample counts (5× and 25×),
i.e. assumed the reduced plan's cost per sample. This script runs chosen chains of the plan at several densities
(the reduced plan's ranges and pairs, only `count_1d` / `count_2d` changed), one chain per process with
RAYON_NUM_THREADS=1, and reports CPU time (user + sys of the child, from getrusage), Newton steps and the warm
median per density, with the CPU time per sample relative to the sparsest density.

Resumable: sample files and CPU times stay in validation/plan_density/ (not committed); delete a pair of files to
measure that run again.

usage: validation/plan_density.py [--hylc BIN] [--chains 0-4,9] [--counts-1d 30,150] [--counts-2d 10,20,50]
                                  [--extra FLAGS] [--tag T] PATTERN ...
  chains: 0-4 are the 1D chains (s_x, s_a, s_y, II00, II11), 5-13 the 2D grids (as in the reduced plan)
"""
import argparse
import json
import os
import subprocess

from inertia_perf import CHAINS, SHARED, shard_list, steps_summary, timed_sample

OUT = "validation/plan_density"


def plan_file(args, c1, c2):
    """The reduced plan with `count_1d` = c1 and `count_2d` = c2, written once."""
    path = f"{OUT}/plan_{c1}_{c2}.json"
    if not os.path.exists(path):
        subprocess.run([args.hylc, "plan", "--reduced", "--write", path], check=True, capture_output=True)
        with open(path) as f:
            plan = json.load(f)
        plan["count_1d"], plan["count_2d"] = c1, c2
        with open(path, "w") as f:
            json.dump(plan, f, indent=2)
    return path


def run(args, pattern, chain, c1, c2):
    """One chain at one density (skipped when its sample file and CPU time exist): (records, CPU seconds)."""
    stem = f"{OUT}/{pattern}_{chain}_{c1}_{c2}{args.tag}"
    cmd = [args.hylc, "sample", f"{SHARED}/data/hylc2020/patterns/{pattern}.pyp", "--plan",
           plan_file(args, c1, c2), "--shard", f"{chain}/14", "--out", stem + ".jsonl"] + args.extra.split()
    cpu = timed_sample(cmd, stem, f"{pattern} {CHAINS[chain]} {c1}/{c2}")
    with open(stem + ".jsonl") as f:
        return [json.loads(line) for line in f], cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hylc", default="target/release/hylc")
    ap.add_argument("--chains", default="0-4")
    ap.add_argument("--counts-1d", default="30,150")
    ap.add_argument("--counts-2d", default="10,20")
    ap.add_argument("--extra", default="")
    ap.add_argument("--tag", default="")
    ap.add_argument("patterns", nargs="+")
    args = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    counts_1d = shard_list(args.counts_1d)
    counts_2d = shard_list(args.counts_2d)
    print("| pattern | chain | samples | CPU (s) | CPU per sample (ms) | per sample against the sparsest | "
          "Newton steps | warm steps, median / mean | not converged |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for pattern in args.patterns:
        for chain in shard_list(args.chains):
            one_d = chain < 5
            base = None
            for count in counts_1d if one_d else counts_2d:
                c1, c2 = (count, counts_2d[0]) if one_d else (counts_1d[0], count)
                recs, cpu = run(args, pattern, chain, c1, c2)
                per = cpu / len(recs)
                base = base or per
                steps, median, mean = steps_summary(recs)
                failed = sum(1 for r in recs if r["status"] != "Converged")
                print(f"| {pattern} | {CHAINS[chain]} | {len(recs)} | {cpu:.1f} | {1e3 * per:.0f} | "
                      f"{per / base:.2f} | {steps} | {median:g} / {mean:.1f} | {failed} |", flush=True)


if __name__ == "__main__":
    main()
