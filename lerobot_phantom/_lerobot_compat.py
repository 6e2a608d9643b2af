"""The one place where lerobot-phantom touches LeRobot internals (pinned: lerobot==0.4.4).

Everything here leans on names that are not LeRobot's public API. tests/test_lerobot_compat.py checks each seam,
so that a LeRobot upgrade fails loudly here instead of quietly elsewhere. Sections: version pin, transforms,
datasets, training, environments, evaluation.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from importlib.metadata import version
from typing import Any

LEROBOT_VERSION = "0.4.4"


def lerobot_version() -> str:
    return version("lerobot")


# ---------------------------------------------------------------------------------------------------------------
# training (lerobot_phantom.train; checked by tests/test_lerobot_compat.py)
#
# lerobot-phantom-train runs LeRobot's own ``train()`` (lerobot/scripts/lerobot_train.py) unchanged and only swaps,
# for the duration of one call, the module-level names that loop looks up: the dataset factory (to wrap the
# dataset in the mixer), make_policy (PEFT resume guard), make_pre_post_processors (device-side attack step),
# update_policy (per-attack loss) and cycle (epoch counter).
# ---------------------------------------------------------------------------------------------------------------
TRAIN_LOOP_HOOKS = ("make_dataset", "make_policy", "make_pre_post_processors", "update_policy", "cycle")
UPDATE_POLICY_PARAMETERS = (
    "train_metrics",
    "policy",
    "batch",
    "optimizer",
    "grad_clip_norm",
    "accelerator",
    "lr_scheduler",
    "lock",
    "rabc_weights_provider",
)


def train_script_module():
    """``lerobot.scripts.lerobot_train``: the module whose globals the training loop resolves at call time."""
    import lerobot.scripts.lerobot_train as module

    return module


def train_loop_function():
    """LeRobot's ``train(cfg, accelerator=None)`` without its ``@parser.wrap()``.

    The wrapper re-parses ``sys.argv`` whenever ``type(cfg) is not TrainPipelineConfig``, which a subclass never
    is, so the undecorated function (``functools.wraps`` keeps it as ``__wrapped__``) is called instead.
    """
    return train_script_module().train.__wrapped__


@contextmanager
def patched_train_loop(**replacements: Any) -> Iterator[dict[str, Any]]:
    """Swap names in ``lerobot_train``'s module globals (only those in ``TRAIN_LOOP_HOOKS``); yield the originals."""
    module = train_script_module()
    unknown = sorted(set(replacements) - set(TRAIN_LOOP_HOOKS))
    if unknown:
        raise ValueError(f"cannot patch {unknown} in lerobot_train; hookable names: {TRAIN_LOOP_HOOKS}")
    originals = {name: getattr(module, name) for name in replacements}
    try:
        for name, value in replacements.items():
            setattr(module, name, value)
        yield originals
    finally:
        for name, value in originals.items():
            setattr(module, name, value)


def train_pipeline_config_class():
    from lerobot.configs.train import TrainPipelineConfig

    return TrainPipelineConfig


def config_parser_wrap():
    """``lerobot.configs.parser.wrap``: draccus parsing plus ``--config_path`` / ``--policy.path`` handling."""
    from lerobot.configs import parser

    return parser.wrap


def load_checkpoint_step(checkpoint_dir) -> int:
    """The training step stored in ``checkpoint_dir/training_state``."""
    from pathlib import Path

    from lerobot.utils.constants import TRAINING_STATE_DIR
    from lerobot.utils.train_utils import load_training_step

    return int(load_training_step(Path(checkpoint_dir) / TRAINING_STATE_DIR))


def register_lerobot_plugins() -> None:
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()


def processor_step_registry():
    from lerobot.processor import ProcessorStepRegistry

    return ProcessorStepRegistry


def processor_step_base():
    from lerobot.processor import ProcessorStep

    return ProcessorStep


