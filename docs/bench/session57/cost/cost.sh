#!/bin/bash
# One drawn case at a time at two package versions side by side (one process each, so both carry the same
# contention). TREES holds two worktrees, old/ and new/ (session 57: c2eb636 and e5cd32f); outputs go beside them.
set -u
: "${TREES:?set TREES to a folder holding the worktrees old/ and new/}"
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1
for spec in "lit 2945606860" "interior 2945606860" "lit 3298423851" "interior 3298423851"; do
  set -- $spec
  for tree in old new; do
    (cd "$TREES/$tree" && PYTHONPATH="$TREES/$tree" /usr/bin/time -f "$tree $1 $2 user %U s wall %e s" \
      python docs/bench/second_camera_sweep.py --frames "$1" "$2" > "$TREES/cost_${tree}_$1_$2.txt" \
      2>> "$TREES/cost_times.txt") &
  done
  wait
done
