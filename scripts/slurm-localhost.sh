#!/usr/bin/env bash
# A one-node SLURM cluster on this machine, for trying bionav's SLURM sweeps and for its tests.
#
#   scripts/slurm-localhost.sh start    install (Debian/Ubuntu, apt-get) if needed, then start munge,
#                                       MariaDB + slurmdbd (accounting), slurmctld and slurmd
#   scripts/slurm-localhost.sh stop     stop every daemon this script started (pid files in $SLURM_LOCAL_DIR,
#                                       each checked by its command name; never the system's munge or MariaDB)
#   scripts/slurm-localhost.sh status   print what runs; exit 0 when slurmctld answers, else 3
#
# Idempotent: `start` starts only what is not running, `stop` stops only what runs. Needs root (or
# password-less sudo) for apt-get and for the daemons. Works without systemd: every daemon is started
# by hand. State, spool and logs live in $SLURM_LOCAL_DIR (default /tmp/slurm); the config is
# /etc/slurm/slurm.conf and /etc/slurm/slurmdbd.conf, written only when absent or written by this
# script before (marker line below), never over a configuration of your own.
# Set SLURM_LOCAL_ACCOUNTING=0 to run without slurmdbd/MariaDB (then sacct has nothing to report).
set -euo pipefail

DIR="${SLURM_LOCAL_DIR:-/tmp/slurm}"
ACCOUNTING="${SLURM_LOCAL_ACCOUNTING:-1}"
MARKER="# written by bionav scripts/slurm-localhost.sh"
CONF=/etc/slurm/slurm.conf
DBDCONF=/etc/slurm/slurmdbd.conf

say() { echo "slurm-localhost: $*" >&2; }
die() { say "error: $*"; exit 1; }

if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
        exec sudo -n -E bash "$0" "$@"
    fi
    die "needs root (apt-get and the SLURM daemons); run it as root or with sudo."
fi

