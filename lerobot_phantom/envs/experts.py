"""Scripted experts: reactive pick-and-place controllers that read privileged simulator state.

The expert re-plans from the current state at every step (which object is held, where everything is), so it
recovers from small perturbations: for each unmet goal in order it moves above the object at a safe travel height,
descends, closes, lifts, carries the object above the target, descends to just above the support and opens.
``aim_offset`` shifts the grasp point in xy, which lets a recorder execute a deliberate miss while it records the
unshifted expert's actions as labels.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from lerobot_phantom.envs.interface import MAX_STEP_M
from lerobot_phantom.envs.scene import OBJECT_HALF_SIZE
from lerobot_phantom.envs.table_env import PhantomTableEnv

TRAVEL_Z = 0.12
RELEASE_CLEARANCE = 0.008
REACHED_TOL = 1e-3


def _move_towards(tcp: np.ndarray, waypoint: np.ndarray) -> np.ndarray:
    """Normalised delta that reaches ``waypoint`` exactly when it is within one step (max-norm scaling)."""
    delta = (waypoint - tcp) / MAX_STEP_M
    largest = float(np.max(np.abs(delta)))
    return delta / largest if largest > 1.0 else delta


class ScriptedExpert:
    """Callable ``obs -> action`` for one PhantomTableEnv (the observation itself is not needed)."""

    def __init__(self, env):
        self.env: PhantomTableEnv = env.unwrapped
        if not isinstance(self.env, PhantomTableEnv):
            raise TypeError(f"ScriptedExpert needs a PhantomTableEnv, got {type(self.env).__name__}")

    def _action(self, waypoint: np.ndarray | None, close: bool) -> np.ndarray:
        move = np.zeros(3) if waypoint is None else _move_towards(self.env.tcp, waypoint)
        return np.array([*move, 1.0 if close else -1.0], dtype=np.float32)

    def _go_via_travel_height(self, goal_xy: np.ndarray, goal_z: float, close: bool) -> np.ndarray | None:
        """Action towards (goal_xy, goal_z) going up, across at TRAVEL_Z, then down; None once there."""
        tcp = self.env.tcp
        if np.linalg.norm(tcp[:2] - goal_xy) > REACHED_TOL:
            if tcp[2] < TRAVEL_Z - REACHED_TOL:
                return self._action(np.array([*tcp[:2], TRAVEL_Z]), close)
            return self._action(np.array([*goal_xy, TRAVEL_Z]), close)
        if abs(tcp[2] - goal_z) > REACHED_TOL:
            return self._action(np.array([*goal_xy, goal_z]), close)
        return None

    def __call__(self, observation=None, aim_offset: np.ndarray | None = None) -> np.ndarray:
        env = self.env
        for relation, obj, target in env.goals():
            if env.goal_holds(relation, obj, target):
                continue
            held = env.held_object
            if held is not None and held != obj:
                return self._action(None, close=False)  # holding the wrong thing: drop it
            if held == obj:
                place_xy = env.position(target)[:2]
                offset = env.position(obj) - env.tcp
                place_z = (
                    env.support_height(relation, target) + OBJECT_HALF_SIZE + RELEASE_CLEARANCE - offset[2]
                )
                action = self._go_via_travel_height(place_xy, place_z, close=True)
                return self._action(None, close=False) if action is None else action
            if env.gripper_closed:
                return self._action(None, close=False)  # closed on nothing: re-open before grasping
            obj_pos = env.position(obj)
            if aim_offset is not None:
                obj_pos[:2] += aim_offset
            action = self._go_via_travel_height(obj_pos[:2], float(obj_pos[2]), close=False)
            return self._action(None, close=True) if action is None else action
        # Every goal holds (the env terminates on that); stay put with the gripper open.
        return self._action(None, close=False)


def scripted_expert(env) -> Callable[[object], np.ndarray]:
    """The scripted expert for ``env`` (a PhantomTableEnv, possibly wrapped): a callable ``obs -> action``."""
    return ScriptedExpert(env)


def record_expert_episode(env, seed: int, task_id: int | None = None) -> dict:
    """Run the scripted expert for one episode; returns the instruction, success and per-step observations/actions.

    ``frames`` holds the observations seen before each action plus the final one (for GIFs and demos).
    """
    options = None if task_id is None else {"task_id": task_id}
    obs, info = env.reset(seed=seed, options=options)
    expert = scripted_expert(env)
    frames, actions = [obs], []
    while True:
        action = expert(obs)
        obs, _, terminated, truncated, info = env.step(action)
        frames.append(obs)
        actions.append(action)
        if terminated or truncated:
            break
    return {
        "language": env.unwrapped.task_description,
        "success": bool(info["is_success"]),
        "frames": frames,
        "actions": np.stack(actions),
    }
