#!/usr/bin/env bash
# The Axis table (10 held-out splits) and the Logitech table (split 0) calibrated by the code after the drift re-grid
# (this checkout) and before it (a worktree of the commit given as $1, imported through PYTHONPATH), one run at a time.
# Usage: stripe_tables_before_after.sh BEFORE_WORKTREE AXIS_CSV LOGITECH_CSV
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../../.." && pwd)"
before="$1"; axis="$2"; logitech="$3"
after_commit="$(git -C "$repo" rev-parse --short HEAD)"
before_commit="$(git -C "$before" rev-parse --short HEAD)"
run() {  # label commit pythonpath table out seeds flags...
  local label=$1 commit=$2 path=$3 table=$4 out=$5 seeds=$6; shift 6
  PYTHONPATH="$path" HF_HUB_OFFLINE=1 python "$repo/docs/bench/stripe_table_seeds.py" "$table" "$out" \
    --seeds "$seeds" --note "session 38, $label ($commit), alone on the machine" "$@"
}
cd "$repo/docs/bench"
run after "$after_commit" "$repo" "$axis" "$here/axis_table_seeds_$after_commit.json" 0-9 --image-height 720 --exposure-unit-s 1e-6
run before "$before_commit" "$before" "$axis" "$here/axis_table_seeds_$before_commit.json" 0-9 --image-height 720 --exposure-unit-s 1e-6
run after "$after_commit" "$repo" "$logitech" "$here/logitech_table_seed0_$after_commit.json" 0 --image-height 720 --exposure-unit-s 1e-4
run before "$before_commit" "$before" "$logitech" "$here/logitech_table_seed0_$before_commit.json" 0 --image-height 720 --exposure-unit-s 1e-4
