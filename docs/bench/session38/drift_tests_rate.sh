#!/usr/bin/env bash
# the four drift-naming tests (placement, entry, null: locked; entry told from placement) on fresh STRIPES_SEED
# values, one seed at a time; prints each test's outcome and the first assertion line of a failure
cd "$(dirname "$0")/../../.." || exit 1
for seed in "$@"; do
  result=$(HF_HUB_OFFLINE=1 STRIPES_SEED=$seed python -m pytest -q -p no:cacheprovider -rA \
    tests/calibration/test_stripes.py -k "recordings_that_drift or entry_start_is_told" 2>&1 \
    | grep -a -E "^(PASSED|FAILED|XFAIL|XPASS)|^E +assert |[0-9]+ (passed|failed)" | tr '\n' ' ')
  echo "STRIPES_SEED=$seed $result"
done
