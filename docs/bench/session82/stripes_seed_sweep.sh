#!/usr/bin/env bash
# Runs tests/calibration/test_stripes.py (as the README's suite selects it) once per fresh STRIPES_SEED and prints
# each run's summary line and failures: how often a fresh draw fails a stripe test.
# Usage: docs/bench/session82/stripes_seed_sweep.sh RUNS
set -u
for _ in $(seq "$1"); do
  seed=$(python3 -c "import secrets; print(secrets.randbelow(2**32))")
  echo "STRIPES_SEED=$seed"
  STRIPES_SEED=$seed HF_HUB_OFFLINE=1 python3 -m pytest -q -n 2 -p no:cacheprovider -rfxX \
    tests/calibration/test_stripes.py 2>&1 | grep -E "^(FAILED|XPASS|XFAIL|ERROR)|passed|failed" | cut -c1-220
done
