#!/usr/bin/env bash
# A one-node Slurm on this machine, for testing the sweep scripts without a
# cluster (docs/user-guide.md, "Running on a cluster"): Debian's slurm-wlm and munge, daemons
# run as root, no systemd, no cgroups, no accounting; configuration, state
# and logs under STATE_DIR.
#
#   scripts/slurm/local_cluster.sh start [STATE_DIR]   # prints: export SLURM_CONF=STATE_DIR/slurm.conf
#   scripts/slurm/local_cluster.sh stop  [STATE_DIR]
#
# STATE_DIR defaults to /tmp/posebench_slurm. Clients (sbatch, squeue,
# scontrol) find this cluster through SLURM_CONF; /etc/slurm is not touched.
# Exit 2 with a message when a package is missing, this is not root, or
# another slurmctld runs; exit 1 with the daemon log's last lines when the
# node does not come up.
set -euo pipefail
cmd="${1:-}"
STATE="${2:-/tmp/posebench_slurm}"
CONF="$STATE/slurm.conf"

die() { echo "local_cluster: $1" >&2; exit "${2:-2}"; }

stop_pidfile() {  # never by name: another user's daemons may run
  local f="$1"
  [ -f "$f" ] || return 0
  local pid
  pid="$(cat "$f")"
  if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
    kill "$pid"
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
  fi
  rm -f "$f"
}

case "$cmd" in
  start)
    for b in slurmctld slurmd munged sbatch; do
      command -v "$b" >/dev/null || [ -x "/usr/sbin/$b" ] ||
        die "$b not found: install Debian's slurm-wlm and munge (scripts/setup.sh does)"
    done
    [ "$(id -u)" -eq 0 ] || die "the daemons run as root here; run this as root"
    if pid="$(pgrep -x slurmctld)"; then
      die "a slurmctld already runs (pid $pid); stop it first (local_cluster.sh stop STATE_DIR)"
    fi
    mkdir -p "$STATE/state" "$STATE/spool"
    # munge: the key comes from munge's postinst; without systemd the socket
    # folder must be made by hand (munged will not create it).
    [ -f /etc/munge/munge.key ] || die "/etc/munge/munge.key missing: reinstall munge"
    if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
      mkdir -p /run/munge && chown munge:munge /run/munge
      su -s /bin/sh munge -c "/usr/sbin/munged --pid-file=/run/munge/posebench_munged.pid" ||
        die "munged did not start" 1
      echo "/run/munge/posebench_munged.pid" >"$STATE/munged.pidfile"
      for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
      munge -n | unmunge >/dev/null || die "munge does not answer" 1
    fi
    host="$(hostname -s)"
    node="$(/usr/sbin/slurmd -C | head -n 1)"
    cat >"$CONF" <<CONF
ClusterName=posebench
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MailProg=/bin/true
EnforcePartLimits=ALL
StateSaveLocation=$STATE/state
SlurmdSpoolDir=$STATE/spool
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
$node State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$CONF"
    /usr/sbin/slurmctld -c -f "$CONF" || die "slurmctld did not start: $(tail -n 5 "$STATE/slurmctld.log" 2>/dev/null)" 1
    /usr/sbin/slurmd -c -f "$CONF" || die "slurmd did not start: $(tail -n 5 "$STATE/slurmd.log" 2>/dev/null)" 1
    for _ in $(seq 300); do
      [ "$(sinfo -h -N -o %T 2>/dev/null | head -n 1)" = "idle" ] && { echo "export SLURM_CONF=$CONF"; exit 0; }
      sleep 0.2
    done
    echo "local_cluster: the node did not become idle in 60 s; last log lines:" >&2
    tail -n 5 "$STATE/slurmctld.log" "$STATE/slurmd.log" >&2 || true
    exit 1
    ;;
  stop)
    stop_pidfile "$STATE/slurmd.pid"
    stop_pidfile "$STATE/slurmctld.pid"
    if [ -f "$STATE/munged.pidfile" ]; then  # only a munged this script started
      stop_pidfile "$(cat "$STATE/munged.pidfile")"
      rm -f "$STATE/munged.pidfile"
    fi
    ;;
  *)
    die "usage: local_cluster.sh start|stop [STATE_DIR]"
    ;;
esac
