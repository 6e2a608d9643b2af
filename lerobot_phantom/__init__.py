"""lerobot-phantom: physical sensor attacks for LeRobot policies (Phantom Menace, AAAI-26).

Importing the package calls ``register()``, which makes LeRobot accept the camera attacks in image-transform
configs (``ImageTransformConfig(type="LaserBlinding", ...)``), registers the ``phantom_table`` env type and its
gymnasium ids (so ``--env.discover_packages_path=lerobot_phantom`` works with stock ``lerobot-eval``) and the
``phantom_servo`` reference policy type.
"""

__version__ = "0.1.0"


def register() -> None:
    """Register the plugin with LeRobot and gymnasium (idempotent)."""
    from lerobot_phantom.envs import register_gym_envs
    from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig  # noqa: F401  (registers "phantom_table")
    from lerobot_phantom.eval import servo_policy  # noqa: F401  (registers the "phantom_servo" policy type)
    from lerobot_phantom.transforms.lerobot_registration import register_image_transforms

    register_image_transforms()
    register_gym_envs()


register()
