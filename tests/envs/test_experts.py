import pytest

from lerobot_phantom.envs import SUITE_NAMES, SUITES, make_phantom_env, scripted_expert


def run_expert(env, seed, task_id):
    obs, info = env.reset(seed=seed, options={"task_id": task_id})
    expert = scripted_expert(env)
    for _ in range(env.max_episode_steps):
        obs, reward, terminated, truncated, info = env.step(expert(obs))
        if terminated or truncated:
            break
    return info, reward, terminated


@pytest.mark.parametrize("suite", SUITE_NAMES)
def test_expert_solves_every_task_of_the_suite(suite):
    env = make_phantom_env(suite)
    try:
        for task_id in range(len(SUITES[suite])):
            for seed in (11 + task_id, 101 + task_id):
                info, reward, terminated = run_expert(env, seed, task_id)
                assert info["is_success"] and terminated and reward == 1.0, (suite, task_id, seed)
    finally:
        env.close()


def test_goal_suite_outcome_depends_on_the_instruction():
    """Each goal-suite task ends in a state that satisfies none of the other tasks, so a policy that ignores the
    instruction can succeed on at most one task per layout (chance level)."""
    env = make_phantom_env("goal")
    try:
        n_tasks = len(SUITES["goal"])
        for task_id in range(n_tasks):
            info, _, _ = run_expert(env, seed=5, task_id=task_id)
            assert info["is_success"]
            satisfied = [
                other for other in range(n_tasks) if all(env.goal_holds(*g) for g in env.goals(other))
            ]
            assert satisfied == [task_id]
    finally:
        env.close()


def test_long_tasks_need_both_subgoals():
    env = make_phantom_env("long", task_id=0)
    try:
        obs, _ = env.reset(seed=2)
        expert = scripted_expert(env)
        first, _ = env.goals()
        done_first_at = None
        for step in range(env.max_episode_steps):
            obs, _, terminated, _, info = env.step(expert(obs))
            if done_first_at is None and env.goal_holds(*first):
                done_first_at = step
                assert not info["is_success"]  # one sub-goal is not enough
            if terminated:
                break
        assert info["is_success"] and done_first_at is not None and done_first_at < step
    finally:
        env.close()


def test_expert_rejects_foreign_envs():
    import gymnasium as gym

    with pytest.raises(TypeError, match="PhantomTableEnv"):
        scripted_expert(gym.make("CartPole-v1"))


def test_record_expert_episode_returns_aligned_frames_and_actions():
    from lerobot_phantom.envs import record_expert_episode

    env = make_phantom_env("object")
    try:
        episode = record_expert_episode(env, seed=4, task_id=3)
        assert episode["success"]
        assert episode["language"] == SUITES["object"][3]["language"]
        assert len(episode["frames"]) == len(episode["actions"]) + 1
        assert episode["actions"].shape[1] == 4
        # The last frame shows the object in the basket, not where it started.
        first, last = episode["frames"][0]["pixels"]["front"], episode["frames"][-1]["pixels"]["front"]
        assert not (first == last).all()
    finally:
        env.close()
