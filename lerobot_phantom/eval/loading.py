"""What both evaluation modes (rollouts in ``eval.py``, recorded frames in ``offline.py``) need: the policy and its
processors, loaded exactly as ``lerobot-eval`` loads them, and the metadata every eval.json records about them.

Kept in its own module so that ``eval.py`` (which dispatches to the offline mode) and ``offline.py`` do not import
each other.
"""

import platform
from typing import Any

import torch

import lerobot_phantom
from lerobot_phantom import _lerobot_compat as compat
from lerobot_phantom.eval.config import PhantomEvalConfig


def identity_processors():
    """Pass-through pre/post processors for an in-memory policy that needs no normalisation."""
    from lerobot.processor import PolicyProcessorPipeline
    from lerobot.processor.converters import policy_action_to_transition, transition_to_policy_action

    return (
        PolicyProcessorPipeline(steps=[]),
        PolicyProcessorPipeline(
            steps=[], to_transition=policy_action_to_transition, to_output=transition_to_policy_action
        ),
    )


def load_policy(cfg: PhantomEvalConfig, ds_meta=None):
    """Policy and its pre/post processors from ``--policy.path``, exactly as ``lerobot-eval`` builds them
    (``ds_meta``: a dataset's metadata instead of the env config, for the offline mode)."""
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    if cfg.policy is None:
        raise ValueError(
            "no policy to evaluate: pass --policy.path=<checkpoint dir> (or policy= to evaluate())"
        )
    # A dataset's metadata (offline mode) or the env config tells make_policy the features.
    source = {"ds_meta": ds_meta} if ds_meta is not None else {"env_cfg": cfg.env}
    policy = make_policy(cfg=cfg.policy, rename_map=cfg.rename_map, **source)
    preprocessor, postprocessor = make_pre_post_processors(
        policy_cfg=cfg.policy,
        pretrained_path=cfg.policy.pretrained_path,
        preprocessor_overrides={
            "device_processor": {"device": str(policy.config.device)},
            "rename_observations_processor": {"rename_map": cfg.rename_map},
        },
    )
    return policy, preprocessor, postprocessor


def ready_policy(cfg: PhantomEvalConfig, policy=None, preprocessor=None, postprocessor=None, ds_meta=None):
    """``(policy, preprocessor, postprocessor)`` in eval mode: the given in-memory policy (pass-through processors
    unless given) or the one loaded from ``--policy.path``."""
    if policy is None:
        policy, preprocessor, postprocessor = load_policy(cfg, ds_meta=ds_meta)
    elif preprocessor is None or postprocessor is None:
        preprocessor, postprocessor = identity_processors()
    policy.eval()
    return policy, preprocessor, postprocessor


def with_step(pipeline, *steps):
    """A copy of ``pipeline`` with ``steps`` appended (same converters), leaving the original untouched."""
    return type(pipeline)(
        steps=[*pipeline.steps, *steps],
        name=pipeline.name,
        to_transition=pipeline.to_transition,
        to_output=pipeline.to_output,
    )


def versions() -> dict[str, str]:
    return {
        "lerobot": compat.lerobot_version(),
        "lerobot_phantom": lerobot_phantom.__version__,
        "torch": torch.__version__,
        "python": platform.python_version(),
    }


def policy_metadata(cfg: PhantomEvalConfig, policy) -> dict[str, Any]:
    path = (
        None if cfg.policy is None or cfg.policy.pretrained_path is None else str(cfg.policy.pretrained_path)
    )
    config = getattr(policy, "config", None)
    return {"path": path, "type": getattr(config, "type", None) or type(policy).__name__}
