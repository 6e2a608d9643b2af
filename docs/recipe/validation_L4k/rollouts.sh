#!/bin/bash
# Failure modes of neighbouring checkpoints that swing (L4k 3500: 60% vs 3750: 14% on validation): every gripper close
# logged on the recipe's 54 rollout episodes (seeds 1000-1053), replanning every step.
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
K=/work/diag/L4k/train/checkpoints
for s in 003500 003750; do
  nice -n 5 python3 /work/main/scripts/recipe_rollouts.py $K/$s/pretrained_model --episodes 54 --replan 1 --out /work/diag/swing/L4k_$s.json
done
# and run L's step 2000 for comparison (docs/recipe/rollouts/L_2000_r1.json)
nice -n 5 python3 /work/main/scripts/recipe_rollouts.py /work/diag/L/train/checkpoints/002000/pretrained_model --episodes 54 --replan 1 \
  --out /work/diag/swing/L_002000.json
