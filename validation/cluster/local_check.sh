#!/usr/bin/env bash
# Stand up a one-node Slurm on this machine, sample the reduced plan of the generated plain weave through
# `slurm_sample.sh` with n = 4 shards, and check that the merged file equals the unsharded run (Ψ̄ bitwise, the same
# ids); then the same with GNU parallel; then resume: a shard file cut short and the array re-submitted finishes
# only the missing samples. Not part of CI (≈ 10 min on 2 cores; installs Debian packages).
#
#   validation/cluster/local_check.sh [WORKDIR]      (default WORKDIR: target/cluster-check)
#
# Installs slurm-wlm, munge and parallel with apt-get, writes /etc/slurm/slurm.conf for this host (container
# friendly: proctrack/linuxproc, task/none, no cgroups, no accounting), starts munged, slurmctld and slurmd.
# Exit code 0 when both runs reproduce the unsharded samples bitwise, 1 otherwise.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
work="$(mkdir -p "${1:-$root/target/cluster-check}" && cd "${1:-$root/target/cluster-check}" && pwd)"
HYLC="${HYLC:-$root/target/release/hylc}"
n=4
pattern=plain
plan=reduced

step() { echo; echo "== $* ($(date -u +%H:%M:%S))"; }

step "install slurm-wlm, munge, parallel"
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null || ! command -v parallel >/dev/null; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq slurm-wlm munge parallel >/dev/null
fi
slurmctld -V

step "munge"
if [[ ! -s /etc/munge/munge.key ]]; then
    mkdir -p /etc/munge
    dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key status=none
fi
chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge 2>/dev/null || true
chmod 0400 /etc/munge/munge.key
mkdir -p /run/munge && chown munge:munge /run/munge
if ! munge -n </dev/null >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged
fi
munge -n </dev/null | unmunge >/dev/null && echo "munge works"

step "slurm.conf for $(hostname -s)"
host="$(hostname -s)"
cpus="$(nproc)"
mem_mb="$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024))"
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat >/etc/slurm/slurm.conf <<CONF
# one-node Slurm for validation/cluster/local_check.sh (written by the script)
ClusterName=hylc-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
SchedulerType=sched/backfill
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

step "start slurmctld and slurmd"
if ! scontrol ping 2>/dev/null | grep -q UP; then
    slurmctld
fi
if ! pgrep -x slurmd >/dev/null; then
    slurmd
fi
for _ in $(seq 60); do
    if sinfo -h -o %T 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then break; fi
    scontrol update nodename="$host" state=resume 2>/dev/null || true
    sleep 1
done
sinfo

step "unsharded reference run: hylc sample $pattern --plan $plan"
rm -rf "$work/ref" "$work/slurm" "$work/parallel"
mkdir -p "$work/ref"
t0=$SECONDS
"$HYLC" sample "$pattern" --plan "$plan" --out "$work/ref/samples.jsonl" || [[ $? -eq 3 ]]
echo "unsharded: $((SECONDS - t0)) s"

wait_for() { # job id: wait until it left the queue, then print its state
    while squeue -h -j "$1" 2>/dev/null | grep -q .; do sleep 2; done
    scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | head -1 || true
}

compare() { # merged file, label: Ψ̄ bitwise (relative tolerance 0) and the same ids
    local out rc=0
    out="$("$HYLC" compare-samples "$work/ref/samples.jsonl" "$1" --rel 0)" || rc=$?
    echo "$out"
    if [[ $rc -eq 0 ]] && echo "$out" | grep -q "(0 only in .*, 0 only in .*)"; then
        echo "$2: merged samples equal the unsharded run (Ψ̄ bitwise, same ids)"
    else
        echo "$2: MISMATCH"
        return 1
    fi
}

status=0
step "Slurm: job array of $n shards and a dependent merge"
t0=$SECONDS
submitted="$("$here/slurm_sample.sh" "$pattern" "$plan" "$work/slurm" "$n")"
echo "$submitted"
merge_id="$(echo "$submitted" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')"
echo "merge job: $(wait_for "$merge_id")"
echo "Slurm: $((SECONDS - t0)) s"
tail -n 2 "$work/slurm/logs/"shard-*.log
cat "$work/slurm/logs/merge.log"
compare "$work/slurm/samples.jsonl" "Slurm" || status=1

step "Slurm resume: shard 1 cut to half its lines, the array re-submitted"
f="$work/slurm/shard-1-of-$n.jsonl"
lines=$(wc -l <"$f")
head -n $((lines / 2)) "$f" >"$f.cut" && mv "$f.cut" "$f"
rm -f "$work/slurm/samples.jsonl"
submitted="$("$here/slurm_sample.sh" "$pattern" "$plan" "$work/slurm" "$n")"
merge_id="$(echo "$submitted" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')"
echo "merge job: $(wait_for "$merge_id")"
grep -h "already done" "$work/slurm/logs/"shard-*.log
compare "$work/slurm/samples.jsonl" "Slurm (resumed)" || status=1

step "GNU parallel: $n shards, 2 at a time, then merge"
mkdir -p "$work/parallel"
t0=$SECONDS
seq 0 $((n - 1)) | RAYON_NUM_THREADS=1 parallel -j "$cpus" --halt never \
    "'$HYLC' sample $pattern --plan $plan --shard {}/$n --out '$work/parallel/shard-{}-of-$n.jsonl' || [ \$? -eq 3 ]"
"$HYLC" merge "$work/parallel/samples.jsonl" "$work/parallel"/shard-*-of-$n.jsonl
echo "GNU parallel: $((SECONDS - t0)) s"
compare "$work/parallel/samples.jsonl" "GNU parallel" || status=1

step "result"
if [[ $status -eq 0 ]]; then echo "PASS: Slurm and GNU parallel reproduce the unsharded samples bitwise"; else echo "FAIL"; fi
exit $status
