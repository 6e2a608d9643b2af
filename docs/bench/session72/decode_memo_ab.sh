#!/bin/bash
# decode_memo_ab.txt's two runs, alone and one after the other: usage decode_memo_ab.sh BEFORE_TREE AFTER_TREE PAIRS OUT
# (PAIRS: camsim's colour-correcting blinding_halo pairs of master seed 2964165977, as session64/run_camsim_case.py
# renders them with CAMSIM_CCM=1; the calibration seed is that case's, 1023687039)
here=$(cd "$(dirname "$0")" && pwd)
before=$1; after=$2; pairs=$3; out=$4
mkdir -p "$out"
for side in before after; do
  tree=$before; [ $side = after ] && tree=$after
  (cd "$tree" && OMP_NUM_THREADS=1 PYTHONPATH=$tree python "$here/calibrate_cpu.py" "$pairs" "$out/$side" 1023687039 \
    laser_blinding 2>/dev/null | tail -1 | sed "s/^/$side: /") >> "$out/times.txt"
done
