#!/usr/bin/env bash
# What drives the fit (`docs/yarn-parameters.md`, "What drives the fit"): for each original pattern, at the parameters
# `run.sh` identified (validation/identify/<pattern>/identified.yarn.json), θ ∂Ψ̄/∂θ along the original material's five
# 1D ranges (study.png) and the parameter correlations of the default residual set there (report.json), written to
# validation/identify/<pattern>/drivers/. Run run.sh first.
#
#   validation/identify/study.sh [pattern …]
set -uo pipefail
cd "$(dirname "$0")/../.."
. validation/identify/common.sh
for pat in "${PATTERNS[@]}"; do
  mat=${MAT[$pat]:?unknown pattern $pat}
  yarn="$OUT/$pat/identified.yarn.json"
  [ -f "$yarn" ] || { echo "$pat: $yarn missing: run validation/identify/run.sh $pat first"; continue; }
  mkdir -p "$OUT/$pat/study"
  echo "== $pat"
  "$HYLC" identify "$D/patterns/$pat.pyp" --data "$D/displacements/${DISP[$pat]}" --material "$D/materials/$mat.json" \
    --yarn "$yarn" --max-iterations 0 --no-conventions --study --out "$OUT/$pat/drivers" 2>&1 | tee "$OUT/$pat/drivers/log.txt"
done
