"""The four task families of the paper on the Drake table: scene layouts and candidate actions.

The arm stands at the origin facing +x. A layout draws the landmark places and the object placements
from the seed. The family's *nominal* controller acts on one object chosen without regard to intent
(nearest to the container or the spill); when the scene has both relevant and irrelevant objects, the
layout puts an irrelevant object in that spot, so that a demonstration in the scene shows the human doing
something the nominal controller would not do.

Actions, each acting on one thing:

- pack_backpack / store_drawer: pick object ``i`` and put it into the open container
  (keyframes: pre-grasp, grasp, lift, transit, above the container, place);
- sweep_spill: push object ``i`` sideways (towards +y or -y) across the table
  (pre-contact, contact, mid-push, end of push, retreat);
- place_mug: carry the mug from its start to its goal (start, lift, three via points, above the goal,
  place): low (:data:`CARRY_HEIGHT`), passing each via point on the straight line or
  :data:`MUG_STEER` to either side of it (27 routes: straight, shifted to one side, bends and S-curves
  around single objects), or raised over the table (:data:`MUG_RAISED`).

Layouts: pack_backpack / store_drawer put the objects anywhere on the table beside the container, and,
given the arm's ``reach``, only where it can pick them (the lift above each one within reach, with a
margin); sweep_spill puts them in slots on either side of the spill; place_mug beside the mug's straight
path, on both sides of it and :data:`MUG_LATERAL` away from it. When a place_mug scene has both kinds, the
relevant objects lie on one side and the irrelevant ones on the other, so that steering around the
relevant objects (what the simulated human does, :class:`gift.tasks.PlaceMug`) takes the mug towards the
others rather than away from every object at once; otherwise the objects are split evenly between the sides.

Each family is a :class:`gift_sim_drake.families.MotionFamily`, registered as ``drake/<family>`` by
:mod:`gift_sim_drake.plugin`.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

from gift.core.data import ObjectSpec, Scene
from gift.core.errors import GiftError
from gift_sim_drake.families import ActionSet, MotionFamily, Reach
from gift_sim_drake.plant import CONTAINERS, MUG, footprint_radius, half_height
from gift_sim_drake.scenes import REACH_MARGIN, nearest_object, place_apart

#: Height (m) of the place point inside a container above the table.
PLACE_HEIGHT = {"backpack": 0.09, "drawer": 0.07}
MUG_CENTER_Z = MUG.size[1] / 2
#: place_mug: distance (m) of an object's centre from the mug's straight path, drawn uniformly in this range.
#: At least half the steer of the low carries (:data:`MUG_STEER`), so that a carry steered towards an object's
#: side passes closer to it than the straight path, not round its far side.
MUG_LATERAL = (0.08, 0.14)
#: The most the pick motion's perturbation raises the lift (m; :meth:`ContainerFamily.perturb`).
LIFT_JITTER = 0.05
PUSH_LENGTH = 0.24
CARRY_HEIGHT = 0.18
#: place_mug via points, as fractions of the way from the mug's start to its goal.
MUG_VIAS = (0.25, 0.5, 0.75)
#: place_mug low carries: at each via point the mug passes on the straight line or this far (m) to either side.
MUG_STEER = 0.15
#: place_mug raised carries: (lateral offset of the middle via point in m, towards +x; height of the via points in m).
MUG_RAISED = ((0.0, 0.38), (-0.1, 0.3), (0.15, 0.3))


def lift_height(center_z: float) -> float:
    """Height (m) to which picking an object whose centre is at ``center_z`` lifts the gripper: 0.25 m, or 0.15 m
    above a tall object's centre (:meth:`ContainerFamily.actions`)."""
    return max(center_z + 0.15, 0.25)


