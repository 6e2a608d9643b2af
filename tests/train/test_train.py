"""End-to-end runs of lerobot-phantom-train (LeRobot's loop) on a tiny dataset: SmolVLA (tiny VLM) and ACT."""

import json
import math
from pathlib import Path

import pytest
import torch
from safetensors.torch import load_file
from train_testkit import CONFIGS, FRAMES, dataset_args, smolvla_args

from lerobot_phantom.train.device_step import ATTACK_STEP_NAME
from lerobot_phantom.train.loss_log import CLEAN, LOG_FILE_NAME
from lerobot_phantom.train.train import PhantomTrainPipelineConfig, main, train_phantom


def parse_args(args: list[str]) -> PhantomTrainPipelineConfig:
    import draccus

    from lerobot_phantom import _lerobot_compat as compat

    compat.train_script_module()  # registers LeRobot's policy config types
    return draccus.parse(PhantomTrainPipelineConfig, args=args)


def pretrained_dir(out: Path, step: str = "last") -> Path:
    return out / "checkpoints" / step / "pretrained_model"


def train_config(out: Path, step: str = "last") -> dict:
    return json.loads((pretrained_dir(out, step) / "train_config.json").read_text())


def loss_log(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / LOG_FILE_NAME).read_text().splitlines()]


def preprocessor_step_names(pretrained: Path) -> list[str]:
    config = json.loads((pretrained / "policy_preprocessor.json").read_text())
    return [step.get("registry_name", step.get("class", "")) for step in config["steps"]]


def assert_reloads_offline(pretrained: Path, dataset_root: Path) -> None:
    """The checkpoint loads with LeRobot's make_policy (no hub) and its weights are the saved ones."""
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.datasets.lerobot_dataset import LeRobotDatasetMetadata
    from lerobot.policies.factory import make_policy

    cfg = PreTrainedConfig.from_pretrained(pretrained)
    cfg.pretrained_path = pretrained
    policy = make_policy(cfg, ds_meta=LeRobotDatasetMetadata("phantom/tiny", root=dataset_root))
    saved = load_file(pretrained / "model.safetensors")
    state = policy.state_dict()
    name = next(k for k in saved if saved[k].is_floating_point() and saved[k].numel() > 1)
    torch.testing.assert_close(state[name], saved[name])
    assert ATTACK_STEP_NAME not in preprocessor_step_names(pretrained)


def test_clean_run_saves_phantom_config_and_reloads_offline(clean_smolvla_run, tiny_dataset_root):
    assert train_config(clean_smolvla_run)["phantom"]["rate"] == 0
    assert_reloads_offline(pretrained_dir(clean_smolvla_run), tiny_dataset_root)
    records = loss_log(clean_smolvla_run)
    assert records[-1]["seen"]["attacked"] == 0
    assert set(records[-1]["loss"]) == {CLEAN}


@pytest.mark.slow
def test_attacked_fraction_seen_by_the_loop_matches_rate(tmp_path, tiny_dataset_root, tiny_vlm):
    out = tmp_path / "rate"
    # batch 4 x 6 steps = exactly one pass over the 24 frames.
    main(smolvla_args(tiny_dataset_root, tiny_vlm, out, "--steps=6", "--log_freq=3", "--phantom.rate=0.3"))
    by_step = {r["step"]: r for r in loss_log(out)}
    assert sorted(by_step) == [3, 6]
    assert by_step[6]["seen"]["total"] == FRAMES
    assert by_step[6]["seen"]["attacked"] == round(0.3 * FRAMES)
    assert sum(by_step[6]["seen"]["groups"].values()) == FRAMES  # camera attacks only: one group per sample
    # Per-attack loss: the training forward's own per-sample losses, grouped by the mixer's labels.
    camera_attacks = set(train_config(out)["phantom"]["attacks"])
    groups = set().union(*(r["loss"] for r in by_step.values()))
    assert CLEAN in groups and groups & camera_attacks and groups <= camera_attacks | {CLEAN}
    assert all(math.isfinite(v) for r in by_step.values() for v in r["loss"].values())
    assert sum(sum(r["loss_samples"].values()) for r in by_step.values()) == FRAMES
    assert {r["mode"] for r in by_step.values()} == {"per_sample"}


@pytest.mark.slow
def test_device_mode_run_keeps_attack_step_out_of_checkpoint(
    tmp_path, tiny_dataset_root, tiny_vlm, clean_smolvla_run
):
    out = tmp_path / "device"
    main(
        smolvla_args(
            tiny_dataset_root,
            tiny_vlm,
            out,
            "--steps=2",
            "--log_freq=1",
            "--phantom.where=device",
            "--phantom.rate=0.5",
            '--phantom.attacks=["laser_blinding","em_truncation","voice_dos"]',  # JSON lists with --config_path
        )
    )
    assert train_config(out)["phantom"]["where"] == "device"
    record = loss_log(out)[-1]
    assert record["seen"]["total"] == 8 and record["seen"]["attacked"] > 0
    assert set(record["seen"]["groups"]) <= {CLEAN, "laser_blinding", "em_truncation", "voice_dos"}
    assert preprocessor_step_names(pretrained_dir(out)) == preprocessor_step_names(
        pretrained_dir(clean_smolvla_run)
    )
    assert_reloads_offline(pretrained_dir(out), tiny_dataset_root)


