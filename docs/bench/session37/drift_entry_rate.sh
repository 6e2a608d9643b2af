#!/usr/bin/env bash
# the entry-drift test on fresh STRIPES_SEED values, one at a time
cd "$(dirname "$0")/../../.." || exit 1
for seed in "$@"; do
  result=$(HF_HUB_OFFLINE=1 STRIPES_SEED=$seed python -m pytest -q -p no:cacheprovider \
    "tests/calibration/test_stripes.py::test_recordings_that_drift_are_named_and_locked_ones_are_not[two recordings drift from the entry]" 2>&1 \
    | grep -a -E "^E +assert [0-9.]+ <|^E +AssertionError|[0-9]+ (passed|failed)" | head -2 | tr '\n' ' ')
  echo "STRIPES_SEED=$seed $result"
done
