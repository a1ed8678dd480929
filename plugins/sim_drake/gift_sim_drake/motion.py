"""Trajectory generation: keyframes solved by Drake IK, joint-space interpolation, batched forward kinematics.

For a scene, every family has a finite set of candidate *actions*, each acting on one thing:

- pack_backpack / store_drawer: pick object ``i`` and put it into the open container
  (keyframes: pre-grasp, grasp, lift, transit, above the container, place);
- sweep_spill: push object ``i`` sideways (towards +y or -y) across the table
  (pre-contact, contact, mid-push, end of push, retreat);
- place_mug: carry the mug from its start to its goal (start, lift, three via points, above the goal,
  place): low (:data:`CARRY_HEIGHT`), passing each via point on the straight line or
  :data:`MUG_STEER` to either side of it (27 routes: straight, shifted to one side, bends and S-curves
  around single objects), or raised over the table (:data:`MUG_RAISED`).

Drake's ``InverseKinematics`` solves each action's nominal keyframes once per scene (cached). Each
generated trajectory then perturbs its keyframes (start posture, grasp and place points, lift height,
push length, mug start and goal) and re-solves them with a few batched damped-least-squares steps from
the Drake solutions (falling back to Drake when those do not converge). Keyframes are joined in joint
space with minimum-jerk blends over T = 61 steps (0..60); forward kinematics gives the end effector, and
the carried object (or the pushed one, in the table plane) keeps its offset to the gripper between
grasp and release.

Generators: ``default`` is the nominal, intent-blind controller (pack/store: the object nearest the
container; sweep: the object nearest the spill, pushed away from it; place_mug: the straight line);
``preferred`` takes, per trajectory, one of the actions whose nominal trajectory maximises the family's
ground-truth reward for ``scene.relevant`` (near-ties, within :data:`TIE_TOLERANCE`, are broken at
random so demonstrations cover every relevant object); ``random`` takes a uniformly random action.
"""

from __future__ import annotations

import itertools
import threading
from collections import OrderedDict

import attrs
import numpy as np

from gift.core.data import Scene, TrajectoryBatch
from gift.core.errors import GiftError
from gift_sim_drake.features import compute_features, resolve_task
from gift_sim_drake.plant import CONTAINERS, drake_ik, footprint_radius, half_height
from gift_sim_drake.robots import RobotSpec
from gift_sim_drake.scenes import FAMILIES, check_family, lift_height, nominal_target

N_STEPS = 61
GENERATORS = ("preferred", "default", "random")
TIE_TOLERANCE = 0.05
#: Damped-least-squares residual (m + axis error) above which a keyframe is re-solved by Drake.
REFINE_TOLERANCE = 1e-3

PUSH_LENGTH = 0.24
CARRY_HEIGHT = 0.18
#: place_mug via points, as fractions of the way from the mug's start to its goal.
MUG_VIAS = (0.25, 0.5, 0.75)
#: place_mug low carries: at each via point the mug passes on the straight line or this far (m) to either side.
MUG_STEER = 0.15
#: place_mug raised carries: (lateral offset of the middle via point in m, towards +x; height of the via points in m).
MUG_RAISED = ((0.0, 0.38), (-0.1, 0.3), (0.15, 0.3))


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


@attrs.frozen
class ActionSet:
    """The candidate actions of one scene.

    ``targets`` ``[A, K, 3]``: nominal end-effector keyframes (m); ``times`` ``[K]``: their step indices
    (a keyframe at 0 means the trajectory starts there, otherwise it starts at the rest posture);
    ``carried`` ``[A]``: object index acted on (-1: the mug); ``attach``/``detach``: keyframe indices of
    grasp/contact and release (None: held to the end); ``push``: the object follows in the table plane only;
    ``labels``: what each action does; ``nominal``: the default controller's action.
    """

    targets: np.ndarray = attrs.field(eq=False)
    times: tuple[int, ...]
    carried: np.ndarray = attrs.field(eq=False)
    attach: int
    detach: int | None
    push: bool
    labels: tuple[str, ...]
    nominal: int

    @property
    def start_from_rest(self) -> bool:
        return self.times[0] != 0


