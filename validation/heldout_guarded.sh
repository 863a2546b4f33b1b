#!/usr/bin/env bash
# The held-out 9×9×9 error of the knits with a defined Ψ̄ (`docs/results.md`, "Held-out error with a defined Ψ̄", the
# rows "the way to each start checked too"): per pattern, the wide plan sampled with the crossing guard (stockinette and
# rib `--crossings reject`, honeycomb `--starts warm+cold`), fitted with and without `--compression-residual
# --asymmetric-shear`; the held-out grid sampled on its own with `--starts warm+cold` (the lowest in-fabric equilibrium
# of the warm and the cold start, every start's way checked); then `fit_candidates.py` (all held-out samples and the
# mirror-consistent ones).
#
#   cargo build --release && validation/heldout_guarded.sh                    # the three knits (about 1 h CPU)
#   validation/heldout_guarded.sh slip_stitch_honeycomb                       # one of them
#
# Resumable: every `hylc sample` skips finished samples. Output in $OUT (default out/heldout_guarded).
set -uo pipefail
cd "$(dirname "$0")/.."
HYLC=${HYLC:-target/release/hylc}
D=${HYLC_SHARED:-../shared}/data/hylc2020
OUT=${OUT:-out/heldout_guarded}
if [ ! -d "$D" ]; then
  echo "skipped: $D not found (set HYLC_SHARED)"; exit 0
fi
if [ ! -x "$HYLC" ]; then echo "$HYLC not found: cargo build --release first"; exit 2; fi
mkdir -p "$OUT"
"$HYLC" plan --holdout --write "$OUT/holdout.json" > /dev/null || exit $?
PATTERNS=("$@")
[ ${#PATTERNS[@]} -eq 0 ] && PATTERNS=(stockinette slip_stitch_honeycomb cartridge_belt_rib)
for pat in "${PATTERNS[@]}"; do
  case $pat in
    slip_stitch_honeycomb) guard=(--starts warm+cold) ;;
    stockinette|cartridge_belt_rib) guard=(--crossings reject) ;;
    *) echo "no wide plan for $pat"; exit 2 ;;
  esac
  echo "== $pat"
  wide=$OUT/${pat}_wide.jsonl
  /usr/bin/time -f "wide plan: %e s wall, %U s user" "$HYLC" sample "$D/patterns/$pat.pyp" \
    --plan "validation/plans/${pat}_wide.json" --out "$wide" "${guard[@]}" | tail -n 1
  "$HYLC" fit "$wide" --preset design --out "$OUT/${pat}_wide.material.json" --report "$OUT/${pat}_wide.fit.json" --no-plots \
    | grep -E "all fitted|held-out"
  "$HYLC" fit "$wide" --preset design --compression-residual --asymmetric-shear --out "$OUT/${pat}_wide_ext.material.json" \
    --report "$OUT/${pat}_wide_ext.fit.json" --no-plots | grep -E "all fitted|held-out"
  held=$OUT/${pat}_holdout.jsonl
  /usr/bin/time -f "held-out grid: %e s wall, %U s user" "$HYLC" sample "$D/patterns/$pat.pyp" \
    --plan "$OUT/holdout.json" --out "$held" --starts warm+cold | tail -n 1
  HYLC=$HYLC python3 validation/fit_candidates.py "$held" "$OUT/${pat}_wide.material.json" \
    "$OUT/${pat}_wide_ext.material.json" | grep -v "^  z = "
done
