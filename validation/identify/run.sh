#!/usr/bin/env bash
# Identification of the yarn parameters from the original data (`docs/yarn-parameters.md`): `hylc identify` on the five
# original patterns with the default residual set (a: stored-state equilibrium, b: the six grid points nearest
# z = 0, c: the original material's s_x curve), after the conventions check. With VALIDATE=1 also the held-out
# numbers before and after (the full 9×9×9 grid and the five 1D curves; about 2 × 5 min per pattern on 2 cores).
# Writes validation/identify/<pattern>/{identified.yarn.json, report.json, *.png, log.txt}.
#
#   cargo build --release && validation/identify/run.sh                 # all five, fit only (seconds to minutes)
#   VALIDATE=1 validation/identify/run.sh basket satin                  # with the held-out numbers
#   EXTRA="--residuals b,c" validation/identify/run.sh basket           # another residual set
set -uo pipefail
cd "$(dirname "$0")/../.."
. validation/identify/common.sh
for pat in "${PATTERNS[@]}"; do
  mat=${MAT[$pat]:?unknown pattern $pat}
  flags=${EXTRA:-}
  [ "${VALIDATE:-0}" = 1 ] && flags="$flags --validate"
  mkdir -p "$OUT/$pat"
  echo "== $pat"
  # shellcheck disable=SC2086
  /usr/bin/time -f "wall %e s" "$HYLC" identify "$D/patterns/$pat.pyp" --data "$D/displacements/${DISP[$pat]}" \
    --material "$D/materials/$mat.json" --out "$OUT/$pat" $flags 2>&1 | tee "$OUT/$pat/log.txt"
done
