"""camsim ``blinding_halo`` with an oracle dark level: the laser capture's dark level read per pixel, the package's
(the median of the farthest tenth) plus the true dark room's departure from its own median there (noise-free,
from the draw; in the laser's channel, and in the others times the laser's colour, as the beam is read), so that
the beam holds no dark-room gradient. Linear light alone and with the halo, with and
without the dark level's share of the glare (``addback_survey.py``), fitted on the CLI's fit pairs. sRGB cameras.

Usage: ``PYTHONPATH=. python docs/bench/session79/halo/oracle_dark.py SEED CASE_DIR``"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[4] / "tests" / "calibration"))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import camsim
from addback_survey import survey
from dark_room_gradient import case_draws, recorded_render

from lerobot_phantom.calibration.frame_models import laser_blinding
from lerobot_phantom.transforms import physics


def main() -> None:
    master, case_dir = int(sys.argv[1]), Path(sys.argv[2])
    ((_m, _sim, case, _seed, rng, cam),) = list(case_draws("blinding_halo", [master]))
    assert cam.tone == "srgb", "the oracle decodes the dark level as sRGB"
    seen = recorded_render(case, rng, cam)
    dark = camsim.optics(0.01 * seen["dark_ambient"], cam) * seen["capture_exposure"]  # H, W, 3
    yy, xx = np.mgrid[0 : cam.height, 0 : cam.width]
    radius = np.hypot(yy - seen["centre"][0], xx - seen["centre"][1])
    far = radius >= np.quantile(radius, 0.9)
    departure = torch.from_numpy((dark - np.median(dark[far], axis=0)).reshape(-1, 3))
    features = laser_blinding.BlindingFrames.features

    def oracle_features(self, index, pixels):
        f = features(self, index, pixels)
        rows = departure if pixels is None else departure[pixels]
        # the beam's fainter channels are its laser channel times the laser's colour (laser_blinding.beam_profile),
        # so they hold the laser channel's departure in that ratio, not their own
        laser = self.laser_channel
        rows = rows[:, laser : laser + 1] * self.colours[index].reshape(1, 3)
        f["dark"] = physics.linear_to_srgb(physics.srgb_to_linear(f["dark"]) + rows)
        return f

    laser_blinding.BlindingFrames.features = oracle_features
    print(f"{master}, oracle dark level: {survey(case_dir)}")


if __name__ == "__main__":
    main()
