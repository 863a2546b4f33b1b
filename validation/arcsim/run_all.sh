#!/usr/bin/env bash
# The original's 42 cloth scenes: runs every ARCSim-HYLC scene of
# ../shared/data/arcsim-hylc/tests/{1D,2D,small}/conf with `hylc simulate` (read as ARCSim scenes, converted on the
# fly), then writes validation/arcsim/results.md (one row per scene: wall time per simulated second, Newton
# iterations per step, substeps, steps not converged, final elastic energy and bounding box, handle forces of the
# stretch scenes) and one PNG per stretch family (handle |F| over time for the five materials, 1D and 2D) with
# summarize.py. Each run's frames, log.jsonl, stdout/stderr, exit code and wall time stay in $OUT/<set>/<scene>/;
# the handle forces over time of each stretch scene in $OUT/<set>/<scene>/handle_forces.csv.
#
#   cargo build --release && validation/arcsim/run_all.sh             # the first 0.5 s of each scene
#   FULL=1 validation/arcsim/run_all.sh                               # full length (end_time: 1 to 2.5 s)
#   DURATION=0.2 validation/arcsim/run_all.sh 2D/stock_stretchX       # some scenes (<set>/<scene> or a regex)
#   SUMMARY_ONLY=1 validation/arcsim/run_all.sh                       # only rebuild the table and plots
#   RERUN=1 validation/arcsim/run_all.sh                              # rerun scenes already done (default: resume)
#   FLAGS="--time-tol off" validation/arcsim/run_all.sh               # extra `hylc simulate` flags (here: one
#                                                                     # implicit step per frame, as results.md)
#
# Environment: HYLC (binary, default target/release/hylc), HYLC_SHARED (default ../shared), OUT (default
# out/arcsim), FLAGS (extra flags for every `hylc simulate`, named in the table), DURATION (default 0.5), FULL=1 (the scenes' own end_time), SUMMARY_ONLY=1, RESULTS (the table,
# default validation/arcsim/results.md), PLOTS (the PNGs' folder, default validation/arcsim).
set -uo pipefail
cd "$(dirname "$0")/../.."
HYLC=${HYLC:-target/release/hylc}
D=${HYLC_SHARED:-../shared}/data/arcsim-hylc
OUT=${OUT:-out/arcsim}
DURATION=${DURATION:-0.5}
FULL=${FULL:-0}
if [ ! -d "$D/tests" ]; then
  echo "skipped: $D not found (set HYLC_SHARED)"; exit 0
fi
if [ ! -x "$HYLC" ]; then
  echo "error: $HYLC not found (cargo build --release, or set HYLC)"; exit 2
fi
mkdir -p "$OUT"
select_re=""
if [ $# -gt 0 ]; then select_re=$(IFS='|'; echo "$*"); fi

if [ "${SUMMARY_ONLY:-0}" != 1 ]; then
  for f in "$D"/tests/{1D,2D,small}/conf/*.json; do
    set_name=$(basename "$(dirname "$(dirname "$f")")")
    scene=$(basename "$f" .json)
    id="$set_name/$scene"
    if [ -n "$select_re" ] && ! [[ "$id" =~ ^($select_re)$ ]] && ! [[ "$id" =~ $select_re ]]; then continue; fi
    dir="$OUT/$id"
    tag=$([ "$FULL" = 1 ] && echo full || echo "$DURATION")
    # resumable: a scene finished with the same duration is kept unless RERUN=1
    if [ "${RERUN:-0}" != 1 ] && [ -f "$dir/exit_code" ] && [ "$(cat "$dir/duration" 2>/dev/null)" = "$tag" ]; then
      echo "== $id: done before (exit code $(cat "$dir/exit_code")), kept"; continue
    fi
    rm -rf "$dir"; mkdir -p "$dir"
    echo "$tag" > "$dir/duration"
    args=(simulate "$f" --quiet --out "$dir")
    # shellcheck disable=SC2206 # FLAGS is split into words on purpose
    args+=(${FLAGS:-})
    if [ "$FULL" != 1 ]; then args+=(--duration "$DURATION"); fi
    if [ "$FULL" = 1 ]; then echo "== $id (full length)"; else echo "== $id (first $DURATION s)"; fi
    start=$(date +%s.%N)
    "$HYLC" "${args[@]}" > "$dir/stdout.txt" 2> "$dir/stderr.txt"
    rc=$?
    end=$(date +%s.%N)
    echo "$rc" > "$dir/exit_code"
    awk -v a="$start" -v b="$end" 'BEGIN { printf "%.3f\n", b - a }' > "$dir/wall_seconds"
    grep " steps in " "$dir/stdout.txt"
    if [ $rc -ne 0 ]; then echo "exit code $rc: $(grep -v warning "$dir/stderr.txt" | tail -n 1)"; fi
  done
fi

python3 validation/arcsim/summarize.py --out "$OUT" --results "${RESULTS:-validation/arcsim/results.md}" \
  --plots "${PLOTS:-validation/arcsim}"
