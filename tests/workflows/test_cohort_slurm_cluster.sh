#!/usr/bin/env bash
# A private single-node Slurm cluster for the cohort tests
# (recipe: ../shared/notes/slurm-localhost.md): munged + slurmctld + slurmd
# with a fresh state folder B, on the given ports.
#   start B CTLD_PORT SLURMD_PORT OWNER_PID   -> writes B/slurm.conf, B/pids
#   stop B                                    -> cancels jobs, waits, stops the daemons, removes B
# A watchdog stops the cluster when OWNER_PID (the test process) dies, so a
# crashed test does not leave daemons behind.
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

ctld_port=$3; slurmd_port=$4; owner=$5
rm -rf "$B"; mkdir -p "$B/munge" "$B/state" "$B/spool" "$B/log"; chmod 755 "$B" "$B/munge"
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
munged -F --socket="$B/munge/munge.socket.2" --key-file="$B/munge/munge.key" --log-file="$B/log/munged.log" \
  --pid-file="$B/munge/munged.pid" --seed-file="$B/munge/munged.seed" </dev/null >/dev/null 2>&1 &
echo $! > "$B/pids"
for _ in $(seq 1 100); do [ -S "$B/munge/munge.socket.2" ] && break; sleep 0.05; done
[ -S "$B/munge/munge.socket.2" ] || { echo "munged did not start: $(tail -3 "$B/log/munged.log")"; stop; exit 1; }
setsid slurmctld -D -c -f "$SLURM_CONF" </dev/null >"$B/log/slurmctld.out" 2>&1 &
echo $! >> "$B/pids"
setsid slurmd -D -N localhost -f "$SLURM_CONF" </dev/null >"$B/log/slurmd.out" 2>&1 &
echo $! >> "$B/pids"
( while kill -0 "$owner" 2>/dev/null; do sleep 1; done; "$0" stop "$B" ) </dev/null >/dev/null 2>&1 &
echo $! > "$B/watchdog.pid"
for _ in $(seq 1 300); do
  [ "$(sinfo -h -o %t 2>/dev/null)" = idle ] && exit 0
  sleep 0.1
done
echo "Slurm node did not become idle in 30 s; slurmctld: $(tail -3 "$B/log/slurmctld.log" 2>/dev/null); slurmd: $(tail -3 "$B/log/slurmd.log" 2>/dev/null)"
stop
exit 1
