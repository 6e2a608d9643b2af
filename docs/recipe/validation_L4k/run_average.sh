#!/bin/bash
# Post-hoc weight averages of run L's checkpoints, validated on the study's seeds 5000-5049 like every checkpoint.
cd /work/diag/avg
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
while pgrep -f validate.sh > /dev/null; do sleep 20; done
L=/work/diag/L/train/checkpoints; K=/work/diag/L4k/train/checkpoints
python3 /work/main/docs/recipe/validation_L4k/average.py avg_L_1000_2000 $L/{001000,001250,001500,001750,002000}/pretrained_model
python3 /work/main/docs/recipe/validation_L4k/average.py avg_L4k_2000_4000 $L/002000/pretrained_model $K/{002250,002500,002750,003000,003250,003500,003750,004000}/pretrained_model
python3 /work/main/docs/recipe/validation_L4k/average.py avg_L4k_3000_4000 $K/{003000,003250,003500,003750,004000}/pretrained_model
for name in avg_L_1000_2000 avg_L4k_2000_4000 avg_L4k_3000_4000; do
  lerobot-phantom-eval --policy.path=/work/diag/avg/$name --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/avg/validation/$name > /work/diag/avg/val_$name.log 2>&1
  echo "$name $(date -u)"
done
