"""``phantom_servo``: a non-learned, camera-driven reference policy for the ``phantom_table`` benchmark.

It lets anyone measure what the attacks do on a CPU in minutes, without training: it sees only what a learned
policy sees (``observation.images.front``, ``observation.state`` = TCP x, y, z + finger opening, and ``task``)
and runs a deliberately naive perception pipeline:

1. the instruction is parsed into goals (object = colour + shape or ``left``/``right``; relation ``in`` the
   basket, ``on`` the plate, or ``stack`` on another object; ``A and then B`` gives two goals in order). An
   instruction it cannot parse (e.g. emptied by voice DoS) makes it stay still rather than guess; a later
   "ignore the above instruction ..." replaces what came before, and "do not move" is obeyed (voice spoofing);
2. objects, basket and plate are found by colour thresholds in the front image; a pixel is mapped to the table by
   intersecting its camera ray with a horizontal plane, using the front camera's pose and field of view read once
   from the scene model (no per-episode privileged state);
3. the hand is driven like the scripted expert (above the object at travel height, down, close, up, across, down,
   open), closed loop on the proprioceptive state; a grasp is checked from the finger opening.

Nothing here is made robust on purpose: laser spots, projected colours or stripes that look like the target
colours move the estimates, and the task success rate drops, which is the point of a reference victim.

    from lerobot_phantom.eval.servo_policy import save_servo_policy
    path = save_servo_policy("outputs/servo")
    # lerobot-phantom-eval --policy.path=outputs/servo --env.type=phantom_table --env.task=goal ...

Importing this module registers the ``phantom_servo`` config type with LeRobot (draccus needs it to read the
checkpoint's config.json); LeRobot's ``make_policy`` / ``make_pre_post_processors`` then find
``PhantomServoPolicy`` and ``make_phantom_servo_pre_post_processors`` here by their naming convention, and a saved
checkpoint carries its own pass-through processor pipelines.
"""

from __future__ import annotations

import functools
import itertools
import re
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
import torch
from lerobot.configs.policies import PreTrainedConfig
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.optim.optimizers import AdamConfig
from lerobot.policies.pretrained import PreTrainedPolicy

from lerobot_phantom.envs.interface import ACTION_DIM, MAX_STEP_M, STATE_DIM
from lerobot_phantom.envs.scene import (
    BASKET_FLOOR_TOP,
    FINGER_CLOSED_HALF_GAP,
    FINGER_HALF_THICKNESS,
    FINGER_OPEN_HALF_GAP,
    OBJECT_HALF_SIZE,
    PLATE_TOP,
)

POLICY_TYPE = "phantom_servo"
FRONT_IMAGE_KEY = "observation.images.front"
STATE_KEY = "observation.state"

SHAPES = ("cube", "cylinder")
SIDES = ("left", "right")
OBJECT_COLOURS = ("red", "green", "blue", "yellow", "orange")

# Finger opening seen in the state: open 8 cm, closed on an object 4.8 cm, closed on nothing 1.2 cm; thresholds
# half-way between them tell the three apart.
GRASP_MIN_OPENING = FINGER_CLOSED_HALF_GAP + OBJECT_HALF_SIZE + FINGER_HALF_THICKNESS
OPEN_MIN_OPENING = FINGER_OPEN_HALF_GAP + OBJECT_HALF_SIZE + FINGER_HALF_THICKNESS


# ---------------------------------------------------------------------------------------------- instruction
@dataclass(frozen=True)
class ObjectRef:
    colour: str | None  # None for a spatial reference ("the left cube")
    shape: str
    side: str | None = None


@dataclass(frozen=True)
class Goal:
    relation: str  # "in" (basket), "on" (plate) or "stack" (on ``target``, an ObjectRef)
    obj: ObjectRef
    target: str | ObjectRef


@dataclass(frozen=True)
class Plan:
    """What the instruction asks: goals in order, or ``hold`` (stay still)."""

    goals: tuple[Goal, ...] = ()
    hold: bool = False


