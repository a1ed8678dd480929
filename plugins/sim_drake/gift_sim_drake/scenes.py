"""Randomised tabletop layouts of the four task families (positions in metres, table top at z = 0).

The arm stands at the origin facing +x. A layout draws the landmark places and the object placements
from the seed. The family's *nominal* controller (see :mod:`gift_sim_drake.motion`) acts on one object
chosen without regard to intent (nearest to the container or the spill); when the scene has both
relevant and irrelevant objects, the layout puts an irrelevant object in that spot, so that a
demonstration in the scene shows the human doing something the nominal controller would not do.

- pack_backpack / store_drawer: objects anywhere on the table beside the container, and, given the arm's
  ``reach``, only where it can pick them (the lift above each one within reach, with a margin).
- sweep_spill: objects in slots on either side of the spill.
- place_mug: objects beside the mug's straight path from its start to its goal, on both sides of it and
  :data:`MUG_LATERAL` away from it. When the scene has both kinds, the relevant objects lie on one side
  and the irrelevant ones on the other, so that steering around the relevant objects (what the simulated
  human does, :class:`gift.tasks.PlaceMug`) takes the mug towards the others rather than away from every
  object at once; otherwise the objects are split evenly between the sides.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from gift.core.data import ObjectSpec, Scene
from gift.core.errors import GiftError, PlacementError
from gift_sim_drake.plant import CONTAINERS, MUG, footprint_radius, half_height

#: Families this simulator can generate motion for, and the landmark each uses.
FAMILIES = {"pack_backpack": "backpack", "store_drawer": "drawer", "sweep_spill": "spill", "place_mug": "mug"}
#: Height (m) of the place point inside a container above the table.
PLACE_HEIGHT = {"backpack": 0.09, "drawer": 0.07}
MUG_CENTER_Z = MUG.size[1] / 2
#: place_mug: distance (m) of an object's centre from the mug's straight path, drawn uniformly in this range.
#: At least half the steer of the low carries (:data:`gift_sim_drake.motion.MUG_STEER`), so that a carry
#: steered towards an object's side passes closer to it than the straight path, not round its far side.
MUG_LATERAL = (0.08, 0.14)
#: The most the pick motion's perturbation raises the lift (m; :meth:`gift_sim_drake.motion.MotionPlanner.perturb`).
LIFT_JITTER = 0.05
#: Margin (m) kept inside the arm's reach: the grasp perturbation (1 cm) and the gap between the local-IK reach
#: (:meth:`gift_sim_drake.kinematics.ArmKinematics.reach_pointing_down`) and Drake's IK (up to 2 cm).
REACH_MARGIN = 0.03


def check_family(task: str) -> str:
    """The landmark of ``task``, or a clear error for a family this simulator has no motions for."""
    if task not in FAMILIES:
        raise GiftError(f"the Drake simulator has no motion generator for task family {task!r}; it supports "
                        f"{sorted(FAMILIES)}")
    return FAMILIES[task]


def lift_height(center_z: float) -> float:
    """Height (m) to which picking an object whose centre is at ``center_z`` lifts the gripper: 0.25 m, or 0.15 m
    above a tall object's centre (:func:`gift_sim_drake.motion.build_actions`)."""
    return max(center_z + 0.15, 0.25)


def _place(rng: np.random.Generator, radii: np.ndarray, sample, what: str, restarts: int = 200,
           tries: int = 60, fits=None) -> np.ndarray:
    """Rejection-sample non-overlapping xy positions ``[n, 2]`` (largest objects first, restarting the whole
    layout when one does not fit); ``sample(rng)`` proposes one point, ``fits(i, p)`` (if given) says whether
    object ``i`` may stand at ``p``."""
    order = np.argsort(-radii, kind="stable")
    for _ in range(restarts):
        out: dict[int, np.ndarray] = {}
        for i in order:
            for _ in range(tries):
                p = sample(rng)
                if fits is not None and not fits(int(i), p):
                    continue
                if all(np.hypot(*(p - q)) >= radii[i] + radii[j] + 0.015 for j, q in out.items()):
                    out[int(i)] = p
                    break
            else:
                break
        if len(out) == len(radii):
            return np.array([out[i] for i in range(len(radii))]).reshape(len(radii), 2)
    where = f"the {what} region" + (" within the arm's reach" if fits is not None else "")
    raise PlacementError(f"cannot place {len(radii)} objects of these sizes (footprint radii "
                         f"{np.round(radii, 3).tolist()} m) in {where} without overlap; use fewer or smaller objects")


