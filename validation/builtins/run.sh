#!/usr/bin/env bash
# The built-in scenes with the original's basket1 (`docs/results.md`, "Built-in scenes"; the table was
# rerun after the stretch strips moved to the original's handlebar geometry and steps became adaptive): each built-in
# for 1 s at 1/60 s, PSD `psi` (and `full` for stretch-x); prints one table row per run from the run's log.
#
#   cargo build --release && validation/builtins/run.sh        # needs ../shared/data/hylc2020 (skips without it)
#   MATERIAL=satin1 validation/builtins/run.sh                  # another of the original materials
#   RUNS="stretch-x:psi drape-x:psi" validation/builtins/run.sh   # some of the runs (scene:psd)
# Output in $OUT/<scene>-<psd>/ (default out/builtins/<material>); finished runs are kept and reported again on the
# next call (RERUN=1 reruns them).
set -uo pipefail
cd "$(dirname "$0")/../.."
HYLC=${HYLC:-target/release/hylc}
M=${HYLC_SHARED:-../shared}/data/hylc2020/materials/${MATERIAL:-basket1}.json
OUT=${OUT:-out/builtins/${MATERIAL:-basket1}}
if [ ! -f "$M" ]; then echo "skipped: $M not found"; exit 0; fi
mkdir -p "$OUT"
echo "| scene | PSD | exit | wall | Newton iterations | substeps (max per step) | steps not converged | the last step |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
RUNS=${RUNS:-stretch-x:psi stretch-x:full stretch-y:psi drape-x:psi drape-y:psi hanging:psi}
for run in $RUNS; do
  scene=${run%%:*}; psd=${run##*:}
  dir="$OUT/$scene-$psd"
  # resumable: a run that finished (its exit code written) is reported again, not rerun, unless RERUN=1
  if [ "${RERUN:-0}" = 1 ] || [ ! -f "$dir/exit_code" ]; then
    mkdir -p "$dir"
    "$HYLC" simulate "$scene" --material "$M" --psd "$psd" --quiet --out "$dir" > "$dir.txt" 2>&1
    echo $? > "$dir/exit_code"
  fi
  python3 - "$dir/log.jsonl" "$scene" "$psd" "$(cat "$dir/exit_code")" <<'PY'
import json, sys
rs = [json.loads(l) for l in open(sys.argv[1])]
last = rs[-1]
forces = ", ".join(f"{n} ({f[0]:+.3f}, {f[1]:+.3f}, {f[2]:+.3f}) N" for n, f in last["handle_forces"])
# a step that fails even at the smallest substep ends the run (exit code 3) and is not in the log
failed = sum(not r["converged"] for r in rs) + (sys.argv[4] == "3")
print(f"| `{sys.argv[2]}` | `{sys.argv[3]}` | {sys.argv[4]} | {sum(r['wall'] for r in rs):.1f} s | {sum(r['newton'] for r in rs)} | "
      f"{sum(r['substeps'] for r in rs)} ({max(r['substeps'] for r in rs)}) | {failed} | t = {last['time']:.3f} s: "
      f"{forces or 'kinetic energy %.1e J' % last['energy_kinetic']} |")
PY
done
