#!/bin/bash
# Validate experiment L's checkpoints as they appear (clean only, the study's validation seeds 5000-5049), one at a time.
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
for s in 002250 002500 002750 003000 003250 003500 003750 004000; do
  while [ ! -f /work/diag/L4k/train/checkpoints/$s/pretrained_model/model.safetensors ]; do sleep 15; done
  sleep 20  # the checkpoint's other files
  lerobot-phantom-eval --policy.path=/work/diag/L4k/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/L4k/validation/$s > /work/diag/L4k/val_$s.log 2>&1
  echo "$s $(date -u)"
done
