#!/bin/bash
# one drawn case at the old and the new package side by side (one process each, the same contention)
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1
for spec in "lit 2945606860" "interior 2945606860" "lit 3298423851" "interior 3298423851"; do
  set -- $spec
  for tree in old new; do
    (cd /work/scratch/s57/$tree && PYTHONPATH=/work/scratch/s57/$tree /usr/bin/time -f "$tree $1 $2 user %U s wall %e s" python docs/bench/second_camera_sweep.py --frames $1 $2 > /work/scratch/s57/cost_${tree}_$1_$2.txt 2>> /work/scratch/s57/cost_times.txt) &
  done
  wait
done