def check_scene(scene: Scene) -> str:
    """The family's landmark, after checking ``scene`` has what motion needs (else a clear error)."""
    mark = check_family(scene.task)
    need = {"mug": ("mug", "mug_goal")}.get(mark, (mark,))
    missing = [k for k in need if k not in scene.landmarks]
    if missing or np.asarray(scene.positions).shape != (len(scene.objects), 3) or not scene.objects:
        raise GiftError(f"this {scene.task} scene (seed {scene.seed}) lacks object positions or the landmarks "
                        f"{list(need)} (missing {missing}); build scenes with the simulator's make_scene")
    return mark


def build_actions(scene: Scene) -> ActionSet:
    """The candidate actions of ``scene`` (see the module docstring)."""
    mark = check_scene(scene)
    pos = np.asarray(scene.positions)
    names = scene.object_names
    if mark in CONTAINERS:
        c = np.asarray(scene.landmarks[mark], dtype=float)
        above = np.array([c[0], c[1], CONTAINERS[mark]["height"] + 0.08])
        targets = []
        for p in pos:
            lift = np.array([p[0], p[1], lift_height(p[2])])
            transit = np.array([(p[0] + c[0]) / 2, (p[1] + c[1]) / 2, max(lift[2], above[2]) + 0.03])
            grasp = np.array([p[0], p[1], max(p[2], 0.02)])  # thin objects: keep the fingers off the table
            targets.append([grasp + [0, 0, 0.12], grasp, lift, transit, above, c])
        return ActionSet(np.array(targets), (12, 20, 30, 40, 50, 60), np.arange(len(pos)), 1, None, False,
                         tuple(f"put {n} into the {mark}" for n in names),
                         nominal_target(scene.task, pos, dict(scene.landmarks)))
    if mark == "spill":
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
        k = nominal_target(scene.task, pos, dict(scene.landmarks))
        away = 0 if pos[k, 1] >= s[1] else 1
        return ActionSet(np.array(targets), (14, 22, 34, 46, 60), np.array(carried), 1, 3, True, tuple(labels),
                         2 * k + away)
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


def _blend(times: tuple[int, ...], start_from_rest: bool) -> tuple[np.ndarray, np.ndarray]:
    """Per step: the segment index into the keyframe list and the minimum-jerk phase in [0, 1]."""
    knots = ((0,) if start_from_rest else ()) + tuple(times)
    seg = np.zeros(N_STEPS, dtype=np.intp)
    phase = np.zeros(N_STEPS)
    for k in range(len(knots) - 1):
        a, b = knots[k], knots[k + 1]
        t = np.arange(a, b + 1)
        u = (t - a) / (b - a)
        seg[a:b + 1] = k
        phase[a:b + 1] = u ** 3 * (10 - 15 * u + 6 * u ** 2)
    seg[-1], phase[-1] = len(knots) - 2, 1.0
    return seg, phase


