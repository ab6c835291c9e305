#!/usr/bin/env bash
# The private single-node Slurm cluster shared by every Slurm cohort test
# (CTest fixture; recipe: ../shared/notes/slurm-localhost.md): munged +
# slurmctld + slurmd with a fresh state folder B, on ports checked free.
#   start B  -> writes B/slurm.conf and B/pids (munged, slurmctld, slurmd)
#   stop B   -> cancels every job, waits for an empty queue, stops those PIDs, removes B
# slurmd runs in its own mount namespace in which B/hidden is an empty tmpfs:
# a work folder under B/hidden is invisible to the jobs, as on a cluster whose
# compute nodes do not mount it (the probe-job test). A watchdog stops the
# cluster when the owner (ctest, the parent) dies, so nothing is left behind.
# Missing Slurm: exit 77 (skipped) with the reason, unless CI is set (exit 1).
set -u
cmd=$1; B=$2

stop() {
  export SLURM_CONF=$B/slurm.conf
  if [ -f "$B/pids" ]; then
    ids=$(squeue -h -o %A 2>/dev/null || true)
    [ -n "$ids" ] && scancel $ids 2>/dev/null
    for _ in $(seq 1 100); do [ -z "$(squeue -h -o %A 2>/dev/null)" ] && break; sleep 0.1; done
    for p in $(cat "$B/pids"); do kill -TERM "$p" 2>/dev/null; done
    for p in $(cat "$B/pids"); do
      for _ in $(seq 1 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
      kill -KILL "$p" 2>/dev/null
    done
    [ -f "$B/watchdog.pid" ] && kill "$(cat "$B/watchdog.pid")" 2>/dev/null
  fi
  rm -rf "$B"
}

if [ "$cmd" = stop ]; then stop; exit 0; fi

for tool in munged mungekey slurmctld slurmd sbatch squeue scancel scontrol sinfo; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    msg="Slurm not installed ('$tool' missing; Debian packages slurmctld slurmd slurm-client munge, scripts/install-deps.sh)"
    if [ -n "${CI:-}" ]; then echo "CI is set: $msg"; exit 1; fi
    echo "SKIPPED: $msg"; exit 77
  fi
done
# A TCP port nobody on this machine uses (bound or connected), from /proc/net/tcp*.
port_in_use() { grep -qi ":$(printf '%04X' "$1") " /proc/net/tcp /proc/net/tcp6 2>/dev/null; }
free_port() {
  local p
  for _ in $(seq 1 200); do
    p=$((20000 + RANDOM % 30000))
    port_in_use "$p" || [ "$p" = "${1:-0}" ] || { echo "$p"; return; }
  done
  echo "no free port found" >&2; exit 1
}
ctld_port=$(free_port); slurmd_port=$(free_port "$ctld_port"); owner=$PPID
[ -f "$B/pids" ] && "$0" stop "$B"
rm -rf "$B"; mkdir -p "$B/munge" "$B/state" "$B/spool" "$B/log" "$B/hidden"; chmod 755 "$B" "$B/munge"
cpus=$(nproc)
cat > "$B/slurm.conf" <<EOF
ClusterName=stentsimtest
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$B/munge/munge.socket.2
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
StateSaveLocation=$B/state
SlurmdSpoolDir=$B/spool
SlurmctldPidFile=$B/slurmctld.pid
SlurmdPidFile=$B/slurmd.pid
SlurmctldLogFile=$B/log/slurmctld.log
SlurmdLogFile=$B/log/slurmd.log
MailProg=/bin/true
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=4000 State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$B/slurm.conf
mungekey --create --keyfile="$B/munge/munge.key" >/dev/null 2>&1 || { echo "mungekey failed"; exit 1; }
setsid munged -F --socket="$B/munge/munge.socket.2" --key-file="$B/munge/munge.key" --log-file="$B/log/munged.log" \
  --pid-file="$B/munge/munged.pid" --seed-file="$B/munge/munged.seed" </dev/null >"$B/log/munged.out" 2>&1 &
echo $! > "$B/pids"
for _ in $(seq 1 100); do [ -S "$B/munge/munge.socket.2" ] && break; sleep 0.05; done
# munged refuses a socket below a folder that others cannot enter (a build under mktemp -d's 0700 folder).
[ -S "$B/munge/munge.socket.2" ] || {
  echo "munged did not start: $(tail -3 "$B/log/munged.out" "$B/log/munged.log" 2>/dev/null)"
  echo "(munged needs execute permission for user, group and others on every folder above $B: chmod a+x on the one it names)"
  stop; exit 1; }
setsid slurmctld -D -c -f "$SLURM_CONF" </dev/null >"$B/log/slurmctld.out" 2>&1 &
echo $! >> "$B/pids"
# slurmd (and so every job) in a private mount namespace with B/hidden over-mounted;
# where namespaces are not permitted, plain slurmd and B/hidden_unsupported says so.
if unshare -m --propagation private true 2>/dev/null; then
  setsid unshare -m --propagation private sh -c 'mount -t tmpfs -o size=1m none "$1/hidden" && exec slurmd -D -N localhost -f "$1/slurm.conf"' \
    sh "$B" </dev/null >"$B/log/slurmd.out" 2>&1 &
else
  touch "$B/hidden_unsupported"
  setsid slurmd -D -N localhost -f "$SLURM_CONF" </dev/null >"$B/log/slurmd.out" 2>&1 &
fi
echo $! >> "$B/pids"
setsid bash -c 'while kill -0 "$1" 2>/dev/null; do sleep 1; done; "$2" stop "$3"' watchdog "$owner" "$0" "$B" </dev/null >/dev/null 2>&1 &
echo $! > "$B/watchdog.pid"
for _ in $(seq 1 300); do
  if [ "$(sinfo -h -o %t 2>/dev/null)" = idle ]; then
    echo "Slurm cluster up: SLURM_CONF=$B/slurm.conf ports $ctld_port/$slurmd_port PIDs $(tr '\n' ' ' < "$B/pids")"
    exit 0
  fi
  sleep 0.1
done
echo "Slurm node did not become idle in 30 s; slurmctld: $(tail -3 "$B/log/slurmctld.log" 2>/dev/null); slurmd: $(tail -3 "$B/log/slurmd.log" 2>/dev/null)"
stop
exit 1
