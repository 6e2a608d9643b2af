"""Stock ``lerobot-train`` (LeRobot 0.4.4's own console script) mixes attacks through ``PhantomMix`` (issue 13, item 5).

The plugin is loaded the way a LeRobot user loads it, ``--dataset.discover_packages_path=lerobot_phantom``, and the
attacks come in through ``--dataset.image_transforms``. The console script runs unmodified in a subprocess; a
``sitecustomize`` on its ``PYTHONPATH`` only observes ``PhantomMix`` (how often it ran and whether it changed the
view) and writes that down at exit. The rate itself is tested in-process (tests/transforms/test_mixing.py).
"""

import json
import os
import shutil
import subprocess
import textwrap
from pathlib import Path

import pytest

STEPS, BATCH = 2, 2
CAMERAS = ("observation.images.front", "observation.images.wrist")

SPY = """
import atexit, json, os

import torch

from lerobot_phantom.transforms.mixing import PhantomMix

_views = []
_forward = PhantomMix.forward


def _observed_forward(self, *inputs):
    out = _forward(self, *inputs)
    _views.append(not torch.equal(out, inputs[0]))
    return out


PhantomMix.forward = _observed_forward
atexit.register(lambda: open(os.environ["PHANTOM_SPY_FILE"], "w").write(json.dumps(_views)))
"""


@pytest.fixture(scope="module")
def tiny_root(tmp_path_factory) -> Path:
    from lerobot_phantom.datasets.synthetic import build_synthetic_dataset

    root = tmp_path_factory.mktemp("stock_train") / "tiny"
    build_synthetic_dataset(root, "phantom/tiny", episode_lengths=(6, 4), cameras=CAMERAS, size=32)
    return root


def lerobot_train(tmp_path, root, *flags):
    """Run the stock console script; returns (completed process, the views PhantomMix saw: attacked or not)."""
    executable = shutil.which("lerobot-train")
    if executable is None:
        pytest.skip("the lerobot-train console script is not on PATH")
    spy_dir = tmp_path / "spy"
    spy_dir.mkdir()
    (spy_dir / "sitecustomize.py").write_text(textwrap.dedent(SPY))
    spy_file = tmp_path / "views.json"
    env = {
        **os.environ,
        "HF_HUB_OFFLINE": "1",
        "OMP_NUM_THREADS": "1",
        "PYTHONPATH": os.pathsep.join([str(spy_dir), *filter(None, [os.environ.get("PYTHONPATH")])]),
        "PHANTOM_SPY_FILE": str(spy_file),
    }
    argv = [
        executable,
        "--policy.type=act",
        "--policy.pretrained_backbone_weights=null",
        "--policy.device=cpu",
        "--policy.push_to_hub=false",
        "--policy.dim_model=16",
        "--policy.n_heads=2",
        "--policy.dim_feedforward=32",
        "--policy.n_encoder_layers=1",
        "--policy.n_decoder_layers=1",
        "--policy.chunk_size=2",
        "--policy.n_action_steps=2",
        "--policy.use_vae=false",
        "--dataset.repo_id=phantom/tiny",
        f"--dataset.root={root}",
        "--dataset.image_transforms.enable=true",
        *flags,
        f"--steps={STEPS}",
        f"--batch_size={BATCH}",
        "--num_workers=0",
        "--save_checkpoint=false",
        "--wandb.enable=false",
        f"--output_dir={tmp_path / 'out'}",
    ]
    result = subprocess.run(argv, capture_output=True, text=True, timeout=600, env=env, cwd=tmp_path)
    views = json.loads(spy_file.read_text()) if spy_file.exists() else []
    return result, views


def phantom_tfs(rate):
    return "--dataset.image_transforms.tfs=" + json.dumps(
        {"phantom": {"type": "PhantomMix", "kwargs": {"rate": rate}}}
    )


@pytest.mark.slow
def test_stock_lerobot_train_attacks_every_view_through_the_plugin(tmp_path, tiny_root):
    result, views = lerobot_train(
        tmp_path, tiny_root, "--dataset.discover_packages_path=lerobot_phantom", phantom_tfs(1.0)
    )
    assert result.returncode == 0, result.stderr[-4000:]
    assert "End of training" in result.stderr + result.stdout
    # every camera view of every sample the training loop fetched went through PhantomMix and was attacked
    assert len(views) >= STEPS * BATCH * len(CAMERAS)
    assert all(views)


@pytest.mark.slow
def test_stock_lerobot_train_refuses_phantom_mix_without_the_plugin(tmp_path, tiny_root):
    result, views = lerobot_train(tmp_path, tiny_root, phantom_tfs(0.3))
    assert result.returncode != 0
    assert "Transform 'PhantomMix' is not valid" in result.stderr
    assert views == []