class MotionPlanner:
    """Generates trajectory batches for one arm. Thread-safe; caches per-scene IK anchors."""

    def __init__(self, robot: RobotSpec, cache_size: int = 64) -> None:
        self.robot = robot
        self.kin = robot.kinematics
        self.rest = np.asarray(robot.rest, dtype=float)
        self._cache: OrderedDict[tuple, tuple[ActionSet, np.ndarray, np.ndarray]] = OrderedDict()
        self._cache_size = cache_size
        self._lock = threading.Lock()

    # ---------------------------------------------------------------- per scene (cached)
    @staticmethod
    def _scene_key(scene: Scene) -> tuple:
        return (scene.task, np.asarray(scene.positions).tobytes(), tuple(sorted(scene.landmarks.items())),
                tuple(o.appearance for o in scene.objects))

    def prepare(self, scene: Scene) -> tuple[ActionSet, np.ndarray, np.ndarray]:
        """``(actions, anchors [A, K, 7], feasible [A])``: Drake IK at each action's nominal keyframes."""
        key = self._scene_key(scene)
        with self._lock:
            if key in self._cache:
                self._cache.move_to_end(key)
                return self._cache[key]
        acts = build_actions(scene)
        ik = drake_ik(self.robot)
        n_act, n_key = acts.targets.shape[:2]
        anchors = np.full((n_act, n_key, self.kin.dof), np.nan)
        feasible = np.ones(n_act, dtype=bool)
        for a in range(n_act):
            guess = self.rest
            try:
                for k in range(n_key):
                    guess = anchors[a, k] = ik.solve(acts.targets[a, k], guess)
            except GiftError:
                feasible[a] = False
        if not feasible[acts.nominal]:
            raise GiftError(f"{self.robot.name}: the nominal action of this {scene.task} scene "
                            f"({acts.labels[acts.nominal]}) is out of reach; scene seed {scene.seed}")
        out = (acts, anchors, feasible)
        with self._lock:
            self._cache[key] = out
            while len(self._cache) > self._cache_size:
                self._cache.popitem(last=False)
        return out

    def nominal_rewards(self, scene: Scene) -> np.ndarray:
        """Ground-truth reward ``[A]`` of each action's unperturbed trajectory (-inf when out of reach)."""
        acts, anchors, feasible = self.prepare(scene)
        idx = np.flatnonzero(feasible)
        batch = self._assemble(scene, acts, idx, acts.targets[idx], anchors[idx],
                               np.broadcast_to(self.rest, (len(idx), self.kin.dof)))
        task = resolve_task(scene.task)
        rewards = np.full(len(feasible), -np.inf)
        rewards[idx] = task.ground_truth_reward(compute_features(batch, task), sorted(scene.relevant))
        return rewards

    # ---------------------------------------------------------------- generation
    def choose(self, scene: Scene, generator: str, n: int, rng: np.random.Generator) -> np.ndarray:
        """Action index per trajectory ``[n]``."""
        acts, _, feasible = self.prepare(scene)
        if generator == "default":
            return np.full(n, acts.nominal)
        if generator == "random":
            return rng.choice(np.flatnonzero(feasible), size=n)
        rewards = self.nominal_rewards(scene)
        best = np.flatnonzero(rewards >= rewards.max() - TIE_TOLERANCE)
        return rng.choice(best, size=n)

    def perturb(self, acts: ActionSet, chosen: np.ndarray, rng: np.random.Generator,
                scale: float) -> tuple[np.ndarray, np.ndarray]:
        """Per-trajectory keyframe targets ``[n, K, 3]`` and start postures ``[n, 7]``."""
        n = len(chosen)
        targets = acts.targets[chosen].copy()
        start = np.clip(self.rest + rng.normal(0.0, 0.06 * scale, size=(n, self.kin.dof)),
                        self.kin.lower, self.kin.upper)
        if acts.push:  # contact point and push length
            grip = rng.uniform(-0.01, 0.01, size=(n, 1, 3)) * scale * [1, 0, 0]
            d = targets[:, 3] - targets[:, 1]
            d /= np.linalg.norm(d, axis=-1, keepdims=True)
            extra = rng.uniform(-0.03, 0.03, size=(n, 1)) * scale
            targets += grip
            targets[:, 2] += d * extra / 2
            targets[:, 3:] += (d * extra)[:, None]
        elif acts.start_from_rest:  # pick and place: grasp point, lift height, place point
            grasp = rng.uniform(-0.01, 0.01, size=(n, 1, 3)) * [1, 1, 0] * scale
            targets[:, :3] += grasp
            targets[:, 2:4, 2] += rng.uniform(-0.03, 0.05, size=(n, 1)) * scale
            r = 0.014 * np.sqrt(rng.uniform(size=n)) * scale
            phi = rng.uniform(0, 2 * np.pi, size=n)
            place = np.column_stack([r * np.cos(phi), r * np.sin(phi), np.zeros(n)])
            targets[:, 4:] += place[:, None]
        else:  # mug: start, goal and the via points
            s = rng.uniform(-0.03, 0.03, size=(n, 3)) * [1, 1, 0] * scale
            g = rng.uniform(-0.03, 0.03, size=(n, 3)) * [1, 1, 0] * scale
            w = np.linspace(0, 1, targets.shape[1])[None, :, None]
            targets += (1 - w) * s[:, None] + w * g[:, None]
            targets[:, 2:5] += rng.uniform(-0.02, 0.02, size=(n, 1, 3)) * scale
        return targets, start

    def generate(self, scene: Scene, generator: str, n: int, seed: int) -> TrajectoryBatch:
        """``n`` trajectories of ``generator`` in ``scene``; the same arguments give identical arrays."""
        if generator not in GENERATORS:
            raise GiftError(f"unknown trajectory generator {generator!r}; use one of {GENERATORS}")
        if not isinstance(n, (int, np.integer)) or n < 1:
            raise GiftError(f"generate: n must be a positive integer, got {n!r}")
        acts, anchors, _ = self.prepare(scene)
        rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(GENERATORS.index(generator),)))
        chosen = self.choose(scene, generator, int(n), rng)
        targets, start = self.perturb(acts, chosen, rng, scale=1.0)
        q_keys = self._solve_keyframes(targets, anchors[chosen])
        batch = self._assemble(scene, acts, chosen, targets, q_keys, start)
        meta = {**batch.meta, "generator": generator, "seed": int(seed), "n": int(n)}
        return attrs.evolve(batch, meta=meta)

    def _solve_keyframes(self, targets: np.ndarray, seeds: np.ndarray) -> np.ndarray:
        """Joint keyframes ``[n, K, 7]`` reaching ``targets`` ``[n, K, 3]``, starting from ``seeds``."""
        shape = seeds.shape
        q, err = self.kin.solve_pointing_down(seeds.reshape(-1, shape[-1]), targets.reshape(-1, 3))
        bad = np.flatnonzero(err > REFINE_TOLERANCE)
        if bad.size:
            ik = drake_ik(self.robot)
            flat_seeds = seeds.reshape(-1, shape[-1])
            flat_targets = targets.reshape(-1, 3)
            for i in bad:
                try:
                    q[i] = ik.solve(flat_targets[i], flat_seeds[i])
                except GiftError:  # the perturbed point is out of reach: keep the nominal keyframe
                    q[i] = flat_seeds[i]
        return q.reshape(shape)

    def _assemble(self, scene: Scene, acts: ActionSet, chosen: np.ndarray, targets: np.ndarray,
                  q_keys: np.ndarray, start: np.ndarray) -> TrajectoryBatch:
        n = len(chosen)
        mark = FAMILIES[scene.task]
        keys = np.concatenate([start[:, None], q_keys], axis=1) if acts.start_from_rest else q_keys
        seg, phase = _blend(acts.times, acts.start_from_rest)
        q = keys[:, seg] + phase[None, :, None] * (keys[:, seg + 1] - keys[:, seg])  # [n, T, 7]
        ee, _ = self.kin.fk(q)
        t_on = acts.times[acts.attach]
        t_off = acts.times[acts.detach] if acts.detach is not None else N_STEPS - 1
        follow = np.zeros(N_STEPS, dtype=bool)
        follow[t_on:t_off + 1] = True
        hold = np.arange(N_STEPS) > t_off
        n_obj = len(scene.objects)
        objects = np.broadcast_to(np.asarray(scene.positions, dtype=float), (n, N_STEPS, n_obj, 3)).copy()
        carried = acts.carried[chosen]
        if mark == "mug":
            offset = targets[:, 0] - ee[:, t_on]  # the mug's centre where the gripper holds it
            landmarks = (ee + offset[:, None])[:, :, None, :]
        else:
            rows = np.arange(n)
            initial = objects[rows, 0, carried]  # [n, 3]
            offset = initial - ee[:, t_on]
            moved = ee + offset[:, None]  # [n, T, 3]
            if acts.push:
                moved[..., 2] = initial[:, None, 2]
            moved = np.where(follow[None, :, None], moved, initial[:, None])
            moved = np.where(hold[None, :, None], moved[:, t_off][:, None], moved)
            objects[rows, :, carried] = moved
            landmarks = np.broadcast_to(np.asarray(scene.landmarks[mark], dtype=float), (n, N_STEPS, 1, 3))
        meta = {"robot": self.robot.name, "task": scene.task, "scene_seed": scene.seed,
                "objects": list(scene.object_names), "relevant": sorted(scene.relevant),
                "actions": chosen.tolist(), "acted_on": [scene.object_names[c] if c >= 0 else "mug" for c in carried],
                "action_labels": [acts.labels[a] for a in chosen]}
        return TrajectoryBatch(q, ee, objects, scene.object_names, landmark_positions=landmarks,
                               landmark_names=(mark,), meta=meta)
