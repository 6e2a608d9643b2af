"""--mask_state: the processor step, its place in the policy preprocessor, and that the saved checkpoint applies it
at inference (the gripper-shortcut remedy of docs/recipe/README.md)."""

import json
from pathlib import Path

import pytest
import torch
from train_testkit import smolvla_args

from lerobot_phantom.train.state_mask import STEP_NAME, MaskStateProcessorStep, add_state_mask
from lerobot_phantom.train.train import main


def test_the_step_zeroes_only_the_listed_entries_and_round_trips_its_config():
    from lerobot.processor.pipeline import ProcessorStepRegistry

    state = torch.arange(8, dtype=torch.float32).reshape(2, 4) + 1
    step = MaskStateProcessorStep(indices=[3])
    out = step.observation({"observation.state": state, "observation.images.front": torch.ones(2, 3, 4, 4)})
    torch.testing.assert_close(out["observation.state"][:, :3], state[:, :3])
    assert (out["observation.state"][:, 3] == 0).all()
    assert state[0, 3] == 4  # the input is not modified in place
    rebuilt = ProcessorStepRegistry.get(STEP_NAME)(**step.get_config())
    assert rebuilt.indices == [3]
    with pytest.raises(IndexError, match="size 4"):
        MaskStateProcessorStep(indices=[4]).observation({"observation.state": state})
    with pytest.raises(KeyError, match=r"observation\.state"):
        step.observation({"observation.images.front": state})


class Pipeline:
    def __init__(self, steps):
        self.steps = steps


def test_the_mask_goes_right_after_the_normaliser_once():
    from lerobot.configs.types import FeatureType, NormalizationMode, PolicyFeature
    from lerobot.processor.normalize_processor import NormalizerProcessorStep

    normaliser = NormalizerProcessorStep(
        features={"observation.state": PolicyFeature(type=FeatureType.STATE, shape=(4,))},
        norm_map={FeatureType.STATE: NormalizationMode.MEAN_STD},
        stats={"observation.state": {"mean": torch.zeros(4), "std": torch.ones(4)}},
    )
    first, last = object(), object()
    pipeline = add_state_mask(Pipeline([first, normaliser, last]), [3])
    assert pipeline.steps[0] is first and pipeline.steps[1] is normaliser and pipeline.steps[3] is last
    assert isinstance(pipeline.steps[2], MaskStateProcessorStep) and pipeline.steps[2].indices == [3]
    # A loaded checkpoint's mask is kept (fine-tuning without the flag) and never doubled.
    assert len(add_state_mask(pipeline, []).steps) == 4
    assert len(add_state_mask(pipeline, [3]).steps) == 4
    with pytest.raises(ValueError, match="masks state entries"):
        add_state_mask(pipeline, [2])
    assert add_state_mask(Pipeline([first, normaliser]), []).steps == [first, normaliser]
    with pytest.raises(ValueError, match="no normaliser"):
        add_state_mask(Pipeline([first]), [3])


def test_bad_indices_are_refused_naming_the_form(tmp_path, tiny_dataset_root, tiny_vlm):
    with pytest.raises(ValueError, match=r"distinct indices >= 0"):
        main(smolvla_args(tiny_dataset_root, tiny_vlm, tmp_path / "bad", "--steps=1", "--mask_state=[3,3]"))
    assert not (tmp_path / "bad").exists()


@pytest.mark.slow
def test_a_masked_run_saves_the_mask_and_inference_applies_it(tmp_path, tiny_dataset_root, tiny_vlm):
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.policies.factory import make_pre_post_processors

    out = tmp_path / "masked"
    main(smolvla_args(tiny_dataset_root, tiny_vlm, out, "--steps=1", "--log_freq=1", "--mask_state=[3]"))
    pretrained = Path(out) / "checkpoints" / "last" / "pretrained_model"
    steps = json.loads((pretrained / "policy_preprocessor.json").read_text())["steps"]
    names = [s.get("registry_name") for s in steps]
    assert names[names.index("normalizer_processor") + 1] == STEP_NAME
    assert json.loads((pretrained / "train_config.json").read_text())["mask_state"] == [3]

    # Inference as lerobot-phantom-eval loads it: the gripper entry no longer reaches the policy.
    config = PreTrainedConfig.from_pretrained(pretrained)
    preprocessor, _ = make_pre_post_processors(config, pretrained_path=str(pretrained))
    mask = next(s for s in preprocessor.steps if isinstance(s, MaskStateProcessorStep))
    observation = {"observation.state": torch.tensor([[0.1, 0.2, 0.3, 0.08]])}
    assert mask.observation(observation)["observation.state"][0, 3] == 0