def mug_routes() -> tuple[tuple[tuple[float, ...], float], ...]:
    """place_mug routes: ``((lateral offset at each of MUG_VIAS in m, towards +x), height in m)``; the first is
    the straight low carry (the nominal one), then the other low carries, then the raised ones."""
    sides = (0.0, -MUG_STEER, MUG_STEER)
    low = [(offsets, CARRY_HEIGHT) for offsets in itertools.product(sides, repeat=len(MUG_VIAS))]
    raised = [(tuple(offset * np.sin(np.pi * f) for f in MUG_VIAS), height) for offset, height in MUG_RAISED]
    return tuple(low + raised)


def _route_label(offsets: tuple[float, ...], height: float) -> str:
    if height == CARRY_HEIGHT and not any(offsets):
        return "carry the mug straight to the goal"
    where = "low" if height == CARRY_HEIGHT else f"raised to {height:.2f} m"
    return f"carry the mug {where}, passing the via points at {'/'.join(f'{o:+.2f}' for o in offsets)} m sideways"


class _Tabletop(MotionFamily):
    """Shared layout steps: the rng, footprints, then the nominal object swapped for an irrelevant one."""

    def layout(self, objects: Sequence[ObjectSpec], relevant: Sequence[str], seed: int,
               reach: Reach | None = None) -> Scene:
        if not objects:
            raise GiftError(f"a {self.task} scene needs at least one object")
        rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(0x5CE,)))
        radii = np.array([footprint_radius(o.appearance) for o in objects])
        heights = np.array([half_height(o.appearance) for o in objects])
        rel = np.array([o.name in set(relevant) for o in objects])
        landmarks, xy = self._place(rng, radii, heights, rel, reach)
        positions = np.column_stack([xy, heights])
        # the nominal controller's object should be an irrelevant one when the scene has both kinds
        k = self.nominal_object(positions, landmarks)
        if k >= 0 and rel[k] and not rel.all():
            others = np.flatnonzero(~rel)
            j = others[np.argmin(np.hypot(*(positions[others, :2] - np.asarray(landmarks[self.landmark])[:2]).T))]
            positions[[k, j], :2] = positions[[j, k], :2]
        return Scene(task=self.task, objects=tuple(objects), relevant=frozenset(relevant), positions=positions,
                     landmarks=landmarks, seed=int(seed))

    def _place(self, rng: np.random.Generator, radii: np.ndarray, heights: np.ndarray, rel: np.ndarray,
               reach: Reach | None) -> tuple[dict, np.ndarray]:
        """``(landmarks, xy [n, 2])`` for objects of footprint ``radii``, centre ``heights`` and relevance ``rel``."""
        raise NotImplementedError

    def nominal_object(self, positions: np.ndarray, landmarks: dict) -> int:
        """Index of the object the intent-blind nominal controller acts on (-1: none)."""
        return nearest_object(positions, landmarks[self.landmark])


