#!/usr/bin/env python3
"""Inertia-controlled Newton steps against the shift rule (`docs/micro-solver.md`, "Inertia-controlled Newton steps"):
each chain of the reduced plan solved twice with the same binary, `--no-inertia` (the design rule, bitwise the solver
before the change) and the default, one chain per process with RAYON_NUM_THREADS=1 so that the CPU time (user + sys of
the child, from getrusage) is the solve's own. Prints the speed table (Newton steps, warm median / mean, CPU time,
ratio) and the accuracy table (Ψ̄ of samples converged in both, moved by more than 1e-8 relative, lower / higher).

Resumable: sample files and their CPU times stay in validation/inertia_perf/ (not committed); delete a pair of
files to measure that chain again.

usage: validation/inertia_perf.py [--hylc BIN] [--shards 0-4] [--extra "--crossings reject"] [--tag T]
                                  [--base FLAGS] [--new FLAGS] [--labels A,B] [PATTERN ...]
  shards of the reduced plan: 0-4 are the 1D chains (s_x, s_a, s_y, II00, II11), 5-13 the 2D grids
  --base / --new: the two variants' own flags (default `--no-inertia` / none: design rule against inertia);
  e.g. --base "" --new "--crossings reject" --tag _cr --labels "guard off,guard reject"
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys

SHARED = os.environ.get("HYLC_SHARED", "../shared")
ALL = ["basket", "satin", "slip_stitch_honeycomb", "stockinette", "cartridge_belt_rib"]
OUT = "validation/inertia_perf"
CHAINS = ["s_x", "s_a", "s_y", "II00", "II11", "s_x×s_a", "s_x×s_y", "s_a×s_y", "s_x×II00", "s_x×II11",
          "s_a×II00", "s_a×II11", "s_y×II00", "s_y×II11"]


def shard_list(text):
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def load(path):
    with open(path) as f:
        return {r["index"]: r for r in map(json.loads, f)}


def timed_sample(cmd, stem, label):
    """Runs `cmd` (an `hylc sample … --out stem.jsonl`) with RAYON_NUM_THREADS=1 unless `stem`.jsonl and its CPU
    time `stem`.cpu both exist; returns the CPU seconds (user + sys of the child, from getrusage)."""
    if not (os.path.exists(stem + ".cpu") and os.path.exists(stem + ".jsonl")):
        if os.path.exists(stem + ".jsonl"):
            os.remove(stem + ".jsonl")  # an interrupted run: its CPU time is lost, so measure it again
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        p = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, RAYON_NUM_THREADS="1"))
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if p.returncode not in (0, 3):
            sys.exit(f"{' '.join(cmd)}: exit {p.returncode}\n{p.stderr}")
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        with open(stem + ".cpu", "w") as f:
            f.write(f"{cpu:.3f}\n")
        print(f"  {label}: {cpu:.2f} s CPU", file=sys.stderr, flush=True)
    with open(stem + ".cpu") as f:
        return float(f.read())


def run(args, pattern, shard, variant):
    """Solves one chain (skipped when its sample file and CPU time exist); returns (records, CPU seconds)."""
    stem = f"{OUT}/{pattern}_{shard}_{variant}{args.tag}"
    cmd = [args.hylc, "sample", f"{SHARED}/data/hylc2020/patterns/{pattern}.pyp", "--plan", f"{OUT}/reduced.json",
           "--shard", f"{shard}/14", "--out", stem + ".jsonl"] + args.extra.split()
    cmd += (args.base if variant == "off" else args.new).split()
    cpu = timed_sample(cmd, stem, f"{pattern} {CHAINS[shard]} {variant}")
    return load(stem + ".jsonl"), cpu


def steps_summary(recs):
    """Total Newton steps, and the median and mean of the warm solves (of all solves in a `--cold` run)."""
    warm = [r["steps"] for r in recs if r["start"] != "cold"] or [r["steps"] for r in recs]
    return sum(r["steps"] for r in recs), statistics.median(warm), statistics.mean(warm)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hylc", default="target/release/hylc")
    ap.add_argument("--shards", default="0-4")
    ap.add_argument("--extra", default="", help="more `hylc sample` options for both variants")
    ap.add_argument("--tag", default="", help="suffix of the sample files, to keep runs with other --extra apart")
    ap.add_argument("--base", default="--no-inertia", help="flags of the baseline variant (files `_off`)")
    ap.add_argument("--new", default="", help="flags of the new variant (files `_on`)")
    ap.add_argument("--labels", default="design rule,inertia", help="the two variants' names in the tables")
    ap.add_argument("patterns", nargs="*", default=ALL)
    args = ap.parse_args()
    base, new = args.labels.split(",")
    if not os.path.isdir(f"{SHARED}/data/hylc2020/patterns"):
        print(f"skipped: {SHARED}/data/hylc2020/patterns not found (set HYLC_SHARED)")
        return
    os.makedirs(OUT, exist_ok=True)
    if not os.path.exists(f"{OUT}/reduced.json"):
        subprocess.run([args.hylc, "plan", "--reduced", "--write", f"{OUT}/reduced.json"], check=True,
                       capture_output=True)
    shards = shard_list(args.shards)
    speed, accuracy, per_chain, moved_big = [], [], [], []
    for pat in args.patterns:
        data = {v: ([], 0.0) for v in ("off", "on")}
        groups = {}  # "1D chains" / "2D grids" -> variant -> (records, CPU)
        medians = {"off": [], "on": []}
        for k in shards:
            group = groups.setdefault("1D chains" if k < 5 else "2D grids", {"off": ([], 0.0), "on": ([], 0.0)})
            for v in ("off", "on"):
                recs, cpu = run(args, pat, k, v)
                data[v] = (data[v][0] + list(recs.values()), data[v][1] + cpu)
                group[v] = (group[v][0] + list(recs.values()), group[v][1] + cpu)
                medians[v].append(f"{steps_summary(list(recs.values()))[1]:g}")
        if len(groups) > 1:
            groups["all"] = data
        for name, g in groups.items():
            cells = []
            for v in ("off", "on"):
                total, med, mean = steps_summary(g[v][0])
                cells.append(f"{med:g} / {mean:.1f} | {total} | {g[v][1]:.1f}")
            speed.append(f"| {pat} | {name} | {' | '.join(cells)} | {g['off'][1] / g['on'][1]:.2f}× |")
        per_chain.append(f"| {pat} | {', '.join(medians['off'])} | {', '.join(medians['on'])} |")
        off = {r["index"]: r for r in data["off"][0]}
        on = {r["index"]: r for r in data["on"][0]}
        both = [(off[i], on[i]) for i in off if i in on and off[i]["psi"] is not None and on[i]["psi"] is not None]
        rel = [((b["psi"] - a["psi"]) / abs(a["psi"]), a, b) for a, b in both]
        moved = [x for x in rel if abs(x[0]) > 1e-8]
        status = sum(1 for i in off if i in on and off[i]["status"] != on[i]["status"])
        bins = [sum(1 for x in moved if lo < abs(x[0]) <= hi) for lo, hi in
                ((1e-8, 1e-6), (1e-6, 1e-4), (1e-4, 1e-2), (1e-2, float("inf")))]
        worst = max((abs(x[0]) for x in moved), default=0.0)
        lower = sum(1 for x in moved if x[0] < 0)
        big = [(a, b) for d, a, b in moved if abs(d) > 1e-2]
        counted = all("crossings" in a and "crossings" in b for a, b in big)
        clean = sum(1 for a, b in big if a.get("crossings") == 0 and b.get("crossings") == 0) if counted else "–"
        accuracy.append(f"| {pat} | {len(both)} | {len(moved)} | {' / '.join(map(str, bins))} | {worst:.2g} | "
                        f"{lower} / {len(moved) - lower} | {clean} | {status} |")
        for d, a, b in moved:
            if abs(d) > 1e-2:
                z = ", ".join(f"{v:.3g}" for v in a["z"])
                crossed = f"{a.get('crossings', '–')} / {b.get('crossings', '–')}"
                moved_big.append(f"| {pat} | {a['index']} | ({z}) | {a['psi']:.5g} | {b['psi']:.5g} | {d:+.2g} | "
                                 f"{a['steps']} / {b['steps']} | {crossed} |")
    print(f"Chains: {', '.join(CHAINS[k] for k in shards)}; options: {args.extra or '(defaults)'}; "
          f"{base}: {args.base or '(defaults)'}; {new}: {args.new or '(defaults)'}\n")
    print(f"| pattern | chains | {base}: warm steps, median / mean | total steps | CPU (s) | "
          f"{new}: warm steps, median / mean | total steps | CPU (s) | CPU ratio {base} / {new} |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    print("\n".join(speed))
    print(f"\n| pattern | warm median per chain, {base} | warm median per chain, {new} |")
    print("| --- | --- | --- |")
    print("\n".join(per_chain))
    print("\n| pattern | converged in both | Ψ̄ moved > 1e-8 relative | of them ≤ 1e-6 / ≤ 1e-4 / ≤ 1e-2 / more | "
          "largest | lower / higher | > 1e-2 and crossing-free in both | status changed |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    print("\n".join(accuracy))
    if moved_big:
        print(f"\n| pattern | index | z | Ψ̄ {base} | Ψ̄ {new} | relative | steps {base} / {new} | "
              f"crossings {base} / {new} |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        print("\n".join(moved_big))


if __name__ == "__main__":
    main()
