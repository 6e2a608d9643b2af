#!/usr/bin/env bash
# test_a_drifting_recording_matches_the_simulator (4 cases) on STRIPES_SEED values, one at a time: the outcome line
cd "$(dirname "$0")/../../.." || exit 1
for seed in "$@"; do
  result=$(HF_HUB_OFFLINE=1 STRIPES_SEED=$seed python -m pytest -q -p no:cacheprovider \
    tests/calibration/test_stripes.py -k "drifting_recording_matches" 2>&1 \
    | grep -a -E "^E +AssertionError|[0-9]+ (passed|failed)" | tr '\n' ' ')
  echo "STRIPES_SEED=$seed $result"
done
