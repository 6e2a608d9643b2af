#!/bin/bash
# G continued (killed at step ~2900, when it was found competing with the study): its saved checkpoints validated
# like G's, on the study's seeds 5000-5049, once the study (pid 25464) has finished.
cd /work/diag/G3k
export OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=/work/main
while kill -0 25464 2>/dev/null; do sleep 10; done
for s in 002750 002500 002250; do
  lerobot-phantom-eval --policy.path=/work/diag/G3k/train/checkpoints/$s/pretrained_model --env.type=phantom_table \
    --env.task=goal --env.observation_height=96 --env.observation_width=96 --eval.n_episodes=50 --eval.batch_size=10 \
    --seed=5000 '--phantom.attacks=[]' --output_dir=/work/diag/G3k/validation/$s > val_$s.log 2>&1
  echo "$s $(date -u)"
done
