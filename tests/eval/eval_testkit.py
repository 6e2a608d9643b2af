"""Test kit for the evaluation tests: a tiny LeRobot env whose target can only be seen in the front camera, and
two real LeRobot policies (``PreTrainedPolicy`` subclasses) plugged into ``evaluate(cfg, policy=...)``:

* ``oracle`` reads the true target position from ``observation.environment_state`` (camera attacks cannot hurt it);
* ``colour`` finds the red target in the front image and moves there (camera attacks can);
* ``instructed`` is the oracle, but only moves when the task text names the red dot (instruction attacks can hurt).
"""

from dataclasses import dataclass
from typing import ClassVar

import gymnasium as gym
import numpy as np
import torch
from gymnasium import spaces
from lerobot.configs.policies import PreTrainedConfig
from lerobot.envs.configs import EnvConfig
from lerobot.policies.pretrained import PreTrainedPolicy

from lerobot_phantom.eval.servo_policy import NonLearnedPolicyConfig

GYM_ID = "eval_testkit/DotReach-v0"
MAX_STEPS = 20
STEP_LIMIT = 0.2
SUCCESS_RADIUS = 0.06
# Two tasks with the same goal, drawn per episode at reset (as phantom_table's suites do): the per-task rows of
# eval.json have something to separate.
TASK_NAMES = ("move", "reach")
INSTRUCTIONS = ("move to the red dot", "reach the red dot")
TASK = INSTRUCTIONS[0]


class DotReachEnv(gym.Env):
    """A point agent moves to a red dot drawn in the front camera; the wrist camera shows nothing useful."""

    metadata: ClassVar[dict] = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, size: int = 32, render_mode: str = "rgb_array"):
        self.size = size
        self.render_mode = render_mode
        image = spaces.Box(0, 255, (size, size, 3), np.uint8)
        self.observation_space = spaces.Dict(
            {
                "pixels": spaces.Dict({"front": image, "wrist": image}),
                "agent_pos": spaces.Box(-1.0, 2.0, (2,), np.float32),
                "environment_state": spaces.Box(0.0, 1.0, (2,), np.float32),
            }
        )
        self.action_space = spaces.Box(-STEP_LIMIT, STEP_LIMIT, (2,), np.float32)
        self.task_id = 0
        self.task = TASK_NAMES[0]
        self.task_description = INSTRUCTIONS[0]
        self.agent = np.full(2, 0.5, np.float32)
        self.target = np.full(2, 0.5, np.float32)
        self.steps = 0
        # Read by LeRobot's rollout through env.call; kept on the env (not a TimeLimit wrapper) so that the
        # vector env's envs[0] is this class and LeRobot's add_envs_task finds `task_description`.
        self._max_episode_steps = MAX_STEPS

    def _pixel(self, xy: np.ndarray) -> tuple[int, int]:
        col, row = np.clip((xy * self.size).astype(int), 1, self.size - 2)
        return int(row), int(col)

    def _front(self) -> np.ndarray:
        img = np.full((self.size, self.size, 3), 128, np.uint8)
        row, col = self._pixel(self.target)
        img[row - 1 : row + 2, col - 1 : col + 2] = (230, 20, 20)
        return img

    def _obs(self) -> dict:
        wrist = np.full((self.size, self.size, 3), (40, 160, 40), np.uint8)
        return {
            "pixels": {"front": self._front(), "wrist": wrist},
            "agent_pos": self.agent.copy(),
            "environment_state": self.target.copy(),
        }

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.agent = np.full(2, 0.5, np.float32)
        self.steps = 0
        while True:  # a target far enough away that reaching it takes a few steps
            self.target = self.np_random.uniform(0.1, 0.9, 2).astype(np.float32)
            if np.linalg.norm(self.target - self.agent) > 0.25:
                break
        self.task_id = int(self.np_random.integers(len(TASK_NAMES)))
        self.task, self.task_description = TASK_NAMES[self.task_id], INSTRUCTIONS[self.task_id]
        return self._obs(), {"is_success": False}

    def step(self, action):
        self.agent = np.clip(self.agent + np.clip(action, -STEP_LIMIT, STEP_LIMIT), 0.0, 1.0).astype(
            np.float32
        )
        self.steps += 1
        success = bool(np.linalg.norm(self.agent - self.target) < SUCCESS_RADIUS)
        return self._obs(), float(success), success, self.steps >= MAX_STEPS, {"is_success": success}

    def render(self):
        return self._front()


if GYM_ID not in gym.registry:
    gym.register(id=GYM_ID, entry_point=DotReachEnv, order_enforce=False)


