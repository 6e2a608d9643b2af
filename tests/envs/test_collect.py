import numpy as np
import pytest
from lerobot.datasets.lerobot_dataset import LeRobotDataset

from lerobot_phantom.envs import SUITES
from lerobot_phantom.envs import collect as collect_module
from lerobot_phantom.envs.collect import CollectConfig, collect, main, normalize_argv

REPO_ID = "local/phantom_test"


def _collect(root, **overrides):
    cfg = CollectConfig(suite="goal", episodes=2, repo_id=REPO_ID, root=str(root), progress=False)
    for key, value in overrides.items():
        setattr(cfg, key, value)
    return collect(cfg)


@pytest.fixture(scope="module")
def goal_dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("collect") / "goal"
    return _collect(root, seed=3)


def test_collected_dataset_reloads_offline_with_expected_contents(goal_dataset):
    ds = LeRobotDataset(REPO_ID, root=goal_dataset.root)
    assert ds.num_episodes == 2 == goal_dataset.episodes
    assert ds.num_frames == goal_dataset.frames
    assert ds.fps == 10
    assert set(ds.meta.tasks.index) == {SUITES["goal"][0]["language"], SUITES["goal"][1]["language"]}
    for key in ("observation.images.front", "observation.images.wrist"):
        assert ds.features[key]["dtype"] == "image" and tuple(ds.features[key]["shape"]) == (96, 96, 3)
    assert tuple(ds.features["observation.state"]["shape"]) == (4,)
    assert tuple(ds.features["action"]["shape"]) == (4,)
    frame = ds[0]
    assert frame["observation.images.front"].shape == (3, 96, 96)
    assert frame["task"] == SUITES["goal"][0]["language"]
    assert frame["action"].abs().max() <= 1.0


def test_collection_is_deterministic_for_a_seed(goal_dataset, tmp_path):
    again = _collect(tmp_path / "again", seed=3)
    other = _collect(tmp_path / "other", seed=4)
    first = LeRobotDataset(REPO_ID, root=goal_dataset.root).hf_dataset.with_format(None)
    second = LeRobotDataset(REPO_ID, root=again.root).hf_dataset.with_format(None)
    third = LeRobotDataset(REPO_ID, root=other.root).hf_dataset.with_format(None)
    for column in ("action", "observation.state", "task_index"):
        assert first[column] == second[column]
    for key in ("observation.images.front", "observation.images.wrist"):
        np.testing.assert_array_equal(
            np.stack([np.asarray(im) for im in first[key]]), np.stack([np.asarray(im) for im in second[key]])
        )
    assert (
        np.asarray(first["observation.state"])[0].tolist()
        == np.asarray(third["observation.state"])[0].tolist()
    )
    assert first["action"] != third["action"]  # another seed, other layouts


def test_a_failed_rollout_is_dropped_and_retried_with_a_new_seed(tmp_path, monkeypatch):
    """The expert's failures never reach the dataset: the failed rollout's frames are cleared from the episode
    buffer, the task is tried again, and the attempts past ``max_failed_attempts`` stop the collection."""
    recorded = collect_module._record_episode
    calls = []

    def first_attempt_fails(env, expert, seed, *args, **kwargs):
        success, length = recorded(env, expert, seed, *args, **kwargs)
        calls.append(seed)
        return (success and len(calls) > 1), length

    monkeypatch.setattr(collect_module, "_record_episode", first_attempt_fails)
    result = _collect(tmp_path / "retried", seed=3)
    assert result.failed_attempts == 1 and len(calls) == 3
    assert calls[0] != calls[1]  # the retry is a new episode, not the failed one again
    dataset = LeRobotDataset(REPO_ID, root=result.root)
    assert dataset.num_episodes == 2
    assert dataset.num_frames == result.frames  # no frame of the failed rollout was saved

    monkeypatch.setattr(collect_module, "_record_episode", lambda *args, **kwargs: (False, 1))
    with pytest.raises(RuntimeError, match=r"failed 3 times \(last: suite goal, task 0\)"):
        _collect(tmp_path / "hopeless", max_failed_attempts=2)


def test_refuses_to_overwrite_unless_told(goal_dataset, tmp_path):
    root = tmp_path / "existing"
    root.mkdir()
    (root / "keep.txt").write_text("precious")
    with pytest.raises(FileExistsError, match="--overwrite"):
        _collect(root, episodes=1)
    assert (root / "keep.txt").read_text() == "precious"
    result = _collect(root, episodes=1, overwrite=True)
    assert not (root / "keep.txt").exists()
    assert LeRobotDataset(REPO_ID, root=result.root).num_episodes == 1


def test_bad_arguments_name_the_valid_values(tmp_path):
    with pytest.raises(ValueError, match="valid: spatial, object, goal, long or 'all'"):
        _collect(tmp_path / "x", suite="kitchen")
    with pytest.raises(ValueError, match="cannot be combined"):
        _collect(tmp_path / "x", suite="all", task_id=0)
    with pytest.raises(ValueError, match=r"valid 0\.\.5"):
        _collect(tmp_path / "x", task_id=9)
    assert not (tmp_path / "x").exists()


def test_cli_reports_user_errors_in_one_line(goal_dataset):
    with pytest.raises(SystemExit, match="--overwrite"):
        main(["--suite", "goal", "--episodes", "1", "--root", str(goal_dataset.root)])


def test_cli_accepts_dashed_names_and_bare_flags():
    argv = ["--suite", "all", "--repo-id", "local/x", "--video", "--overwrite", "--seed", "2"]
    assert normalize_argv(argv) == [
        "--suite",
        "all",
        "--repo_id",
        "local/x",
        "--video=true",
        "--overwrite=true",
        "--seed",
        "2",
    ]


