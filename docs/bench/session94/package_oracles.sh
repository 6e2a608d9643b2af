#!/bin/bash
# Usage: bash docs/bench/session94/package_oracles.sh OUT (OUT relative to the repository root)
# session 93's oracles at the package with the inner core (e9b4c00; no knob): as drawn, the simplest camera, camsim
# metering uniformly, a fixed exposure; outputs in docs/bench/session94/package_oracles/ (stderr not kept: the
# capture reader's warnings only)
set -euo pipefail
cd "$(dirname "$0")/../../.."
OUT=$1
mkdir -p "$OUT"
SEEDS="2714032072 3993845907 3139070691"
FULL=linear_light_saturation,auto_exposure,tone_shoulder,colour_correction,frame_exposure
run() { local name=$1 effects=$2 camera=$3; shift 3
  env "$@" PROBE_EFFECTS="$effects" PROBE_CAMERA="$camera" CAMSIM_SEED=0 OMP_NUM_THREADS=1 \
    PYTHONPATH=.:tests/calibration:tests python docs/bench/session93/ccm_oracles.py $SEEDS 2> "$OUT/$name.err" > "$OUT/$name.txt"; }
run as_drawn $FULL '{}'
run simplest linear_light_saturation,colour_correction '{"full_well_e": 1e9, "read_noise_e": 0.0, "jpeg_quality": 100, "auto_exposure": false, "tone": "srgb"}' PROBE_GREY=1 PROBE_NO_MOSAIC=1
run uniform_meter $FULL '{}' PROBE_UNIFORM_METER=1
run fixed_exposure linear_light_saturation,tone_shoulder,colour_correction '{"auto_exposure": false}'
