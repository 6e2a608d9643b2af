"""The four suites (mirroring LIBERO's spatial / object / goal / long axes), their tasks and seeded layouts.

A task is a dict with ``name``, ``language`` (the instruction given to the policy) and ``goals``: a tuple of
``(relation, object_ref, target_ref)`` that must all hold at once for success. Relations: ``in`` (inside the
basket), ``on`` (on the plate) and ``stack`` (on top of another object). An ``object_ref`` starting with ``@`` is a
role resolved per episode from the layout (``@left`` / ``@right``: the identical cube with the smaller / larger y,
i.e. the one on the left / right of the front camera image).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lerobot_phantom.envs.scene import CONTAINER_RADIUS, ObjectSpec

SUITE_NAMES = ("spatial", "object", "goal", "long")

# Where objects and containers may be placed (table coordinates, metres).
SPAWN_X = (-0.16, 0.16)
SPAWN_Y = (-0.24, 0.24)
MIN_CLEARANCE = 0.025
SPATIAL_MIN_DY = 0.1  # "left" and "right" must be unambiguous from the front camera
GOAL_JITTER = 0.015


@dataclass(frozen=True)
class SuiteSpec:
    name: str
    objects: tuple[ObjectSpec, ...]
    containers: tuple[str, ...]
    tasks: tuple[dict, ...]
    max_episode_steps: int
    fixed_layout: dict[str, tuple[float, float]] | None = None  # goal suite: one layout, jittered per seed


def _pick_place(name: str, language: str, obj: str, relation: str, target: str) -> dict:
    return {"name": name, "language": language, "goals": ((relation, obj, target),)}


_SPATIAL_TASKS = tuple(
    _pick_place(
        f"{side}_cube_{'in_basket' if rel == 'in' else 'on_plate'}",
        f"pick up the {side} cube and place it {'in the basket' if rel == 'in' else 'on the plate'}",
        f"@{side}",
        rel,
        "basket" if rel == "in" else "plate",
    )
    for rel in ("in", "on")
    for side in ("left", "right")
)

_OBJECT_NAMES = ("red_cube", "green_cube", "blue_cylinder", "yellow_cylinder")
_OBJECT_TASKS = tuple(
    _pick_place(
        f"{obj}_in_basket",
        f"pick up the {obj.replace('_', ' ')} and place it in the basket",
        obj,
        "in",
        "basket",
    )
    for obj in _OBJECT_NAMES
)

_GOAL_TASKS = (
    _pick_place("red_cube_in_basket", "put the red cube in the basket", "red_cube", "in", "basket"),
    _pick_place("red_cube_on_plate", "put the red cube on the plate", "red_cube", "on", "plate"),
    _pick_place("blue_cube_in_basket", "put the blue cube in the basket", "blue_cube", "in", "basket"),
    _pick_place("blue_cube_on_plate", "put the blue cube on the plate", "blue_cube", "on", "plate"),
    _pick_place("stack_red_on_blue", "stack the red cube on the blue cube", "red_cube", "stack", "blue_cube"),
    _pick_place("stack_blue_on_red", "stack the blue cube on the red cube", "blue_cube", "stack", "red_cube"),
)

_LONG_TASKS = (
    {
        "name": "red_in_basket_then_blue_on_plate",
        "language": "put the red cube in the basket and then put the blue cube on the plate",
        "goals": (("in", "red_cube", "basket"), ("on", "blue_cube", "plate")),
    },
    {
        "name": "green_in_basket_then_red_on_plate",
        "language": "put the green cube in the basket and then put the red cube on the plate",
        "goals": (("in", "green_cube", "basket"), ("on", "red_cube", "plate")),
    },
    {
        "name": "blue_in_basket_then_green_on_plate",
        "language": "put the blue cube in the basket and then put the green cube on the plate",
        "goals": (("in", "blue_cube", "basket"), ("on", "green_cube", "plate")),
    },
    {
        "name": "stack_red_on_green_then_blue_in_basket",
        "language": "stack the red cube on the green cube and then put the blue cube in the basket",
        "goals": (("stack", "red_cube", "green_cube"), ("in", "blue_cube", "basket")),
    },
)

SUITE_SPECS: dict[str, SuiteSpec] = {
    "spatial": SuiteSpec(
        name="spatial",
        objects=(ObjectSpec("cube_a", "box", "orange"), ObjectSpec("cube_b", "box", "orange")),
        containers=("basket", "plate"),
        tasks=_SPATIAL_TASKS,
        max_episode_steps=80,
    ),
    "object": SuiteSpec(
        name="object",
        objects=(
            ObjectSpec("red_cube", "box", "red"),
            ObjectSpec("green_cube", "box", "green"),
            ObjectSpec("blue_cylinder", "cylinder", "blue"),
            ObjectSpec("yellow_cylinder", "cylinder", "yellow"),
        ),
        containers=("basket",),
        tasks=_OBJECT_TASKS,
        max_episode_steps=80,
    ),
    "goal": SuiteSpec(
        name="goal",
        objects=(ObjectSpec("red_cube", "box", "red"), ObjectSpec("blue_cube", "box", "blue")),
        containers=("basket", "plate"),
        tasks=_GOAL_TASKS,
        max_episode_steps=80,
        fixed_layout={
            "red_cube": (0.07, -0.08),
            "blue_cube": (0.07, 0.08),
            "basket": (-0.09, 0.14),
            "plate": (-0.09, -0.14),
        },
    ),
    "long": SuiteSpec(
        name="long",
        objects=(
            ObjectSpec("red_cube", "box", "red"),
            ObjectSpec("green_cube", "box", "green"),
            ObjectSpec("blue_cube", "box", "blue"),
        ),
        containers=("basket", "plate"),
        tasks=_LONG_TASKS,
        max_episode_steps=160,
    ),
}

SUITES: dict[str, list[dict]] = {name: [dict(t) for t in spec.tasks] for name, spec in SUITE_SPECS.items()}


def get_suite(suite: str) -> SuiteSpec:
    if suite not in SUITE_SPECS:
        raise ValueError(f"unknown suite {suite!r}; valid suites: {', '.join(SUITE_NAMES)}")
    return SUITE_SPECS[suite]


def get_task(suite: str, task_id: int) -> dict:
    tasks = get_suite(suite).tasks
    if not 0 <= task_id < len(tasks):
        raise ValueError(f"task_id {task_id} out of range for suite {suite!r}: valid 0..{len(tasks) - 1}")
    return tasks[task_id]


def _footprint(spec: SuiteSpec, item: str) -> float:
    if item in CONTAINER_RADIUS:
        return CONTAINER_RADIUS[item]
    return next(o.radius for o in spec.objects if o.name == item)


def sample_layout(spec: SuiteSpec, rng: np.random.Generator, max_tries: int = 1000) -> dict[str, np.ndarray]:
    """Per-episode xy positions of every container and object, collision-free, drawn from ``rng``."""
    items = list(spec.containers) + [o.name for o in spec.objects]
    if spec.fixed_layout is not None:
        return {
            item: np.asarray(spec.fixed_layout[item]) + rng.uniform(-GOAL_JITTER, GOAL_JITTER, size=2)
            for item in items
        }
    for _ in range(max_tries):
        layout: dict[str, np.ndarray] = {}
        for item in items:
            radius = _footprint(spec, item)
            low = np.array([SPAWN_X[0], SPAWN_Y[0]]) + radius
            high = np.array([SPAWN_X[1], SPAWN_Y[1]]) - radius
            for _ in range(200):
                xy = rng.uniform(low, high)
                if all(
                    np.linalg.norm(xy - other) >= radius + _footprint(spec, name) + MIN_CLEARANCE
                    for name, other in layout.items()
                ):
                    layout[item] = xy
                    break
            else:
                break
        else:
            if spec.name == "spatial":
                (ya, yb) = (layout["cube_a"][1], layout["cube_b"][1])
                if abs(ya - yb) < SPATIAL_MIN_DY:
                    continue
            return layout
    raise RuntimeError(f"could not sample a layout for suite {spec.name!r} in {max_tries} tries")


def resolve_roles(spec: SuiteSpec, layout: dict[str, np.ndarray]) -> dict[str, str]:
    """Map ``@role`` references to body names for this layout (identity for plain names)."""
    roles = {o.name: o.name for o in spec.objects} | {c: c for c in spec.containers}
    if spec.name == "spatial":
        left, right = sorted(("cube_a", "cube_b"), key=lambda name: layout[name][1])
        roles |= {"@left": left, "@right": right}
    return roles
