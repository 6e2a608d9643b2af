#!/bin/bash
# Experiment G, seed 1: G's command (demonstrations with --grasp-miss-rate 0.5, /work/diag/G/demos) with --seed=1, to
# compare against seed 1 of L (validation_S1) as G against L: the seed moves a checkpoint by up to 28 pp.
set -e
cd /work/diag/G1
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
# (ran beside G, one run per core, like S1/S2)
lerobot-phantom-train --config_path=/work/main/configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal \
  --dataset.root=/work/diag/G/demos --policy.vlm_model_name=/work/main/outputs/study/vlm \
  --output_dir=/work/diag/G1/train --phantom.rate=0 --seed=1 > train.log 2>&1
echo "trained $(date -u)"
for s in 002000 001750 001500 001250 001000; do
  lerobot-phantom-eval --policy.path=/work/diag/G1/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/G1/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
