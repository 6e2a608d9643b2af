#!/bin/bash
# Experiment H128: run L's recipe (configs/smolvla_goal_cpu.json, lr 1e-4, seed 0, same VLM) on demos rendered at
# 128 px instead of 96 px. The policy input is 128x128 either way (resize_imgs_with_padding upsamples 96 px frames),
# so compute per step is unchanged; the question is whether real pixels at the grasp (0.75x the pixel pitch) lower the
# 2.6-2.8 cm xy misses that cap the recipe at 50-60 %.
set -e
cd /work/diag/H128
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
[ -d data ] || lerobot-phantom-collect --suite=goal --episodes=100 --action_noise=0.3 --image_size=128 --seed=0 \
  --repo_id=local/phantom_goal_128 --root=/work/diag/H128/data > collect.log 2>&1
lerobot-phantom-train --config_path=/work/main/configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal_128 \
  --dataset.root=/work/diag/H128/data --policy.vlm_model_name=/work/main/outputs/study/vlm \
  --output_dir=/work/diag/H128/train --phantom.rate=0 --seed=0 > train.log 2>&1
for s in 000250 000500 000750 001000 001250 001500 001750 002000; do
  lerobot-phantom-eval --policy.path=/work/diag/H128/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=128 --env.observation_width=128 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/H128/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
