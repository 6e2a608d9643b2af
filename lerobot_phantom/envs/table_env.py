"""PhantomTableEnv: a cheap, language-conditioned MuJoCo tabletop with a mocap gripper and two cameras.

Action (float32, shape (4,), bounds [-1, 1], out-of-range values are clipped):
    [dx, dy, dz, grip] — the tool centre point (TCP) moves by ``MAX_STEP_M * (dx, dy, dz)`` metres per control step
    (10 Hz), clipped to the workspace ``TCP_LOW..TCP_HIGH``; ``grip > 0`` closes the gripper, ``grip <= 0`` opens it.
Observation (LeRobot convention, the same keys as gym-aloha / gym-pusht):
    ``pixels``: {"front": uint8 HxWx3, "wrist": uint8 HxWx3}; ``agent_pos`` (float32, (4,)): TCP x, y, z in metres
    and the finger opening in metres (wider when closed on an object than when closed on nothing).
Grasping: closing the gripper (an open->closed transition) with an object centred between the fingertips
(within ``GRASP_XY_TOL`` / ``GRASP_Z_TOL`` of the TCP) attaches it rigidly to the gripper; opening releases it.
Episodes terminate on success (``info["is_success"]``) and truncate after ``max_episode_steps``.
The instruction is exposed like LeRobot's LIBERO env: ``task_description`` (language, read by lerobot-eval's
``add_envs_task``) and ``task`` (a short task name).
"""

from __future__ import annotations

import atexit
import weakref
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from lerobot_phantom.envs.interface import (
    ACTION_DIM,
    CAMERAS,
    CONTROL_HZ,
    GRASP_XY_TOL,
    GRASP_Z_TOL,
    MAX_STEP_M,
    OBS_TYPES,
)
from lerobot_phantom.envs.rendering import select_gl_backend
from lerobot_phantom.envs.scene import (
    BASKET_FLOOR_TOP,
    BASKET_INNER_HALF,
    FINGER_CLOSED_HALF_GAP,
    FINGER_HALF_THICKNESS,
    FINGER_OPEN_HALF_GAP,
    OBJECT_HALF_SIZE,
    PLATE_RADIUS,
    PLATE_TOP,
    build_scene_xml,
)
from lerobot_phantom.envs.suites import get_suite, get_task, resolve_roles, sample_layout

select_gl_backend()  # must run before mujoco is imported
import mujoco  # noqa: E402

PHYSICS_SUBSTEPS = 20  # 20 x 5 ms = one 100 ms control step
TCP_LOW = np.array([-0.25, -0.3, 0.015])
TCP_HIGH = np.array([0.25, 0.3, 0.25])
HOME_TCP = np.array([-0.2, 0.0, 0.2])
SETTLED_SPEED = 0.05  # m/s; a placed object must be at rest to count
HEIGHT_TOL = 0.01


def _close_renderers(renderers: dict) -> None:
    for renderer in renderers.values():
        renderer.close()
    renderers.clear()


_LIVE_ENVS: weakref.WeakSet = weakref.WeakSet()
_EXIT_HOOK_REGISTERED = False


def _close_live_envs() -> None:
    for env in list(_LIVE_ENVS):
        env.close()


def _register_exit_hook() -> None:
    # mujoco's EGL backend registers eglTerminate with atexit when it creates its first context; registering
    # after that (atexit is LIFO) closes our contexts while the display still exists, avoiding noisy EGL errors.
    global _EXIT_HOOK_REGISTERED
    if not _EXIT_HOOK_REGISTERED:
        atexit.register(_close_live_envs)
        _EXIT_HOOK_REGISTERED = True


def _image_hw(image_size: int | tuple[int, int] | list[int]) -> tuple[int, int]:
    if isinstance(image_size, int):
        return image_size, image_size
    height, width = image_size
    return int(height), int(width)


