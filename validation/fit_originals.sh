#!/usr/bin/env bash
# Validation of sampling and fitting (validation item d; `docs/results.md`, "Fitted materials of the original patterns")
# on the five original patterns. For each pattern, one sample run of `validation/plans/<pattern>.json`: the five 1D
# ranges (150 samples each, over the range the original material was fitted on: its knot span / 0.95 times its strain
# scale), the three in-plane 2D grids (20×20), and the 9×9×9 in-plane grid of the original displacement data, which is
# held out (never fitted, only predicted). Then `hylc fit` against the original material (`--compare`). Writes
# validation/fit/<pattern>.{jsonl,meta.json,material.json,fit.json,plots/} and prints the tables.
#
#   cargo build --release && validation/fit_originals.sh            # all five (the four other than basket: 81 min on 2 cores, 61 of them rib)
#   validation/fit_originals.sh basket satin                        # some of them
#   PLAN=_1d validation/fit_originals.sh                            # the 1D ranges only (plans/<pattern>_1d.json)
#
# Resumable: rerunning skips finished samples.
set -uo pipefail
cd "$(dirname "$0")/.."
HYLC=${HYLC:-target/release/hylc}
D=${HYLC_SHARED:-../shared}/data/hylc2020
OUT=validation/fit
PLAN=${PLAN:-}
if [ ! -d "$D" ]; then
  echo "skipped: $D not found (set HYLC_SHARED)"; exit 0
fi
mkdir -p "$OUT"
declare -A MAT=([basket]=basket1 [satin]=satin1 [slip_stitch_honeycomb]=honey1 [stockinette]=stock1 [cartridge_belt_rib]=rib1)
PATTERNS=("$@")
[ ${#PATTERNS[@]} -eq 0 ] && PATTERNS=(basket satin slip_stitch_honeycomb stockinette cartridge_belt_rib)
for pat in "${PATTERNS[@]}"; do
  mat=${MAT[$pat]:?unknown pattern $pat}
  flags="--preset design"  # the method's settings, as the original materials were fitted
  [ "$pat" = stockinette ] && flags="--preset design-stockinette"
  echo "== $pat"
  /usr/bin/time -f "sample wall time %e s" "$HYLC" sample "$D/patterns/$pat.pyp" --plan "validation/plans/$pat$PLAN.json" \
    --out "$OUT/$pat$PLAN.jsonl"
  rc=$?
  if [ $rc -ne 0 ] && [ $rc -ne 3 ]; then echo "sample failed ($rc)"; exit $rc; fi
  "$HYLC" fit "$OUT/$pat$PLAN.jsonl" --compare "$D/materials/$mat.json" $flags || exit $?
done