def policy_processor_pipeline_class():
    from lerobot.processor import PolicyProcessorPipeline

    return PolicyProcessorPipeline


def transition_keys():
    """LeRobot's ``TransitionKey`` enum (``OBSERVATION``, ``COMPLEMENTARY_DATA``, ...)."""
    from lerobot.processor.core import TransitionKey

    return TransitionKey


def pretrained_policy_class():
    from lerobot.policies.pretrained import PreTrainedPolicy

    return PreTrainedPolicy


def accelerate_process_state():
    """accelerate's process-wide state (rank, world size, device) of the ``Accelerator`` that ``train()`` made."""
    from accelerate import PartialState

    return PartialState()


# ---------------------------------------------------------------------------------------------------------------
# evaluation (lerobot_phantom.eval; checked by tests/eval/test_compat_eval.py)
# ---------------------------------------------------------------------------------------------------------------
EVAL_ROLLOUT_PARAMETERS = (
    "env",
    "policy",
    "env_preprocessor",
    "env_postprocessor",
    "preprocessor",
    "postprocessor",
    "seeds",
    "return_observations",
    "render_callback",
)


def eval_rollout():
    """LeRobot's batched rollout loop (``lerobot/scripts/lerobot_eval.py:rollout``), a script-module function."""
    from lerobot.scripts.lerobot_eval import rollout

    return rollout


def eval_env_processors(env_cfg, policy_cfg):
    """Env-specific pre/post processors (e.g. LIBERO's image flip), as ``lerobot-eval`` builds them."""
    from lerobot.envs.factory import make_env_pre_post_processors

    return make_env_pre_post_processors(env_cfg=env_cfg, policy_cfg=policy_cfg)


def eval_close_envs(envs) -> None:
    from lerobot.envs.utils import close_envs

    close_envs(envs)


def eval_write_video(path, frames, fps: float) -> None:
    from lerobot.utils.io_utils import write_video

    write_video(str(path), frames, fps)


def eval_seed_everything(seed: int) -> None:
    """LeRobot's ``set_seed``: seeds the global RNGs that stochastic policies (diffusion noise, ...) sample from."""
    from lerobot.utils.random_utils import set_seed

    set_seed(seed)


# ---------------------------------------------------------------------------------------------------------------
# plugin discovery (lerobot_phantom.lerobot_plugin; checked by tests/test_standalone_import.py and
# tests/train/test_stock_lerobot_train.py)
#
# Any ``--<field>.discover_packages_path=lerobot_phantom`` makes LeRobot 0.4.4's ``parser.wrap`` call
# ``lerobot.configs.parser.load_plugin("lerobot_phantom")`` before parsing: it imports the package, then every module
# and subpackage directly under it (``pkgutil.iter_modules``, not recursive), and drops the flag. The package
# itself registers nothing on import; its ``lerobot_plugin`` module calls ``register()``.
# ---------------------------------------------------------------------------------------------------------------
def plugin_loader():
    """``lerobot.configs.parser.load_plugin``: what ``--*.discover_packages_path=PACKAGE`` runs."""
    from lerobot.configs.parser import load_plugin

    return load_plugin


# ---------------------------------------------------------------------------------------------------------------
# transforms (lerobot_phantom.transforms.lerobot_registration; checked by tests/transforms/test_lerobot_registration.py)
#
# LeRobot 0.4.4 builds every ImageTransformConfig through lerobot.datasets.transforms.make_transform_from_config,
# which knows only torchvision.transforms.v2 classes and SharpnessJitter. ImageTransforms resolves that name in its
# module globals each time it is constructed, so replacing the module attribute with a wrapper (phantom class names
# first, everything else to the original, which keeps raising LeRobot's own error for unknown names) is enough.
# Modules that did ``from lerobot.datasets.transforms import make_transform_from_config`` before registration
# (only lerobot/scripts/lerobot_imgtransform_viz.py) keep the original. LeRobot >= 0.5 has a _CUSTOM_TRANSFORMS
# table (name -> class) that is filled instead when present.
# ---------------------------------------------------------------------------------------------------------------
def image_transforms_module():
    """``lerobot.datasets.transforms``: ImageTransformConfig, ImageTransformsConfig, ImageTransforms."""
    import lerobot.datasets.transforms as module

    return module


