#!/bin/bash
# Experiment D300: run L's recipe (configs/smolvla_goal_cpu.json, lr 1e-4, seed 0, the study's VLM, 96 px) on 300
# scripted demonstrations instead of 100, for 3000 steps instead of 2000 (~5 epochs instead of ~21). Data at the lower
# rate is untested (500 demos at 3e-4 scored 19 %, under the rate's collapses).
set -e
cd /work/diag/D300
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
[ -d data ] || lerobot-phantom-collect --suite=goal --episodes=300 --action_noise=0.3 --image_size=96 --seed=0 \
  --repo_id=local/phantom_goal_300 --root=/work/diag/D300/data > collect.log 2>&1
lerobot-phantom-train --config_path=/work/main/configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal_300 \
  --dataset.root=/work/diag/D300/data --policy.vlm_model_name=/work/main/outputs/study/vlm \
  --output_dir=/work/diag/D300/train --phantom.rate=0 --seed=0 --steps=3000 > train.log 2>&1
for s in 001000 001500 002000 002250 002500 002750 003000; do
  lerobot-phantom-eval --policy.path=/work/diag/D300/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/D300/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
