#!/bin/bash
# Experiment L continued: L's step-2000 checkpoint resumed (LeRobot --resume: optimizer, scheduler and step restored)
# to 4000 steps at the same constant lr 1e-4; every 250-step checkpoint validated on the study's seeds 5000-5049.
cd /work/diag/L4k
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
lerobot-phantom-train --config_path=/work/diag/L4k/train/checkpoints/002000/pretrained_model/train_config.json \
  --resume=true --steps=4000 --output_dir=/work/diag/L4k/train > /work/diag/L4k/train.log 2>&1
