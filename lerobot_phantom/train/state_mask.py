"""Hide entries of the proprioceptive state from the policy (``lerobot-phantom-train --mask_state='[3]'``).

Why: in scripted demonstrations the gripper action equals the current gripper state on every frame but the
grasp and the release (93 % of `phantom_table`'s frames), so behaviour cloning learns to copy the state and the
grasp decision has to outweigh it; checkpoints where it does not never close the gripper (docs/recipe/README.md,
"the gripper shortcut"). Masking the gripper entry forces the decision onto the cameras (the wrist camera sees
the fingers and what they hold).

The mask is a LeRobot processor step placed right after the policy's normaliser, so the masked entries read 0, the
normalised dataset mean (or the middle of the range under min-max normalisation), and it is saved in the
checkpoint's preprocessor: ``lerobot-phantom-eval``, stock ``lerobot-eval`` (with the plugin discovered) and any
``make_pre_post_processors(pretrained_path=...)`` apply the same mask at inference without a flag.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from lerobot.processor.normalize_processor import NormalizerProcessorStep
from lerobot.processor.pipeline import ObservationProcessorStep, ProcessorStepRegistry

STATE_KEY = "observation.state"
STEP_NAME = "phantom_mask_state"


@dataclass
@ProcessorStepRegistry.register(name=STEP_NAME)
class MaskStateProcessorStep(ObservationProcessorStep):
    """Sets ``observation.state[..., indices]`` to 0 (after normalisation: the dataset mean)."""

    indices: list[int] = field(default_factory=list)

    def observation(self, observation: dict[str, Any]) -> dict[str, Any]:
        state = observation.get(STATE_KEY)
        if state is None:
            raise KeyError(
                f"{STEP_NAME}: the observation has no {STATE_KEY} to mask (keys: {sorted(observation)})"
            )
        size = state.shape[-1]
        if any(not -size <= i < size for i in self.indices):
            raise IndexError(f"{STEP_NAME}: indices {self.indices} out of range for a state of size {size}")
        masked = state.clone()
        masked[..., self.indices] = 0.0
        return {**observation, STATE_KEY: masked}

    def get_config(self) -> dict[str, Any]:
        return {"indices": list(self.indices)}

    def transform_features(self, features):
        return features


def add_state_mask(preprocessor, indices: list[int]):
    """The policy preprocessor with the mask right after its normaliser. Unchanged if no mask is asked for or if a
    loaded checkpoint's preprocessor already has one (fine-tuning keeps the checkpoint's mask); a different mask than
    the checkpoint's is refused."""
    steps = list(preprocessor.steps)
    existing = [s for s in steps if isinstance(s, MaskStateProcessorStep)]
    if existing:
        if indices and sorted(existing[0].indices) != sorted(indices):
            raise ValueError(
                f"the pretrained preprocessor masks state entries {existing[0].indices}, not --mask_state={indices}; "
                "train with the checkpoint's mask"
            )
        return preprocessor
    if not indices:
        return preprocessor
    normalisers = [i for i, s in enumerate(steps) if isinstance(s, NormalizerProcessorStep)]
    if not normalisers:
        raise ValueError("the policy preprocessor has no normaliser step to place the state mask after")
    steps.insert(normalisers[0] + 1, MaskStateProcessorStep(indices=list(indices)))
    preprocessor.steps = steps
    return preprocessor
