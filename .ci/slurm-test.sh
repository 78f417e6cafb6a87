#!/usr/bin/env bash
# A real Slurm cluster on localhost: munged, slurmctld and slurmd from a minimal config
# in a temporary folder; 4-part renders of cornell-box (path) and cornell-caustics
# (sppm) submitted with `radiant slurm --submit`, waited for, and compared byte for byte
# (PFM: no metadata) with single-machine renders. Installs Debian's slurm-wlm and munge
# when absent and run as root; otherwise skipped with a message. Everything it starts,
# it stops.
set -euo pipefail
cd "$(dirname "$0")/.."

skip() {
    echo "slurm-test: skipped: $*"
    exit 0
}

have() { command -v "$1" >/dev/null 2>&1; }

if ! have slurmctld || ! have slurmd || ! have munged || ! have sbatch; then
    if [ "$(id -u)" = 0 ] && have apt-get; then
        (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
            --no-install-recommends slurm-wlm munge >/dev/null) ||
            skip "slurm-wlm and munge could not be installed"
    else
        skip "slurm-wlm and munge are not installed and cannot be installed here (not root or no apt-get)"
    fi
fi
have slurmctld && have slurmd && have munged && have sbatch || skip "the Slurm daemons are missing after installation"

cargo build --release -q -p radiant-cli
RADIANT="$PWD/target/release/radiant"

T=$(mktemp -d /tmp/radiant-slurm.XXXXXX)
chmod 755 "$T"
PIDS=()
cleanup() {
    local rc=$?
    for pid in "${PIDS[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    for pid in "${PIDS[@]}"; do
        wait "$pid" 2>/dev/null || true
    done
    rm -rf "$T"
    exit $rc
}
trap cleanup EXIT INT TERM

HOST=$(hostname -s)
CPUS=$(nproc)
USER_NAME=$(id -un)
# Ports off Slurm's defaults, so a cluster already on this machine is left alone.
CTLD_PORT=${RADIANT_SLURM_PORT:-16817}
SLURMD_PORT=$((CTLD_PORT + 1))

# munge: a key and a socket of our own.
dd if=/dev/urandom of="$T/munge.key" bs=1024 count=1 status=none
chmod 400 "$T/munge.key"
mkdir -m 711 "$T/munge"
munged --force --foreground --key-file="$T/munge.key" --socket="$T/munge/socket" \
    --pid-file="$T/munge/pid" --log-file="$T/munge/log" --seed-file="$T/munge/seed" \
    >"$T/munge/out" 2>&1 &
PIDS+=($!)

mkdir -p "$T/state" "$T/spool" "$T/log"
cat >"$T/slurm.conf" <<EOF
ClusterName=radiantci
SlurmctldHost=$HOST
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=$USER_NAME
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$T/munge/socket
CredType=cred/munge
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=600
NodeName=$HOST CPUs=$CPUS State=UNKNOWN
PartitionName=ci Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$T/slurm.conf"

for _ in $(seq 50); do [ -S "$T/munge/socket" ] && break; sleep 0.1; done
[ -S "$T/munge/socket" ] || { cat "$T/munge/log" || true; echo "slurm-test: munged did not start"; exit 1; }

slurmctld -D -i -f "$SLURM_CONF" >"$T/log/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" >"$T/log/slurmd.out" 2>&1 &
PIDS+=($!)

show_logs() {
    for f in "$T"/log/*; do
        echo "--- $f"
        tail -n 30 "$f" || true
    done
}

# The node up and idle.
up=""
for _ in $(seq 120); do
    if sinfo -h -o "%T" 2>/dev/null | grep -qE "^idle"; then up=1; break; fi
    sleep 0.5
done
[ -n "$up" ] || { show_logs; echo "slurm-test: the node did not come up"; exit 1; }
echo "slurm-test: cluster up ($HOST, $CPUS CPUs): $(sinfo -h -o '%P %D %T')"

# Submits one distributed render, waits, prints the jobs' states and compares bits.
render_case() {
    local name=$1
    shift
    local dir="$T/$name"
    mkdir -p "$dir"
    local line
    line=$("$RADIANT" slurm "$@" --parts 4 --dir "$dir/jobs" -o "$dir/merged.pfm" --submit | tail -n 1)
    echo "slurm-test: $name: $line"
    local array merge
    array=$(echo "$line" | sed -n 's/.*array job \([0-9]*\).*/\1/p')
    merge=$(echo "$line" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')
    [ -n "$array" ] && [ -n "$merge" ] || { echo "slurm-test: $name: no job ids"; return 1; }
    local waited=0
    while [ -n "$(squeue -h -j "$array,$merge" 2>/dev/null)" ]; do
        sleep 1
        waited=$((waited + 1))
        if [ "$waited" -ge 900 ]; then
            show_logs
            echo "slurm-test: $name: jobs still queued after 900 s"
            return 1
        fi
    done
    scontrol -o show job "$array" | sed -n 's/.*\(JobId=[0-9]*\).*\(ArrayTaskId=[0-9]*\).*\(JobState=[A-Z_]*\).*/slurm-test:   \1 \2 \3/p'
    scontrol -o show job "$merge" | sed -n 's/.*\(JobId=[0-9]*\).*\(JobState=[A-Z_]*\).*/slurm-test:   \1 (merge) \2/p'
    local bad
    bad=$( (scontrol -o show job "$array"; scontrol -o show job "$merge") | grep -v "JobState=COMPLETED" || true)
    if [ -n "$bad" ]; then
        cat "$dir"/jobs/logs/* 2>/dev/null || true
        echo "slurm-test: $name: a job did not complete"
        return 1
    fi
    "$RADIANT" render "$@" -o "$dir/single.pfm" --quiet
    if cmp -s "$dir/merged.pfm" "$dir/single.pfm"; then
        echo "slurm-test: $name: merged image bit-identical to the single-machine render"
    else
        echo "slurm-test: $name: merged image DIFFERS from the single-machine render"
        return 1
    fi
}

render_case cornell-box cornell-box --spp 16 --resolution 64x64 --seed 7
render_case cornell-caustics-sppm cornell-caustics --integrator sppm --spp 8 --resolution 64x64 --seed 7
echo "slurm-test: passed"
