"""Which light a meter reads, on camsim's colour-correcting camera (``CAMSIM_CCM=1``): on each pair of a draw of the
auto-exposure blinding case, camsim's meter factor ``k`` (the attacked frame's exposure over the clean one's; camsim
meters the centre-weighted luma of its raw light, before the matrix) beside four uniform meters of the same light:
luma or channel mean, of the raw light (what a model with ``colour_correction`` meters) or of the matrix's output
``max(M raw, 0)`` (what a model without it meters, its channels being the frame's). The fitted meter power ``a``
takes ``k`` to ``k ** a``, so per draw and form: ``a`` fitted through the origin on log k over the pairs, and the RMS
of what is left (what no power absorbs), beside the median ``k``. No calibration runs.

Usage: ``CAMSIM_SEED=0 CAMSIM_CCM=1 PYTHONPATH=.:tests/calibration:tests:docs/bench/session88:docs/bench/session90
python docs/bench/session91/ccm_meter_parts.py MASTER_SEED...`` (the case's seed is drawn from each master seed as
the camsim test draws it).
"""

from __future__ import annotations

import sys

import camsim
import numpy as np
import test_independent_sim as sim
from blinding_exposure_sensitivity import record_captures
from camsim_meter_parts import solve


def main() -> None:
    calls = record_captures()  # (irradiance, camera, exposure asked or None, exposure used)
    case = sim.CASE_BY_NAME["blinding_auto_exposure"]
    index = [c.name for c in sim.CASES].index(case.name)
    for master in [int(s) for s in sys.argv[1:]]:
        seed = int(np.random.SeedSequence(master, spawn_key=(index,)).generate_state(1)[0])
        calls.clear()
        _, rng, cam = sim.case_camera(case, seed)
        if cam.ccm is None:
            raise SystemExit("CAMSIM_CCM=1 is needed: this camera has no colour correction matrix")
        matrix = np.reshape(cam.ccm, (3, 3))
        case.render(rng, cam)
        attacked_calls = [k for k, c in enumerate(calls) if c[2] is None]
        clean_calls = [0] + [k - 1 for k in attacked_calls[1:]]
        forms = {
            "raw luma": lambda x: x @ camsim.LUMA,
            "raw channel mean": lambda x: x.mean(2),
            "output luma": lambda x, m=matrix: np.maximum(x @ m.T, 0.0) @ camsim.LUMA,
            "output channel mean": lambda x, m=matrix: np.maximum(x @ m.T, 0.0).mean(2),
        }
        uniform = np.full((cam.height, cam.width), 1.0 / (cam.height * cam.width))
        log_k = {name: [] for name in ("camsim", *forms)}
        for attacked, clean in zip(attacked_calls, clean_calls, strict=True):
            exposure = calls[clean][3]
            light = exposure * camsim.optics(calls[attacked][0], cam)
            scene = exposure * camsim.optics(calls[clean][0], cam)
            log_k["camsim"].append(np.log(calls[attacked][3] / exposure))
            for name, statistic in forms.items():
                target = float((np.minimum(statistic(scene), 1.0) * uniform).sum())
                log_k[name].append(np.log(solve(statistic(light), target, uniform)))
        truth = np.array(log_k["camsim"])
        parts = [f"camsim k {np.exp(np.median(truth)):.3f}"]
        for name in forms:
            x = np.array(log_k[name])
            power = float(x @ truth / (x @ x))
            left = float(np.sqrt(np.mean((truth - power * x) ** 2)))
            parts.append(f"{name}: k {np.exp(np.median(x)):.3f}, power {power:.2f}, log k left {left:.3f}")
        print(f"master seed {master} (case seed {seed}, {len(truth)} pairs): " + "; ".join(parts), flush=True)


if __name__ == "__main__":
    main()