class PhantomTableEnv(gym.Env):
    metadata: ClassVar[dict] = {"render_modes": ["rgb_array"], "render_fps": CONTROL_HZ}

    def __init__(
        self,
        suite: str = "goal",
        task_id: int | None = None,
        image_size: int | tuple[int, int] = 96,
        obs_type: str = "pixels_agent_pos",
        render_mode: str | None = "rgb_array",
        episode_length: int | None = None,
        render_size: int | tuple[int, int] | None = None,
    ):
        super().__init__()
        if obs_type not in OBS_TYPES:
            raise ValueError(f"unknown obs_type {obs_type!r}; valid: {', '.join(OBS_TYPES)}")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"unknown render_mode {render_mode!r}; valid: None, 'rgb_array'")
        self.spec_suite = get_suite(suite)
        self.suite = suite
        self.fixed_task_id = None if task_id is None else int(task_id)
        if self.fixed_task_id is not None:
            get_task(suite, self.fixed_task_id)  # validates the id
        self.obs_type = obs_type
        self.render_mode = render_mode
        self.image_hw = _image_hw(image_size)
        self.render_hw = self.image_hw if render_size is None else _image_hw(render_size)
        self._max_episode_steps = int(episode_length or self.spec_suite.max_episode_steps)

        buffer_size = max(*self.image_hw, *self.render_hw)
        xml = build_scene_xml(self.spec_suite.objects, self.spec_suite.containers, buffer_size)
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        self._mocap = {
            name: int(self.model.body_mocapid[self.model.body(name).id])
            for name in ("gripper", "finger_left", "finger_right", *self.spec_suite.containers)
        }
        self._object_names = tuple(o.name for o in self.spec_suite.objects)
        self._body_id = {name: self.model.body(name).id for name in self._object_names}
        self._qpos_adr = {
            name: int(self.model.jnt_qposadr[self.model.joint(f"{name}_joint").id])
            for name in self._object_names
        }
        self._dof_adr = {
            name: int(self.model.jnt_dofadr[self.model.joint(f"{name}_joint").id])
            for name in self._object_names
        }
        # Renderers own GL contexts; close them at exit at the latest, while the GL libraries are still loaded.
        self._renderers: dict[str, mujoco.Renderer] = {}
        _LIVE_ENVS.add(self)

        height, width = self.image_hw
        image_space = spaces.Box(low=0, high=255, shape=(height, width, 3), dtype=np.uint8)
        obs_spaces: dict[str, spaces.Space] = {"pixels": spaces.Dict({cam: image_space for cam in CAMERAS})}
        if obs_type == "pixels_agent_pos":
            obs_spaces["agent_pos"] = spaces.Box(
                low=np.array([*TCP_LOW, 0.0], dtype=np.float32),
                high=np.array([*TCP_HIGH, 2 * FINGER_OPEN_HALF_GAP], dtype=np.float32),
                dtype=np.float32,
            )
        self.observation_space = spaces.Dict(obs_spaces)
        self.action_space = spaces.Box(low=-1.0, high=1.0, shape=(ACTION_DIM,), dtype=np.float32)

        self._set_task(self.fixed_task_id if self.fixed_task_id is not None else 0)
        self._tcp = HOME_TCP.copy()
        self._closed = False
        self._held: str | None = None
        self._held_offset = np.zeros(3)
        self._half_gap = FINGER_OPEN_HALF_GAP
        self._steps = 0
        self._roles: dict[str, str] = {}

    # ----------------------------------------------------------------------------------------------- task
    def _set_task(self, task_id: int) -> None:
        task = get_task(self.suite, task_id)
        self.task_id = task_id
        self.task = task["name"]
        self.task_description = task["language"]
        self._task = task

    @property
    def max_episode_steps(self) -> int:
        return self._max_episode_steps

    # --------------------------------------------------------------------------------------------- gym API
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        options = options or {}
        # Always consume the task draw, so a seed gives the same layout whichever way the task is chosen.
        task_id = int(self.np_random.integers(len(self.spec_suite.tasks)))
        if "task_id" in options:
            task_id = int(options["task_id"])
        elif self.fixed_task_id is not None:
            task_id = self.fixed_task_id
        self._set_task(task_id)

        layout = sample_layout(self.spec_suite, self.np_random)
        self._roles = resolve_roles(self.spec_suite, layout)
        mujoco.mj_resetData(self.model, self.data)
        for name in self.spec_suite.containers:
            self.data.mocap_pos[self._mocap[name]] = (*layout[name], 0.0)
        for name in self._object_names:
            yaw = self.np_random.uniform(-np.pi / 4, np.pi / 4)
            adr = self._qpos_adr[name]
            self.data.qpos[adr : adr + 3] = (*layout[name], OBJECT_HALF_SIZE)
            self.data.qpos[adr + 3 : adr + 7] = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
        self._tcp = HOME_TCP.copy()
        self._closed = False
        self._held = None
        self._steps = 0
        self._place_gripper(self._tcp)
        for _ in range(PHYSICS_SUBSTEPS // 4):  # let contacts settle
            mujoco.mj_step(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        return self._observation(), self._info(False)

    def step(self, action):
        action = np.asarray(action, dtype=np.float64)
        if action.shape != (4,):
            raise ValueError(f"expected an action of shape (4,) = [dx, dy, dz, grip], got {action.shape}")
        action = np.clip(action, -1.0, 1.0)
        target = np.clip(self._tcp + action[:3] * MAX_STEP_M, TCP_LOW, TCP_HIGH)
        close = bool(action[3] > 0)
        if close and not self._closed:
            self._closed = True
            self._held = self._graspable_object()
            if self._held is not None:
                self._held_offset = self._object_pos(self._held) - self._tcp
        elif not close and self._closed:
            self._closed = False
            self._held = None

        start = self._tcp.copy()
        velocity = (target - start) * CONTROL_HZ
        for k in range(1, PHYSICS_SUBSTEPS + 1):
            tcp = start + (target - start) * (k / PHYSICS_SUBSTEPS)
            self._place_gripper(tcp)
            self._pin_held(tcp, velocity)
            mujoco.mj_step(self.model, self.data)
        self._tcp = target
        self._place_gripper(target)
        self._pin_held(target, np.zeros(3))
        mujoco.mj_forward(self.model, self.data)

        self._steps += 1
        success = self.is_success()
        terminated = success
        truncated = (not terminated) and self._steps >= self._max_episode_steps
        return self._observation(), float(success), terminated, truncated, self._info(success)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return self._render_camera("front", self.render_hw)

    def close(self):
        _close_renderers(self._renderers)

    # ------------------------------------------------------------------------------------------ internals
    def _place_gripper(self, tcp: np.ndarray) -> None:
        if self._held is not None:
            half_gap = OBJECT_HALF_SIZE + FINGER_HALF_THICKNESS
        elif self._closed:
            half_gap = FINGER_CLOSED_HALF_GAP
        else:
            half_gap = FINGER_OPEN_HALF_GAP
        self.data.mocap_pos[self._mocap["gripper"]] = tcp
        finger_offset = np.array([0.0, half_gap, 0.0])
        self.data.mocap_pos[self._mocap["finger_left"]] = tcp - finger_offset
        self.data.mocap_pos[self._mocap["finger_right"]] = tcp + finger_offset
        self._half_gap = half_gap

    def _pin_held(self, tcp: np.ndarray, velocity: np.ndarray) -> None:
        if self._held is None:
            return
        adr, dof = self._qpos_adr[self._held], self._dof_adr[self._held]
        self.data.qpos[adr : adr + 3] = tcp + self._held_offset
        self.data.qvel[dof : dof + 3] = velocity
        self.data.qvel[dof + 3 : dof + 6] = 0.0

    def _graspable_object(self) -> str | None:
        best, best_dist = None, np.inf
        for name in self._object_names:
            delta = self._object_pos(name) - self._tcp
            xy = float(np.linalg.norm(delta[:2]))
            if xy < GRASP_XY_TOL and abs(delta[2]) < GRASP_Z_TOL and xy < best_dist:
                best, best_dist = name, xy
        return best

    def _render_camera(self, camera: str, hw: tuple[int, int] | None = None) -> np.ndarray:
        hw = hw or self.image_hw
        key = f"{hw[0]}x{hw[1]}"
        if key not in self._renderers:
            self._renderers[key] = mujoco.Renderer(self.model, *hw)
            _register_exit_hook()
        renderer = self._renderers[key]
        renderer.update_scene(self.data, camera=camera)
        return renderer.render()

    def _observation(self) -> dict:
        obs: dict[str, Any] = {"pixels": {cam: self._render_camera(cam) for cam in CAMERAS}}
        if self.obs_type == "pixels_agent_pos":
            obs["agent_pos"] = self.agent_pos()
        return obs

    def _info(self, success: bool) -> dict:
        return {"is_success": bool(success), "task": self.task, "task_id": self.task_id, "suite": self.suite}

    # ------------------------------------------------------------------ state queries (also used by experts)
    def agent_pos(self) -> np.ndarray:
        return np.array([*self._tcp, 2 * self._half_gap], dtype=np.float32)

    @property
    def tcp(self) -> np.ndarray:
        return self._tcp.copy()

    @property
    def gripper_closed(self) -> bool:
        return self._closed

    @property
    def held_object(self) -> str | None:
        return self._held

    def _object_pos(self, name: str) -> np.ndarray:
        return self.data.xpos[self._body_id[name]].copy()

    def position(self, name: str) -> np.ndarray:
        """World position of an object body or container (containers sit on the table, z=0)."""
        if name in self._body_id:
            return self._object_pos(name)
        return self.data.mocap_pos[self._mocap[name]].copy()

    def _speed(self, name: str) -> float:
        dof = self._dof_adr[name]
        return float(np.linalg.norm(self.data.qvel[dof : dof + 3]))

    def goals(self, task_id: int | None = None) -> list[tuple[str, str, str]]:
        """Goals of the current task (or of ``task_id`` in this layout), roles resolved: (relation, object, target)."""
        task = self._task if task_id is None else get_task(self.suite, task_id)
        return [(rel, self._roles[obj], self._roles[target]) for rel, obj, target in task["goals"]]

    def support_height(self, relation: str, target: str) -> float:
        """Height of the surface an object rests on when ``relation`` to ``target`` holds."""
        if relation == "in":
            return BASKET_FLOOR_TOP
        if relation == "on":
            return PLATE_TOP
        if relation == "stack":
            return float(self._object_pos(target)[2]) + OBJECT_HALF_SIZE
        raise ValueError(f"unknown relation {relation!r}; valid: 'in', 'on', 'stack'")

    def goal_holds(self, relation: str, obj: str, target: str) -> bool:
        if self._held == obj or self._speed(obj) > SETTLED_SPEED:
            return False
        pos, target_pos = self._object_pos(obj), self.position(target)
        offset = pos[:2] - target_pos[:2]
        resting_z = self.support_height(relation, target) + OBJECT_HALF_SIZE
        if abs(pos[2] - resting_z) > HEIGHT_TOL:
            return False
        if relation == "in":
            return bool(np.all(np.abs(offset) < BASKET_INNER_HALF))
        if relation == "on":
            return bool(np.linalg.norm(offset) < PLATE_RADIUS)
        # stack: the base must itself rest on the table and the object be centred on it
        base_on_table = abs(target_pos[2] - OBJECT_HALF_SIZE) < HEIGHT_TOL and self._held != target
        return bool(base_on_table and np.linalg.norm(offset) < OBJECT_HALF_SIZE)

    def is_success(self) -> bool:
        return all(self.goal_holds(*goal) for goal in self.goals())


def make_phantom_env(
    suite: str,
    task_id: int | None = None,
    image_size: int | tuple[int, int] = 96,
    seed: int | None = None,
    obs_type: str = "pixels_agent_pos",
    render_mode: str | None = "rgb_array",
    episode_length: int | None = None,
    render_size: int | tuple[int, int] | None = None,
) -> PhantomTableEnv:
    """Build a PhantomTableEnv; with ``seed`` it is also reset once with that seed (seeding its RNG)."""
    env = PhantomTableEnv(
        suite=suite,
        task_id=task_id,
        image_size=image_size,
        obs_type=obs_type,
        render_mode=render_mode,
        episode_length=episode_length,
        render_size=render_size,
    )
    if seed is not None:
        env.reset(seed=seed)
    return env
