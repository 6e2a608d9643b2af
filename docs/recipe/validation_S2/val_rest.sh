#!/bin/bash
# S2's steps 1250 and 1000, which the session-7 run did not reach (validated like the others), for pairing G1 with S2
cd /work/diag/S2
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
for s in 001250 001000; do
  lerobot-phantom-eval --policy.path=/work/diag/S2/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/S2/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
