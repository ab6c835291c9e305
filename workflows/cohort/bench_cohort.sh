#!/usr/bin/env bash
# Benchmark (not a test), issue 10: a cohort of N phantom cases through the
# preprocessing stages (segmentation, centerline by default) with --force:
#   local back-end, 1 worker vs 2 workers (speed-up), and
#   Slurm back-end on a private single-node cluster (tests/workflows/
#   test_cohort_slurm_cluster.sh) vs the local pool: overhead per case.
# Median of R runs each; prints nproc and the load average before and after
# every run (the machine may be shared: compare like with like).
# Usage: bench_cohort.sh STENTSIM_BINARY [N=8] [R=3] [UNTIL=centerline] [slurm|noslurm]
set -euo pipefail
bin=$(realpath "$1"); n=${2:-8}; reps=${3:-3}; until=${4:-centerline}; slurm=${5:-slurm}
src=$(cd "$(dirname "$0")/../.." && pwd)
dir=$(mktemp -d /tmp/stentsim-bench-cohort.XXXXXX); chmod 755 "$dir"  # munged wants its socket path traversable by all
cluster=$dir/cluster
cleanup() { [ -f "$cluster/pids" ] && "$src/tests/workflows/test_cohort_slurm_cluster.sh" stop "$cluster"; rm -rf "$dir"; }
trap cleanup EXIT
"$bin" init --cohort "$dir" > /dev/null
{
  echo "name: bench"; echo "template: patient.yaml"; echo "slurm: {poll_interval_s: 0.2}"; echo "cases:"
  for i in $(seq 1 "$n"); do
    echo "  - id: c$i"; echo "    overrides: {input: {phantom: {preset: case2-rca, seed: $i}}}"
  done
} > "$dir/bench.yaml"
load() { cut -d' ' -f1-3 /proc/loadavg; }
echo "date=$(date -u +%FT%TZ) nproc=$(nproc) load=$(load) cases=$n until=$until reps=$reps"
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
declare -A med
bench() {  # label, extra args
  local label=$1; shift
  local times=() loads=()
  for r in $(seq 1 "$reps"); do
    local l0; l0=$(cut -d' ' -f1 /proc/loadavg)
    local t0; t0=$(date +%s.%N)
    "$bin" cohort run "$dir/bench.yaml" --until "$until" --force "$@" > "$dir/run-$label-$r.log" 2>&1 || { cat "$dir/run-$label-$r.log"; exit 1; }
    local t1; t1=$(date +%s.%N)
    times+=("$(echo "$t1 - $t0" | bc)"); loads+=("$l0")
  done
  med[$label]=$(printf '%s\n' "${times[@]}" | median)
  echo "$label runs: ${times[*]} s, median ${med[$label]} s (1-min load before each: ${loads[*]}; after: $(cut -d' ' -f1 /proc/loadavg))"
}
bench local-1 --workers 1
bench local-2 --workers 2
echo "speed-up 2 vs 1 workers: $(echo "scale=3; ${med[local-1]} / ${med[local-2]}" | bc)"
if [ "$slurm" = slurm ]; then
  "$src/tests/workflows/test_cohort_slurm_cluster.sh" start "$cluster"
  export SLURM_CONF=$cluster/slurm.conf
  bench slurm --backend slurm
  echo "slurm overhead vs local pool (2 workers, node CPUs=$(nproc)): $(echo "scale=3; (${med[slurm]} - ${med[local-2]}) / $n" | bc) s per case," \
       "$(echo "scale=3; ${med[slurm]} - ${med[local-2]}" | bc) s per cohort (probe job included)"
fi