def original_make_transform_from_config():
    """LeRobot's own ``make_transform_from_config``, whether or not the phantom wrapper is installed."""
    current = image_transforms_module().make_transform_from_config
    return getattr(current, "__phantom_original__", current)


def register_image_transform_types(resolve, classes: dict[str, type]) -> str:
    """Let LeRobot's image-transform config build extra types by name; idempotent.

    ``resolve(type_name)`` returns a transform class or None (then LeRobot's own factory decides); ``classes`` is
    the same mapping spelled out, for LeRobot's ``_CUSTOM_TRANSFORMS`` table when it exists. Returns "table" or
    "wrapped" (how it was done).
    """
    import functools

    module = image_transforms_module()
    table = getattr(module, "_CUSTOM_TRANSFORMS", None)
    if isinstance(table, dict):
        for name, cls in classes.items():
            table.setdefault(name, cls)
        return "table"
    current = module.make_transform_from_config
    if getattr(current, "__phantom_original__", None) is not None:
        current.__phantom_resolve__ = resolve  # already wrapped: only refresh the resolver
        return "wrapped"
    original = current

    @functools.wraps(original)
    def make_transform_from_config(cfg):
        cls = make_transform_from_config.__phantom_resolve__(cfg.type)
        if cls is None:
            return original(cfg)
        return cls(**cfg.kwargs)

    make_transform_from_config.__phantom_original__ = original
    make_transform_from_config.__phantom_resolve__ = resolve
    module.make_transform_from_config = make_transform_from_config
    return "wrapped"


def unregister_image_transform_types() -> None:
    """Put LeRobot's original factory back (tests use it to check registration from a clean state)."""
    module = image_transforms_module()
    module.make_transform_from_config = original_make_transform_from_config()


# ---------------------------------------------------------------------------------------------------------------
# datasets (lerobot_phantom.datasets; checked by tests/datasets/test_compat_datasets.py)
#
# The mixer relies on LeRobotDataset.__getitem__ applying ``self.image_transforms`` to every ``meta.camera_keys``
# entry (so it can take them over and run them after the attack). The augment tool writes staged single-episode
# datasets and merges them with LeRobot's aggregate_datasets, reading episode frame ranges from the v3 episodes
# table.
# ---------------------------------------------------------------------------------------------------------------
def lerobot_home():
    """``$HF_LEROBOT_HOME``: where LeRobot keeps datasets that are named without a root."""
    from lerobot.utils.constants import HF_LEROBOT_HOME

    return HF_LEROBOT_HOME


def default_feature_keys() -> tuple[str, ...]:
    """Columns LeRobot adds to every frame itself (``timestamp``, ``frame_index``, ``index``, ...)."""
    from lerobot.datasets.utils import DEFAULT_FEATURES

    return tuple(DEFAULT_FEATURES)


def aggregate_datasets(repo_ids, roots, aggr_repo_id: str, aggr_root) -> None:
    """Merge datasets in order into one (LeRobot's ``lerobot.datasets.aggregate.aggregate_datasets``)."""
    from lerobot.datasets.aggregate import aggregate_datasets as aggregate

    aggregate(repo_ids=list(repo_ids), roots=list(roots), aggr_repo_id=aggr_repo_id, aggr_root=aggr_root)


def episode_frame_range(meta, position: int) -> tuple[int, int, int]:
    """``(episode_index, first frame, end frame)`` of the ``position``-th episode of a v3 dataset's metadata."""
    episode = meta.episodes[position]
    return int(episode["episode_index"]), int(episode["dataset_from_index"]), int(episode["dataset_to_index"])
