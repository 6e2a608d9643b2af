#!/bin/bash
# The camsim core selection (tests/calibration/test_independent_sim.py) on several master seeds, one after another.
# usage: [CAMSIM_CASES=a,b] [CAMSIM_TIMEOUT=s] [CAMSIM_TESTS=expr] docs/bench/camsim_core_batch.sh TREE OUTDIR SEED...
# (TREE: a checkout; its package is what is tested; CAMSIM_CASES: the cases, default the core selection; CAMSIM_TIMEOUT: seconds per
# seed, default 5400: CAMSIM_CASES=all took 1592-1942 s per seed in session 56, two seeds side by side; CAMSIM_TESTS:
# a pytest -k expression, e.g. test_case for the drawn cases without the file's fixed-seed tests)
# Per seed: OUTDIR/log_SEED.txt (pytest -rA output, --runxfail), OUTDIR/bt_SEED (pytest's basetemp, with every
# case's pairs and report.json) and one line in OUTDIR/summary.txt; docs/bench/camsim_batch_misses.py OUTDIR counts it.
tree=$1; out=$2; shift 2
mkdir -p "$out"
for s in "$@"; do
  (cd "$tree" && CAMSIM_SEED=$s CAMSIM_CASES=${CAMSIM_CASES:-core} HF_HUB_OFFLINE=1 OMP_NUM_THREADS=1 PYTHONPATH=$tree timeout ${CAMSIM_TIMEOUT:-5400} \
    python3 -m pytest -q -p no:cacheprovider --runxfail -rA --durations=0 --basetemp="$out/bt_$s" -k "${CAMSIM_TESTS:-}" \
    tests/calibration/test_independent_sim.py > "$out/log_$s.txt" 2>&1)
  echo "seed $s: $(grep -E 'AssertionError: planted|passed|failed' "$out/log_$s.txt" | tail -2 | tr '\n' ' ')" >> "$out/summary.txt"
done
