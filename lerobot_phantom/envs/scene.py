"""MJCF for the phantom tabletop, generated in code (no downloaded assets).

World frame: the table top is the plane z=0; the robot reaches in from -x; the ``front`` camera stands at +x
looking back at the robot, so image-right is +y (a "left" object has the smaller y). The gripper is a mocap body
(the tool centre point, TCP, sits between the fingertips) carrying the ``wrist`` camera; its fingers are mocap
bodies too and never collide, so grasping is done by the env (see table_env.py), which makes it reliable.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

OBJECT_HALF_SIZE = 0.02  # every graspable object is 4 cm wide and 4 cm tall
BASKET_INNER_HALF = 0.041
BASKET_WALL_HALF_THICKNESS = 0.004
BASKET_WALL_HEIGHT = 0.03
BASKET_FLOOR_TOP = 0.006
PLATE_RADIUS = 0.05
PLATE_TOP = 0.006
FINGER_OPEN_HALF_GAP = 0.04
FINGER_CLOSED_HALF_GAP = 0.006
FINGER_HALF_THICKNESS = 0.004

COLOURS = {
    "red": (0.85, 0.15, 0.15, 1.0),
    "green": (0.2, 0.7, 0.25, 1.0),
    "blue": (0.2, 0.35, 0.9, 1.0),
    "yellow": (0.95, 0.8, 0.1, 1.0),
    "orange": (0.95, 0.5, 0.1, 1.0),
}


@dataclass(frozen=True)
class ObjectSpec:
    name: str
    shape: str  # "box" or "cylinder"
    colour: str

    @property
    def radius(self) -> float:
        """Footprint radius used to keep sampled layouts collision-free."""
        return OBJECT_HALF_SIZE * (1.42 if self.shape == "box" else 1.0)


CONTAINER_RADIUS = {"basket": BASKET_INNER_HALF + 2 * BASKET_WALL_HALF_THICKNESS, "plate": PLATE_RADIUS}


FRONT_CAMERA_POS = (0.3, 0.0, 0.6)
FRONT_CAMERA_TARGET = (-0.04, 0.0, 0.0)


def look_at_xyaxes(pos, target) -> str:
    """MJCF ``xyaxes`` for a camera at ``pos`` looking at ``target`` with image-right along +y."""
    forward = np.asarray(target, dtype=float) - np.asarray(pos, dtype=float)
    z_axis = -forward / np.linalg.norm(forward)
    x_axis = np.array([0.0, 1.0, 0.0])
    y_axis = np.cross(z_axis, x_axis)
    return " ".join(f"{v:.4f}" for v in (*x_axis, *(y_axis / np.linalg.norm(y_axis))))


def _rgba(colour: str) -> str:
    return " ".join(f"{c:g}" for c in COLOURS[colour])


def _object_xml(spec: ObjectSpec) -> str:
    h = OBJECT_HALF_SIZE
    if spec.shape == "box":
        geom = f'type="box" size="{h} {h} {h}"'
    elif spec.shape == "cylinder":
        geom = f'type="cylinder" size="{h} {h}"'
    else:
        raise ValueError(f"unknown object shape {spec.shape!r}; valid: 'box', 'cylinder'")
    return (
        f'<body name="{spec.name}" pos="0 0 {h}"><freejoint name="{spec.name}_joint"/>'
        f'<geom name="{spec.name}_geom" {geom} rgba="{_rgba(spec.colour)}" mass="0.05" friction="1 0.01 0.001"'
        ' condim="3"/></body>'
    )


def _basket_xml() -> str:
    inner, t, top = BASKET_INNER_HALF, BASKET_WALL_HALF_THICKNESS, BASKET_WALL_HEIGHT
    outer = inner + 2 * t
    wall_half_h = top / 2
    rgba = 'rgba="0.3 0.3 0.35 1"'
    walls = []
    for sx, sy, size in (
        (inner + t, 0.0, f"{t} {outer} {wall_half_h}"),
        (-(inner + t), 0.0, f"{t} {outer} {wall_half_h}"),
        (0.0, inner + t, f"{outer} {t} {wall_half_h}"),
        (0.0, -(inner + t), f"{outer} {t} {wall_half_h}"),
    ):
        walls.append(f'<geom type="box" pos="{sx:g} {sy:g} {wall_half_h:g}" size="{size}" {rgba}/>')
    floor = f'<geom type="box" pos="0 0 {BASKET_FLOOR_TOP / 2:g}" size="{outer} {outer} {BASKET_FLOOR_TOP / 2:g}" {rgba}/>'
    return f'<body name="basket" mocap="true" pos="0 0.3 0">{floor}{"".join(walls)}</body>'


def _plate_xml() -> str:
    return (
        '<body name="plate" mocap="true" pos="0 -0.3 0">'
        f'<geom type="cylinder" pos="0 0 {PLATE_TOP / 2:g}" size="{PLATE_RADIUS} {PLATE_TOP / 2:g}" '
        'rgba="0.95 0.95 0.92 1"/></body>'
    )


def _gripper_xml() -> str:
    # Fingers span from 1.5 cm below the TCP to the palm; the arm is a purely visual rod going up.
    finger_half_h = 0.034
    finger_z = -0.015 + finger_half_h
    finger = (
        f'<geom type="box" size="0.012 {FINGER_HALF_THICKNESS} {finger_half_h}" pos="0 0 {finger_z:g}" '
        'rgba="0.15 0.15 0.15 1" contype="0" conaffinity="0"/>'
    )
    return (
        '<body name="gripper" mocap="true" pos="-0.2 0 0.2">'
        '<geom type="box" size="0.018 0.052 0.008" pos="0 0 0.061" rgba="0.25 0.25 0.28 1" '
        'contype="0" conaffinity="0"/>'
        '<geom type="capsule" fromto="0 0 0.07 -0.05 0 0.45" size="0.014" rgba="0.6 0.6 0.65 1" '
        'contype="0" conaffinity="0"/>'
        # Wrist camera: just in front of the palm, looking down at the fingertips and the object between them.
        f'<camera name="wrist" pos="0.045 0 0.05" xyaxes="{look_at_xyaxes((0.045, 0, 0.05), (0, 0, -0.03))}" fovy="75"/>'
        "</body>"
        f'<body name="finger_left" mocap="true" pos="-0.2 {-FINGER_OPEN_HALF_GAP} 0.2">{finger}</body>'
        f'<body name="finger_right" mocap="true" pos="-0.2 {FINGER_OPEN_HALF_GAP} 0.2">{finger}</body>'
    )


def build_scene_xml(objects: tuple[ObjectSpec, ...], containers: tuple[str, ...], image_size: int) -> str:
    """MJCF string for a table with ``objects`` (free bodies) and ``containers`` (subset of basket, plate)."""
    unknown = set(containers) - set(CONTAINER_RADIUS)
    if unknown:
        raise ValueError(f"unknown containers {sorted(unknown)}; valid: {sorted(CONTAINER_RADIUS)}")
    container_xml = "".join({"basket": _basket_xml, "plate": _plate_xml}[name]() for name in containers)
    objects_xml = "".join(_object_xml(spec) for spec in objects)
    # No shadows and no multisampling: in software GL a shadow map costs ~100x the whole 96x96 frame.
    return f"""<mujoco model="phantom_table">
  <option timestep="0.005" integrator="implicitfast"/>
  <visual>
    <global offwidth="{image_size}" offheight="{image_size}"/>
    <quality shadowsize="0" offsamples="0"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.5 0.5 0.5" specular="0 0 0"/>
  </visual>
  <asset>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.75 0.8 0.85" rgb2="0.45 0.5 0.55" width="32" height="32"/>
  </asset>
  <worldbody>
    <light pos="0.3 0 1.2" dir="-0.25 0 -1" directional="true" castshadow="false" diffuse="0.5 0.5 0.5"/>
    <geom name="table" type="plane" size="0.45 0.45 0.15" rgba="0.62 0.48 0.34 1" friction="1 0.01 0.001"/>
    <geom name="floor" type="plane" pos="0 0 -0.75" size="3 3 1" rgba="0.35 0.35 0.38 1" contype="0" conaffinity="0"/>
    <camera name="front" pos="{" ".join(map(str, FRONT_CAMERA_POS))}" xyaxes="{look_at_xyaxes(FRONT_CAMERA_POS, FRONT_CAMERA_TARGET)}" fovy="45"/>
    {_gripper_xml()}
    {container_xml}
    {objects_xml}
  </worldbody>
</mujoco>
"""
