"""The attacks without LeRobot, and the three routes that register the plugin with LeRobot (issue 13, item 3).

* ``import lerobot_phantom.transforms`` and making and applying every attack load torch, torchvision and Pillow
  only (checked in a fresh interpreter: no third-party top-level module beyond those, and numpy which torch loads);
* LeRobot's plugin discovery (``load_plugin``, which ``--*.discover_packages_path`` runs), every
  ``lerobot-phantom-*`` console script, and an explicit ``lerobot_phantom.register()`` register it.
"""

import importlib
import os
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest

import lerobot_phantom

REPO = Path(__file__).resolve().parents[1]


def run_python(code: str) -> str:
    result = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "HF_HUB_OFFLINE": "1", "OMP_NUM_THREADS": "1"},
    )
    assert result.returncode == 0, result.stderr[-4000:]
    return result.stdout


def test_import_transforms_loads_neither_lerobot_nor_gymnasium():
    out = run_python(
        """
        import sys
        import lerobot_phantom.transforms
        print(sorted({m.split(".")[0] for m in sys.modules} & {"lerobot", "gymnasium", "mujoco", "draccus"}))
        """
    )
    assert out.strip() == "[]"


def test_making_and_applying_every_attack_needs_torch_torchvision_and_pillow_only():
    out = run_python(
        """
        import sys

        import PIL.Image
        import torch
        import torchvision.transforms.v2

        def top_level():
            return {m.split(".")[0] for m in sys.modules if not m.startswith("_")} - set(sys.stdlib_module_names)

        baseline = top_level()
        from lerobot_phantom.transforms import ATTACK_NAMES, CAMERA_ATTACKS, make_attack
        from lerobot_phantom.transforms.mixing import PhantomMix

        image = torch.rand(2, 3, 24, 24, generator=torch.Generator().manual_seed(0))
        for name in ATTACK_NAMES:
            attack = make_attack(name, intensity="strong", seed=0)
            out = attack(image) if name in CAMERA_ATTACKS else attack("pick up the red block")
            assert out is not None
        PhantomMix(rate=1.0)(image)
        print(" ".join(sorted(top_level() - baseline)))
        """
    )
    # beyond what importing torch, torchvision's v2 transforms and Pillow loads by itself: the package alone
    assert out.split() == ["lerobot_phantom"]


REGISTERED = """
    import gymnasium
    import torch
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.datasets.transforms import ImageTransformConfig, ImageTransforms, ImageTransformsConfig
    from lerobot.envs.configs import EnvConfig

    def phantom_mix_builds():
        config = ImageTransformsConfig(
            enable=True, tfs={"phantom": ImageTransformConfig(type="PhantomMix", kwargs={"rate": 1.0})}
        )
        try:
            transforms = ImageTransforms(config)
        except ValueError:
            return False
        image = torch.rand(3, 16, 16)
        return not torch.equal(transforms(image), image)

    def registered():
        return {
            "image_transforms": phantom_mix_builds(),
            "env": "phantom_table" in EnvConfig.get_known_choices(),
            "policy": "phantom_servo" in PreTrainedConfig.get_known_choices(),
            "gym": "lerobot_phantom/PhantomTable-v0" in gymnasium.registry,
        }
"""
NOTHING = {"image_transforms": False, "env": False, "policy": False, "gym": False}
EVERYTHING = {"image_transforms": True, "env": True, "policy": True, "gym": True}


def registrations_before_and_after(route: str) -> tuple[dict, dict]:
    out = run_python(
        REGISTERED
        + f"""
    import lerobot_phantom
    before = registered()
    {route}
    print(before)
    print(registered())
    """
    )
    before, after = out.strip().splitlines()[-2:]
    return eval(before), eval(after)


def test_importing_the_package_registers_nothing_and_lerobot_plugin_discovery_registers_everything():
    # what `lerobot-train --dataset.discover_packages_path=lerobot_phantom` runs before parsing its flags
    before, after = registrations_before_and_after(
        "from lerobot_phantom import _lerobot_compat; _lerobot_compat.plugin_loader()('lerobot_phantom')"
    )
    assert before == NOTHING
    assert after == EVERYTHING


def test_explicit_register_registers_everything():
    before, after = registrations_before_and_after("lerobot_phantom.register()")
    assert before == NOTHING
    assert after == EVERYTHING


class Registered(Exception):
    """Raised by the stand-in ``register()`` so that no console script runs past it."""


def console_scripts() -> dict[str, str]:
    scripts = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["scripts"]
    assert scripts and all(name.startswith("lerobot-phantom-") for name in scripts)
    return scripts


@pytest.mark.parametrize("script", sorted(console_scripts()))
def test_every_console_script_registers_before_anything_else(script, monkeypatch):
    module_name, function_name = console_scripts()[script].split(":")
    main = getattr(importlib.import_module(module_name), function_name)

    def register():
        raise Registered

    monkeypatch.setattr(lerobot_phantom, "register", register)
    monkeypatch.setattr(sys, "argv", [script, "--help"])
    with pytest.raises(Registered):
        main()
