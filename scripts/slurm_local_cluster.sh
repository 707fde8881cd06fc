#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, everything in one folder: the
# Debian packages' munged, slurmctld and slurmd (scripts/setup.sh --cluster
# installs them), run by hand as root, without systemd and without touching
# /etc. For trying LAUNCH="srun -N1 -n1" of Makefile.pipeline against a real
# controller (tests/pipeline/slurm_test.sh).
#
#   slurm_local_cluster.sh start DIR    write DIR/slurm.conf and a munge key into
#                                       the new or empty folder DIR, start the three
#                                       daemons, wait until the node is idle
#   slurm_local_cluster.sh status DIR   sinfo and squeue of the cluster in DIR
#   slurm_local_cluster.sh stop DIR     stop the daemons of DIR (their pid files)
#   slurm_local_cluster.sh run DIR COMMAND...
#                                       start, run COMMAND, stop (also when COMMAND
#                                       fails or is interrupted); COMMAND's exit code
#
# Clients find the cluster with SLURM_CONF=DIR/slurm.conf (run sets it).
# Every job that ends leaves one line in DIR/jobcomp.txt (jobcomp/filetxt:
# JobId, Name, JobState, ExitCode, …); the logs are DIR/*.log. The node is
# this host (hostname -s) with nproc CPUs and the memory free -m reports;
# CPUs are the consumable resource (jobs asking for no memory share the node).
# Ports: two free TCP ports picked at start.
set -euo pipefail
# The daemons live in /usr/sbin, which a user's PATH may lack.
export PATH=$PATH:/usr/sbin:/sbin

