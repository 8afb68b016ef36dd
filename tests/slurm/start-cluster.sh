#!/bin/bash
# A one-node Slurm on this machine, for the Slurm tests (pytest -m slurm) and for trying
# `filmfriction sweep --profile slurm` without a cluster.  Debian 12, as root:
#
#   tests/slurm/start-cluster.sh      # or: make slurm-up
#   tests/slurm/stop-cluster.sh       # or: make slurm-down
#
# It installs (apt-get) munge, mariadb-server, slurmdbd, slurmctld, slurmd and slurm-client,
# writes /etc/slurm/slurm.conf and slurmdbd.conf (only files it wrote itself, or none), and
# starts munged, MariaDB, slurmdbd (accounting, so `sacct` works: the Snakemake Slurm
# executor asks sacct for the jobs' states), slurmctld and slurmd.  The node offers the
# machine's CPUs and memory (`slurmd -C`); the partition is `main`, the account
# `filmfriction` (the default account of root and of $SUDO_USER).  No systemd and no
# delegated cgroups are assumed: ProctrackType=proctrack/linuxproc, TaskPlugin=task/none
# (a production site uses the cgroup plugins).
#
# Running it again is harmless: what runs is left running, what is missing is started.
# Exit status: 0 the cluster is up (sinfo shows the node idle, sacct answers); 3 it cannot
# run here (the message says what it needs); 1 a step failed (the message names its log).
set -euo pipefail

MARK="# written by filmfriction tests/slurm/start-cluster.sh"
STATE=/run/filmfriction-slurm          # which daemons this script started (for the stop)
CONF=/etc/slurm
CLUSTER=filmfriction
ACCOUNT=filmfriction
PARTITION=main
PACKAGES="munge mariadb-server slurmdbd slurmctld slurmd slurm-client"

say() { echo "start-cluster: $*" >&2; }
cannot() { say "cannot start a Slurm cluster here: $*"; exit 3; }
fail() { say "$*"; exit 1; }

# wait_for SECONDS WHAT COMMAND...: run COMMAND until it succeeds
wait_for() {
    local seconds=$1 what=$2
    shift 2
    for _ in $(seq "$((seconds * 2))"); do
        if "$@" >/dev/null 2>&1; then return 0; fi
        sleep 0.5
    done
    return 1
}

