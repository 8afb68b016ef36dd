#!/bin/bash
# Stop the one-node Slurm that tests/slurm/start-cluster.sh started: its jobs are
# cancelled, then slurmd, slurmctld, slurmdbd, and MariaDB and munged when that script
# started them (a MariaDB or munged that ran before is left running).  The packages, the
# configuration and the accounting database stay, so the next start is quick.  (With Slurm's
# commands installed and no controller up, each Snakemake start waits ~10 s: the Slurm
# executor plugin asks `scontrol show config` when it is imported.)
# Running it again, or with nothing running, is harmless.
set -uo pipefail

STATE=/run/filmfriction-slurm
say() { echo "stop-cluster: $*" >&2; }

[ "$(id -u)" = 0 ] || { say "needs root (it stops daemons)"; exit 3; }

# stop PIDFILE NAME: TERM the pid in PIDFILE and wait for it to end
stop() {
    local pidfile=$1 name=$2 pid
    [ -s "$pidfile" ] || return 0
    pid=$(cat "$pidfile")
    if kill -0 "$pid" 2>/dev/null; then
        kill -TERM "$pid"
        for _ in $(seq 60); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.5
        done
        if kill -0 "$pid" 2>/dev/null; then
            say "$name (pid $pid) did not stop within 30 s"
            return 1
        fi
        say "stopped $name"
    fi
    rm -f "$pidfile"
}

ours() { grep -qx "$1" "$STATE/started" 2>/dev/null; }

status=0
if [ -s /run/slurm/slurmctld.pid ] && command -v scancel >/dev/null; then
    scancel --full --quiet --user="$(id -un)" 2>/dev/null || true
    scancel --full --quiet $(squeue -h -o %i 2>/dev/null) 2>/dev/null || true
fi
stop /run/slurm/slurmd.pid slurmd || status=1
stop /run/slurm/slurmctld.pid slurmctld || status=1
stop /run/slurm/slurmdbd.pid slurmdbd || status=1
if ours mariadb; then
    /etc/init.d/mariadb stop >/dev/null 2>&1 && say "stopped MariaDB" || status=1
fi
if ours munge; then
    stop /run/munge/munged.pid munged || status=1
fi
[ "$status" != 0 ] || rm -f "$STATE/started"
exit "$status"
