#!/bin/bash
# CPU and wall time of camsim projection calibrations at two packages, one at a time, nothing else running:
# docs/bench/session97/time_projection_cases.sh OLD_TREE NEW_TREE OUTDIR CASE:SEED...  [CAMSIM_CCM=1 for its cameras]
old=$1; new=$2; out=$3; shift 3
for item in "$@"; do
  case_name=${item%%:*}; seed=${item##*:}
  for tree in "$old" "$new"; do
    label=$(git -C "$tree" rev-parse --short HEAD)
    start=$(date +%s.%N)
    times=$( { (cd "$tree" && OMP_NUM_THREADS=1 PYTHONPATH=$tree:$tree/tests/calibration:$tree/tests \
      bash -c "time python docs/bench/session64/run_camsim_case.py $case_name $out/$label/$case_name $seed" \
      > "$out/$label-$case_name-$seed.log" 2>&1); } 2>&1 )
    grep -v Warn "$out/$label-$case_name-$seed.log" | grep "$seed"
    echo "$label $case_name $seed: $(tail -3 "$out/$label-$case_name-$seed.log" | tr '\n' ' ')"
  done
done
