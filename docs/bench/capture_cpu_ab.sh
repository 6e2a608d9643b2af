#!/bin/bash
# User CPU of the laser-capture calibration on the shared captures, two checkouts alternating, ROUNDS rounds each,
# one process at a time (run it alone on the machine), with the report.json of every run kept in OUT_DIR:
#   docs/bench/capture_cpu_ab.sh OLD_TREE NEW_TREE OUT_DIR [ROUNDS] [MEASURED_DIR]
# (MEASURED_DIR defaults to ../shared/measured, third-party data that is not in this repository.)
set -euo pipefail
old=$1 new=$2 out=$3 rounds=${4:-2} measured=${5:-../shared/measured}
mkdir "$out"  # refuses an existing directory: results are never overwritten
for round in $(seq 1 "$rounds"); do
  for tree in old new; do
    checkout=$old
    [ "$tree" = new ] && checkout=$new
    /usr/bin/time -f "$tree round $round: %U s user" -a -o "$out/times.txt" \
      env OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH="$checkout" python3 -m lerobot_phantom.calibration.cli \
      --attack laser_blinding --measured "$measured/blinding" --out "$out/${tree}_$round" > /dev/null
  done
done
cat "$out/times.txt"
for round in $(seq 1 "$rounds"); do
  if cmp -s "$out/old_$round/calibrated.json" "$out/new_$round/calibrated.json"; then same=same; else same=DIFFERENT; fi
  echo "round $round: calibrated.json $same"
done
