#!/bin/bash
# Experiment M: the shipped recipe (A2's exact command) with the gripper entry of the state masked.
cd /work/diag/M
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
lerobot-phantom-train --config_path=/work/main/configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal \
  --dataset.root=/work/main/outputs/study/data/demos --policy.vlm_model_name=/work/main/outputs/study/vlm \
  --output_dir=/work/diag/M/train --phantom.rate=0 --seed=0 --mask_state='[3]' > /work/diag/M/train.log 2>&1
for s in 000250 000500 000750 001000 001250 001500 001750 002000; do
  lerobot-phantom-eval --policy.path=/work/diag/M/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/M/validation/$s > /work/diag/M/val_$s.log 2>&1
done
