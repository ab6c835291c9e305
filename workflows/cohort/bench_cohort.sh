#!/usr/bin/env bash
# Benchmark (not a test): a cohort of N phantom cases through segmentation and
# centerline on the local back-end, 1 worker vs 2 workers, median of R runs.
# Usage: bench_cohort.sh STENTSIM_BINARY [N=8] [R=3] [UNTIL=centerline]
set -euo pipefail
bin=$1; n=${2:-8}; reps=${3:-3}; until=${4:-centerline}
dir=$(mktemp -d /tmp/stentsim-bench-cohort.XXXXXX)
trap 'rm -rf "$dir"' EXIT
"$bin" init --cohort "$dir" > /dev/null
{
  echo "name: bench"; echo "template: patient.yaml"; echo "cases:"
  for i in $(seq 1 "$n"); do
    echo "  - id: c$i"; echo "    overrides: {input: {phantom: {preset: case2-rca, seed: $i}}}"
  done
} > "$dir/bench.yaml"
echo "nproc=$(nproc) load=$(cut -d' ' -f1-3 /proc/loadavg) cases=$n until=$until"
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for w in 1 2; do
  times=()
  for r in $(seq 1 "$reps"); do
    t0=$(date +%s.%N)
    "$bin" cohort run "$dir/bench.yaml" --workers "$w" --until "$until" --force > "$dir/run-$w-$r.log" 2>&1 || { cat "$dir/run-$w-$r.log"; exit 1; }
    t1=$(date +%s.%N)
    times+=("$(echo "$t1 - $t0" | bc)")
  done
  echo "workers=$w runs: ${times[*]} median: $(printf '%s\n' "${times[@]}" | median) s (load after: $(cut -d' ' -f1 /proc/loadavg))"
done