class ContainerFamily(_Tabletop):
    """Pick an object and put it into an open container (``backpack`` or ``drawer``) beside the objects."""

    def __init__(self, task: str, container: str) -> None:
        if container not in CONTAINERS:
            raise GiftError(f"unknown container {container!r}; containers: {sorted(CONTAINERS)}")
        self.task, self.landmark = task, container

    def _place(self, rng, radii, heights, rel, reach):
        side = rng.choice([-1.0, 1.0])
        c = (0.42 + rng.uniform(-0.03, 0.03), side * (0.42 + rng.uniform(-0.03, 0.03)), PLACE_HEIGHT[self.landmark])

        def sample(r):
            return np.array([r.uniform(0.28, 0.62), side * r.uniform(-0.45, 0.14)])

        fits = None
        if reach is not None:  # the lift above each object (+ its perturbation) within reach, less the margin
            limit = np.asarray(reach(np.array([lift_height(z) + LIFT_JITTER for z in heights])), dtype=float)

            def fits(i, p):
                return float(np.hypot(*p)) <= limit[i] - REACH_MARGIN

        return {self.landmark: c}, place_apart(rng, radii, sample, f"{self.task} table", fits=fits)

    def actions(self, scene: Scene) -> ActionSet:
        pos = np.asarray(scene.positions)
        mark = self.landmark
        c = np.asarray(scene.landmarks[mark], dtype=float)
        above = np.array([c[0], c[1], CONTAINERS[mark]["height"] + 0.08])
        targets = []
        for p in pos:
            lift = np.array([p[0], p[1], lift_height(p[2])])
            transit = np.array([(p[0] + c[0]) / 2, (p[1] + c[1]) / 2, max(lift[2], above[2]) + 0.03])
            grasp = np.array([p[0], p[1], max(p[2], 0.02)])  # thin objects: keep the fingers off the table
            targets.append([grasp + [0, 0, 0.12], grasp, lift, transit, above, c])
        return ActionSet(np.array(targets), (12, 20, 30, 40, 50, 60), np.arange(len(pos)), 1, None, False,
                         tuple(f"put {n} into the {mark}" for n in scene.object_names),
                         self.nominal_object(pos, dict(scene.landmarks)))

    def perturb(self, targets, acts, rng, scale):
        """Grasp point (+-1 cm), lift height (-3..+5 cm), place point (within 1.4 cm)."""
        n = len(targets)
        grasp = rng.uniform(-0.01, 0.01, size=(n, 1, 3)) * [1, 1, 0] * scale
        targets[:, :3] += grasp
        targets[:, 2:4, 2] += rng.uniform(-0.03, 0.05, size=(n, 1)) * scale
        r = 0.014 * np.sqrt(rng.uniform(size=n)) * scale
        phi = rng.uniform(0, 2 * np.pi, size=n)
        place = np.column_stack([r * np.cos(phi), r * np.sin(phi), np.zeros(n)])
        targets[:, 4:] += place[:, None]
        return targets


class SweepSpill(_Tabletop):
    """Push an object sideways across the table, towards or away from a spill in front of the arm."""

    task = "sweep_spill"
    landmark = "spill"

    def _place(self, rng, radii, heights, rel, reach):
        n = len(radii)
        s = np.array([0.42 + rng.uniform(-0.03, 0.03), rng.uniform(-0.04, 0.04)])
        landmarks = {"spill": (float(s[0]), float(s[1]), 0.0)}
        slots = np.array([(dx, sy * dy) for sy in (1.0, -1.0) for dx, dy in ((-0.12, 0.1), (0.0, 0.09),
                                                                              (0.12, 0.1))])
        if n > len(slots):
            raise GiftError(f"a sweep_spill scene holds at most {len(slots)} objects, got {n}")
        pick = rng.permutation(len(slots))[:n]
        return landmarks, s + slots[pick] + rng.uniform(-0.012, 0.012, size=(n, 2))

    def actions(self, scene: Scene) -> ActionSet:
        pos = np.asarray(scene.positions)
        s = np.asarray(scene.landmarks["spill"], dtype=float)
        targets, carried, labels = [], [], []
        for i, (p, o) in enumerate(zip(pos, scene.objects)):
            for side in (1.0, -1.0):
                d = np.array([0.0, side, 0.0])
                contact = p - d * (footprint_radius(o.appearance) + 0.02)
                contact[2] = min(max(half_height(o.appearance), 0.03), 0.06)
                end = contact + d * PUSH_LENGTH
                targets.append([contact + [0, 0, 0.12], contact, contact + d * PUSH_LENGTH / 2, end,
                                end + [0, 0, 0.12]])
                carried.append(i)
                labels.append(f"push {o.name} towards {'+y' if side > 0 else '-y'}")
        k = self.nominal_object(pos, dict(scene.landmarks))
        away = 0 if pos[k, 1] >= s[1] else 1
        return ActionSet(np.array(targets), (14, 22, 34, 46, 60), np.array(carried), 1, 3, True, tuple(labels),
                         2 * k + away)

    def perturb(self, targets, acts, rng, scale):
        """Contact point (+-1 cm along x) and push length (+-3 cm)."""
        n = len(targets)
        grip = rng.uniform(-0.01, 0.01, size=(n, 1, 3)) * scale * [1, 0, 0]
        d = targets[:, 3] - targets[:, 1]
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        extra = rng.uniform(-0.03, 0.03, size=(n, 1)) * scale
        targets += grip
        targets[:, 2] += d * extra / 2
        targets[:, 3:] += (d * extra)[:, None]
        return targets