HOLD = Plan(hold=True)
_OVERRIDE = re.compile(r"\bignore (?:the |all )?(?:above|previous|prior|earlier)(?: instructions?)?\b")
_STOP = re.compile(r"\b(?:do not|don't|dont) move\b|\bstay still\b|\bstop\b|\bfreeze\b")
_PUT = re.compile(
    r"^(?:put|place|move) the (?P<obj>.+?) (?P<rel>in|into|on|onto) the (?P<target>basket|plate)$"
)
_PICK = re.compile(
    r"^pick up the (?P<obj>.+?) and (?:put|place) it (?P<rel>in|into|on|onto) the (?P<target>basket|plate)$"
)
_STACK = re.compile(r"^stack the (?P<obj>.+?) on(?: top of)? the (?P<target>.+)$")


def _object_ref(words: str) -> ObjectRef | None:
    parts = words.split()
    if len(parts) != 2 or parts[1] not in SHAPES:
        return None
    if parts[0] in SIDES:
        return ObjectRef(colour=None, shape=parts[1], side=parts[0])
    if parts[0] in OBJECT_COLOURS:
        return ObjectRef(colour=parts[0], shape=parts[1])
    return None


def _parse_clause(clause: str) -> Goal | None:
    if match := _STACK.match(clause):
        obj, target = _object_ref(match["obj"]), _object_ref(match["target"])
        if obj is None or target is None or obj == target:
            return None
        return Goal("stack", obj, target)
    match = _PUT.match(clause) or _PICK.match(clause)
    if match is None:
        return None
    obj = _object_ref(match["obj"])
    relation = "in" if match["target"] == "basket" else "on"
    return None if obj is None else Goal(relation, obj, match["target"])


def parse_instruction(text: str) -> Plan | None:
    """The plan an instruction asks for; ``None`` when it cannot be understood (the policy then stays still).

    Only the part after the last "ignore the above instruction" counts, and any "do not move" / "stop" in it
    means ``HOLD``: a spoofed command is obeyed, as a real speech-driven robot would.
    """
    text = re.sub(r"[^a-z' ]+", " ", str(text).lower())
    text = " ".join(text.split())
    overrides = list(_OVERRIDE.finditer(text))
    if overrides:
        text = text[overrides[-1].end() :].strip()
        text = re.sub(r"^(?:and|then|instead)\s+", "", text)
    if _STOP.search(text):
        return HOLD
    if not text:
        return None
    goals = []
    for clause in re.split(r",? and then |, then |\. then ", text):
        goal = _parse_clause(clause.strip())
        if goal is None:
            return None
        goals.append(goal)
    return Plan(goals=tuple(goals))


# ------------------------------------------------------------------------------------------------- camera
@dataclass(frozen=True)
class CameraModel:
    """Pinhole model of a fixed MuJoCo camera: world point <-> pixel (column u, row v; pixel centres at +0.5)."""

    position: np.ndarray  # (3,)
    axes: np.ndarray  # (3, 3) rows: camera x (image right), y (image up), z (backwards) in world coordinates
    fovy_deg: float

    def focal(self, height: int) -> float:
        return (height / 2) / np.tan(np.radians(self.fovy_deg) / 2)

    def project(self, points: np.ndarray, height: int, width: int) -> np.ndarray:
        """(N, 3) world points -> (N, 2) pixel (u, v)."""
        cam = (np.atleast_2d(points) - self.position) @ self.axes.T
        depth = -cam[:, 2]
        f = self.focal(height)
        return np.stack([width / 2 + f * cam[:, 0] / depth, height / 2 - f * cam[:, 1] / depth], axis=1)

    def pixel_to_plane(self, uv: np.ndarray, height: int, width: int, plane_z: float) -> np.ndarray:
        """(N, 2) pixels -> (N, 2) table xy where their rays meet the plane z = plane_z."""
        uv = np.atleast_2d(uv)
        f = self.focal(height)
        rays_cam = np.stack([(uv[:, 0] - width / 2) / f, -(uv[:, 1] - height / 2) / f, -np.ones(len(uv))], 1)
        rays = rays_cam @ self.axes
        t = (plane_z - self.position[2]) / rays[:, 2]
        return (self.position + t[:, None] * rays)[:, :2]


