#!/bin/bash
# decode_memo_ab.txt's two runs, alone and one after the other, by session68/blinding_cost.py (process CPU of one
# laser blinding calibration): usage decode_memo_ab.sh BEFORE_TREE AFTER_TREE PAIRS OUT
# (PAIRS: camsim's colour-correcting blinding_halo pairs of master seed 2964165977, as session64/run_camsim_case.py
# renders them with CAMSIM_CCM=1; the calibration seed is that case's, 1023687039)
cost=$(cd "$(dirname "$0")/.." && pwd)/session68/blinding_cost.py
before=$1; after=$2; pairs=$3; out=$4
mkdir -p "$out"
for side in before after; do
  tree=$before; [ $side = after ] && tree=$after
  (cd "$tree" && OMP_NUM_THREADS=1 PYTHONPATH=$tree python "$cost" "$pairs" 1023687039 "$out/$side" 2>/dev/null \
    | tail -1 | sed "s/^/$side: /") >> "$out/times.txt"
done