@EnvConfig.register_subclass("phantom_test_dot")
@dataclass
class DotReachEnvConfig(EnvConfig):
    task: str | None = "DotReach-v0"
    fps: int = 10
    size: int = 32

    @property
    def package_name(self) -> str:
        return "eval_testkit"

    @property
    def gym_kwargs(self) -> dict:
        return {"size": self.size}


@PreTrainedConfig.register_subclass("phantom_test_toy")
@dataclass
class ToyPolicyConfig(NonLearnedPolicyConfig):
    mode: str = "oracle"  # oracle | colour | instructed


def locate_red(front: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Centroid (x, y in [0, 1]) of red pixels per image of a (B, 3, H, W) batch, and whether any were found."""
    r, g, b = front[:, 0], front[:, 1], front[:, 2]
    mask = ((r > 0.7) & (g < 0.3) & (b < 0.3)).to(torch.float32)
    count = mask.sum(dim=(1, 2))
    height, width = mask.shape[-2:]
    rows = (mask * torch.arange(height, dtype=torch.float32)[:, None]).sum(dim=(1, 2)) / count.clamp(min=1)
    cols = (mask * torch.arange(width, dtype=torch.float32)[None, :]).sum(dim=(1, 2)) / count.clamp(min=1)
    xy = torch.stack([(cols + 0.5) / width, (rows + 0.5) / height], dim=1)
    return xy, count > 0


class ToyPolicy(PreTrainedPolicy):
    config_class = ToyPolicyConfig
    name = "phantom_test_toy"

    def __init__(self, config: ToyPolicyConfig):
        super().__init__(config)
        self.anchor = torch.nn.Parameter(torch.zeros(1))  # a module with a parameter, like any policy
        self.calls = 0

    def get_optim_params(self):
        return self.parameters()

    def reset(self):
        return None

    def forward(self, batch):
        raise NotImplementedError("a scripted test policy is not trained")

    def predict_action_chunk(self, batch, **kwargs):
        return self.select_action(batch)[:, None]

    def select_action(self, batch, **kwargs):
        self.calls += 1
        agent = batch["observation.state"].to(torch.float32)
        if self.config.mode == "colour":
            target, seen = locate_red(batch["observation.images.front"])
            target = torch.where(seen[:, None], target, agent)  # nothing seen: stay
        else:
            target = batch["observation.environment_state"].to(torch.float32)
        if self.config.mode == "instructed":
            follows = torch.tensor(["red dot" in task for task in batch["task"]])
            target = torch.where(follows[:, None], target, agent)
        return (target - agent).clamp(-STEP_LIMIT, STEP_LIMIT)


def make_toy_policy(mode: str) -> ToyPolicy:
    return ToyPolicy(ToyPolicyConfig(mode=mode))


def write_toy_dataset(root, episodes: int = 2, size: int = 32):
    """A LeRobotDataset v3 (images, no videos) of oracle rollouts in DotReachEnv, written under ``root``."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    image = {"dtype": "image", "shape": (size, size, 3), "names": ["height", "width", "channels"]}
    vector = {"dtype": "float32", "shape": (2,), "names": None}
    features = {
        "observation.images.front": image,
        "observation.images.wrist": image,
        "observation.state": vector,
        "observation.environment_state": vector,
        "action": vector,
    }
    dataset = LeRobotDataset.create("local/dot_reach", fps=10, features=features, root=root, use_videos=False)
    env = DotReachEnv(size=size)
    for episode in range(episodes):
        obs, _ = env.reset(seed=episode)
        for _ in range(6):
            action = np.clip(obs["environment_state"] - obs["agent_pos"], -STEP_LIMIT, STEP_LIMIT).astype(
                np.float32
            )
            dataset.add_frame(
                {
                    "observation.images.front": obs["pixels"]["front"],
                    "observation.images.wrist": obs["pixels"]["wrist"],
                    "observation.state": obs["agent_pos"],
                    "observation.environment_state": obs["environment_state"],
                    "action": action,
                    "task": TASK,
                }
            )
            obs, *_ = env.step(action)
        dataset.save_episode()
    dataset.finalize()
    return dataset


class PhantomTableExpertPolicy(ToyPolicy):
    """The phantom_table scripted expert behind LeRobot's policy interface (it reads the true sim state, not the
    observation); it also keeps the first front/wrist images it was shown in each rollout."""

    def bind(self, vector_env):
        from lerobot_phantom.envs import scripted_expert

        self.experts = [scripted_expert(env) for env in vector_env.envs]
        self.first_images: list[dict[str, torch.Tensor]] = []
        self._fresh = False
        return self

    def reset(self):
        self._fresh = True

    def select_action(self, batch, **kwargs):
        if self._fresh:
            self.first_images.append(
                {k: batch[f"observation.images.{k}"].clone() for k in ("front", "wrist")}
            )
            self._fresh = False
        return torch.as_tensor(np.stack([expert() for expert in self.experts]))