alive() {  # alive PIDFILE: the pid in PIDFILE is a live process
    [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null
}

# ---------------------------------------------------------------- what it needs
[ "$(id -u)" = 0 ] || cannot "needs root (it installs Debian packages and starts daemons); run it as root"
[ -r /etc/debian_version ] || cannot "needs Debian (12) and apt-get"
missing=""
for pkg in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" \
        || missing="$missing $pkg"
done
if [ -n "$missing" ]; then
    command -v apt-get >/dev/null || cannot "needs apt-get to install:$missing"
    say "installing$missing (apt-get; about a minute)"
    log=/tmp/filmfriction-slurm-apt.log
    # no daemon started by the packages' scripts: this script starts them, with its config
    policy=""
    if [ ! -e /usr/sbin/policy-rc.d ]; then
        printf '#!/bin/sh\nexit 101\n' > /usr/sbin/policy-rc.d
        chmod +x /usr/sbin/policy-rc.d
        policy=/usr/sbin/policy-rc.d
    fi
    # shellcheck disable=SC2086
    if ! (DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
              $missing >"$log" 2>&1 \
          || { apt-get update -q >>"$log" 2>&1 \
               && DEBIAN_FRONTEND=noninteractive apt-get install -y -q \
                      --no-install-recommends $missing >>"$log" 2>&1; }); then
        [ -z "$policy" ] || rm -f "$policy"
        cannot "apt-get install$missing failed (see $log)"
    fi
    [ -z "$policy" ] || rm -f "$policy"
fi

mkdir -p "$STATE" /run/slurm /run/munge /var/log/slurm /var/lib/slurm/slurmctld \
         /var/lib/slurm/slurmd
chown slurm:slurm /run/slurm /var/log/slurm /var/lib/slurm/slurmctld /var/lib/slurm/slurmd
chown munge:munge /run/munge

# ---------------------------------------------------------------- configuration
# write_conf FILE MODE OWNER: stdin into FILE, unless FILE is someone else's
write_conf() {
    local file=$1 mode=$2 owner=$3 tmp
    if [ -e "$file" ] && ! grep -qF "$MARK" "$file"; then
        fail "$file exists and was not written by this script; not touching it (a Slurm is configured on this machine already)"
    fi
    tmp=$(mktemp "$file.XXXXXX")
    cat > "$tmp"
    chmod "$mode" "$tmp"
    chown "$owner" "$tmp"
    mv -f "$tmp" "$file"
}

node=$(slurmd -C | head -1)         # NodeName=... CPUs=... RealMemory=...: this machine
name=$(echo "$node" | sed -n 's/^NodeName=\([^ ]*\).*/\1/p')
[ -n "$name" ] || fail "slurmd -C gave no node description: $node"

write_conf "$CONF/slurm.conf" 644 root:root <<EOF
$MARK
# A one-node test cluster; see that script.
ClusterName=$CLUSTER
SlurmctldHost=$name(127.0.0.1)
SlurmUser=slurm
AuthType=auth/munge
StateSaveLocation=/var/lib/slurm/slurmctld
SlurmdSpoolDir=/var/lib/slurm/slurmd
SlurmctldPidFile=/run/slurm/slurmctld.pid
SlurmdPidFile=/run/slurm/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
# no systemd, no delegated cgroups: processes tracked by their parent, no binding
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=1000
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=5
# accounting: sacct answers from slurmdbd, with each job's resources and steps
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
AccountingStorageEnforce=associations
AccountingStoreFlags=job_comment
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=10
JobCompType=jobcomp/none
MinJobAge=300
KillWait=10
InactiveLimit=0
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=$PARTITION Nodes=$name Default=YES MaxTime=INFINITE State=UP
EOF

write_conf "$CONF/slurmdbd.conf" 600 slurm:slurm <<EOF
$MARK
AuthType=auth/munge
DbdHost=localhost
SlurmUser=slurm
LogFile=/var/log/slurm/slurmdbd.log
PidFile=/run/slurm/slurmdbd.pid
StorageType=accounting_storage/mysql
StorageHost=localhost
StorageUser=slurm
StorageLoc=slurm_acct_db
EOF

# ---------------------------------------------------------------- daemons
started() { grep -qx "$1" "$STATE/started" 2>/dev/null || echo "$1" >> "$STATE/started"; }

# munge: credentials between the Slurm daemons and commands
[ -s /etc/munge/munge.key ] || { mungekey --create --keyfile=/etc/munge/munge.key \
    && chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key; }
if ! munge -n >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged --pid-file=/run/munge/munged.pid \
        || fail "munged did not start (see /var/log/munge/munged.log)"
    started munge
    wait_for 10 munge munge -n || fail "munged does not answer (see /var/log/munge/munged.log)"
fi

# MariaDB: the accounting database (the slurm user logs in through its unix socket)
if ! mysqladmin ping >/dev/null 2>&1; then
    /etc/init.d/mariadb start >/tmp/filmfriction-slurm-mariadb.log 2>&1 \
        || fail "MariaDB did not start (see /tmp/filmfriction-slurm-mariadb.log)"
    started mariadb
fi
mysql <<'EOF' || fail "could not create the accounting database in MariaDB"
CREATE DATABASE IF NOT EXISTS slurm_acct_db;
CREATE USER IF NOT EXISTS 'slurm'@'localhost' IDENTIFIED VIA unix_socket;
GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost';
EOF

if ! alive /run/slurm/slurmdbd.pid; then
    /usr/sbin/slurmdbd || fail "slurmdbd did not start (see /var/log/slurm/slurmdbd.log)"
    started slurmdbd
fi
wait_for 60 slurmdbd sacctmgr -n list cluster \
    || fail "slurmdbd does not answer (see /var/log/slurm/slurmdbd.log)"
if [ -z "$(sacctmgr -n -P list cluster "$CLUSTER" format=cluster)" ]; then
    sacctmgr -i add cluster "$CLUSTER" >/dev/null
fi
if [ -z "$(sacctmgr -n -P list account "$ACCOUNT" format=account)" ]; then
    sacctmgr -i add account "$ACCOUNT" cluster="$CLUSTER" \
        description="filmfriction test cluster" organization=filmfriction >/dev/null
fi
for user in root ${SUDO_USER:-}; do
    if [ -z "$(sacctmgr -n -P list association user="$user" account="$ACCOUNT" format=user)" ]
    then
        sacctmgr -i add user "$user" account="$ACCOUNT" defaultaccount="$ACCOUNT" >/dev/null
    fi
done

if ! alive /run/slurm/slurmctld.pid; then
    /usr/sbin/slurmctld || fail "slurmctld did not start (see /var/log/slurm/slurmctld.log)"
    started slurmctld
fi
wait_for 60 slurmctld scontrol ping \
    || fail "slurmctld does not answer (see /var/log/slurm/slurmctld.log)"
if ! alive /run/slurm/slurmd.pid; then
    /usr/sbin/slurmd || fail "slurmd did not start (see /var/log/slurm/slurmd.log)"
    started slurmd
fi

node_ready() {
    local state
    state=$(sinfo -h -n "$name" -o %T 2>/dev/null)
    case $state in
        idle|mixed|allocated|completing) return 0 ;;
        down*|drain*|fail*) scontrol update nodename="$name" state=resume >/dev/null 2>&1 ;;
    esac
    return 1
}
wait_for 60 node node_ready \
    || fail "node $name is not ready: $(sinfo -h -n "$name" -o '%T %E') (see /var/log/slurm/slurmd.log)"
sacct -n -X -S now-1hours >/dev/null 2>&1 || fail "sacct does not answer (see /var/log/slurm/slurmdbd.log)"

say "cluster $CLUSTER up: node $(sinfo -h -n "$name" -o '%N %c CPUs %m MB %T'), partition $PARTITION, account $ACCOUNT"
