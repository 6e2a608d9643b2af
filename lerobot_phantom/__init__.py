"""lerobot-phantom: physical sensor attacks for LeRobot policies (Phantom Menace, AAAI-26).

Importing the package (or ``lerobot_phantom.transforms``) imports neither LeRobot nor gymnasium: the attacks need
torch, torchvision and Pillow only. ``register()`` plugs the package into LeRobot: camera attacks and the
``PhantomMix`` mixing transform become valid image-transform types (``ImageTransformConfig(type="LaserBlinding",
...)``), and the ``phantom_table`` env type with its gymnasium ids and the ``phantom_servo`` reference policy type
are registered. It runs by itself on each of the three routes a LeRobot user takes:

* LeRobot's plugin discovery, ``--<anything>.discover_packages_path=lerobot_phantom`` on any stock ``lerobot-*``
  script (LeRobot imports the package and each of its top-level modules; ``lerobot_phantom.lerobot_plugin``
  registers on import);
* every ``lerobot-phantom-*`` console script;
* an explicit ``lerobot_phantom.register()`` in your own code.
"""

__version__ = "0.1.0"


def register() -> None:
    """Register the plugin with LeRobot and gymnasium (idempotent)."""
    from lerobot_phantom.envs import register_gym_envs
    from lerobot_phantom.envs.lerobot_config import PhantomTableEnvConfig  # noqa: F401  (registers "phantom_table")
    from lerobot_phantom.eval import servo_policy  # noqa: F401  (registers the "phantom_servo" policy type)
    from lerobot_phantom.train import state_mask  # noqa: F401  (registers the "phantom_mask_state" processor step)
    from lerobot_phantom.transforms.lerobot_registration import register_image_transforms

    register_image_transforms()
    register_gym_envs()
