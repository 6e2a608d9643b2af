import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from lerobot_phantom.envs import GYM_ID, SUITE_NAMES, SUITES, make_phantom_env, suite_gym_id
from lerobot_phantom.envs.interface import MAX_STEP_M
from lerobot_phantom.envs.scene import OBJECT_HALF_SIZE
from lerobot_phantom.envs.suites import GOAL_JITTER, SPATIAL_MIN_DY, get_suite


@pytest.fixture(scope="module")
def goal_env():
    env = make_phantom_env("goal", task_id=0)
    yield env
    env.close()


@pytest.mark.parametrize("suite", SUITE_NAMES)
def test_gymnasium_env_checker_passes(suite):
    env = gym.make(suite_gym_id(suite))
    try:
        check_env(env.unwrapped)
    finally:
        env.close()


def test_gym_make_returns_the_bare_env_so_lerobot_sees_task_description():
    env = gym.make(GYM_ID, suite="object", task_id=2)
    try:
        assert hasattr(env, "task_description")
        assert env.task_description == SUITES["object"][2]["language"]
        assert env.task == SUITES["object"][2]["name"]
    finally:
        env.close()


@pytest.mark.parametrize("suite", SUITE_NAMES)
def test_seeded_reset_is_deterministic_and_seeds_differ(suite):
    env_a, env_b = make_phantom_env(suite), make_phantom_env(suite)
    try:
        obs_a, info_a = env_a.reset(seed=7)
        obs_b, info_b = env_b.reset(seed=7)
        for cam in ("front", "wrist"):
            np.testing.assert_array_equal(obs_a["pixels"][cam], obs_b["pixels"][cam])
        np.testing.assert_array_equal(obs_a["agent_pos"], obs_b["agent_pos"])
        np.testing.assert_array_equal(env_a.data.qpos, env_b.data.qpos)
        assert info_a == info_b
        obs_c, _ = env_b.reset(seed=8)
        assert not np.array_equal(obs_a["pixels"]["front"], obs_c["pixels"]["front"])
        # Identical actions keep the two rollouts identical.
        action = np.array([0.5, -0.3, -0.8, 1.0], dtype=np.float32)
        env_b.reset(seed=7)
        for _ in range(3):
            step_a, step_b = env_a.step(action), env_b.step(action)
            np.testing.assert_array_equal(step_a[0]["pixels"]["front"], step_b[0]["pixels"]["front"])
            np.testing.assert_array_equal(step_a[0]["agent_pos"], step_b[0]["agent_pos"])
    finally:
        env_a.close()
        env_b.close()


def test_observation_layout_and_configurable_image_size():
    env = make_phantom_env("spatial", image_size=(64, 80))
    try:
        obs, info = env.reset(seed=0)
        assert set(obs) == {"pixels", "agent_pos"}
        assert set(obs["pixels"]) == {"front", "wrist"}
        for img in obs["pixels"].values():
            assert img.shape == (64, 80, 3) and img.dtype == np.uint8
        assert obs["agent_pos"].shape == (4,) and obs["agent_pos"].dtype == np.float32
        assert info["is_success"] is False and info["suite"] == "spatial"
        assert env.observation_space.contains(obs)
    finally:
        env.close()


def test_pixels_only_obs_type_has_no_state():
    env = make_phantom_env("goal", obs_type="pixels")
    try:
        obs, _ = env.reset(seed=0)
        assert set(obs) == {"pixels"}
        assert env.observation_space.contains(obs)
    finally:
        env.close()


def test_action_moves_the_tcp_by_the_documented_step_and_is_clipped(goal_env):
    goal_env.reset(seed=0)
    start = goal_env.tcp
    goal_env.step(np.array([1.0, -0.5, 0.0, -1.0], dtype=np.float32))
    np.testing.assert_allclose(goal_env.tcp - start, [MAX_STEP_M, -0.5 * MAX_STEP_M, 0.0], atol=1e-9)
    before = goal_env.tcp
    goal_env.step(np.array([5.0, 0.0, 0.0, -1.0], dtype=np.float32))  # out of bounds: clipped to 1
    np.testing.assert_allclose(goal_env.tcp - before, [MAX_STEP_M, 0.0, 0.0], atol=1e-9)
    for _ in range(20):
        goal_env.step(np.array([0.0, 0.0, -1.0, -1.0], dtype=np.float32))
    assert goal_env.tcp[2] >= 0.0  # the workspace floor keeps the fingers above the table
    with pytest.raises(ValueError, match="shape"):
        goal_env.step(np.zeros(3, dtype=np.float32))


