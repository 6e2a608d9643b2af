"""lerobot-phantom-augment: content, stats, refusal, resume after kill -9, episode unit, instructions, videos."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from lerobot_phantom.config import PhantomConfig
from lerobot_phantom.datasets import PhantomDataset, camera_attack_params
from lerobot_phantom.datasets.augment import (
    AugmentConfig,
    augment,
    main,
    normalize_argv,
    temporary_dir,
)
from lerobot_phantom.datasets.schedule import attacked_count, sample_seed
from lerobot_phantom.datasets.synthetic import CAMERAS, build_synthetic_dataset

FRONT, WRIST = CAMERAS
# LeRobot stores shape-(1,) features through datasets.Value, which calls float() on a 1-element array.
pytestmark = pytest.mark.filterwarnings("ignore:Conversion of an array with ndim > 0:DeprecationWarning")
ATTACKS = ["em_truncation", "laser_blinding"]
REPO = "phantom/tiny"


def tree_digest(root: Path) -> dict[str, str]:
    return {
        str(path.relative_to(root)): hashlib.sha256(path.read_bytes()).hexdigest()
        for path in sorted(root.rglob("*"))
        if path.is_file()
    }


def config(source: Path, output: Path, **kwargs) -> AugmentConfig:
    phantom = kwargs.pop("phantom", PhantomConfig(rate=0.5, attacks=ATTACKS, seed=1))
    return AugmentConfig(
        repo_id=REPO,
        root=str(source),
        output_repo_id="phantom/tiny_aug",
        output_root=str(output),
        phantom=phantom,
        **kwargs,
    )


def load(root: Path, repo_id: str = "phantom/tiny_aug"):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    return LeRobotDataset(repo_id, root=root)


@pytest.fixture(scope="module")
def augmented(image_dataset_root, tmp_path_factory):
    before = tree_digest(image_dataset_root)
    output = tmp_path_factory.mktemp("aug") / "out"
    result = augment(config(image_dataset_root, output))
    assert tree_digest(image_dataset_root) == before  # the source is only read
    return result


def test_output_reloads_with_exact_rate_and_pixels_matching_the_labels(augmented, image_dataset_root):
    source, output = load(image_dataset_root, REPO), load(augmented.output_root)
    assert len(output) == len(source) == augmented.num_frames
    assert output.meta.total_episodes == source.meta.total_episodes
    assert not temporary_dir(augmented.output_root).exists()
    mixer = PhantomDataset(source, PhantomConfig(rate=0.5, attacks=ATTACKS, seed=1))
    names = []
    for i in range(len(output)):
        frame, raw = output[i], source[i]
        name, decision = frame["phantom_attack"], mixer.decision(i, epoch=0)
        names.append(name)
        assert name == (decision["attack"] or "none")
        assert float(frame["phantom_intensity"]) == pytest.approx(decision["intensity"], abs=1e-7)
        assert torch.equal(frame[WRIST], raw[WRIST])  # cameras=[first]: the wrist camera is never attacked
        assert torch.equal(frame["action"], raw["action"]) and frame["task"] == raw["task"]
        if name == "none":
            assert torch.equal(frame[FRONT], raw[FRONT])  # clean frames are bit-identical (PNG round trip)
        else:
            attack = mixer.attacks[name]
            (params,) = camera_attack_params(attack, decision["seed"], decision["intensity"], [(32, 32)])
            expected = (attack.apply_params(raw[FRONT], params) * 255).round() / 255
            assert torch.equal(frame[FRONT], expected)
            assert not torch.equal(frame[FRONT], raw[FRONT])
    attacked = sum(name != "none" for name in names)
    assert attacked == attacked_count(0.5, len(source))
    assert augmented.summary["attacked_frames"] == attacked
    assert sum(e["frames"] for e in augmented.summary["attacks"].values()) == len(source)
    assert (augmented.output_root / "meta" / "phantom_augment.json").is_file()


def test_stats_are_recomputed_from_the_written_frames(augmented):
    output = load(augmented.output_root)
    frames = [output[i] for i in range(len(output))]
    stats = output.meta.stats
    for key in ("action", "observation.state", "phantom_intensity"):
        values = torch.stack([f[key].reshape(-1) for f in frames]).double().numpy()
        np.testing.assert_allclose(stats[key]["mean"], values.mean(0), rtol=1e-5, atol=1e-6)
        np.testing.assert_allclose(stats[key]["std"], values.std(0), rtol=1e-4, atol=1e-6)
        np.testing.assert_allclose(stats[key]["min"], values.min(0), atol=1e-6)
        np.testing.assert_allclose(stats[key]["max"], values.max(0), atol=1e-6)
        assert int(np.asarray(stats[key]["count"]).reshape(-1)[0]) == len(frames)
    for key in CAMERAS:
        images = torch.stack([f[key] for f in frames]).double()
        # LeRobot computes image stats per channel from sampled frames; with these short episodes it samples all.
        # (Its image std is not compared: LeRobot 0.4.4's own value is far from the pixels' std for any dataset,
        # the source included.)
        np.testing.assert_allclose(
            np.ravel(stats[key]["mean"]), images.mean(dim=(0, 2, 3)).numpy(), atol=1e-4
        )
        np.testing.assert_allclose(np.ravel(stats[key]["min"]), images.amin(dim=(0, 2, 3)).numpy(), atol=1e-6)
        np.testing.assert_allclose(np.ravel(stats[key]["max"]), images.amax(dim=(0, 2, 3)).numpy(), atol=1e-6)


def test_refuses_to_write_over_the_source_or_an_existing_output(augmented, image_dataset_root, tmp_path):
    with pytest.raises(ValueError, match="is the source"):
        augment(config(image_dataset_root, image_dataset_root))
    with pytest.raises(ValueError, match="inside the source"):
        augment(config(image_dataset_root, image_dataset_root / "meta" / "aug"))
    before = tree_digest(augmented.output_root)
    with pytest.raises(FileExistsError, match="--overwrite"):
        augment(config(image_dataset_root, augmented.output_root))
    assert tree_digest(augmented.output_root) == before
    with pytest.raises(FileExistsError, match="complete already"):
        augment(config(image_dataset_root, augmented.output_root, resume=True))


def test_overwrite_replaces_the_output_once_the_new_one_is_complete(image_dataset_root, tmp_path):
    output = tmp_path / "out"
    augment(config(image_dataset_root, output, phantom=PhantomConfig(rate=0.0)))
    assert load(output).meta.stats["phantom_intensity"]["max"][0] == 0
    main(
        [
            f"--repo-id={REPO}", f"--root={image_dataset_root}", "--output-repo-id", "phantom/tiny_aug",
            "--output-root", str(output), "--phantom.rate", "1.0", "--phantom.attacks=[em_truncation]", "--overwrite",
        ]
    )  # fmt: skip
    reloaded = load(output)
    assert {reloaded[i]["phantom_attack"] for i in range(len(reloaded))} == {"em_truncation"}
    assert not temporary_dir(output).exists()


def test_unit_episode_attacks_whole_episodes_with_one_parameter_set(image_dataset_root, tmp_path):
    phantom = PhantomConfig(rate=0.7, attacks=["laser_blinding"], seed=2)
    result = augment(config(image_dataset_root, tmp_path / "out", phantom=phantom, unit="episode"))
    source, output = load(image_dataset_root, REPO), load(result.output_root)
    attack = PhantomDataset(source, phantom).attacks["laser_blinding"]
    attacked_episodes = 0
    for episode in range(output.meta.total_episodes):
        start = int(output.meta.episodes[episode]["dataset_from_index"])
        stop = int(output.meta.episodes[episode]["dataset_to_index"])
        labels = {
            (output[i]["phantom_attack"], float(output[i]["phantom_intensity"])) for i in range(start, stop)
        }
        assert len(labels) == 1  # the same attack and intensity for every frame of the episode
        ((name, _),) = labels
        attacked_episodes += name != "none"
        if name == "none":
            continue
        images = torch.stack([output[i][FRONT] for i in range(start, stop)])
        raws = torch.stack([source[i][FRONT] for i in range(start, stop)])
        # One parameter set, from the episode's seed, attacks every frame of the episode.
        seed = sample_seed(2, 0, episode)
        (params,) = camera_attack_params(attack, seed, float(output[start]["phantom_intensity"]), [(32, 32)])
        expected = (attack.apply_params(raws, params) * 255).round() / 255
        assert torch.equal(images, expected)
    assert attacked_episodes == attacked_count(0.7, 3) == 2


def test_instruction_attacks_become_new_tasks(image_dataset_root, tmp_path):
    phantom = PhantomConfig(rate=0.0, instruction_attacks=["voice_spoofing"], instruction_rate=0.5, seed=3)
    result = augment(config(image_dataset_root, tmp_path / "out", phantom=phantom))
    source, output = load(image_dataset_root, REPO), load(result.output_root)
    spoofed = 0
    for i in range(len(output)):
        frame = output[i]
        if frame["phantom_instruction_attack"] == "voice_spoofing":
            spoofed += 1
            assert frame["task"] != source[i]["task"] and frame["task"].startswith(source[i]["task"])
        else:
            assert frame["phantom_instruction_attack"] == "none" and frame["task"] == source[i]["task"]
    assert spoofed == attacked_count(0.5, len(source))
    assert len(output.meta.tasks) == 2 * len(source.meta.tasks)


def test_bad_augment_configs(image_dataset_root, tmp_path):
    with pytest.raises(ValueError, match="frame"):
        AugmentConfig(repo_id=REPO, output_repo_id="x", unit="sample")
    with pytest.raises(ValueError, match="num-workers"):
        AugmentConfig(repo_id=REPO, output_repo_id="x", num_workers=-1)
    with pytest.raises(ValueError, match="--output-repo-id"):
        augment(AugmentConfig(repo_id=REPO, root=str(image_dataset_root)))
    with pytest.raises(ValueError, match=r"observation\.images\.wrist"):
        augment(
            config(
                image_dataset_root, tmp_path / "o", phantom=PhantomConfig(cameras=["observation.images.top"])
            )
        )


def test_normalize_argv_accepts_dashes_and_bare_flags():
    assert normalize_argv(["--repo-id", "a/b", "--resume", "--num-workers=2", "--overwrite"]) == [
        "--repo_id", "a/b", "--resume=true", "--num_workers=2", "--overwrite=true",
    ]  # fmt: skip
    assert normalize_argv(["--resume", "false", "--phantom.instruction-rate", "0.1"]) == [
        "--resume", "false", "--phantom.instruction_rate", "0.1",
    ]  # fmt: skip


@pytest.mark.slow
def test_kill_9_then_resume_gives_the_uninterrupted_output(augmented, image_dataset_root, tmp_path):
    # The reference is the module's uninterrupted run (in-process, no workers); the resumed run finishes with
    # two worker processes, so this also checks that --num-workers does not change a byte.
    output = tmp_path / "resumed"
    episodes = temporary_dir(output) / "episodes"
    command = [
        sys.executable, "-m", "lerobot_phantom.datasets.augment", "--repo-id", REPO, "--root", str(image_dataset_root),
        "--output-repo-id", "phantom/tiny_aug", "--output-root", str(output), "--phantom.rate", "0.5",
        "--phantom.attacks=[em_truncation,laser_blinding]", "--phantom.seed", "1",
    ]  # fmt: skip
    process = subprocess.Popen(
        command,
        env={**os.environ, "HF_HUB_OFFLINE": "1"},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and process.poll() is None:
            if episodes.exists() and any(not p.name.endswith(".partial") for p in episodes.iterdir()):
                break
            time.sleep(0.005)
        os.kill(process.pid, signal.SIGKILL)
    finally:
        process.wait()
    assert process.returncode == -signal.SIGKILL, "the run finished before it could be killed"
    assert not output.exists()
    done = [p for p in episodes.iterdir() if not p.name.endswith(".partial")]
    assert 1 <= len(done) < 3

    with pytest.raises(FileExistsError, match="--resume"):
        augment(config(image_dataset_root, output))
    with pytest.raises(ValueError, match="phantom"):
        augment(
            config(image_dataset_root, output, phantom=PhantomConfig(rate=0.5, attacks=ATTACKS), resume=True)
        )
    resumed = augment(config(image_dataset_root, output, resume=True, num_workers=2))
    assert resumed.episodes_reused == len(done)
    assert tree_digest(output) == tree_digest(augmented.output_root)
    assert resumed.summary == augmented.summary


@pytest.mark.slow
def test_video_dataset_is_decoded_attacked_and_reencoded(tmp_path):
    source_root = tmp_path / "videos"
    build_synthetic_dataset(
        source_root, "phantom/tiny_video", episode_lengths=(8, 8), use_videos=True, size=64
    )
    phantom = PhantomConfig(rate=0.5, attacks=["em_truncation"], intensity="strong", seed=6)
    cfg = AugmentConfig(
        repo_id="phantom/tiny_video", root=str(source_root), output_repo_id="phantom/tiny_video_aug",
        output_root=str(tmp_path / "out"), phantom=phantom,
    )  # fmt: skip
    result = augment(cfg)
    source, output = (
        load(source_root, "phantom/tiny_video"),
        load(result.output_root, "phantom/tiny_video_aug"),
    )
    assert output.meta.video_keys == list(CAMERAS) and len(output) == 16
    clean_error, attacked_error, attacked = [], [], 0
    for i in range(16):
        frame, raw = output[i], source[i]
        error = float((frame[FRONT] - raw[FRONT]).abs().mean())
        if frame["phantom_attack"] == "none":
            clean_error.append(error)
        else:
            attacked += 1
            attacked_error.append(error)
    assert attacked == 8
    # Re-encoding is lossy, so clean frames only stay close; attacked frames move far more.
    assert max(clean_error) < 0.05 < min(attacked_error)


def test_an_attack_error_stops_the_run_with_its_context(image_dataset_root, tmp_path, monkeypatch):
    from lerobot_phantom.transforms.registry import get_attack_class

    def broken(self, image, params):
        raise ValueError("kernel exploded")

    monkeypatch.setattr(get_attack_class("em_truncation"), "apply_params", broken)
    output = tmp_path / "out"
    phantom = PhantomConfig(rate=1.0, attacks=["em_truncation"])
    with pytest.raises(ValueError, match="kernel exploded") as info:
        augment(config(image_dataset_root, output, phantom=phantom))
    notes = "\n".join(info.value.__notes__)
    assert "sample index 0" in notes and "source episode 0" in notes and "em_truncation" in notes
    assert not output.exists() and temporary_dir(output).exists()  # nothing half-written in place; resumable


def test_cli_reports_bad_settings_in_one_line(image_dataset_root, tmp_path):
    base = ["--repo-id", REPO, "--root", str(image_dataset_root), "--output-repo-id", "x", "--output-root"]
    with pytest.raises(SystemExit) as info:
        main([*base, str(tmp_path / "a"), "--phantom.attacks=[laser]"])
    assert "valid attacks: laser_blinding" in str(info.value.code)
    with pytest.raises(SystemExit) as info:
        main([*base, str(image_dataset_root)])
    assert "is the source dataset" in str(info.value.code)
    assert not (tmp_path / "a").exists()
