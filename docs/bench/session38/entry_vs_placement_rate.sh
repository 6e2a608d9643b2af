#!/usr/bin/env bash
# test_the_entry_start_is_told_from_any_whole_placement on STRIPES_SEED values, one at a time: outcome and the
# failing assertion's line
cd "$(dirname "$0")/../../.." || exit 1
for seed in "$@"; do
  result=$(HF_HUB_OFFLINE=1 STRIPES_SEED=$seed python -m pytest -q -p no:cacheprovider \
    tests/calibration/test_stripes.py -k "entry_start_is_told" 2>&1 \
    | grep -a -E "^E +entry gain|^E +assert |[0-9]+ (passed|failed)" | tr '\n' ' ')
  echo "STRIPES_SEED=$seed $result"
done
