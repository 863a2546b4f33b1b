#!/usr/bin/env python3
"""What a sampling plan that stops short of the compressed corners would save and lose (target: the default
plan in ≤ 30 min). From one finished sample file (e.g. `hylc sample P.pyp --plan default --out P.jsonl`):

- the share of the summed solve time (the records' `time`) in the samples with s_x ≥ CUT and s_y ≥ CUT, for
  each CUT given: what a plan with those ranges would cost relative to the run;
- with `--fit`: a material fitted to all records (`hylc fit`) and one fitted to the records with s_x, s_y ≥ the
  first CUT only (the sidecar `.meta.json` copied, so both fits see the same plan), both evaluated with
  `hylc material --z-file` on every converged sample. Reported per region (kept / corners) as the median
  relative error |ψ − Ψ̄| / Ψ̄ and the RMS error relative to the RMS of Ψ̄.

The cut file is an approximation of a cut plan: a plan with the range [CUT, max] would place its samples more
densely in the kept range and start its chains there.

- the share of the solve time in the compressed half-planes of the six grids that pair a stretch with another
  strain (s_x < 0 on s_x×s_a, s_x×II00, s_x×II11; s_y < 0 on s_a×s_y, s_y×II00, s_y×II11), where the default
  fit zeroes the 2D residual; with `--perturb F`: Ψ̄ of those samples scaled by F, refitted, and the largest
  relative change of ψ at the other samples (0 would mean the default fit does not use their values).

Work files go to validation/plan_cut/ (not committed).

usage: validation/plan_cut.py [--hylc BIN] [--cuts -0.44,-0.3,-0.2] [--fit] [--perturb F]... SAMPLES.jsonl
"""
import argparse
import json
import math
import os
import shutil
import statistics
import subprocess

OUT = "validation/plan_cut"


def kept(record, cut):
    return record["z"][0] >= cut and record["z"][2] >= cut


def in_half_plane(plan, record):
    """Whether a grid sample lies in the compressed half-plane of a pair of a stretch with another strain."""
    i, start = record["index"], plan["n1d"]
    if i < start:
        return False
    p = (i - start) // plan["n2d"]
    if p >= len(plan["pairs"]):
        return False
    a, b = plan["pairs"][p]
    stretch = [c for c in (a, b) if c in ("s_x", "s_y")]
    if len(stretch) != 1:
        return False
    return record["z"][0 if stretch[0] == "s_x" else 2] < 0


def read_plan(meta):
    """The parts of the sidecar's plan that locate the grids (uniform counts only)."""
    with open(meta) as f:
        plan = json.load(f)["plan"]
    if plan.get("counts_1d") or plan.get("counts_2d") or plan.get("ranges_2d") is not None:
        raise SystemExit(f"{meta}: plans with per-range counts are not handled")
    return {"n1d": 5 * plan["count_1d"], "n2d": plan["count_2d"] ** 2, "pairs": plan["pairs"]}


def errors(records, psi, idx):
    e = [psi[i] - records[i]["psi"] for i in idx]
    y = [records[i]["psi"] for i in idx]
    rms = math.sqrt(sum(v * v for v in e) / len(e)) / math.sqrt(sum(v * v for v in y) / len(y))
    median = statistics.median(abs(a) / abs(b) for a, b in zip(e, y))
    return median, rms