@functools.cache
def front_camera() -> CameraModel:
    """The ``front`` camera as the scene defines it, read once from a MuJoCo model of the empty table."""
    from lerobot_phantom.envs.rendering import select_gl_backend
    from lerobot_phantom.envs.scene import build_scene_xml

    select_gl_backend()
    import mujoco

    model = mujoco.MjModel.from_xml_string(build_scene_xml((), (), 16))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    cam = model.camera("front").id
    # cam_xmat columns are the camera axes in world coordinates.
    axes = data.cam_xmat[cam].reshape(3, 3).T.copy()
    return CameraModel(data.cam_xpos[cam].copy(), axes, float(model.cam_fovy[cam]))


# ------------------------------------------------------------------------------------------------ vision
# Height of the plane a blob's centroid is mapped onto (measured once on clean renderings: the visible top and
# front faces of an object average at its centre; the basket shows its floor and its walls).
OBJECT_PLANE_Z = OBJECT_HALF_SIZE
PLATE_PLANE_Z = PLATE_TOP / 2
BASKET_PLANE_Z = 0.012
MIN_BLOB_PIXELS = 3
TRACK_RADIUS_PX = 7 / 96  # x image height; identical objects are >= 10 cm (~16 px at 96x96) apart (spatial)
HUE_RANGES = {  # degrees
    "red": ((345.0, 360.0), (0.0, 15.0)),
    "orange": ((18.0, 38.0),),
    "yellow": ((42.0, 70.0),),
    "green": ((90.0, 170.0),),
    "blue": ((200.0, 250.0),),
}
MIN_SATURATION = 0.6
MIN_VALUE = 0.25


def colour_masks(image: np.ndarray) -> dict[str, np.ndarray]:
    """Boolean (H, W) masks of every colour the scene uses, from an (H, W, 3) float image in [0, 1]."""
    # OpenCV's float HSV: hue in degrees [0, 360), saturation and value in [0, 1].
    hue, saturation, value = np.moveaxis(cv2.cvtColor(image.astype(np.float32), cv2.COLOR_RGB2HSV), -1, 0)
    vivid = (saturation >= MIN_SATURATION) & (value >= MIN_VALUE)
    masks = {}
    for colour, ranges in HUE_RANGES.items():
        in_range = np.zeros_like(vivid)
        for low, high in ranges:
            in_range |= (hue >= low) & (hue < high)
        masks[colour] = vivid & in_range
    r, b = image[..., 0], image[..., 2]
    masks["plate"] = (image.min(-1) > 0.88) & (saturation < 0.12)
    # The basket is a bluish dark grey (0.3, 0.3, 0.35); the gripper's greys are masked out separately.
    masks["basket"] = (saturation < 0.25) & (value > 0.3) & (value < 0.55) & (b >= r) & (b - r < 0.12)
    return masks


def two_clusters(points: np.ndarray, iterations: int = 10) -> list[np.ndarray]:
    """Split (N, 2) pixel coordinates into a left and a right group (2-means started from the extreme columns)."""
    data = points.astype(np.float32)
    extremes = data[[np.argmin(data[:, 0]), np.argmax(data[:, 0])]]
    initial = np.argmin(((data[:, None] - extremes[None]) ** 2).sum(-1), axis=1).astype(np.int32)
    criteria = (cv2.TERM_CRITERIA_MAX_ITER, iterations, 0.0)
    _, labels, _ = cv2.kmeans(data, 2, initial[:, None], criteria, 1, cv2.KMEANS_USE_INITIAL_LABELS)
    labels = labels.ravel()
    return [points[labels == k] for k in range(2)]


# Table region the objects and containers can be in (metres); pixels elsewhere (floor, sky) are ignored.
WORKSPACE_X = (-0.3, 0.3)
WORKSPACE_Y = (-0.35, 0.35)


