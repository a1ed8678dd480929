"""Trajectory generation for any arm: keyframes solved by Drake IK, joint-space interpolation, batched
forward kinematics.

For a scene, the task family's :class:`~gift_sim_drake.families.MotionFamily` gives a finite set of candidate
*actions* (an :class:`~gift_sim_drake.families.ActionSet`), each acting on one thing: tool-centre-point
keyframes with the gripper pointing down, and the object (or the family's landmark, e.g. the mug) it moves.
The paper's four families are in :mod:`gift_sim_drake.tabletop`.

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

import threading
from collections import OrderedDict

import attrs
import numpy as np

from gift.core.data import Scene, TrajectoryBatch
from gift.core.errors import GiftError
from gift_sim_drake.families import N_STEPS, ActionSet, check_scene, motion_family
from gift_sim_drake.features import compute_features, resolve_task
from gift_sim_drake.plant import drake_ik
from gift_sim_drake.robots import RobotSpec, arm_kinematics

GENERATORS = ("preferred", "default", "random")
TIE_TOLERANCE = 0.05
#: Damped-least-squares residual (m + axis error) above which a keyframe is re-solved by Drake.
REFINE_TOLERANCE = 1e-3


def build_actions(scene: Scene) -> ActionSet:
    """The candidate actions of ``scene`` (its motion family's, after checking the scene)."""
    return check_scene(scene).actions(scene)


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
        self.kin = arm_kinematics(robot)
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
        """``(actions, anchors [A, K, dof], feasible [A])``: Drake IK at each action's nominal keyframes."""
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

    def perturb(self, scene: Scene, acts: ActionSet, chosen: np.ndarray, rng: np.random.Generator,
                scale: float) -> tuple[np.ndarray, np.ndarray]:
        """Per-trajectory keyframe targets ``[n, K, 3]`` (the motion family's
        :meth:`~gift_sim_drake.families.MotionFamily.perturb`) and start postures ``[n, dof]`` (the rest
        posture plus Gaussian noise of 0.06 rad per joint, clipped to the limits)."""
        n = len(chosen)
        start = np.clip(self.rest + rng.normal(0.0, 0.06 * scale, size=(n, self.kin.dof)),
                        self.kin.lower, self.kin.upper)
        targets = motion_family(scene.task).perturb(acts.targets[chosen].copy(), acts, rng, scale)
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
        targets, start = self.perturb(scene, acts, chosen, rng, scale=1.0)
        q_keys = self._solve_keyframes(targets, anchors[chosen])
        batch = self._assemble(scene, acts, chosen, targets, q_keys, start)
        meta = {**batch.meta, "generator": generator, "seed": int(seed), "n": int(n)}
        return attrs.evolve(batch, meta=meta)

    def _solve_keyframes(self, targets: np.ndarray, seeds: np.ndarray) -> np.ndarray:
        """Joint keyframes ``[n, K, dof]`` reaching ``targets`` ``[n, K, 3]``, starting from ``seeds``."""
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
        mark = motion_family(scene.task).landmark
        keys = np.concatenate([start[:, None], q_keys], axis=1) if acts.start_from_rest else q_keys
        seg, phase = _blend(acts.times, acts.start_from_rest)
        q = keys[:, seg] + phase[None, :, None] * (keys[:, seg + 1] - keys[:, seg])  # [n, T, dof]
        ee, _ = self.kin.fk(q)
        t_on = acts.times[acts.attach]
        t_off = acts.times[acts.detach] if acts.detach is not None else N_STEPS - 1
        follow = np.zeros(N_STEPS, dtype=bool)
        follow[t_on:t_off + 1] = True
        hold = np.arange(N_STEPS) > t_off

        def carry(rows: np.ndarray, initial: np.ndarray) -> np.ndarray:
            """Path ``[len(rows), T, 3]`` of a thing at ``initial`` that keeps its offset to the gripper from
            grasp (or contact) to release, and stays where it was released."""
            offset = initial - ee[rows, t_on]
            moved = ee[rows] + offset[:, None]
            if acts.push:
                moved[..., 2] = initial[:, None, 2]
            moved = np.where(follow[None, :, None], moved, initial[:, None])
            return np.where(hold[None, :, None], moved[:, t_off][:, None], moved)

        n_obj = len(scene.objects)
        objects = np.broadcast_to(np.asarray(scene.positions, dtype=float), (n, N_STEPS, n_obj, 3)).copy()
        landmarks = np.broadcast_to(np.asarray(scene.landmarks[mark], dtype=float), (n, N_STEPS, 1, 3)).copy()
        carried = acts.carried[chosen]
        rows = np.flatnonzero(carried >= 0)
        if rows.size:
            objects[rows, :, carried[rows]] = carry(rows, objects[rows, 0, carried[rows]])
        rows = np.flatnonzero(carried < 0)
        if rows.size:  # the landmark itself (the mug), grasped where the gripper reaches it
            landmarks[rows, :, 0] = carry(rows, targets[rows, acts.attach])
        meta = {"robot": self.robot.name, "task": scene.task, "scene_seed": scene.seed,
                "objects": list(scene.object_names), "relevant": sorted(scene.relevant),
                "actions": chosen.tolist(), "acted_on": [scene.object_names[c] if c >= 0 else mark for c in carried],
                "action_labels": [acts.labels[a] for a in chosen]}
        return TrajectoryBatch(q, ee, objects, scene.object_names, landmark_positions=landmarks,
                               landmark_names=(mark,), meta=meta)
