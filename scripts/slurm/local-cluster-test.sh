#!/usr/bin/env bash
# End-to-end test of scripts/slurm/campaign.sbatch on a one-node Slurm cluster started here.
#
#   sudo bash scripts/slurm/local-cluster-test.sh
#
# 1. installs slurm-wlm and munge from Debian if they are missing (needs root and apt);
# 2. starts munged (key /etc/munge/munge.key, owned by munge, created if absent), slurmctld and
#    slurmd with a minimal slurm.conf in a scratch folder (own socket, ports and state; nothing
#    under /etc/slurm is touched);
# 3. submits campaigns/smoke.toml as a 3-task array into ONE results folder, waits for it;
# 4. runs `campaign report` and checks that all 24 jobs are done exactly once;
# 5. stops the daemons it started, by PID (and only those).
# Not part of `cargo test` (it installs packages and starts daemons).
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$PWD
[ "$(id -u)" -eq 0 ] || { echo "$0: must run as root (starts munged and Slurm daemons)" >&2; exit 1; }

say() { echo "[local-cluster-test] $*"; }

# ---- 1. packages ----
missing=()
command -v slurmctld >/dev/null 2>&1 || missing+=(slurm-wlm)
command -v munged >/dev/null 2>&1 || missing+=(munge)
if [ ${#missing[@]} -gt 0 ]; then
    say "installing ${missing[*]} from Debian"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
say "$(slurmctld -V), munge $(munged -V 2>&1 | awk '{print $1}' | sed 's/munge-//')"

# ---- the binary ----
bin=$repo/target/release/campaign
if [ ! -x "$bin" ] || [ -n "$(find src Cargo.toml Cargo.lock -newer "$bin" -print -quit)" ]; then
    say "building the release binary"
    cargo build --release --locked -q
fi

# ---- 2. daemons ----
work=$(mktemp -d /tmp/hinfix-slurm.XXXXXX)
chmod 755 "$work"
pids=()
stop() {
    local rc=$?
    for p in "${pids[@]}"; do
        kill "$p" 2>/dev/null || true
    done
    for p in "${pids[@]}"; do
        for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$p" 2>/dev/null || true
    done
    [ ${#pids[@]} -eq 0 ] || say "stopped daemons ${pids[*]}"
    if [ $rc -ne 0 ]; then
        for f in "$work"/*.log; do [ -f "$f" ] && { echo "---- $f (tail)"; tail -n 20 "$f"; }; done
    fi
    exit $rc
}
trap stop EXIT

if [ ! -s /etc/munge/munge.key ]; then
    say "creating /etc/munge/munge.key"
    install -d -o munge -g munge -m 700 /etc/munge
    (umask 277; dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none)
fi
chown munge:munge /etc/munge/munge.key
chmod 400 /etc/munge/munge.key
mdir=$work/munge
install -d -o munge -g munge -m 755 "$mdir"
sock=$mdir/munge.socket
setpriv --reuid=munge --regid=munge --init-groups \
    munged -F --socket="$sock" --pid-file="$mdir/munged.pid" --log-file="$mdir/munged.log" \
    --seed-file="$mdir/munged.seed" --key-file=/etc/munge/munge.key 2>"$mdir/munged.err" &
pids+=($!)
for _ in $(seq 50); do [ -S "$sock" ] && break; sleep 0.1; done
[ -S "$sock" ] || { echo "munged did not start"; exit 1; }
munge -S "$sock" -n | unmunge -S "$sock" >/dev/null
say "munged up (pid ${pids[-1]})"

host=$(hostname -s)
# Six CPUs whatever the machine has (config_overrides), so that the three 2-CPU tasks run at the
# same time and really share the results folder; CPU budgets make the results independent of it.
cpus=6
mkdir -p "$work/state" "$work/spool"
cat > "$work/slurm.conf" <<CONF
ClusterName=hinfixtest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=26817
SlurmdPort=26818
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
slurmctld -D -i -f "$SLURM_CONF" >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
    state=$(sinfo -h -o %T 2>/dev/null | head -n1 || true)
    [ "$state" = idle ] && break
    sleep 0.3
done
[ "$state" = idle ] || { echo "the node did not come up (state '$state')"; sinfo || true; exit 1; }
say "slurmctld (pid ${pids[-2]}) and slurmd (pid ${pids[-1]}) up; node $host idle with $cpus CPUs ($(nproc) real)"

# ---- 3. the array ----
results=$work/results
export HINFIX_SBATCH_ARGS="--output=$work/slurm-%A_%a.out"
t0=$(date +%s)
sub=$(bash scripts/slurm/campaign.sbatch campaigns/smoke.toml 3 "$results")
echo "$sub"
jobid=$(echo "$sub" | awk '/Submitted batch job/ {print $4}')
[ -n "$jobid" ] || { echo "submission failed"; exit 1; }
shown=0
while [ -n "$(squeue -h -j "$jobid" 2>/dev/null)" ]; do
    sleep 5
    if [ $shown -eq 0 ] && [ $(( $(date +%s) - t0 )) -ge 20 ]; then
        shown=1
        squeue -j "$jobid" || true
        "$bin" status campaigns/smoke.toml --results "$results" || true
    fi
    [ $(( $(date +%s) - t0 )) -lt 3600 ] || { echo "the array did not finish within an hour"; exit 1; }
done
say "array $jobid finished after $(( $(date +%s) - t0 )) s"
for f in "$work"/slurm-"$jobid"_*.out; do
    echo "---- $(basename "$f")"
    grep -E '^(hinfix shard|campaign |[0-9]+ jobs:|error|warning)' "$f" || true
done

# ---- 4. report and checks ----
"$bin" report campaigns/smoke.toml --results "$results"
"$bin" status campaigns/smoke.toml --results "$results"
journals=("$results"/smoke/runs*.jsonl)
lines=$(cat "${journals[@]}" | grep -c '"job_id"')
ids=$(cat "${journals[@]}" | grep -o '"job_id":"[0-9a-f]*"' | sort -u | wc -l)
say "${#journals[@]} journal(s), $lines record(s), $ids distinct job id(s)"
fail=0
[ "$lines" -eq 24 ] || { echo "FAIL: expected 24 records, found $lines"; fail=1; }
[ "$ids" -eq 24 ] || { echo "FAIL: expected 24 distinct jobs, found $ids"; fail=1; }
traces=$(find "$results/smoke/traces" -name '*.mcap' | wc -l)
tmps=$(find "$results/smoke/traces" -name '*.tmp' | wc -l)
[ "$traces" -eq 24 ] && [ "$tmps" -eq 0 ] || { echo "FAIL: $traces traces, $tmps tmp files"; fail=1; }
for k in 1 2 3; do
    grep -q "hinfix shard $k/3" "$work"/slurm-"$jobid"_*.out || { echo "FAIL: no output of shard $k/3"; fail=1; }
done
grep -h -o '"host":"[^"]*"' "${journals[@]}" | sort | uniq -c | sed 's/^/[local-cluster-test] provenance /'
[ $fail -eq 0 ] && say "PASS: all 24 jobs done exactly once by a 3-task array into one folder"
exit $fail