def fit_and_evaluate(args, stem, source_meta, records, zfile):
    """Fit `stem`.jsonl (its sidecar copied from `source_meta`), evaluate at every record: ψ per record."""
    shutil.copy(source_meta, stem + ".meta.json")
    subprocess.run([args.hylc, "fit", stem + ".jsonl", "--no-plots", "--preset", "design"], check=True, capture_output=True)
    out = subprocess.run([args.hylc, "material", stem + ".material.json", "--z-file", zfile, "--json"],
                         check=True, capture_output=True, text=True).stdout
    psi = [json.loads(line)["psi"] for line in out.splitlines() if line.strip()]
    assert len(psi) == len(records), f"{len(psi)} evaluations for {len(records)} records"
    return psi


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--hylc", default="target/release/hylc")
    ap.add_argument("--cuts", default="-0.44,-0.3,-0.2")
    ap.add_argument("--fit", action="store_true")
    ap.add_argument("--perturb", type=float, action="append", default=[])
    ap.add_argument("samples")
    args = ap.parse_args()
    cuts = [float(c) for c in args.cuts.split(",")]
    meta = args.samples.removesuffix(".jsonl") + ".meta.json"
    for path in (args.samples, meta):
        if not os.path.exists(path):
            raise SystemExit(f"{path}: no such file (a sample file of `hylc sample` and its sidecar are needed)")
    records = []
    with open(args.samples) as f:
        for n, line in enumerate(f, 1):
            if line.strip():
                try:
                    record = json.loads(line)
                except json.JSONDecodeError as e:
                    raise SystemExit(f"{args.samples}:{n}: not a JSON record ({e})")
                missing = [k for k in ("index", "z", "psi", "status", "time") if k not in record]
                if missing:
                    raise SystemExit(f"{args.samples}:{n}: not a sample record (no {', '.join(missing)})")
                records.append(record)
    if not records:
        raise SystemExit(f"{args.samples}: no records")
    total = sum(r["time"] for r in records)
    print(f"{args.samples}: {len(records)} samples, {total:.1f} s of solve time")
    print("| cut | samples kept | share of the solve time | not converged among the kept |")
    print("| --- | --- | --- | --- |")
    for cut in cuts:
        k = [r for r in records if kept(r, cut)]
        share = sum(r["time"] for r in k) / total
        failed = sum(r["status"] != "Converged" for r in k)
        print(f"| {cut} | {len(k)} of {len(records)} | {share:.3f} | {failed} |")
    plan = read_plan(meta)
    half = [in_half_plane(plan, r) for r in records]
    share = sum(r["time"] for r, h in zip(records, half) if h) / total
    print(f"\ncompressed half-planes of the stretch pairs: {sum(half)} samples, {share:.3f} of the solve time")
    if not (args.fit or args.perturb):
        return
    os.makedirs(OUT, exist_ok=True)
    name = os.path.basename(args.samples).removesuffix(".jsonl")
    zfile = f"{OUT}/{name}_z.txt"
    with open(zfile, "w") as f:
        for r in records:
            z = r["z"]
            f.write(f"{z[0]!r},{z[1]!r},{z[2]!r},{z[3]!r},0,{z[4]!r}\n")
    shutil.copy(args.samples, f"{OUT}/{name}_full.jsonl")
    with open(f"{OUT}/{name}_cut.jsonl", "w") as f:
        for r in records:
            if kept(r, cuts[0]):
                f.write(json.dumps(r) + "\n")
    full = fit_and_evaluate(args, f"{OUT}/{name}_full", meta, records, zfile)
    for factor in args.perturb:
        stem = f"{OUT}/{name}_perturb{factor}"
        with open(stem + ".jsonl", "w") as f:
            for r, h in zip(records, half):
                if h and r["psi"] is not None:
                    r = dict(r, psi=r["psi"] * factor)
                f.write(json.dumps(r) + "\n")
        psi = fit_and_evaluate(args, stem, meta, records, zfile)
        others = [i for i, h in enumerate(half) if not h and records[i]["status"] == "Converged"]
        change = max(abs(psi[i] - full[i]) / abs(full[i]) for i in others)
        moved = sum(abs(psi[i] - full[i]) > 1e-12 * abs(full[i]) for i in others)
        print(f"half-planes' Ψ̄ × {factor}: ψ at the other {len(others)} converged samples moves by up to "
              f"{change:.3f} relative ({moved} move by more than 1e-12)")
    if not args.fit:
        return
    cut = fit_and_evaluate(args, f"{OUT}/{name}_cut", meta, records, zfile)
    conv = [i for i, r in enumerate(records) if r["status"] == "Converged"]
    inside = [i for i in conv if kept(records[i], cuts[0])]
    corners = [i for i in conv if not kept(records[i], cuts[0])]
    print(f"\nfits: all records against s_x, s_y >= {cuts[0]} only; errors on the converged samples")
    print("| region | samples | all: median rel. | all: RMS / RMS(Ψ̄) | cut: median rel. | cut: RMS / RMS(Ψ̄) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for label, idx in [(f"s_x, s_y >= {cuts[0]}", inside), ("corners", corners)]:
        if not idx:
            continue
        (ma, ra), (mb, rb) = errors(records, full, idx), errors(records, cut, idx)
        print(f"| {label} | {len(idx)} | {ma:.3f} | {ra:.3f} | {mb:.3f} | {rb:.3f} |")


if __name__ == "__main__":
    main()
