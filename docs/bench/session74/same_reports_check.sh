# usage: ROOT=DIR bash same_reports_check.sh (DIR/before, DIR/head: worktrees of the two commits)
set -e
for side in before head; do
  cd $ROOT/$side
  for c in projection_null strip_null truncation_null blur_null blinding_null; do
    CAMSIM_CASES=all PYTHONPATH=.:tests/calibration:tests python docs/bench/session64/run_camsim_case.py $c $ROOT/same_$side 1216297851
  done
done
