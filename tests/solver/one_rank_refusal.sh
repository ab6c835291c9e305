#!/bin/sh
# A solver type that runs on one MPI rank, asked for on two: every rank refuses it
# (exit 2, the type named) instead of solving its own rows only.
# Usage: one_rank_refusal.sh MPIEXEC STENTSIM SCENE OUT TYPE
out=$("$1" --allow-run-as-root --oversubscribe --mca mpi_yield_when_idle 1 -np 2 "$2" solve "$3" --linear-solver "$5" --out "$4" 2>&1)
rc=$?
echo "$out"
[ "$rc" -eq 2 ] || { echo "exit $rc, expected 2"; exit 1; }
echo "$out" | grep -q "linear solver $5 runs on one MPI rank" || { echo "the refusal is not in the output"; exit 1; }
