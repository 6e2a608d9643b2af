"""EM truncation's functional call and transform, this checkout against an earlier commit, interleaved:
``python truncation_timing.py REV`` from the checkout's root (``git show REV:...`` supplies the earlier module).
Prints the best time per call of each and their ratio, and checks that both give the same output."""

import importlib.util
import subprocess
import sys
import tempfile
import timeit
from pathlib import Path

import torch

from lerobot_phantom.transforms import em_truncation as current

MODULE = "lerobot_phantom/transforms/em_truncation.py"


def earlier_module(rev: str):
    source = subprocess.run(
        ["git", "show", f"{rev}:{MODULE}"], check=True, capture_output=True, text=True
    ).stdout
    path = Path(tempfile.mkdtemp()) / "earlier_em_truncation.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location("earlier_em_truncation", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def best(call, rounds: int = 6) -> dict[str, float]:
    times = {"earlier": [], "current": []}
    for k in range(rounds):
        for label in ("earlier", "current") if k % 2 == 0 else ("current", "earlier"):
            times[label].append(
                min(timeit.repeat(lambda label=label: call(label), number=200, repeat=3)) / 200
            )
    return {label: min(values) for label, values in times.items()}


def main() -> None:
    earlier = earlier_module(sys.argv[1])
    modules = {"earlier": earlier, "current": current}
    batch = torch.randint(
        0, 256, (8, 3, 224, 224), dtype=torch.uint8, generator=torch.Generator().manual_seed(0)
    )
    ratios = torch.linspace(0.1, 0.3, 8)
    image = batch[0]
    attacks = {label: m.EMTruncation("strong", seed=0) for label, m in modules.items()}
    cases = {
        "functional, 8 x 3 x 224 x 224 uint8, per-sample ratios": lambda label: modules[label].em_truncation(
            batch, ratios
        ),
        "transform at 'strong', one 3 x 224 x 224 uint8 image": lambda label: attacks[label](image),
    }
    for name, call in cases.items():
        assert torch.equal(call("earlier"), call("current")), name
        t = best(call)
        print(
            f"{name}: {sys.argv[1]} {t['earlier'] * 1e6:.1f} us, now {t['current'] * 1e6:.1f} us, "
            f"ratio {t['current'] / t['earlier']:.2f}"
        )


if __name__ == "__main__":
    main()
