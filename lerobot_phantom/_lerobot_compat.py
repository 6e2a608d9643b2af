"""The one place where lerobot-phantom touches LeRobot internals (pinned: lerobot==0.4.4).

Everything here leans on names that are not LeRobot's public API. tests/test_lerobot_compat.py checks each seam,
so that a LeRobot upgrade fails loudly here instead of quietly elsewhere. Sections: version pin, transforms,
datasets, training, environments, evaluation.
"""

from __future__ import annotations

from importlib.metadata import version

LEROBOT_VERSION = "0.4.4"


def lerobot_version() -> str:
    return version("lerobot")


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
