#!/bin/bash
# Run G (grasp-miss demonstrations) on the recipe's 54 rollout episodes (seeds 1000-1053, disjoint from the validation
# seeds 5000-5049 that picked the checkpoints), every gripper close logged, replanning every step: does its
# validation score hold on other episodes, and do its policies re-grasp after a miss (L's step 2000: 4 of 20)?
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
python3 /work/main/scripts/recipe_rollouts.py /work/diag/G/train/checkpoints/002000/pretrained_model --episodes 54 --replan 1 --out G_2000_r1.json
python3 /work/main/scripts/recipe_rollouts.py /work/diag/G1/train/checkpoints/002000/pretrained_model --episodes 54 --replan 1 --out G1_2000_r1.json
python3 /work/main/scripts/recipe_rollouts.py /work/diag/G1/train/checkpoints/001500/pretrained_model --episodes 54 --replan 1 --out G1_1500_r1.json
