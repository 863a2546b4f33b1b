#!/usr/bin/env bash
# Multi-start samples (`docs/sampling.md`, "Multi-start samples"): the cost and the effect of `hylc sample --starts` on
# the reduced plans of the original rib and honeycomb. Per pattern, the plan is sampled warm (today's default), cold
# (`--cold`), warm+cold and all (MODES); reported: wall time per mode, samples whose kept Ψ̄ changes against warm
# (count, by how much), and the warm-first vs cold-first agreement (`hylc compare-samples`, relative tolerance $REL).
#
#   cargo build --release && validation/starts/run.sh           # needs ../shared/data/hylc2020 (skips without it)
#   PATTERNS=rib SHARD=0/14 validation/starts/run.sh            # a subset: shard k/n of the plan's chains
#   PATTERNS=plain SHARD=0/14 validation/starts/run.sh          # a generated kind instead (no ../shared needed)
# Resumable: each mode's sample file is resumed by `hylc sample`; a mode that finished (`<mode>.done`) is not run
# again, and its wall time (summed over the invocations that wrote to it, in `<mode>.wall`) is reported again.
# Output in $OUT/<pattern>[-shard-k-n]/ (default out/starts).
set -uo pipefail
cd "$(dirname "$0")/../.."
HYLC=${HYLC:-target/release/hylc}
SHARED=${HYLC_SHARED:-../shared}
OUT=${OUT:-out/starts}
REL=${REL:-1e-6}
PLAN=${PLAN:-reduced}
PATTERNS=${PATTERNS:-rib honeycomb}
MODES=${MODES:-warm cold warm+cold all warm-guarded cold-guarded}
if [ ! -x "$HYLC" ]; then echo "$HYLC not found: cargo build --release first"; exit 2; fi
for name in $PATTERNS; do
  case "$name" in
    rib) pat=$SHARED/data/hylc2020/patterns/cartridge_belt_rib.pyp ;;
    honeycomb) pat=$SHARED/data/hylc2020/patterns/slip_stitch_honeycomb.pyp ;;
    *) pat=$name ;;
  esac
  if [ "$pat" != "$name" ] && [ ! -f "$pat" ]; then
    echo "skipped $name: $pat not found (set HYLC_SHARED to the shared data directory)"
    continue
  fi
  dir=$OUT/$name${SHARD:+-shard-${SHARD/\//-}}
  mkdir -p "$dir"
  echo "== $name ($pat), plan $PLAN${SHARD:+, shard $SHARD}, load $(cut -d' ' -f1-3 /proc/loadavg)"
  for mode in $MODES; do
    f=$dir/$mode.jsonl
    if [ -f "$dir/$mode.done" ]; then echo "$mode: finished earlier"; continue; fi
    case $mode in
      warm) extra=() ;;
      cold) extra=(--cold) ;;
      warm+cold) extra=(--starts warm+cold) ;;
      all) extra=(--starts all --disagreement "$REL") ;;
      warm-guarded) extra=(--crossings reject) ;;
      cold-guarded) extra=(--cold --crossings reject) ;;
      *) echo "unknown mode $mode (warm, cold, warm+cold, all, warm-guarded, cold-guarded)"; exit 2 ;;
    esac
    t0=$(date +%s.%N)
    "$HYLC" sample "$pat" --plan "$PLAN" --out "$f" ${SHARD:+--shard "$SHARD"} "${extra[@]}" \
      > "$dir/$mode.log" 2>&1
    code=$?
    t1=$(date +%s.%N)
    echo "$t0 $t1" | awk '{printf "%.3f\n", $2 - $1}' >> "$dir/$mode.wall"
    tail -n 1 "$dir/$mode.log"
    # exit 0, or 3 when a sample did not converge: finished; anything else (e.g. interrupted): resume next time
    if [ $code = 0 ] || [ $code = 3 ]; then touch "$dir/$mode.done"; else echo "$mode: exit $code, not finished"; fi
  done
  echo "-- warm-first vs cold-first (relative tolerance $REL):"
  "$HYLC" compare-samples "$dir/warm.jsonl" "$dir/cold.jsonl" --rel "$REL" | tail -n 1
  for mode in warm+cold all; do
    [ -f "$dir/$mode.jsonl" ] || continue
    echo "-- $mode against cold-first:"
    "$HYLC" compare-samples "$dir/$mode.jsonl" "$dir/cold.jsonl" --rel "$REL" | tail -n 1
    if [ -f "$dir/cold-guarded.jsonl" ]; then
      echo "-- $mode against cold-first with the crossing guard:"
      "$HYLC" compare-samples "$dir/$mode.jsonl" "$dir/cold-guarded.jsonl" --rel "$REL" | tail -n 1
    fi
  done
  if [ -f "$dir/warm-guarded.jsonl" ] && [ -f "$dir/cold-guarded.jsonl" ]; then
    echo "-- warm-first vs cold-first, both with the crossing guard:"
    "$HYLC" compare-samples "$dir/warm-guarded.jsonl" "$dir/cold-guarded.jsonl" --rel "$REL" | tail -n 1
  fi
  python3 - "$dir" "$REL" <<'PY'
import json, os, statistics, sys
d, rel = sys.argv[1], float(sys.argv[2])
def load(mode):
    p = os.path.join(d, mode + ".jsonl")
    if not os.path.exists(p):
        return {}
    return {r["id"]: r for r in (json.loads(l) for l in open(p) if l.endswith("\n"))}
def wall(mode):
    p = os.path.join(d, mode + ".wall")
    return sum(float(x) for x in open(p)) if os.path.exists(p) else float("nan")
def conv(r):
    return r["psi"] if r and r["status"] == "Converged" and r["psi"] is not None else None
runs = {m: load(m) for m in ("warm", "cold", "warm+cold", "all", "warm-guarded", "cold-guarded")}
print("| mode | samples | converged | wall (s) | Σ solve time (s) |")
print("| --- | --- | --- | --- | --- |")
for m, rs in runs.items():
    print(f"| {m} | {len(rs)} | {sum(conv(r) is not None for r in rs.values())} | {wall(m):.1f} | "
          f"{sum(r['time'] for r in rs.values()):.1f} |")
warm = runs["warm"]
for mode in ("warm+cold", "all"):
    wc = runs[mode]
    if not wc:
        continue
    changed, gained = [], 0
    for i, r in wc.items():
        a, b = conv(warm.get(i)), conv(r)
        if a is None and b is not None:
            gained += 1
        elif a is not None and b is not None and abs(a - b) > rel * max(abs(a), abs(b)):
            changed.append(((a - b) / abs(a) if a else float("inf"), a, b, r["z"]))
    kept = {}
    for r in wc.values():
        kept[r.get("kept")] = kept.get(r.get("kept"), 0) + 1
    print(f"{mode} against warm: {len(wc)} samples, kept {kept}; {len(changed)} converged in both change by more "
          f"than {rel:g} relative, {gained} converge only with another start")
    if changed:
        ch = sorted(c[0] for c in changed)
        print(f"  relative decrease of Ψ̄: median {statistics.median(ch):.3g}, max {ch[-1]:.3g}")
        for c in sorted(changed, reverse=True)[:5]:
            print(f"  z = {c[3]}: warm {c[1]:.6g} → kept {c[2]:.6g} J/m² ({c[0]:.3g})")
PY
done