@functools.cache
def workspace_mask(height: int, width: int) -> np.ndarray:
    """Pixels whose ray meets the table top inside the workspace (fixed camera: computed once per size)."""
    rows, cols = np.mgrid[0:height, 0:width]
    uv = np.stack([cols.ravel() + 0.5, rows.ravel() + 0.5], axis=1)
    xy = front_camera().pixel_to_plane(uv, height, width, 0.0)
    inside = (
        (xy[:, 0] > WORKSPACE_X[0])
        & (xy[:, 0] < WORKSPACE_X[1])
        & (xy[:, 1] > WORKSPACE_Y[0])
        & (xy[:, 1] < WORKSPACE_Y[1])
    )
    return inside.reshape(height, width)


def dilate(mask: np.ndarray) -> np.ndarray:
    """One-pixel (8-neighbour) binary dilation."""
    return cv2.dilate(mask.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)


# Where the gripper can cover the image, relative to the TCP (metres; see scene.py): the box around the palm and
# the open fingers, and points along the arm rod.
GRIPPER_BOX = ((-0.018, 0.018), (-FINGER_OPEN_HALF_GAP, FINGER_OPEN_HALF_GAP), (-0.015, 0.07))
ARM_ROD = ((0.0, 0.0, 0.07), (-0.05, 0.0, 0.45))


def gripper_mask(camera: CameraModel, tcp: np.ndarray, height: int, width: int, margin_px: int) -> np.ndarray:
    """Pixels the gripper (fingers, palm, arm rod) may cover, from the known TCP (proprioception)."""
    corners = np.array(list(itertools.product(*GRIPPER_BOX)))
    box = camera.project(np.asarray(tcp)[None] + corners, height, width)
    low = np.floor(box.min(0)).astype(int) - margin_px
    high = np.ceil(box.max(0)).astype(int) + margin_px
    mask = np.zeros((height, width), dtype=bool)
    mask[max(low[1], 0) : max(high[1] + 1, 0), max(low[0], 0) : max(high[0] + 1, 0)] = True
    start, end = np.asarray(ARM_ROD)
    rod = camera.project(
        np.asarray(tcp) + start + np.linspace(0, 1, 33)[:, None] * (end - start), height, width
    )
    for u, v in np.round(rod).astype(int):
        mask[
            max(v - margin_px, 0) : max(v + margin_px + 1, 0),
            max(u - margin_px, 0) : max(u + margin_px + 1, 0),
        ] = True
    return mask


# ------------------------------------------------------------------------------------------------- config
@dataclass
class NonLearnedPolicyConfig(PreTrainedConfig):
    """Base of policy configs that are never trained (reference and test policies): no temporal deltas, and the
    optimiser/scheduler presets LeRobot requires are placeholders."""

    device: str | None = "cpu"

    @property
    def observation_delta_indices(self):
        return None

    @property
    def action_delta_indices(self):
        return None

    @property
    def reward_delta_indices(self):
        return None

    def get_optimizer_preset(self):
        return AdamConfig()

    def get_scheduler_preset(self):
        return None

    def validate_features(self) -> None:
        return None


@PreTrainedConfig.register_subclass(POLICY_TYPE)
@dataclass
class PhantomServoConfig(NonLearnedPolicyConfig):
    """Settings of the scripted servo policy (nothing is learned; these are its controller constants)."""

    travel_z: float = 0.12  # metres; height of every horizontal move, as the scripted expert
    reach_tolerance: float = 0.002  # metres; a waypoint is reached within this (the TCP is known exactly)
    release_clearance: float = 0.008  # metres above the support at which the object is let go
    mask_margin_px: int = 2  # pixels added around the projected gripper before ignoring blobs it touches
    max_grasp_attempts: int = 3
    device: str | None = "cpu"
    input_features: dict[str, PolicyFeature] = field(
        default_factory=lambda: {
            FRONT_IMAGE_KEY: PolicyFeature(type=FeatureType.VISUAL, shape=(3, 96, 96)),
            STATE_KEY: PolicyFeature(type=FeatureType.STATE, shape=(STATE_DIM,)),
        }
    )
    output_features: dict[str, PolicyFeature] = field(
        default_factory=lambda: {"action": PolicyFeature(type=FeatureType.ACTION, shape=(ACTION_DIM,))}
    )

    def validate_features(self) -> None:
        if FRONT_IMAGE_KEY not in self.input_features or STATE_KEY not in self.input_features:
            raise ValueError(
                f"phantom_servo needs {FRONT_IMAGE_KEY!r} and {STATE_KEY!r} inputs, "
                f"got {sorted(self.input_features)}"
            )