@pytest.mark.slow
def test_cli_collects_all_suites_as_videos(tmp_path):
    root = tmp_path / "all"
    main(["--suite", "all", "--episodes", "4", "--repo-id", REPO_ID, "--root", str(root), "--video"])
    ds = LeRobotDataset(REPO_ID, root=root)
    assert ds.num_episodes == 4
    assert set(ds.meta.video_keys) == {"observation.images.front", "observation.images.wrist"}
    # --suite all interleaves the suites, so four episodes cover the first task of each suite.
    assert set(ds.meta.tasks.index) == {
        SUITES[s][0]["language"] for s in ("spatial", "object", "goal", "long")
    }
    frame = ds[ds.num_frames - 1]
    assert frame["observation.images.front"].shape == (3, 96, 96)


def test_action_noise_perturbs_execution_but_keeps_successful_expert_labels(goal_dataset, tmp_path):
    noisy = _collect(tmp_path / "noisy", seed=3, episodes=1, action_noise=0.4)
    clean = LeRobotDataset(REPO_ID, root=goal_dataset.root, episodes=[0]).hf_dataset.with_format(None)
    perturbed = LeRobotDataset(REPO_ID, root=noisy.root).hf_dataset.with_format(None)
    assert noisy.failed_attempts == 0
    assert perturbed["observation.state"] != clean["observation.state"]  # same layout, other path
    actions = np.asarray(perturbed["action"])
    assert np.abs(actions).max() <= 1.0
    assert set(np.unique(actions[:, 3])) <= {-1.0, 1.0}  # the recorded gripper command is the expert's
    with pytest.raises(ValueError, match="action-noise"):
        _collect(tmp_path / "bad", action_noise=2.0)


class _FrameLog:
    """Stands in for a LeRobotDataset's episode buffer: keeps the frames a recorder adds."""

    def __init__(self):
        self.frames = []

    def add_frame(self, frame):
        self.frames.append(frame)


@pytest.mark.parametrize("task_id", [0, 2])
def test_grasp_miss_closes_off_target_then_recovers_with_expert_labels(task_id):
    from lerobot_phantom.envs import make_phantom_env, scripted_expert
    from lerobot_phantom.envs.collect import _record_episode
    from lerobot_phantom.envs.interface import GRASP_XY_TOL
    from lerobot_phantom.envs.scene import FINGER_CLOSED_HALF_GAP

    env = make_phantom_env("goal")
    try:
        offset = np.array([0.0, 0.03])
        log = _FrameLog()
        success, length = _record_episode(env, scripted_expert(env), 7, task_id, log, miss_offset=offset)
        reference = _FrameLog()
        _record_episode(env, scripted_expert(env), 7, task_id, reference)
    finally:
        env.close()
    assert success and length == len(log.frames) > len(reference.frames)
    states = np.stack([f["observation.state"] for f in log.frames])
    labels = np.stack([f["action"] for f in log.frames])
    # a frame with the fingers closed on nothing exists, and the label there re-opens the gripper
    empty = np.flatnonzero(np.isclose(states[:, 3], 2 * FINGER_CLOSED_HALF_GAP))
    assert empty.size >= 1 and labels[empty[0], 3] == -1.0
    # the frame before it is where the close was executed: more than the grasp tolerance away from where the expert
    # grasps (its own first close in the reference run); its label is the expert's there: gripper open, and the
    # xy error is corrected the expert's way, up to the travel height first
    reference_states = np.stack([f["observation.state"] for f in reference.frames])
    reference_labels = np.stack([f["action"] for f in reference.frames])
    grasp_xy = reference_states[np.flatnonzero(reference_labels[:, 3] > 0)[0], :2]
    miss_xy = states[empty[0] - 1, :2]
    assert np.linalg.norm(miss_xy - grasp_xy) > GRASP_XY_TOL
    assert labels[empty[0] - 1, 3] == -1.0 and labels[empty[0] - 1, 2] > 0
    assert set(np.unique(labels[:, 3])) <= {-1.0, 1.0}


def test_grasp_miss_offsets_follow_rate_and_range(tmp_path):
    from lerobot_phantom.envs.collect import grasp_miss_offset

    rng = np.random.default_rng(0)
    assert all(grasp_miss_offset(rng, 0.0, 0.02, 0.04) is None for _ in range(100))
    drawn = [grasp_miss_offset(rng, 0.5, 0.022, 0.04) for _ in range(400)]
    misses = [d for d in drawn if d is not None]
    assert 160 < len(misses) < 240
    norms = np.linalg.norm(misses, axis=1)
    assert norms.min() >= 0.022 and norms.max() <= 0.04
    with pytest.raises(ValueError, match="grasp-miss-rate"):
        _collect(tmp_path / "bad", grasp_miss_rate=1.5)
    with pytest.raises(ValueError, match="min <= max"):
        _collect(tmp_path / "bad", grasp_miss_rate=0.5, grasp_miss_min_m=0.05, grasp_miss_max_m=0.03)
    assert not (tmp_path / "bad").exists()


def test_grasp_miss_episodes_are_collected(tmp_path):
    result = _collect(tmp_path / "miss", seed=3, episodes=2, grasp_miss_rate=1.0)
    states = np.asarray(
        LeRobotDataset(REPO_ID, root=result.root).hf_dataset.with_format(None)["observation.state"]
    )
    assert result.episodes == 2 and result.failed_attempts == 0
    from lerobot_phantom.envs.scene import FINGER_CLOSED_HALF_GAP

    assert np.isclose(states[:, 3], 2 * FINGER_CLOSED_HALF_GAP).sum() >= 2