def nominal_target(task: str, positions: np.ndarray, landmarks: dict) -> int:
    """Index of the object the intent-blind nominal controller acts on (-1 for place_mug: none)."""
    mark = FAMILIES[task]
    if task == "place_mug" or len(positions) == 0:
        return -1
    d = np.hypot(*(positions[:, :2] - np.asarray(landmarks[mark])[:2]).T)
    return int(np.argmin(d))


def layout(task: str, objects: Sequence[ObjectSpec], relevant: Sequence[str], seed: int,
           reach: Callable[[np.ndarray], np.ndarray] | None = None) -> Scene:
    """A randomised scene of ``task`` holding ``objects`` (see the module docstring).

    ``reach``: the arm's reach, heights ``[H]`` (m) -> largest distance ``[H]`` (m) from the base's vertical
    axis at which the gripper gets there pointing down (:meth:`DrakeSimulator.reach`); objects to be picked
    are then placed only where their lift is within reach, less :data:`REACH_MARGIN`. None: no reach check.
    """
    mark = check_family(task)
    if not objects:
        raise GiftError(f"a {task} scene needs at least one object")
    rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(0x5CE,)))
    n = len(objects)
    radii = np.array([footprint_radius(o.appearance) for o in objects])
    heights = np.array([half_height(o.appearance) for o in objects])
    landmarks: dict[str, tuple[float, float, float]] = {}
    if mark in CONTAINERS:
        side = rng.choice([-1.0, 1.0])
        c = (0.42 + rng.uniform(-0.03, 0.03), side * (0.42 + rng.uniform(-0.03, 0.03)), PLACE_HEIGHT[mark])
        landmarks[mark] = c

        def sample(r):
            return np.array([r.uniform(0.28, 0.62), side * r.uniform(-0.45, 0.14)])

        fits = None
        if reach is not None:
            limit = np.asarray(reach(np.array([lift_height(z) + LIFT_JITTER for z in heights])), dtype=float)

            def fits(i, p):
                return float(np.hypot(*p)) <= limit[i] - REACH_MARGIN

        xy = _place(rng, radii, sample, f"{task} table", fits=fits)
    elif mark == "spill":
        s = np.array([0.42 + rng.uniform(-0.03, 0.03), rng.uniform(-0.04, 0.04)])
        landmarks["spill"] = (float(s[0]), float(s[1]), 0.0)
        slots = np.array([(dx, sy * dy) for sy in (1.0, -1.0) for dx, dy in ((-0.12, 0.1), (0.0, 0.09),
                                                                              (0.12, 0.1))])
        if n > len(slots):
            raise GiftError(f"a sweep_spill scene holds at most {len(slots)} objects, got {n}")
        pick = rng.permutation(len(slots))[:n]
        xy = s + slots[pick] + rng.uniform(-0.012, 0.012, size=(n, 2))
    else:  # place_mug: objects beside the mug's straight path, on both sides of it
        sy = rng.choice([-1.0, 1.0])
        start = np.array([0.45 + rng.uniform(-0.03, 0.03), sy * (-0.30 + rng.uniform(-0.03, 0.03))])
        goal = np.array([0.45 + rng.uniform(-0.03, 0.03), sy * (0.30 + rng.uniform(-0.03, 0.03))])
        landmarks["mug"] = (float(start[0]), float(start[1]), MUG_CENTER_Z)
        landmarks["mug_goal"] = (float(goal[0]), float(goal[1]), MUG_CENTER_Z)
        along = rng.permutation(np.linspace(0.22, 0.78, n)) if n > 1 else np.array([0.5])
        normal = np.array([-(goal - start)[1], (goal - start)[0]]) / np.linalg.norm(goal - start)
        rel = np.array([o.name in set(relevant) for o in objects])
        if rel.any() and not rel.all():
            sides = np.where(rel, 1.0, -1.0) * rng.choice([-1.0, 1.0])
        else:
            sides = rng.permutation(np.resize([1.0, -1.0], n))
        lateral = sides * rng.uniform(*MUG_LATERAL, size=n)
        xy = start + along[:, None] * (goal - start) + lateral[:, None] * normal
    positions = np.column_stack([xy, heights])
    # the nominal controller's object should be an irrelevant one when the scene has both kinds
    rel = np.array([o.name in set(relevant) for o in objects])
    k = nominal_target(task, positions, landmarks)
    if k >= 0 and rel[k] and not rel.all():
        others = np.flatnonzero(~rel)
        j = others[np.argmin(np.hypot(*(positions[others, :2] - np.asarray(landmarks[mark])[:2]).T))]
        positions[[k, j], :2] = positions[[j, k], :2]
    return Scene(task=task, objects=tuple(objects), relevant=frozenset(relevant), positions=positions,
                 landmarks=landmarks, seed=int(seed))
