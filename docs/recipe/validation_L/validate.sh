#!/bin/bash
# Validate experiment L's checkpoints as they appear (clean only, the study's validation seeds 5000-5049), one at a time.
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
for s in 000250 000500 000750 001000 001250 001500 001750 002000; do
  while [ ! -f OUT/train/checkpoints/$s/pretrained_model/model.safetensors ]; do sleep 15; done
  sleep 20  # the checkpoint's other files
  lerobot-phantom-eval --policy.path=OUT/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=OUT/validation/$s > OUT/val_$s.log 2>&1
  echo "$s $(date -u)"
done
