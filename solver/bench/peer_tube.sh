#!/usr/bin/env bash
# The svMultiPhysics peer tube (examples/peer_tube.yaml) timed on 1 and 2 MPI
# ranks with each linear solver: the median wall time of RUNS runs, Newton and
# linear iterations, and the deformed inner radius (svMultiPhysics: 0.966890 mm).
#   bash solver/bench/peer_tube.sh [RUNS] [BUILD_DIR]
# Side by side: with SVMP=/path/to/svMultiPhysics and SVMP_INPUT=/path/to/solver.xml
# (the same tube, mesh and loads in svMultiPhysics's own input) the peer runs in turn
# on the same rank counts and the ratios peer/stentsim are printed. svMultiPhysics
# is not a dependency of stentsim: build it from SimVascular/svMultiPhysics.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
runs="${1:-3}"
build="${2:-$here/build}"
solvers="${SOLVERS:-direct gmres_amg}"
ranks_list="${RANKS:-1 2}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
ninja -C "$build" stentsim > /dev/null
bin="$build/workflows/stentsim"
mpi=(mpirun --allow-run-as-root --oversubscribe --bind-to none)

median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }
# One timed run of a command; prints its wall seconds.
timed() {
  local t0 t1
  t0=$(date +%s.%N)
  "$@" > "$work/log" 2>&1 || { echo "failed: $*" >&2; tail -20 "$work/log" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.2f\n", b - a}'
}
# A summary.yaml QoI's value ("  name:\n    value: v").
field() { grep -A2 "^  $1:" "$2" | awk '$1 == "value:" {print $2; exit}'; }

printf '%-6s %-10s %10s %8s %8s %14s %10s\n' ranks solver "median_s" newton linear inner_radius peer_ratio
for ranks in $ranks_list; do
  peer=""
  if [ -n "${SVMP:-}" ]; then
    : > "$work/peer_times"
    for _ in $(seq "$runs"); do
      (cd "$(dirname "$SVMP_INPUT")" && timed "${mpi[@]}" -np "$ranks" "$SVMP" "$SVMP_INPUT") >> "$work/peer_times"
    done
    peer=$(median < "$work/peer_times")
    printf '%-6s %-10s %10s\n' "$ranks" svMultiPhysics "$peer"
  fi
  for solver in $solvers; do
    if [ "$solver" = direct ] && [ "$ranks" -gt 1 ]; then continue; fi  # gathered on rank 0: not a parallel solve
    : > "$work/times"
    for _ in $(seq "$runs"); do
      rm -rf "$work/out"
      timed "${mpi[@]}" -np "$ranks" "$bin" solve "$here/examples/peer_tube.yaml" --out "$work/out" --linear-solver "$solver" \
        >> "$work/times"
    done
    t=$(median < "$work/times")
    s="$work/out/summary.yaml"
    radius=$(field inner_radius_mid "$s")
    ratio=""
    [ -n "$peer" ] && ratio=$(awk -v p="$peer" -v t="$t" 'BEGIN {printf "%.2f", p / t}')
    printf '%-6s %-10s %10s %8s %8s %14s %10s\n' "$ranks" "$solver" "$t" "$(field newton_iterations "$s")" \
      "$(field linear_iterations "$s")" "$radius" "$ratio"
  done
done