alive() {  # alive PIDFILE: the process named in PIDFILE runs and is the daemon the file is named after
    # (a stale pid file may name a pid reused by an unrelated process: its command name tells them apart)
    [ -s "$1" ] || return 1
    local pid name
    pid=$(head -c 32 "$1" | tr -d '[:space:]')
    [[ "$pid" =~ ^[1-9][0-9]*$ ]] || return 1
    name=$(basename "$1" .pid)
    [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$name" ]
}

stop_daemon() {  # stop_daemon PIDFILE: SIGTERM to the daemon named in PIDFILE if it is that daemon
    alive "$1" && kill "$(head -c 32 "$1" | tr -d '[:space:]')" 2>/dev/null || true
}

wait_for() {  # wait_for SECONDS DESCRIPTION COMMAND...
    local deadline=$((SECONDS + $1)) what=$2
    shift 2
    until "$@" >/dev/null 2>&1; do
        [ "$SECONDS" -ge "$deadline" ] && die "$what did not come up; see the logs in $DIR/log."
        sleep 0.2
    done
}

install_packages() {
    local missing=()
    command -v slurmctld >/dev/null && command -v slurmd >/dev/null || missing+=(slurm-wlm)
    command -v munged >/dev/null || missing+=(munge)
    if [ "$ACCOUNTING" = 1 ]; then
        command -v slurmdbd >/dev/null || missing+=(slurmdbd)
        command -v mariadbd >/dev/null || missing+=(mariadb-server)
    fi
    [ "${#missing[@]}" -eq 0 ] && return 0
    command -v apt-get >/dev/null || die "missing ${missing[*]} and no apt-get; install SLURM, munge (and slurmdbd, MariaDB) by hand."
    say "installing ${missing[*]} (apt-get)"
    # no daemon may start during the installation (no systemd here; this script starts them)
    local policy=/usr/sbin/policy-rc.d own_policy=0
    if [ ! -e "$policy" ]; then
        printf '#!/bin/sh\nexit 101\n' >"$policy" && chmod 755 "$policy" && own_policy=1
    fi
    local rc=0
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"; } \
        >"${TMPDIR:-/tmp}/slurm-localhost-apt.log" 2>&1 || rc=$?
    [ "$own_policy" = 1 ] && rm -f "$policy"
    [ "$rc" -eq 0 ] || die "apt-get failed (exit $rc); see ${TMPDIR:-/tmp}/slurm-localhost-apt.log."
}

ours_or_absent() {  # a config file we may (re)write
    [ ! -e "$1" ] || head -n 1 "$1" | grep -qF "$MARKER"
}

write_configs() {
    local host mem
    host=$(hostname -s)
    mkdir -p /etc/slurm "$DIR"/state "$DIR"/spool "$DIR"/log
    ours_or_absent "$CONF" || die "$CONF exists and was not written by this script; move it away to use the local cluster."
    mem=$(slurmd -C 2>/dev/null | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p')
    local cpus
    cpus=$(nproc)
    local acct_lines
    if [ "$ACCOUNTING" = 1 ]; then
        acct_lines="JobAcctGatherType=jobacct_gather/linux
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost"
    else
        acct_lines="JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none"
    fi
    local new
    new=$(cat <<EOF
$MARKER
ClusterName=local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
$acct_lines
JobCompType=jobcomp/filetxt
JobCompLoc=$DIR/log/jobcomp.log
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=1024
ReturnToService=2
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=2
MinJobAge=300
KillWait=5
InactiveLimit=0
NodeName=$host CPUs=$cpus RealMemory=${mem:-1024} State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
)
    if [ ! -e "$CONF" ] || [ "$(cat "$CONF")" != "$new" ]; then
        printf '%s\n' "$new" >"$CONF"
        chmod 644 "$CONF"
    fi
    if [ "$ACCOUNTING" = 1 ]; then
        ours_or_absent "$DBDCONF" || die "$DBDCONF exists and was not written by this script; move it away to use the local cluster."
        cat >"$DBDCONF" <<EOF
$MARKER
AuthType=auth/munge
DbdHost=localhost
SlurmUser=root
LogFile=$DIR/log/slurmdbd.log
PidFile=$DIR/slurmdbd.pid
StorageType=accounting_storage/mysql
StorageHost=localhost
StorageLoc=slurm_acct_db
StorageUser=slurm
StoragePass=slurm
EOF
        chown root:root "$DBDCONF"
        chmod 600 "$DBDCONF"
    fi
}

start_munge() {
    # a munged already answering (the system's own) is used as it is, and never stopped by this script
    munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && return 0
    alive "$DIR/munged.pid" && return 0
    [ -s /etc/munge/munge.key ] || {
        if command -v mungekey >/dev/null; then mungekey --create --keyfile=/etc/munge/munge.key; else
            dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none; fi
        chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
    }
    install -d -o munge -g munge -m 0755 /run/munge "$DIR/munge"
    runuser -u munge -- /usr/sbin/munged --pid-file="$DIR/munge/munged.pid"
    ln -sf "$DIR/munge/munged.pid" "$DIR/munged.pid"
    wait_for 10 munged bash -c 'munge -n | unmunge'
}

start_accounting() {
    [ "$ACCOUNTING" = 1 ] || return 0
    # a MariaDB already answering (the system's own) is used as it is, and never stopped by this script
    if ! mariadb -e 'SELECT 1' >/dev/null 2>&1 && ! alive "$DIR/mariadbd.pid"; then
        install -d -o mysql -g root -m 0755 /run/mysqld "$DIR/mysql"
        setsid /usr/sbin/mariadbd --user=mysql --bind-address=127.0.0.1 --pid-file="$DIR/mysql/mariadbd.pid" \
            >>"$DIR/log/mariadb.log" 2>&1 </dev/null &
        ln -sf "$DIR/mysql/mariadbd.pid" "$DIR/mariadbd.pid"
        wait_for 30 MariaDB mariadb -e 'SELECT 1'
    fi
    mariadb -e "CREATE DATABASE IF NOT EXISTS slurm_acct_db; CREATE OR REPLACE USER 'slurm'@'localhost' IDENTIFIED BY 'slurm'; GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost'"
    if ! alive "$DIR/slurmdbd.pid"; then
        slurmdbd
        wait_for 20 slurmdbd sacctmgr -n list cluster
    fi
    # the cluster must be known to the accounting database before slurmctld registers
    sacctmgr -n list cluster format=cluster | grep -qw local || sacctmgr -i add cluster local >/dev/null
}

start() {
    install_packages
    write_configs
    start_munge
    start_accounting
    if ! alive "$DIR/slurmctld.pid"; then
        slurmctld -i
    fi
    wait_for 20 slurmctld scontrol ping
    if ! alive "$DIR/slurmd.pid"; then
        slurmd
    fi
    wait_for 20 "the node" bash -c "sinfo -h -N -o %t | grep -Eq '^(idle|mix|alloc)'"
    say "running: $(sinfo -h -o '%P %a %D nodes %t')"
}

stop() {
    if alive "$DIR/slurmctld.pid" || alive "$DIR/slurmd.pid"; then
        scontrol shutdown >/dev/null 2>&1 || true
    fi
    # only the daemons this script started (pid files in $DIR), each checked by its command name
    local pidfile
    for pidfile in "$DIR/slurmctld.pid" "$DIR/slurmd.pid" "$DIR/slurmdbd.pid" "$DIR/mariadbd.pid" "$DIR/munged.pid"; do
        stop_daemon "$pidfile"
    done
    local deadline=$((SECONDS + 30))
    for pidfile in "$DIR/slurmctld.pid" "$DIR/slurmd.pid" "$DIR/slurmdbd.pid" "$DIR/mariadbd.pid" "$DIR/munged.pid"; do
        while alive "$pidfile" && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.2; done
        alive "$pidfile" && say "warning: $(basename "$pidfile" .pid) still runs (pid $(cat "$pidfile"))"
    done
    say "stopped"
}

status() {
    local name pidfile
    for name in munged:$DIR/munged.pid mariadbd:$DIR/mariadbd.pid slurmdbd:$DIR/slurmdbd.pid \
        slurmctld:$DIR/slurmctld.pid slurmd:$DIR/slurmd.pid; do
        pidfile=${name#*:}
        if alive "$pidfile"; then echo "${name%%:*}: running (pid $(cat "$pidfile"))"; else echo "${name%%:*}: stopped"; fi
    done
    if command -v scontrol >/dev/null && scontrol ping >/dev/null 2>&1; then
        sinfo
        return 0
    fi
    echo "slurmctld does not answer"
    return 3
}

case "${1:-}" in
    start) start ;;
    stop) stop ;;
    status) status ;;
    *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