# ------------------------------------------------------------------------------------------------- policy
@dataclass
class _EpisodeState:
    instruction: str | None = None
    plan: Plan | None = None
    goal_index: int = 0
    # approach (open, above, down, close) -> grasp (check) -> carry (up, across, down, open) -> retreat (up)
    phase: str = "approach"
    grasp_attempts: int = 0
    estimates: dict = field(default_factory=dict)  # entity key -> table xy (np.ndarray)
    side_choice: dict = field(
        default_factory=dict
    )  # ObjectRef -> xy of the chosen one of the identical objects


LOOK_POSE = np.array([-0.2, 0.0, 0.2])  # the env's start pose: the gripper is at the top edge of the image


def _move_towards(tcp: np.ndarray, waypoint: np.ndarray) -> np.ndarray:
    delta = (waypoint - tcp) / MAX_STEP_M
    largest = float(np.max(np.abs(delta)))
    return delta / largest if largest > 1.0 else delta


class PhantomServoPolicy(PreTrainedPolicy):
    """Colour-segmentation pick-and-place servo over the front camera; see the module docstring."""

    config_class = PhantomServoConfig
    name = POLICY_TYPE

    def __init__(self, config: PhantomServoConfig, **kwargs):
        # kwargs: make_policy passes dataset_stats / dataset_meta when built from a dataset; nothing to normalise.
        super().__init__(config)
        config.validate_features()
        self.config: PhantomServoConfig = config
        self._episodes: list[_EpisodeState] = []

    def get_optim_params(self):
        return []

    def reset(self):
        self._episodes = []

    def forward(self, batch):
        raise NotImplementedError("phantom_servo is a scripted reference policy: it has nothing to train")

    def predict_action_chunk(self, batch, **kwargs):
        return self.select_action(batch)[:, None]

    @torch.no_grad()
    def select_action(self, batch, **kwargs) -> torch.Tensor:
        images = batch[FRONT_IMAGE_KEY]
        states = batch[STATE_KEY].detach().to("cpu", torch.float64).numpy()
        tasks = batch.get("task")
        batch_size = states.shape[0]
        if tasks is None:
            tasks = [""] * batch_size
        elif isinstance(tasks, str):
            tasks = [tasks] * batch_size
        if len(tasks) != batch_size:
            raise ValueError(f"got {len(tasks)} task strings for a batch of {batch_size}")
        if len(self._episodes) != batch_size:
            self._episodes = [_EpisodeState() for _ in range(batch_size)]
        for i, task in enumerate(tasks):
            if self._episodes[i].instruction != task:  # a new episode, or the instruction changed mid-way
                self._episodes[i] = _EpisodeState(instruction=task, plan=parse_instruction(task))
        frames = images.detach().to("cpu")
        # LeRobot hands images over as float in [0, 1]; raw uint8 frames are accepted too.
        frames = frames.float() / 255.0 if frames.dtype == torch.uint8 else frames.float()
        frames = frames.permute(0, 2, 3, 1).numpy()
        actions = [self._act(self._episodes[i], frames[i], states[i]) for i in range(batch_size)]
        return torch.as_tensor(np.stack(actions), dtype=torch.float32, device=images.device)

    # ------------------------------------------------------------------------------------------ one env
    def _act(self, episode: _EpisodeState, image: np.ndarray, state: np.ndarray) -> np.ndarray:
        tcp, opening = state[:3], float(state[3])
        still = np.array([0.0, 0.0, 0.0, -1.0 if opening > OPEN_MIN_OPENING else 1.0], dtype=np.float32)
        if episode.plan is None or episode.plan.hold:
            return still  # not understood or told to stay: do not guess
        self._perceive(episode, image, tcp)
        return self._control(episode, tcp, opening, still)

    def _perceive(self, episode: _EpisodeState, image: np.ndarray, tcp: np.ndarray) -> None:
        height, width = image.shape[:2]
        camera = front_camera()
        occluded = gripper_mask(camera, tcp, height, width, self.config.mask_margin_px)
        occlusion_border = dilate(occluded) & ~occluded
        visible = workspace_mask(height, width) & ~occluded
        masks = colour_masks(image)
        wanted = dict.fromkeys(ref for goal in episode.plan.goals for ref in (goal.obj, goal.target))
        for entity in wanted:
            key = entity if isinstance(entity, str) else entity.colour
            # "the left cube": the identical objects of the spatial suite, whatever their colour
            mask = masks[key] if key is not None else np.logical_or.reduce([masks[c] for c in OBJECT_COLOURS])
            ys, xs = np.nonzero(mask & visible)
            if len(xs) < MIN_BLOB_PIXELS:
                continue
            points = np.stack([xs + 0.5, ys + 0.5], axis=1)
            if isinstance(entity, ObjectRef) and entity.side is not None:
                chosen = episode.side_choice.get(entity)
                if chosen is None:  # pick left or right once, while both are in view
                    if len(points) < 2 * MIN_BLOB_PIXELS:
                        continue
                    groups = sorted(two_clusters(points), key=lambda g: g[:, 0].mean())
                    blob = groups[SIDES.index(entity.side)]
                else:  # then follow that object: the pixels of its colour around where it was last seen
                    centre = camera.project(np.array([*chosen, OBJECT_PLANE_Z]), height, width)[0]
                    blob = points[np.linalg.norm(points - centre, axis=1) <= TRACK_RADIUS_PX * height]
            else:
                blob = points
            if len(blob) < MIN_BLOB_PIXELS:
                continue
            rows, cols = blob[:, 1].astype(int), blob[:, 0].astype(int)
            if occlusion_border[rows, cols].any():
                continue  # the hand may hide part of it: keep the last unobstructed estimate
            plane_z = {"plate": PLATE_PLANE_Z, "basket": BASKET_PLANE_Z}.get(key, OBJECT_PLANE_Z)
            xy = camera.pixel_to_plane(blob.mean(0), height, width, plane_z)[0]
            episode.estimates[entity] = xy
            if isinstance(entity, ObjectRef) and entity.side is not None:
                episode.side_choice[entity] = xy

    def _go_via_travel_height(self, tcp, goal_xy, goal_z) -> np.ndarray | None:
        tol, travel_z = self.config.reach_tolerance, self.config.travel_z
        if np.linalg.norm(tcp[:2] - goal_xy) > tol:
            if tcp[2] < travel_z - tol:
                return _move_towards(tcp, np.array([*tcp[:2], travel_z]))
            return _move_towards(tcp, np.array([*goal_xy, travel_z]))
        if abs(tcp[2] - goal_z) > tol:
            return _move_towards(tcp, np.array([*goal_xy, goal_z]))
        return None

    def _towards_look_pose(self, tcp: np.ndarray) -> np.ndarray:
        """Up first, then to the start pose, from where the gripper hides nothing on the table."""
        if tcp[2] < self.config.travel_z - self.config.reach_tolerance:
            return _move_towards(tcp, np.array([*tcp[:2], self.config.travel_z]))
        return _move_towards(tcp, LOOK_POSE)

    def _control(self, episode: _EpisodeState, tcp, opening, still) -> np.ndarray:
        goals = episode.plan.goals
        if episode.goal_index >= len(goals):
            return still
        goal = goals[episode.goal_index]
        holding = opening > GRASP_MIN_OPENING and opening < OPEN_MIN_OPENING

        def act(move, close):
            return np.array([*(np.zeros(3) if move is None else move), 1.0 if close else -1.0], np.float32)

        if episode.phase == "grasp":  # the previous step closed the gripper: did it catch the object?
            if holding:
                episode.phase = "carry"
            else:
                episode.grasp_attempts += 1
                episode.phase = "approach"
                episode.estimates.pop(goal.obj, None)  # look again
                if episode.grasp_attempts >= self.config.max_grasp_attempts:
                    episode.goal_index = len(goals)
                return act(None, close=False)
        if episode.phase == "approach":
            if opening < OPEN_MIN_OPENING:
                return act(None, close=False)
            obj_xy = episode.estimates.get(goal.obj)
            if obj_xy is None:  # not seen (yet): get the hand out of the camera's way and look again
                return act(self._towards_look_pose(tcp), close=False)
            move = self._go_via_travel_height(tcp, obj_xy, OBJECT_HALF_SIZE)
            if move is None:
                episode.phase = "grasp"
                return act(None, close=True)
            return act(move, close=False)
        if episode.phase == "carry":
            if not holding:  # dropped it
                episode.phase = "approach"
                episode.estimates.pop(goal.obj, None)
                return act(None, close=False)
            target_xy = episode.estimates.get(goal.target)
            if target_xy is None:
                return act(self._towards_look_pose(tcp), close=True)
            if goal.relation == "stack":
                support = 2 * OBJECT_HALF_SIZE
            else:
                support = BASKET_FLOOR_TOP if goal.relation == "in" else PLATE_TOP
            place_z = support + OBJECT_HALF_SIZE + self.config.release_clearance
            move = self._go_via_travel_height(tcp, target_xy, place_z)
            if move is None:
                episode.phase = "retreat"
                return act(None, close=False)
            return act(move, close=True)
        if episode.phase == "retreat":
            if tcp[2] < self.config.travel_z - self.config.reach_tolerance:
                return act(_move_towards(tcp, np.array([*tcp[:2], self.config.travel_z])), close=False)
            episode.goal_index += 1
            episode.phase = "approach"
            episode.grasp_attempts = 0
            episode.estimates.clear()  # the scene changed: look again
            return act(None, close=False)
        raise RuntimeError(f"unknown servo phase {episode.phase!r}")


