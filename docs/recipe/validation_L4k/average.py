"""Scratch: uniform average of the weights of several checkpoints (post-hoc SWA); copies the first checkpoint's
pretrained_model directory (config, processors) and replaces its model.safetensors by the mean."""

import shutil
import sys
from pathlib import Path

from safetensors.torch import load_file, save_file

out, sources = Path(sys.argv[1]), [Path(p) for p in sys.argv[2:]]
if out.exists():
    raise SystemExit(f"{out} exists")
shutil.copytree(sources[0], out)
dtypes = {k: v.dtype for k, v in load_file(sources[0] / "model.safetensors").items()}
total = None
for source in sources:
    weights = load_file(source / "model.safetensors")
    if total is None:
        total = {k: v.double().clone() for k, v in weights.items()}
    else:
        for k, v in weights.items():
            total[k] += v.double()
average = {k: (v / len(sources)).to(dtypes[k]) for k, v in total.items()}
save_file(average, out / "model.safetensors")
print(f"averaged {len(sources)} checkpoints -> {out}")
