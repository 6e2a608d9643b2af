#!/bin/bash
# Experiment L: the shipped recipe (A2 exact command) at a constant lr of 1e-4 instead of 3e-4 (collapses at steps 1250/2000 under 3e-4).
cd OUT
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
lerobot-phantom-train --config_path=configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal \
  --dataset.root=DATA --policy.vlm_model_name=VLM \
  --output_dir=OUT/train --phantom.rate=0 --seed=0 --policy.optimizer_lr=1e-4 --policy.scheduler_decay_lr=1e-4 > OUT/train.log 2>&1
for s in 000250 000500 000750 001000 001250 001500 001750 002000; do
  lerobot-phantom-eval --policy.path=OUT/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=OUT/validation/$s > OUT/val_$s.log 2>&1
done
