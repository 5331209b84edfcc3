#!/usr/bin/env bash
# A real single-node Slurm on this machine, for the sweep's Slurm test (tests/stentkit/sweep.rs) and CI.
#
#   scripts/slurm-single-node.sh up       install slurm-wlm and munge if missing (Debian), create a munge key,
#                                         write /etc/slurm/slurm.conf and cgroup.conf, start munged, slurmctld
#                                         and slurmd, and wait until the node is idle
#   scripts/slurm-single-node.sh down     cancel every job and stop the daemons (packages stay)
#   scripts/slurm-single-node.sh status   sinfo and squeue, or "not running"
#
# Needs root. This host (`hostname -s`) is both the controller and the only compute node, with all its CPUs and
# a little less than its memory, in one partition `debug`. No systemd is needed: process tracking by
# proctrack/linuxproc, no task plugin, and a cgroup.conf with `CgroupPlugin=autodetect` and `IgnoreSystemd=yes`
# (measured to work without systemd on these machines). No accounting daemon: `sacct` is not available, and
# `stentkit sweep status` falls back to squeue and the run folders. KillWait=5: a cancelled task gets SIGTERM,
# then SIGKILL 5 s later (a real cluster's is usually 30 s). A real cluster differs in everything this file
# sets: there the administrators' slurm.conf, partitions and accounts apply, and nothing here is needed.
set -euo pipefail

CONF_DIR=/etc/slurm
STATE_DIR=/var/spool/slurmctld
SPOOL_DIR=/var/spool/slurmd
LOG_DIR=/var/log/slurm
RUN_DIR=/run/slurm

need_root() {
    if [ "$(id -u)" -ne 0 ]; then
        echo "slurm-single-node.sh: run as root (it installs packages and starts daemons)" >&2
        exit 1
    fi
}

install_packages() {
    if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
        echo "installing slurm-wlm and munge (Debian packages)"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
    fi
}

start_munge() {
    install -d -o munge -g munge -m 0700 /etc/munge /var/lib/munge /var/log/munge
    install -d -o munge -g munge -m 0755 /run/munge
    if [ ! -s /etc/munge/munge.key ]; then
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
    chown munge:munge /etc/munge/munge.key
    chmod 0400 /etc/munge/munge.key
    if ! pgrep -x munged >/dev/null; then
        runuser -u munge -- /usr/sbin/munged
    fi
    for _ in $(seq 50); do
        if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
            return 0
        fi
        sleep 0.1
    done
    echo "munge does not work: $(munge -n 2>&1 | unmunge 2>&1 | tail -1)" >&2
    exit 1
}

write_config() {
    local host cpus memory
    host=$(hostname -s)
    cpus=$(nproc)
    # RealMemory a little below MemTotal, in MB, so that slurmd does not drain the node as too small.
    memory=$(awk '/MemTotal/ {printf "%d", $2 / 1024 * 0.9}' /proc/meminfo)
    install -d -m 0755 "$CONF_DIR" "$STATE_DIR" "$SPOOL_DIR" "$LOG_DIR" "$RUN_DIR"
    cat >"$CONF_DIR/slurm.conf" <<EOF
# Written by stentkit's scripts/slurm-single-node.sh: a one-machine cluster for tests.
ClusterName=stentkit
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$STATE_DIR
SlurmdSpoolDir=$SPOOL_DIR
SlurmctldPidFile=$RUN_DIR/slurmctld.pid
SlurmdPidFile=$RUN_DIR/slurmd.pid
SlurmctldLogFile=$LOG_DIR/slurmctld.log
SlurmdLogFile=$LOG_DIR/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
MaxArraySize=10001
KillWait=5
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$host CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    cat >"$CONF_DIR/cgroup.conf" <<EOF
CgroupPlugin=autodetect
IgnoreSystemd=yes
EOF
}

node_state() {
    sinfo --noheader --nodes="$(hostname -s)" --format=%T 2>/dev/null | head -1 | tr -d '*'
}

up() {
    need_root
    install_packages
    start_munge
    write_config
    if ! pgrep -x slurmctld >/dev/null; then
        slurmctld
    fi
    if ! pgrep -x slurmd >/dev/null; then
        slurmd
    fi
    local state=""
    for _ in $(seq 120); do
        state=$(node_state || true)
        case "$state" in
            idle | mixed | allocated) break ;;
            down | drained | draining | "drained*" | fail)
                scontrol update nodename="$(hostname -s)" state=resume 2>/dev/null || true ;;
        esac
        sleep 0.5
    done
    if [[ ! "$state" =~ ^(idle|mixed|allocated)$ ]]; then
        echo "the node did not come up (state: '${state:-unknown}'); the logs end with:" >&2
        tail -n 20 "$LOG_DIR/slurmctld.log" "$LOG_DIR/slurmd.log" >&2 || true
        exit 1
    fi
    echo "slurm is up: node $(hostname -s), $(nproc) CPUs, partition debug, state $state"
}

down() {
    need_root
    if command -v scancel >/dev/null && pgrep -x slurmctld >/dev/null; then
        scancel --user=root 2>/dev/null || true
        scancel --full --signal=KILL --user=root 2>/dev/null || true
    fi
    for daemon in slurmd slurmctld munged; do
        pkill -x "$daemon" 2>/dev/null || true
    done
    for daemon in slurmd slurmctld munged; do
        for _ in $(seq 50); do
            pgrep -x "$daemon" >/dev/null || break
            sleep 0.1
        done
        pkill -9 -x "$daemon" 2>/dev/null || true
    done
    echo "slurm is down"
}

status() {
    if pgrep -x slurmctld >/dev/null; then
        sinfo
        squeue
    else
        echo "slurm is not running"
    fi
}

case "${1:-}" in
    up) up ;;
    down) down ;;
    status) status ;;
    *)
        echo "usage: $0 up|down|status" >&2
        exit 2
        ;;
esac
