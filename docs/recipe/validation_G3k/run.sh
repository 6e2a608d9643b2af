#!/bin/bash
# Experiment G continued: G's step-2000 checkpoint resumed (LeRobot --resume: optimizer, scheduler and step restored)
# to 3000 steps at the same constant lr 1e-4 (45 min of training in all, inside the 90); every 250-step
# checkpoint validated on the study's seeds 5000-5049, like G's. Were G's checkpoints still rising at step 2000?
cd /work/diag/G3k
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
lerobot-phantom-train --config_path=/work/diag/G3k/train/checkpoints/002000/pretrained_model/train_config.json \
  --resume=true --steps=3000 --output_dir=/work/diag/G3k/train > /work/diag/G3k/train.log 2>&1
echo "trained $(date -u)"
for s in 003000 002750 002500 002250; do
  lerobot-phantom-eval --policy.path=/work/diag/G3k/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/G3k/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