class PlaceMug(_Tabletop):
    """Carry a mug from its start to its goal across the table; the objects lie along its straight path."""

    task = "place_mug"
    landmark = "mug"
    required_landmarks = ("mug", "mug_goal")
    carried_landmark = MUG

    def _place(self, rng, radii, heights, rel, reach):
        n = len(radii)
        sy = rng.choice([-1.0, 1.0])
        start = np.array([0.45 + rng.uniform(-0.03, 0.03), sy * (-0.30 + rng.uniform(-0.03, 0.03))])
        goal = np.array([0.45 + rng.uniform(-0.03, 0.03), sy * (0.30 + rng.uniform(-0.03, 0.03))])
        landmarks = {"mug": (float(start[0]), float(start[1]), MUG_CENTER_Z),
                     "mug_goal": (float(goal[0]), float(goal[1]), MUG_CENTER_Z)}
        along = rng.permutation(np.linspace(0.22, 0.78, n)) if n > 1 else np.array([0.5])
        normal = np.array([-(goal - start)[1], (goal - start)[0]]) / np.linalg.norm(goal - start)
        if rel.any() and not rel.all():
            sides = np.where(rel, 1.0, -1.0) * rng.choice([-1.0, 1.0])
        else:
            sides = rng.permutation(np.resize([1.0, -1.0], n))
        lateral = sides * rng.uniform(*MUG_LATERAL, size=n)
        return landmarks, start + along[:, None] * (goal - start) + lateral[:, None] * normal

    def nominal_object(self, positions, landmarks) -> int:
        return -1  # the mug is carried, no object is acted on

    def actions(self, scene: Scene) -> ActionSet:
        start = np.asarray(scene.landmarks["mug"], dtype=float)
        goal = np.asarray(scene.landmarks["mug_goal"], dtype=float)
        line = goal - start
        normal = np.array([-line[1], line[0], 0.0]) / np.linalg.norm(line[:2])
        normal *= np.sign(normal[0]) or 1.0  # positive offsets point away from the robot (+x)
        lift = np.array([start[0], start[1], CARRY_HEIGHT])
        above = np.array([goal[0], goal[1], CARRY_HEIGHT])
        routes = mug_routes()
        targets, labels = [], []
        for offsets, height in routes:
            vias = [start + f * line + offset * normal for f, offset in zip(MUG_VIAS, offsets)]
            vias = [np.array([v[0], v[1], height]) for v in vias]
            targets.append([start, lift, *vias, above, goal])
            labels.append(_route_label(offsets, height))
        return ActionSet(np.array(targets), (0, 8, 20, 30, 40, 52, 60), np.full(len(routes), -1), 0, None, False,
                         tuple(labels), 0)

    def perturb(self, targets, acts, rng, scale):
        """Mug start and goal (+-3 cm each, blended along the keyframes) and the via points (+-2 cm)."""
        n = len(targets)
        s = rng.uniform(-0.03, 0.03, size=(n, 3)) * [1, 1, 0] * scale
        g = rng.uniform(-0.03, 0.03, size=(n, 3)) * [1, 1, 0] * scale
        w = np.linspace(0, 1, targets.shape[1])[None, :, None]
        targets += (1 - w) * s[:, None] + w * g[:, None]
        targets[:, 2:5] += rng.uniform(-0.02, 0.02, size=(n, 1, 3)) * scale
        return targets


def pack_backpack() -> ContainerFamily:
    return ContainerFamily("pack_backpack", "backpack")


def store_drawer() -> ContainerFamily:
    return ContainerFamily("store_drawer", "drawer")


#: The families of this module by task name (what :mod:`gift_sim_drake.plugin` registers as ``drake/<name>``).
FAMILIES = {"pack_backpack": pack_backpack, "store_drawer": store_drawer, "sweep_spill": SweepSpill,
            "place_mug": PlaceMug}
