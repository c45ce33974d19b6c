#!/bin/bash
# A real single-node SLURM on this machine, for testing the job scripts in jobs/.
#
#   bash scripts/slurm_local.sh start    # install (once), configure, start, wait for an idle node
#   bash scripts/slurm_local.sh status   # sinfo + the daemons' pids
#   bash scripts/slurm_local.sh stop     # stop slurmctld, slurmd (and munged if it started it)
#
# What `start` does, idempotently:
#   * installs Debian's `slurm-wlm` and `munge` with apt-get if sbatch/slurmctld are
#     missing (as root, or through sudo);
#   * writes a minimal, cgroup-free /etc/slurm/slurm.conf for one node, this host
#     (proctrack/linuxproc, task/none, select/cons_tres, no accounting database;
#     finished jobs are kept by slurmctld for MinJobAge and logged by jobcomp/filetxt);
#   * starts munged, slurmctld and slurmd directly (no systemd: containers have none)
#     and waits until `sinfo` shows the node idle.
# It refuses to touch a slurm.conf it did not write, so it never reconfigures a real
# site's SLURM.  Everything else lives under $SLURM_LOCAL_DIR (default
# /var/lib/mpipd-slurm): state, spool, logs, pid files, the job-completion log.
#
# Settings (environment):
#   SLURM_LOCAL_DIR   state/log folder                     (/var/lib/mpipd-slurm)
#   SLURM_LOCAL_CPUS  CPUs the node advertises             (nproc, at least 4, so small test
#                     jobs can run side by side; slurmd is told to trust the config)
#   SLURM_LOCAL_WAIT  seconds to wait for the node to be idle (60)
# Exit status: 0 = running (start) / stopped (stop); 1 = could not start, with the
# reason on stderr (the test suite then skips its scheduler tests and says why).
set -uo pipefail

DIR=${SLURM_LOCAL_DIR:-/var/lib/mpipd-slurm}
CONF=/etc/slurm/slurm.conf
MARK="# written by mpipd scripts/slurm_local.sh"
WAIT=${SLURM_LOCAL_WAIT:-60}
NODE=$(hostname -s)

die() { echo "slurm_local: $*" >&2; exit 1; }
say() { echo "slurm_local: $*"; }

as_root() {
  if [ "$(id -u)" = 0 ]; then "$@"
  elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then sudo "$@"
  else return 1; fi
}

install_pkgs() {
  if command -v sbatch >/dev/null && command -v slurmctld >/dev/null \
     && command -v slurmd >/dev/null && command -v munged >/dev/null; then
    return 0
  fi
  command -v apt-get >/dev/null || die "sbatch/slurmctld missing and no apt-get to install slurm-wlm"
  say "installing slurm-wlm and munge with apt-get"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends slurm-wlm munge >"/tmp/slurm_local_apt.log" 2>&1 \
    || { as_root apt-get update -q >>"/tmp/slurm_local_apt.log" 2>&1 \
         && as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends slurm-wlm munge \
              >>"/tmp/slurm_local_apt.log" 2>&1; } \
    || die "apt-get install slurm-wlm munge failed (log: /tmp/slurm_local_apt.log)"
}

pid_alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

write_conf() {
  local cpus=${SLURM_LOCAL_CPUS:-}
  if [ -z "$cpus" ]; then cpus=$(nproc); [ "$cpus" -lt 4 ] && cpus=4; fi
  if [ -f "$CONF" ] && ! grep -qF "$MARK" "$CONF"; then
    die "$CONF exists and was not written by this script: not touching a real site's SLURM"
  fi
  mkdir -p "$DIR"/{ctld,spool,log,run} /etc/slurm
  cat >"$CONF.new" <<EOF
$MARK
# A single-node, cgroup-free SLURM for testing jobs/ (see scripts/slurm_local.sh).
ClusterName=mpipdlocal
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$DIR/log/jobcomp.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
MinJobAge=900
KillWait=20
OverTimeLimit=0
InactiveLimit=0
Waittime=0
StateSaveLocation=$DIR/ctld
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/run/slurmctld.pid
SlurmdPidFile=$DIR/run/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  if ! cmp -s "$CONF.new" "$CONF"; then
    mv "$CONF.new" "$CONF"
    return 1          # changed: running daemons must be restarted
  fi
  rm -f "$CONF.new"
  return 0
}