def _drive_to(env, target, grip):
    for _ in range(40):
        delta = (np.asarray(target) - env.tcp) / MAX_STEP_M
        if np.max(np.abs(delta)) < 1e-6:
            return
        delta = delta / max(1.0, float(np.max(np.abs(delta))))
        env.step(np.array([*delta, grip], dtype=np.float32))
    raise AssertionError("could not reach the target")


def test_grasp_needs_a_centred_object_and_release_drops_it(goal_env):
    goal_env.reset(seed=3)
    cube = goal_env.position("red_cube")
    # Closing 5 cm beside the cube grasps nothing.
    _drive_to(goal_env, cube + np.array([0.0, 0.05, 0.0]), grip=-1.0)
    goal_env.step(np.array([0, 0, 0, 1.0], dtype=np.float32))
    assert goal_env.held_object is None and goal_env.gripper_closed
    goal_env.step(np.array([0, 0, 0, -1.0], dtype=np.float32))
    # Closing around it grasps it; it follows the gripper up and falls back when released.
    _drive_to(goal_env, goal_env.position("red_cube"), grip=-1.0)
    obs, *_ = goal_env.step(np.array([0, 0, 0, 1.0], dtype=np.float32))
    assert goal_env.held_object == "red_cube"
    assert obs["agent_pos"][3] == pytest.approx(2 * (OBJECT_HALF_SIZE + 0.004))
    _drive_to(goal_env, goal_env.tcp + np.array([0.0, 0.0, 0.1]), grip=1.0)
    assert goal_env.position("red_cube")[2] > 0.1
    goal_env.step(np.array([0, 0, 0, -1.0], dtype=np.float32))
    assert goal_env.held_object is None
    for _ in range(5):
        goal_env.step(np.array([0, 0, 0, -1.0], dtype=np.float32))
    assert goal_env.position("red_cube")[2] == pytest.approx(OBJECT_HALF_SIZE, abs=2e-3)


def test_episode_truncates_at_the_step_limit():
    env = make_phantom_env("object", episode_length=4)
    try:
        env.reset(seed=0)
        flags = [env.step(np.zeros(4, dtype=np.float32))[2:4] for _ in range(4)]
        assert flags[:3] == [(False, False)] * 3
        assert flags[3] == (False, True)
    finally:
        env.close()


def test_task_selection_fixed_drawn_and_validated():
    env = make_phantom_env("goal")
    try:
        drawn = {env.reset(seed=s)[1]["task_id"] for s in range(30)}
        assert len(drawn) > 1 and drawn <= set(range(len(SUITES["goal"])))
        _, info = env.reset(seed=0, options={"task_id": 4})
        assert info["task_id"] == 4 and env.task_description == SUITES["goal"][4]["language"]
        layout_with_option = env.data.qpos.copy()
        env.reset(seed=0)
        np.testing.assert_array_equal(
            env.data.qpos, layout_with_option
        )  # the task choice never moves objects
    finally:
        env.close()
    with pytest.raises(ValueError, match="valid suites: spatial, object, goal, long"):
        make_phantom_env("kitchen")
    with pytest.raises(ValueError, match=r"valid 0\.\.3"):
        make_phantom_env("long", task_id=4)


def test_layouts_vary_per_seed_within_each_suite_rules():
    for suite in SUITE_NAMES:
        env = make_phantom_env(suite)
        try:
            positions = []
            for seed in range(5):
                env.reset(seed=seed)
                names = [o.name for o in get_suite(suite).objects]
                positions.append(np.stack([env.position(n)[:2] for n in names]))
                if suite == "spatial":
                    goal = env.goals()[0]
                    y = {n: env.position(n)[1] for n in names}
                    assert abs(y["cube_a"] - y["cube_b"]) >= SPATIAL_MIN_DY
                    side = "left" if "left" in env.task else "right"
                    pick = min if side == "left" else max
                    assert goal[1] == pick(names, key=y.get)
            spread = np.ptp(np.stack(positions), axis=0).max()
            if suite == "goal":
                assert 0 < spread <= 2 * GOAL_JITTER  # one layout, jittered
            else:
                assert spread > 0.05
        finally:
            env.close()


def test_render_returns_the_front_view_at_render_size():
    env = make_phantom_env("goal", render_size=128)
    try:
        env.reset(seed=0)
        frame = env.render()
        assert frame.shape == (128, 128, 3) and frame.dtype == np.uint8
        assert frame.std() > 0
    finally:
        env.close()
