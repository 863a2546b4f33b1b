#!/usr/bin/env bash
# Sample a plan on a Slurm cluster (`docs/sampling.md`, "Sampling on a cluster"): a job array of n shards (`hylc sample
# --shard k/n`, one sample file per shard) and a merge job that runs after the whole array succeeded (`hylc merge`).
#
#   validation/cluster/slurm_sample.sh PATTERN PLAN OUTDIR N [extra `hylc sample` flags...]
#
# Submits `sbatch --array=0-(N-1)` of this script (role "shard") and `sbatch --dependency=afterok:ARRAY` of it
# (role "merge"), and prints both job ids. Every shard appends to OUTDIR/shard-K-of-N.jsonl and `hylc sample`
# skips the samples a file already holds, so re-running the same command after a failure or a pre-emption
# finishes only what is missing. The merged file is OUTDIR/samples.jsonl (with its sidecar samples.meta.json).
#
# Environment: HYLC (the binary; default: `hylc` on PATH, else target/release/hylc of this checkout),
# SBATCH_FLAGS (extra sbatch flags for both jobs, e.g. "--partition=short --time=02:00:00"),
# CPUS_PER_SHARD (default 1: a shard's chains run on this many threads).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [[ -z "${HYLC:-}" ]]; then
    if command -v hylc >/dev/null; then HYLC="$(command -v hylc)"; else HYLC="$here/../../target/release/hylc"; fi
fi

if [[ $# -lt 4 ]]; then
    echo "usage: $0 PATTERN PLAN OUTDIR N [hylc sample flags...]" >&2
    exit 2
fi
pattern="$1" plan="$2" outdir="$3" n="$4"
shift 4
if ! [[ "$n" =~ ^[1-9][0-9]*$ ]]; then
    echo "error: N: expected a positive number of shards, got '$n'" >&2
    exit 2
fi

shard_file() { echo "$outdir/shard-$1-of-$n.jsonl"; }

case "${HYLC_ROLE:-submit}" in
shard)
    k="$SLURM_ARRAY_TASK_ID"
    export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
    echo "shard $k/$n on $(hostname): $HYLC sample $pattern --plan $plan --shard $k/$n --out $(shard_file "$k") $*"
    # exit code 3 = every selected sample was written but some did not converge: that is a result, not a failure
    rc=0
    "$HYLC" sample "$pattern" --plan "$plan" --shard "$k/$n" --out "$(shard_file "$k")" "$@" || rc=$?
    if [[ $rc -eq 3 ]]; then rc=0; fi
    exit $rc
    ;;
merge)
    files=()
    for ((k = 0; k < n; k++)); do files+=("$(shard_file "$k")"); done
    # `hylc merge` writes a temporary file and renames it, and copies the first shard's sidecar beside it
    "$HYLC" merge "$outdir/samples.jsonl" "${files[@]}"
    ;;
submit)
    mkdir -p "$outdir/logs"
    outdir="$(cd "$outdir" && pwd)"
    common=(--parsable --export="ALL,HYLC=$HYLC" ${SBATCH_FLAGS:-})
    array=$(HYLC_ROLE=shard sbatch "${common[@]}" --job-name=hylc-sample --array="0-$((n - 1))" \
        --cpus-per-task="${CPUS_PER_SHARD:-1}" --output="$outdir/logs/shard-%a.log" \
        "$here/slurm_sample.sh" "$pattern" "$plan" "$outdir" "$n" "$@")
    array="${array%%;*}"
    merge=$(HYLC_ROLE=merge sbatch "${common[@]}" --job-name=hylc-merge --dependency="afterok:$array" \
        --output="$outdir/logs/merge.log" "$here/slurm_sample.sh" "$pattern" "$plan" "$outdir" "$n" "$@")
    merge="${merge%%;*}"
    echo "array job $array (shards 0-$((n - 1)) of $n), merge job $merge; merged file: $outdir/samples.jsonl"
    ;;
*)
    echo "error: HYLC_ROLE: expected submit, shard or merge, got '$HYLC_ROLE'" >&2
    exit 2
    ;;
esac