# --------------------------------------------------------------------------------------- processors, save
def make_phantom_servo_pre_post_processors(config: PhantomServoConfig, dataset_stats=None):
    """Pass-through pipelines (the servo reads raw [0, 1] images and metric state); found by LeRobot's
    ``make_pre_post_processors`` for a config of this module when no checkpoint path is given."""
    from lerobot.processor import (
        DeviceProcessorStep,
        PolicyProcessorPipeline,
        RenameObservationsProcessorStep,
    )
    from lerobot.processor.converters import policy_action_to_transition, transition_to_policy_action
    from lerobot.utils.constants import POLICY_POSTPROCESSOR_DEFAULT_NAME, POLICY_PREPROCESSOR_DEFAULT_NAME

    device = config.device or "cpu"
    preprocessor = PolicyProcessorPipeline(
        steps=[RenameObservationsProcessorStep(rename_map={}), DeviceProcessorStep(device=device)],
        name=POLICY_PREPROCESSOR_DEFAULT_NAME,
    )
    postprocessor = PolicyProcessorPipeline(
        steps=[DeviceProcessorStep(device="cpu")],
        name=POLICY_POSTPROCESSOR_DEFAULT_NAME,
        to_transition=policy_action_to_transition,
        to_output=transition_to_policy_action,
    )
    return preprocessor, postprocessor


def save_servo_policy(directory: str | Path, image_size: int = 96) -> Path:
    """Write a ``phantom_servo`` checkpoint (config, empty weights, pass-through processors) loadable with
    ``--policy.path=<directory>``; returns the directory."""
    directory = Path(directory)
    config = PhantomServoConfig()
    config.input_features[FRONT_IMAGE_KEY] = PolicyFeature(
        type=FeatureType.VISUAL, shape=(3, image_size, image_size)
    )
    policy = PhantomServoPolicy(config)
    policy.save_pretrained(directory)
    preprocessor, postprocessor = make_phantom_servo_pre_post_processors(config)
    preprocessor.save_pretrained(directory)
    postprocessor.save_pretrained(directory)
    return directory
