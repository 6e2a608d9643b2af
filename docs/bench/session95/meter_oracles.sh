#!/bin/bash
# Usage: [AT_LUMINANCE_METER=1] bash docs/bench/session95/meter_oracles.sh OUT (OUT relative to the repository root)
# session 93's oracles at the package with the inner core (87cf9cd's package; the first three files), camsim's meter taken apart: the
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
# at 3025648's package (the meter reads luminance under colour_correction): as drawn, and camsim metering luminance
# uniformly (the model's form now)
if [ "${AT_LUMINANCE_METER:-0}" = 1 ]; then
  run luminance_as_drawn
  run luminance_uniform_luma_meter PROBE_UNIFORM_LUMA_METER=1
  exit 0
fi
run uniform_meter PROBE_UNIFORM_METER=1
run uniform_luma_meter PROBE_UNIFORM_LUMA_METER=1
run centred_mean_meter PROBE_CENTRED_MEAN_METER=1
