"""The LeRobot internals lerobot-phantom's training leans on (lerobot_phantom._lerobot_compat, training section).

Each test pins one seam; if a LeRobot upgrade moves it, this file fails first and says which.
"""

import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")

import inspect

import pytest

from lerobot_phantom import _lerobot_compat as compat


def test_lerobot_version_is_the_pinned_one():
    assert compat.lerobot_version() == compat.LEROBOT_VERSION == "0.4.4"


def test_train_loop_looks_up_every_hook_in_its_module_globals():
    module = compat.train_script_module()
    source = inspect.getsource(compat.train_loop_function())
    for name in compat.TRAIN_LOOP_HOOKS:
        assert callable(getattr(module, name)), name
        assert f"{name}(" in source, f"lerobot_train.train no longer calls {name}()"
    assert "dl_iter = cycle(dataloader)" in source
    assert "batch = preprocessor(batch)" in source
    assert "policy = policy.wrap_with_peft(" in source  # the re-wrap behind bug #3459


def test_train_is_parser_wrapped_and_reparses_argv_for_subclasses():
    train = compat.train_script_module().train
    assert list(inspect.signature(compat.train_loop_function()).parameters) == ["cfg", "accelerator"]
    assert train.__wrapped__ is compat.train_loop_function()
    wrapper_source = inspect.getsource(compat.config_parser_wrap())
    assert "type(args[0]) is argtype" in wrapper_source  # why the undecorated function is called


def test_update_policy_signature():
    update_policy = compat.train_script_module().update_policy
    assert tuple(inspect.signature(update_policy).parameters) == compat.UPDATE_POLICY_PARAMETERS
    assert "policy.forward(batch)" in inspect.getsource(update_policy)


def test_patched_train_loop_restores_and_refuses_unknown_names():
    module = compat.train_script_module()
    original = module.cycle
    with compat.patched_train_loop(cycle=len) as originals:
        assert module.cycle is len and originals["cycle"] is original
    assert module.cycle is original
    with pytest.raises(ValueError, match="hookable"), compat.patched_train_loop(train=len):
        pass


def test_train_config_resume_and_save_seams():
    cls = compat.train_pipeline_config_class()
    assert "checkpoint_path" in cls.__dataclass_fields__ and "peft" in cls.__dataclass_fields__
    assert "draccus.parse(cls, config_file" in inspect.getsource(
        cls.from_pretrained
    )  # subclass fields restored
    assert "draccus.dump(self" in inspect.getsource(cls._save_pretrained)  # subclass fields saved


def test_wrap_with_peft_and_make_policy_peft_loading():
    from lerobot.policies import factory

    wrap = compat.pretrained_policy_class().wrap_with_peft
    assert list(inspect.signature(wrap).parameters) == ["self", "peft_config", "peft_cli_overrides"]
    assert "Supply a `policy.pretrained_path`" in inspect.getsource(
        compat.pretrained_policy_class()._validate_peft_config
    )
    assert "PeftModel.from_pretrained(policy, peft_pretrained_path, config=peft_config)" in inspect.getsource(
        factory.make_policy
    )


def test_processor_seams():
    from lerobot.processor.converters import batch_to_transition, transition_to_batch

    registry = compat.processor_step_registry()
    assert callable(registry.register) and callable(registry.get)
    keys = compat.transition_keys()
    # Unknown batch keys are dropped on the way in (hence the labels-keeping converter) ...
    transition = batch_to_transition({"observation.state": 1, "phantom.attack": 2, "task": "t"})
    assert "phantom.attack" not in (transition[keys.COMPLEMENTARY_DATA] or {})
    # ... and complementary data comes back out as batch keys.
    transition[keys.COMPLEMENTARY_DATA]["phantom.attack"] = 2
    assert transition_to_batch(transition)["phantom.attack"] == 2
    pipeline = compat.policy_processor_pipeline_class()(steps=[])
    assert callable(pipeline.to_transition) and callable(pipeline.to_output)
    from lerobot_phantom.train.device_step import ATTACK_STEP_NAME, PhantomAttackProcessorStep

    assert registry.get(ATTACK_STEP_NAME) is PhantomAttackProcessorStep
    assert issubclass(PhantomAttackProcessorStep, compat.processor_step_base())


def test_checkpoint_step_and_process_state(tmp_path):
    from lerobot.utils.train_utils import save_training_step

    (tmp_path / "training_state").mkdir()
    save_training_step(17, tmp_path / "training_state")
    assert compat.load_checkpoint_step(tmp_path) == 17
    state = compat.accelerate_process_state()
    assert state.num_processes >= 1 and 0 <= state.process_index < state.num_processes
