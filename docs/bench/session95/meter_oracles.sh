#!/bin/bash
# Usage: bash docs/bench/session95/meter_oracles.sh OUT (OUT relative to the repository root)
# session 93's oracles at the package with the inner core (87cf9cd's package), camsim's meter taken apart: the
# model's form (uniform channel mean, as session 94's uniform_meter.txt), luminance metered uniformly, the channel
# mean centre-weighted (stderr not kept: the capture reader's warnings only)
set -euo pipefail
cd "$(dirname "$0")/../../.."
OUT=$1
mkdir -p "$OUT"
SEEDS="2714032072 3993845907 3139070691"
FULL=linear_light_saturation,auto_exposure,tone_shoulder,colour_correction,frame_exposure
run() { local name=$1; shift
  env "$@" PROBE_EFFECTS="$FULL" PROBE_CAMERA='{}' CAMSIM_SEED=0 OMP_NUM_THREADS=1 \
    PYTHONPATH=.:tests/calibration:tests python docs/bench/session93/ccm_oracles.py $SEEDS 2> "$OUT/$name.err" > "$OUT/$name.txt"
  rm "$OUT/$name.err"; }
run uniform_meter PROBE_UNIFORM_METER=1
run uniform_luma_meter PROBE_UNIFORM_LUMA_METER=1
run centred_mean_meter PROBE_CENTRED_MEAN_METER=1