usage() {
  echo "usage: slurm_local_cluster.sh start|status|stop DIR  or  run DIR COMMAND..." >&2
  exit 2
}
[ $# -ge 2 ] || usage
ACTION=$1
DIR=$2
shift 2

die() { echo "slurm_local_cluster: $*" >&2; exit 1; }

# A TCP port nothing listens on (a connect to it is refused).
free_port() {
  local port
  for port in $(shuf -i 20000-60000 -n 100); do
    if ! (exec 3<> "/dev/tcp/127.0.0.1/$port") 2> /dev/null; then
      echo "$port"
      return
    fi
  done
  die "no free TCP port found"
}

# Stops the daemon whose pid file is $1 (TERM, then KILL after 10 s).
stop_daemon() {
  local pid_file=$1 pid
  [ -s "$pid_file" ] || return 0
  pid=$(cat "$pid_file")
  if kill -0 "$pid" 2> /dev/null; then
    kill "$pid" 2> /dev/null || true
    for _ in $(seq 100); do
      kill -0 "$pid" 2> /dev/null || break
      sleep 0.1
    done
    kill -KILL "$pid" 2> /dev/null || true
  fi
  rm -f -- "$pid_file"
}

stop() {
  # slurmd first: it reports its jobs' ends to the controller.
  stop_daemon "$DIR/slurmd.pid"
  stop_daemon "$DIR/slurmctld.pid"
  stop_daemon "$DIR/munged.pid"
}

# Starts COMMAND... in the background with its output in LOG, its pid in PID_FILE.
start_daemon() {
  local pid_file=$1 log=$2
  shift 2
  setsid "$@" < /dev/null >> "$log" 2>&1 &
  echo $! > "$pid_file"
}

# Fails, showing the end of its log and output, when the daemon NAME is gone.
check_alive() {
  local name=$1
  kill -0 "$(cat "$DIR/$name.pid")" 2> /dev/null || {
    tail -n 5 "$DIR/$name.log" "$DIR/$name.out" >&2 2> /dev/null || true
    die "$name exited at start (logs: $DIR/$name.log, $DIR/$name.out)"
  }
}

start() {
  [ "$(id -u)" -eq 0 ] || die "needs root (slurmd starts the jobs as their user)"
  local tool
  for tool in munged mungekey slurmctld slurmd sinfo srun; do
    command -v "$tool" > /dev/null ||
      die "$tool not found: install Slurm and munge with scripts/setup.sh --cluster"
  done
  mkdir -p -- "$DIR"
  [ -z "$(ls -A -- "$DIR")" ] || die "$DIR is not empty"
  chmod 700 -- "$DIR"
  DIR=$(cd -- "$DIR" && pwd)
  mkdir -p "$DIR/munge" "$DIR/state" "$DIR/spool"

  # munge: its own key and socket (a socket path holds at most 107 bytes).
  local socket=$DIR/munge/munge.socket
  [ ${#socket} -lt 108 ] || die "$DIR: path too long for a unix socket"
  mungekey --create --keyfile="$DIR/munge/munge.key" 2> /dev/null ||
    die "mungekey could not write $DIR/munge/munge.key"
  chmod 600 "$DIR/munge/munge.key"
  munged --key-file="$DIR/munge/munge.key" --socket="$socket" \
    --pid-file="$DIR/munged.pid" --log-file="$DIR/munged.log" \
    --seed-file="$DIR/munge/munged.seed" --force 2>> "$DIR/munged.log" ||
    { tail -n 5 "$DIR/munged.log" >&2 2> /dev/null || true; die "munged did not start (log: $DIR/munged.log)"; }

  local host cpus memory_mb ctld_port slurmd_port
  host=$(hostname -s)
  cpus=$(nproc)
  memory_mb=$(free -m | awk '$1 == "Mem:" { print $2 }')
  ctld_port=$(free_port)
  slurmd_port=$(free_port)
  [ "$ctld_port" != "$slurmd_port" ] || slurmd_port=$(free_port)
  cat > "$DIR/slurm.conf" << EOF
# One-node cluster written by scripts/slurm_local_cluster.sh.
ClusterName=tiltcal
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/state/slurmctld.pid
SlurmdPidFile=$DIR/spool/slurmd.pid
SlurmctldLogFile=$DIR/slurmctld.log
SlurmdLogFile=$DIR/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$DIR/jobcomp.txt
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SlurmdTimeout=60
InactiveLimit=0
KillWait=5
NodeName=$host CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF=$DIR/slurm.conf
  # -D: in the foreground, so the pid is the daemon's; -c: no saved state.
  start_daemon "$DIR/slurmctld.pid" "$DIR/slurmctld.out" slurmctld -D -c -f "$SLURM_CONF"
  start_daemon "$DIR/slurmd.pid" "$DIR/slurmd.out" slurmd -D -f "$SLURM_CONF" -N "$host"

  # Up when sinfo shows the node idle (about 2 s; 60 s at most).
  local state=""
  for _ in $(seq 120); do
    check_alive slurmctld
    check_alive slurmd
    state=$(sinfo -h -n "$host" -o %T 2> /dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
  done
  [ "$state" = idle ] || {
    tail -n 5 "$DIR/slurmctld.log" "$DIR/slurmd.log" >&2 2> /dev/null || true
    die "the node $host is not idle after 60 s (state: ${state:-none}; logs in $DIR)"
  }
  echo "slurm_local_cluster: node $host idle ($cpus CPUs, $memory_mb MB); export SLURM_CONF=$SLURM_CONF" >&2
}

case "$ACTION" in
  start)
    trap 'status=$?; [ $status -eq 0 ] || stop; exit $status' EXIT
    start
    ;;
  stop)
    [ -d "$DIR" ] || die "no folder $DIR"
    stop
    ;;
  status)
    export SLURM_CONF=$DIR/slurm.conf
    [ -f "$SLURM_CONF" ] || die "no $SLURM_CONF"
    sinfo
    squeue
    ;;
  run)
    [ $# -ge 1 ] || usage
    trap stop EXIT
    trap 'exit 130' INT TERM
    start
    status=0
    "$@" || status=$?
    exit $status
    ;;
  *) usage ;;
esac