@pytest.mark.slow
def test_lora_from_clean_checkpoint_then_resume_keeps_adapter_and_phantom(
    tmp_path, tiny_dataset_root, clean_smolvla_run
):
    out = tmp_path / "lora"
    main(
        [
            f"--config_path={CONFIGS / 'smolvla_lora_phantom.json'}",
            f"--policy.path={pretrained_dir(clean_smolvla_run)}",
            *dataset_args(tiny_dataset_root),
            f"--output_dir={out}",
            "--batch_size=4",
            "--steps=2",
            "--save_freq=2",
            "--log_freq=1",
            "--num_workers=0",
            "--wandb.enable=false",
            "--peft.r=4",
            "--phantom.where=dataloader",
            "--phantom.seed=7",
        ]
    )
    adapter = load_file(pretrained_dir(out, "000002") / "adapter_model.safetensors")
    # The shipped targets adapt the vision side too (vision tower attention + connector), not only the expert.
    for part in ("vision_model.encoder", "connector.modality_projection", "lm_expert"):
        assert any(part in key and "lora_A" in key for key in adapter), part

    main(
        [f"--config_path={pretrained_dir(out, '000002') / 'train_config.json'}", "--resume=true", "--steps=3"]
    )
    resumed = load_file(pretrained_dir(out, "000003") / "adapter_model.safetensors")
    assert resumed.keys() == adapter.keys()
    # One more step at a tiny learning rate moves lora_A by ~1e-5; LeRobot's re-wrap (bug #3459) would replace it
    # by a fresh random init, O(0.1) away.
    for key in (k for k in adapter if "lora_A" in k):
        assert (resumed[key] - adapter[key]).abs().max() < 1e-3, key
    assert train_config(out, "000003")["phantom"] == train_config(out, "000002")["phantom"]
    assert train_config(out, "000003")["phantom"]["seed"] == 7
    assert train_config(out, "000003")["peft"]["r"] == 4
    assert loss_log(out)[-1]["step"] == 3


@pytest.mark.slow
def test_act_run_logs_per_attack_loss_with_log_step_forwards(tmp_path, tiny_dataset_root):
    out = tmp_path / "act"
    # Built and run as a library call: train_phantom(cfg) (main() only adds argv handling for --policy.path/--resume).
    cfg = parse_args(
        [
            *dataset_args(tiny_dataset_root),
            "--policy.type=act",
            "--policy.pretrained_backbone_weights=null",
            "--policy.chunk_size=4",
            "--policy.n_action_steps=4",
            "--policy.dim_model=32",
            "--policy.dim_feedforward=64",
            "--policy.n_encoder_layers=1",
            "--policy.n_decoder_layers=1",
            "--policy.device=cpu",
            "--policy.push_to_hub=false",
            f"--output_dir={out}",
            "--batch_size=4",
            "--steps=2",
            "--log_freq=2",
            "--num_workers=0",
            "--eval_freq=0",
            "--wandb.enable=false",
            "--phantom.rate=0.5",
        ]
    )
    train_phantom(cfg)
    (record,) = loss_log(out)
    assert record["mode"] == "log_step_forward" and record["step"] == 2
    assert sum(record["loss_samples"].values()) == 4  # the log step's batch, split into its groups
    assert record["seen"]["total"] == 8
    assert_reloads_offline(pretrained_dir(out), tiny_dataset_root)


def run_or_dump_stacks(command: list[str], env: dict, timeout_s: float) -> tuple[int, str]:
    """(return code, stderr) of ``command``; if it is still running after ``timeout_s``, every process under it is
    aborted (with ``PYTHONFAULTHANDLER`` set, a Python process prints its threads' stacks on SIGABRT) and the test
    fails with the end of the log."""
    import signal
    import subprocess

    import psutil  # accelerate's dependency

    process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _, log = process.communicate(timeout=timeout_s)
        return process.returncode, log
    except subprocess.TimeoutExpired:
        for child in psutil.Process(process.pid).children(recursive=True):
            child.send_signal(signal.SIGABRT)
        try:
            _, log = process.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            _, log = process.communicate()
        pytest.fail(
            f"still running after {timeout_s} s, its processes aborted; the end of its log:\n{log[-8000:]}"
        )


@pytest.mark.slow
def test_two_processes_share_one_epoch_plan(tmp_path, tiny_dataset_root, tiny_vlm):
    """torchrun (what `accelerate launch` runs) with 2 CPU processes: each rank trains on its share of the sampler,
    and the attacked count over one epoch, summed over both ranks, is still exactly round(rate * N)."""
    import os
    import sys

    out = tmp_path / "ddp"
    args = smolvla_args(tiny_dataset_root, tiny_vlm, out, "--batch_size=2", "--steps=6", "--log_freq=6")
    command = [
        sys.executable,
        "-m",
        "torch.distributed.run",
        "--nproc_per_node=2",
        "-m",
        "lerobot_phantom.train.train",
    ]
    # a rank that hangs prints every thread's Python stack when it is aborted (faulthandler), so a rare hang in a
    # suite run shows where each rank was (session 23: one run stopped before LeRobot's training loop began)
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "OMP_NUM_THREADS": "1", "PYTHONFAULTHANDLER": "1"}
    returncode, log = run_or_dump_stacks([*command, *args], env, timeout_s=300)
    assert returncode == 0, log[-3000:]
    (record,) = loss_log(out)
    assert record["seen"]["total"] == FRAMES  # 6 steps x batch 2 x 2 processes
    assert record["seen"]["attacked"] == round(0.3 * FRAMES)


def test_one_torch_thread_on_two_cores_unless_omp_num_threads_is_set(monkeypatch):
    import torch

    from lerobot_phantom.train import train as train_module

    before = torch.get_num_threads()
    try:
        monkeypatch.setenv("OMP_NUM_THREADS", "2")
        assert train_module.default_torch_threads() is None
        monkeypatch.delenv("OMP_NUM_THREADS")
        monkeypatch.setattr(train_module.os, "cpu_count", lambda: 16)
        assert train_module.default_torch_threads() is None
        monkeypatch.setattr(train_module.os, "cpu_count", lambda: 2)
        assert train_module.default_torch_threads() == 1
        assert torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(before)
