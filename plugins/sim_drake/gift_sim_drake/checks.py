"""Acceptance check of a robot on the Drake simulator: what a robot plugin's tests call.

:func:`check_robot_on_drake` builds the arm's plant, compares the numpy kinematics with Drake's, then
stages every task family with a Drake motion family in a few scenes and generates trajectories with
each generator. It raises one :class:`~gift.core.errors.GiftError` listing every problem, or returns a
report (numbers per family) when the arm works.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from gift.core.data import Appearance, ObjectSpec
from gift.core.errors import GiftError
from gift.core.robots import RobotSpec

#: Four objects of different shapes and sizes (the catalog of the simulator's own tests).
CHECK_OBJECTS = (
    ObjectSpec("paintbrush", "a brush for painting", Appearance("cylinder", (0.015, 0.18), (0.8, 0.55, 0.2))),
    ObjectSpec("banana", "a ripe banana", Appearance("box", (0.18, 0.04, 0.04), (0.95, 0.85, 0.2))),
    ObjectSpec("sketchbook", "a book of drawing paper", Appearance("box", (0.2, 0.15, 0.02), (0.9, 0.9, 0.85))),
    ObjectSpec("coffee mug", "a ceramic mug", Appearance("cylinder", (0.04, 0.1), (0.2, 0.2, 0.25))),
)
CHECK_RELEVANT = ("paintbrush", "sketchbook")


def check_robot_on_drake(robot: str | RobotSpec, *, families: Sequence[str] | None = None,
                         seeds: Sequence[int] = (0, 1, 2), n: int = 8,
                         objects: Sequence[ObjectSpec] = CHECK_OBJECTS,
                         relevant: Sequence[str] = CHECK_RELEVANT) -> dict:
    """Check ``robot`` (a registered name or a spec) on the real Drake plant.

    - the URDF chain, ``rest`` and the joint limits (:func:`gift_sim_drake.robots.check_robot`), Drake parses
      the URDF with exactly the chain's joints, numpy forward kinematics equals Drake's to 1e-6 m;
    - for every family (default: all with a Drake motion family) and scene seed: every nominal keyframe is
      reached by Drake IK with the gripper pointing down (unreachable actions are reported; an unreachable
      nominal action fails), ``n`` trajectories per generator stay in the joint limits and above the table,
      features are finite in [0, 1], and ``preferred`` trajectories beat ``default`` ones on the family's
      ground-truth reward.

    Returns ``{"robot", "dof", "fk_error_m", "families": {family: {"actions", "unreachable_actions",
    "preferred_reward", "default_reward", "seconds"}}}``.
    """
    import gift
    from gift_sim_drake.plant import SceneModel, drake_ik
    from gift_sim_drake.robots import arm_kinematics
    from gift_sim_drake.simulator import DrakeSimulator

    sim = DrakeSimulator(robot)  # numpy-level checks: URDF chain, rest, limits
    spec = sim.robot
    kin = arm_kinematics(spec)
    drake_ik(spec)  # Drake parses it with exactly the chain's joints
    problems: list[str] = []
    model = SceneModel(spec, "pack_backpack", (), {})
    lo, hi = model.joint_limits()
    if not (np.allclose(lo, kin.lower) and np.allclose(hi, kin.upper)):
        problems.append(f"Drake's joint limits {lo.round(4).tolist()} .. {hi.round(4).tolist()} differ from the "
                        f"URDF chain's {kin.lower.round(4).tolist()} .. {kin.upper.round(4).tolist()}")
    rng = np.random.default_rng(0)
    qs = rng.uniform(np.maximum(kin.lower, -np.pi), np.minimum(kin.upper, np.pi), size=(20, kin.dof))
    ours, _ = kin.fk(qs)
    fk_error = 0.0
    for q, p in zip(qs, ours):
        model.set_state(q, {})
        fk_error = max(fk_error, float(np.abs(model.ee_position() - p).max()))
    if fk_error > 1e-6:
        problems.append(f"numpy forward kinematics differs from Drake's by {fk_error:.2e} m")
    rest_ee, _ = kin.fk(np.asarray(spec.rest))
    if rest_ee[2] <= 0.0:
        problems.append(f"the rest posture puts the tool centre point below the table (z = {rest_ee[2]:.3f} m)")
    report: dict = {"robot": spec.name, "dof": kin.dof, "fk_error_m": fk_error, "families": {}}
    for family in (families if families is not None else sim.families):
        t0 = time.perf_counter()
        task = gift.get_task(family)
        row = {"actions": 0, "unreachable_actions": 0, "preferred_reward": [], "default_reward": []}
        for seed in seeds:
            where = f"{family}, scene seed {seed}"
            try:
                scene = sim.make_scene(family, objects, relevant, seed=int(seed))
                _, _, feasible = sim.planner.prepare(scene)
                row["actions"] += len(feasible)
                row["unreachable_actions"] += int((~feasible).sum())
                batches = {g: sim.generate(scene, g, n, seed=1) for g in sim.generators}
            except GiftError as e:
                problems.append(f"{where}: {e}")
                continue
            for g, b in batches.items():
                q = b.joint_positions
                if q.shape[-1] != kin.dof or ((q < kin.lower - 1e-9) | (q > kin.upper + 1e-9)).any():
                    problems.append(f"{where}, {g}: joint positions leave the limits (or have the wrong DoF)")
                if b.ee_positions[..., 2].min() <= 0.0:
                    problems.append(f"{where}, {g}: the tool centre point goes below the table "
                                    f"(min z = {b.ee_positions[..., 2].min():.3f} m)")
                f = sim.features(b, family).values
                if not np.isfinite(f).all() or f.min() < 0.0 or f.max() > 1.0:
                    problems.append(f"{where}, {g}: features are not finite values in [0, 1]")
            feats = {g: sim.features(batches[g], family) for g in ("preferred", "default")}
            rewards = {g: float(task.ground_truth_reward(f, sorted(relevant)).mean()) for g, f in feats.items()}
            row["preferred_reward"].append(rewards["preferred"])
            row["default_reward"].append(rewards["default"])
            if rewards["preferred"] <= rewards["default"]:
                problems.append(f"{where}: preferred trajectories do not beat default ones on the ground-truth "
                                f"reward ({rewards['preferred']:.3f} <= {rewards['default']:.3f})")
        row["seconds"] = round(time.perf_counter() - t0, 2)
        report["families"][family] = row
    if problems:
        raise GiftError(f"robot {spec.name!r} fails on the Drake simulator:\n- " + "\n- ".join(problems))
    return report
