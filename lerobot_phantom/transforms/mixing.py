"""``PhantomMix``: attack a camera view with probability ``rate``, as a torchvision v2 transform, so that stock
``lerobot-train`` mixes attacks through its ``--dataset.image_transforms`` (LeRobot 0.4.4 rejects ``--phantom.*``).

::

    lerobot-train --policy.type=act --dataset.repo_id=D --dataset.discover_packages_path=lerobot_phantom \\
      --dataset.image_transforms.enable=true \\
      --dataset.image_transforms.tfs='{"phantom": {"type": "PhantomMix", "kwargs": {"rate": 0.3}}}'

Each call (``LeRobotDataset.__getitem__`` calls its image transforms once per camera view of a sample; the frames
of a ``delta_timestamps`` stack share one call) attacks with probability ``rate``; the attack is drawn among
``attacks`` with ``weights`` and its intensity and parameters as the attack draws them at ``intensity``. The
options, their defaults and their checks are ``PhantomConfig``'s (the ``--phantom.*`` group): ``rate``,
``attacks`` (camera attacks only), ``weights``, ``intensity``, ``seed``, ``calibration``. Randomness comes from the
transform's own stream (``SeededAttack``: one per dataloader worker and epoch, reproducible under a fixed torch
seed), which the chosen attack draws from too.

LeRobot's ``ImageTransforms`` picks ``max_num_transforms`` of its ``tfs`` at random (weighted by ``weight``) for
every call: listed alone in ``tfs`` (as above), ``PhantomMix`` runs on every call and the attacked fraction is
``rate`` per view in expectation. Next to other entries it runs only when picked, so the fraction drops to
``rate`` times its chance of being picked. ``lerobot-phantom-train`` (``PhantomDataset``) gives what this cannot:
an exact per-epoch rate, instruction attacks, labels for the per-attack loss, attacks on the policy's device.
"""

from __future__ import annotations

from typing import Any, ClassVar

import torch
from torchvision.transforms import v2

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.transforms.base import IMAGE_TYPES, SeededAttack, first_image, rewrap
from lerobot_phantom.transforms.registry import CAMERA_ATTACKS, make_attacks


class PhantomMix(SeededAttack, v2.Transform):
    """Attack each call's image with probability ``rate``; see the module docstring."""

    name: ClassVar[str] = "phantom_mix"
    _transformed_types = IMAGE_TYPES

    def __init__(
        self,
        rate: float | None = None,
        attacks: list[str] | None = None,
        weights: list[float] | None = None,
        intensity: str | None = None,
        seed: int | None = None,
        calibration: str | None = None,
        *,
        generator: torch.Generator | None = None,
    ) -> None:
        super().__init__()
        given = {
            "rate": rate,
            "attacks": attacks,
            "weights": weights,
            "intensity": intensity,
            "seed": seed,
            "calibration": calibration,
        }
        config = PhantomConfig(**{key: value for key, value in given.items() if value is not None})
        not_camera = [name for name in config.attacks if name not in CAMERA_ATTACKS]
        if not_camera:
            raise ValueError(
                f"PhantomMix attacks camera views, so attacks must be camera attacks ({', '.join(CAMERA_ATTACKS)}); "
                f"got {not_camera} (instruction attacks need lerobot-phantom-train's --phantom.instruction_attacks)"
            )
        self.config = config
        self._init_attack(config.intensity, config.seed, generator)
        # Built now, so that a bad name or calibration fails when the dataset is made, not in a worker.
        self.attacks = make_attacks(
            config.attacks, intensity=config.intensity, calibration=config.calibration
        )
        self._weights = torch.tensor(config.attack_weights, dtype=torch.float64)

    def make_params(self, flat_inputs: list[Any]) -> dict[str, Any]:
        image = first_image(flat_inputs)
        generator = self._get_generator()
        if (
            image is None
            or self.config.rate <= 0
            or float(torch.rand((), generator=generator)) >= self.config.rate
        ):
            return {"attack": None}
        slot = int(torch.multinomial(self._weights, 1, generator=generator))
        name = self.config.attacks[slot]
        height, width = image.shape[-2:]
        # One parameter set (leading dim 1) broadcasts over every frame of the call, like the mixer's.
        params = self.attacks[name].sample_params(1, height, width, generator=generator, device=image.device)
        return {"attack": name, "params": params}

    def transform(self, inpt: Any, params: dict[str, Any]) -> Any:
        if params["attack"] is None:
            return inpt
        attack = self.attacks[params["attack"]]
        return rewrap(attack.apply_params(inpt.as_subclass(torch.Tensor), params["params"]), inpt)

    def extra_repr(self) -> str:
        config = self.config
        return (
            f"rate={config.rate}, attacks={config.attacks}, weights={config.weights}, "
            f"intensity={config.intensity!r}, seed={config.seed}"
        )
