"""How many different surfaces ``capture.dark_surface`` reads from one dark frame over repeated calls, with other
tensors allocated between calls (as a calibration allocates between reading its pairs' captures), on one thread as
``calibrate`` runs and on the machine's threads. Prints the counts; the package is the one on PYTHONPATH.

usage: PYTHONPATH=TREE python docs/bench/session101/dark_surface_repeats.py [CALLS]
"""

import hashlib
import sys

import torch

from lerobot_phantom.calibration.core import single_threaded
from lerobot_phantom.transforms.capture import dark_surface

calls = int(sys.argv[1]) if len(sys.argv) > 1 else 40
dark = torch.rand(3, 48, 64, generator=torch.Generator().manual_seed(0), dtype=torch.float64) * 0.1


def distinct() -> int:
    held, seen = [], set()
    for k in range(calls):
        held.append(torch.empty(7 * k + 1, dtype=torch.float64))
        seen.add(hashlib.md5(dark_surface(dark.clone()).numpy().tobytes()).hexdigest())
    return len(seen)


with single_threaded():
    print(f"one thread: {distinct()} different surfaces in {calls} calls")
print(f"{torch.get_num_threads()} threads: {distinct()} different surfaces in {calls} calls")