start_munge() {
  if munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1; then return 0; fi
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  chown munge:munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null
  chmod 0755 /run/munge
  if [ ! -s /etc/munge/munge.key ]; then
    if command -v mungekey >/dev/null; then mungekey --create --force >/dev/null 2>&1
    else dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 2>/dev/null; fi
    chown munge:munge /etc/munge/munge.key; chmod 0400 /etc/munge/munge.key
  fi
  if id munge >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged || die "munged did not start"
  else
    /usr/sbin/munged --force || die "munged did not start"
  fi
  mkdir -p "$DIR/run" && touch "$DIR/run/munged.ours"     # `stop` ends only a munged we started
  for _ in $(seq 20); do
    munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1 && return 0
    sleep 0.5
  done
  die "munge does not answer (munge -n | unmunge)"
}

stop_daemons() {
  local f p
  for f in "$DIR/run/slurmd.pid" "$DIR/run/slurmctld.pid"; do
    if pid_alive "$f"; then
      p=$(cat "$f"); kill "$p" 2>/dev/null
      for _ in $(seq 40); do kill -0 "$p" 2>/dev/null || break; sleep 0.25; done
      kill -0 "$p" 2>/dev/null && kill -9 "$p" 2>/dev/null
    fi
    rm -f "$f"
  done
}

stop_munge() {
  [ -f "$DIR/run/munged.ours" ] || return 0
  rm -f "$DIR/run/munged.ours"
  local f=/run/munge/munged.pid
  [ -f "$f" ] || return 0
  local p
  p=$(cat "$f")
  kill "$p" 2>/dev/null || true
}

node_state() { sinfo -h -N -n "$NODE" -o %T 2>/dev/null | head -1; }

start() {
  [ "$(id -u)" = 0 ] || die "must run as root (it starts system daemons)"
  install_pkgs
  local changed=0
  write_conf || changed=1
  start_munge
  if [ $changed = 1 ]; then stop_daemons; fi
  if ! pid_alive "$DIR/run/slurmctld.pid"; then
    # -c: a clean start, no jobs left over from an earlier session
    /usr/sbin/slurmctld -c -f "$CONF" || die "slurmctld did not start (see $DIR/log/slurmctld.log)"
  fi
  if ! pid_alive "$DIR/run/slurmd.pid"; then
    /usr/sbin/slurmd -f "$CONF" || die "slurmd did not start (see $DIR/log/slurmd.log)"
  fi
  local st=""
  for _ in $(seq $((WAIT * 2))); do
    st=$(node_state)
    case "$st" in
      idle|mixed|allocated) say "node $NODE is $st ($(sinfo -h -o '%c CPUs, partition %P'))"; return 0 ;;
      down*|drain*|fail*) scontrol update nodename="$NODE" state=resume >/dev/null 2>&1 ;;
    esac
    sleep 0.5
  done
  echo "--- slurmctld.log"; tail -n 15 "$DIR/log/slurmctld.log" 2>/dev/null
  echo "--- slurmd.log"; tail -n 15 "$DIR/log/slurmd.log" 2>/dev/null
  die "node $NODE not idle after ${WAIT}s (state: ${st:-none})"
}

status() {
  local ok=0
  for d in slurmctld slurmd; do
    if pid_alive "$DIR/run/$d.pid"; then echo "$d: running, pid $(cat "$DIR/run/$d.pid")"
    else echo "$d: not running"; ok=1; fi
  done
  sinfo 2>/dev/null || ok=1
  return $ok
}

case "${1:-start}" in
  start) start ;;
  stop) stop_daemons; stop_munge; say "stopped slurmctld, slurmd (and munged, if this script started it)" ;;
  status) status ;;
  *) echo "usage: $0 {start|stop|status}" >&2; exit 2 ;;
esac
