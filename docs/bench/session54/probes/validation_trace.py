"""Runs a script with ``stripes.line_move_validates`` traced: for every call, the line's lowest point and the fit's
own, their squared errors, the decision, and per fold the point the training rows put lowest (of the tied ones, the
one nearest the fit's) with the validation rows' error there and at the fit's point.

Usage: ``OMP_NUM_THREADS=1 HF_HUB_OFFLINE=1 PYTHONPATH=. python docs/bench/session54/probes/validation_trace.py SCRIPT [ARGS]``
"""

import runpy
import sys

import numpy as np

import lerobot_phantom.calibration.stripes as stripes
from lerobot_phantom.calibration.core import kfold, ties_lowest

validates = stripes.line_move_validates


def traced(errors, inside, stay):
    decision = validates(errors, inside, stay)
    sse = np.where(inside, errors.sum(1), np.inf)
    lowest = int(np.argmin(sse))
    print(
        f"line: {errors.shape[1]} rows, lowest point {lowest} ({sse[lowest]:.1f}), fit's {stay} ({sse[stay]:.1f}): "
        + ("moves" if decision else "stays")
    )
    for training, validation in kfold(
        np.arange(errors.shape[1]), stripes.LINE_MOVE_FOLDS, stripes.LINE_MOVE_SEED
    ):
        training_error = np.where(inside, errors[:, training].sum(1), np.inf)
        tied = np.flatnonzero(ties_lowest(training_error, float(np.min(training_error))))
        point = int(tied[np.argmin(np.abs(tied - stay))])
        print(
            f"  fold: training lowest at {point}; validation {errors[point, validation].sum():.1f} there, "
            f"{errors[stay, validation].sum():.1f} at the fit's point"
        )
    return decision


stripes.line_move_validates = traced
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
