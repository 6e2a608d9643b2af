#!/bin/bash
# Paired two-process training runs of two source trees on busy cores, counting the runs that hang at exit.
#
#   docs/bench/ddp_teardown_pairs.sh OLD_TREE NEW_TREE PAIRS OUTDIR
#
# Each pair runs torchrun --nproc_per_node=2 lerobot_phantom.train.train (the tiny SmolVLA config, 6 steps, as
# tests/train/test_train.py::test_two_processes_share_one_epoch_plan) once from OLD_TREE, then once from NEW_TREE,
# while two busy-loop processes keep both cores loaded (the test suite's other xdist worker, made worse). A run still
# alive 50 s after it started is counted as hung; gdb's backtrace of every thread of its ranks and torchrun's log
# are written to OUTDIR before they are killed. Prints one line per run and a summary. See docs/bench/ddp_teardown.md.
set -u
old=$(realpath "$1"); new=$(realpath "$2"); pairs=$3; outdir=$4
mkdir -p "$outdir"
if [ -e "$outdir/runs.txt" ]; then echo "$outdir/runs.txt exists; choose a new OUTDIR" >&2; exit 2; fi
work=$(mktemp -d)
PYTHONPATH=$old HF_HUB_OFFLINE=1 python3 - "$work" <<'PY'
import sys
from pathlib import Path

from lerobot_phantom.datasets.synthetic import TASKS, build_synthetic_dataset
from lerobot_phantom.train.make_vlm import make_vlm

work = Path(sys.argv[1])
build_synthetic_dataset(work / "tiny", "phantom/tiny", episode_lengths=(12, 12), cameras=("observation.images.front",))
make_vlm(work / "tiny_vlm", "tiny", tasks=TASKS)
PY
python3 -c "while True: pass" & burner1=$!
python3 -c "while True: pass" & burner2=$!
trap 'kill $burner1 $burner2 2>/dev/null; rm -rf "$work"' EXIT
hung_old=0; hung_new=0
for i in $(seq 1 "$pairs"); do
  for side in old new; do
    if [ $side = old ]; then tree=$old; else tree=$new; fi
    PYTHONPATH=$tree HF_HUB_OFFLINE=1 OMP_NUM_THREADS=1 python3 -m torch.distributed.run --standalone \
      --nproc_per_node=2 -m lerobot_phantom.train.train --config_path="$tree/configs/tiny_smolvla_cpu.json" \
      --dataset.repo_id=phantom/tiny --dataset.root="$work/tiny" --policy.vlm_model_name="$work/tiny_vlm" \
      --output_dir="$work/run_${side}_$i" --batch_size=2 --steps=6 --log_freq=6 > "$work/log.txt" 2>&1 &
    pid=$!
    for _ in $(seq 1 50); do sleep 1; kill -0 $pid 2>/dev/null || break; done
    if kill -0 $pid 2>/dev/null; then
      for rank_pid in $(pgrep -P $pid); do
        gdb -p "$rank_pid" -batch -ex "thread apply all bt" > "$outdir/gdb_${side}_${i}_$rank_pid.txt" 2>&1
      done
      kill -9 $(pgrep -P $pid) $pid; wait $pid 2>/dev/null
      cp "$work/log.txt" "$outdir/log_${side}_$i.txt"  # where it stopped: in training or at exit
      echo "pair $i $side hung" | tee -a "$outdir/runs.txt"
      if [ $side = old ]; then hung_old=$((hung_old + 1)); else hung_new=$((hung_new + 1)); fi
    else
      wait $pid; echo "pair $i $side rc=$?" | tee -a "$outdir/runs.txt"
    fi
    rm -rf "$work/run_${side}_$i"
  done
done
echo "old $old: $hung_old of $pairs hung; new $new: $hung_new of $pairs hung" | tee -a "$outdir/runs.txt"
