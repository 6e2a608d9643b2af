#!/bin/bash
# Experiment G: run L's exact command (configs/smolvla_goal_cpu.json at lr 1e-4, the study's VLM, seed 0) on 100
# demonstrations collected like the study's (seed 0, action noise 0.3, 96 px) but with --grasp-miss-rate 0.5: half
# the episodes aim their first grasp 2.2-4 cm off the object, close on nothing, and recover (labels: the expert's).
# Does recovery data lift the clean TSR ceiling? Validated like L (50 episodes, env seeds 5000-5049).
set -e
cd /work/diag/G
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
lerobot-phantom-collect --suite goal --episodes 100 --action-noise 0.3 --image-size 96 --seed 0 \
  --grasp-miss-rate 0.5 --repo-id local/phantom_goal --root /work/diag/G/demos --progress=false > collect.log 2>&1
echo "collected $(date -u)"
lerobot-phantom-train --config_path=/work/main/configs/smolvla_goal_cpu.json --dataset.repo_id=local/phantom_goal \
  --dataset.root=/work/diag/G/demos --policy.vlm_model_name=/work/main/outputs/study/vlm \
  --output_dir=/work/diag/G/train --phantom.rate=0 --seed=0 > train.log 2>&1
echo "trained $(date -u)"
for s in 002000 001750 001500 001250 001000; do
  lerobot-phantom-eval --policy.path=/work/diag/G/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/G/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
