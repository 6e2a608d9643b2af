#!/bin/bash
# Experiment S1: run L's exact command (configs/smolvla_goal_cpu.json at lr 1e-4, the study's 100 demos and VLM) with
# --seed=1 instead of 0 (other weight initialisation and batch order): how much of L's 50% at step 2000 is its seed?
set -e
cd /work/diag/S1
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
lerobot-phantom-train --config_path=/work/main/configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal \
  --dataset.root=/work/main/outputs/study/data/demos --policy.vlm_model_name=/work/main/outputs/study/vlm \
  --output_dir=/work/diag/S1/train --phantom.rate=0 --seed=1 > train.log 2>&1
for s in 002000 001750 001500 001250 001000; do
  lerobot-phantom-eval --policy.path=/work/diag/S1/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/S1/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
