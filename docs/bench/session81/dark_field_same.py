"""Dark fields of test_blinding_model's glare captures (with a dark frame) under two package trees, and how far apart.

usage: python docs/bench/session81/dark_field_same.py OLD_TREE NEW_TREE
(each tree's package and tests are used; prints the largest absolute difference over every pair's field)
"""

import subprocess
import sys
import tempfile
from pathlib import Path

DUMP = """
import sys, torch
from test_blinding_model import glare_capture
from lerobot_phantom.calibration.frame_models import laser_blinding as lb
fields = {}
for gain in (30.0, 100.0):
    for slope in (0.0, 0.3):
        pairs = glare_capture(gain, room_slope=slope, dark_frame=True)[0].pairs
        fields[(gain, slope)] = [lb.dark_field(p, lb.pattern_centre(p.pattern)) for p in pairs]
torch.save(fields, sys.argv[1])
"""


def dump(tree: Path, out: Path) -> None:
    path = f"{tree}:{tree / 'tests' / 'calibration'}:{tree / 'tests'}"
    subprocess.run(
        [sys.executable, "-c", DUMP, str(out)], check=True, env={"PYTHONPATH": path, "HF_HUB_OFFLINE": "1"}
    )


def main() -> None:
    import torch

    old_tree, new_tree = (Path(a).resolve() for a in sys.argv[1:3])
    with tempfile.TemporaryDirectory() as tmp:
        old, new = Path(tmp, "old.pt"), Path(tmp, "new.pt")
        dump(old_tree, old)
        dump(new_tree, new)
        a, b = torch.load(old), torch.load(new)
    gaps = [float((x - y).abs().max()) for k in a for x, y in zip(a[k], b[k], strict=True)]
    print(f"{len(gaps)} dark fields ({len(a)} glare captures); largest absolute difference {max(gaps):.3g}")


if __name__ == "__main__":
    main()
