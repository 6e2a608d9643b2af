#!/bin/bash
# Every oracle of docs/bench/session93.md on the three colour-correcting auto-exposure draws that miss
# frame_exposure, one output file per variant in OUT. Two streams (A and B) share the two cores.
# Usage: bash docs/bench/session93/ccm_oracles.sh OUT A|B|C (C: the camera as drawn, its core measured, at a fixed
# exposure; run after A and B)
set -euo pipefail
OUT=$1
mkdir -p "$OUT"
SEEDS="2714032072 3993845907 3139070691"
FULL=linear_light_saturation,auto_exposure,tone_shoulder,colour_correction,frame_exposure
SIMPLE=linear_light_saturation,colour_correction
NOISELESS='"full_well_e": 1e9, "read_noise_e": 0.0, "jpeg_quality": 100'
SIMPLEST="{$NOISELESS, \"auto_exposure\": false, \"tone\": \"srgb\"}"
run() { # name effects camera-json knob=1...
  local name=$1 effects=$2 camera=$3
  shift 3
  env "$@" PROBE_EFFECTS="$effects" PROBE_CAMERA="$camera" CAMSIM_SEED=0 OMP_NUM_THREADS=1 \
    PYTHONPATH=.:tests/calibration:tests python docs/bench/session93/ccm_oracles.py $SEEDS 2> "$OUT/$name.err" \
    > "$OUT/$name.txt"
}
if [ "$2" = A ]; then
  run as_drawn $FULL '{}'
  run uniform_meter $FULL '{}' PROBE_UNIFORM_METER=1
  run noiseless $FULL "{$NOISELESS}"
  run grey_noiseless_no_mosaic $FULL "{$NOISELESS}" PROBE_GREY=1 PROBE_NO_MOSAIC=1
  run simplest $SIMPLE "$SIMPLEST" PROBE_GREY=1 PROBE_NO_MOSAIC=1
  run simplest_unsaturated $SIMPLE "$SIMPLEST" PROBE_GREY=1 PROBE_NO_MOSAIC=1 PROBE_UNSATURATED=1
  run simplest_unsaturated_noise_jpeg $SIMPLE '{"auto_exposure": false, "tone": "srgb"}' PROBE_GREY=1 \
    PROBE_NO_MOSAIC=1 PROBE_UNSATURATED=1
  run simplest_unsaturated_camera_tone $SIMPLE,tone_shoulder "{$NOISELESS, \"auto_exposure\": false}" PROBE_GREY=1 \
    PROBE_NO_MOSAIC=1 PROBE_UNSATURATED=1
elif [ "$2" = C ]; then
  run unsaturated_fixed_exposure linear_light_saturation,tone_shoulder,colour_correction '{"auto_exposure": false}' \
    PROBE_UNSATURATED=1
else
  run unsaturated $FULL '{}' PROBE_UNSATURATED=1
  run fixed_exposure linear_light_saturation,tone_shoulder,colour_correction '{"auto_exposure": false}'
  run grey_noiseless $FULL "{$NOISELESS}" PROBE_GREY=1
  run simplest_auto_exposure $SIMPLE,auto_exposure,frame_exposure "{$NOISELESS, \"tone\": \"srgb\"}" PROBE_GREY=1 \
    PROBE_NO_MOSAIC=1
  run simplest_no_matrix linear_light_saturation "{$NOISELESS, \"auto_exposure\": false, \"tone\": \"srgb\", \"ccm\": null}" \
    PROBE_GREY=1 PROBE_NO_MOSAIC=1
  run simplest_unsaturated_mosaic $SIMPLE "$SIMPLEST" PROBE_GREY=1 PROBE_UNSATURATED=1
  run simplest_unsaturated_colour_scenes $SIMPLE "$SIMPLEST" PROBE_NO_MOSAIC=1 PROBE_UNSATURATED=1
  run simplest_unsaturated_auto_exposure $SIMPLE,auto_exposure,frame_exposure "{$NOISELESS, \"tone\": \"srgb\"}" \
    PROBE_GREY=1 PROBE_NO_MOSAIC=1 PROBE_UNSATURATED=1
fi
