"""The arms: URDFs without remote packages, numpy kinematics equal to Drake's MultibodyPlant."""

from __future__ import annotations

import numpy as np
import pytest

from gift_sim_drake.plant import SceneModel, drake_ik
from gift_sim_drake.robots import ROBOTS, arm_kinematics

pytestmark = pytest.mark.drake


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_urdf_is_self_contained(robot):
    text = ROBOTS[robot].urdf_path.read_text()
    assert "package://" not in text and "<mesh" not in text
    assert arm_kinematics(ROBOTS[robot]).dof == 7


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_numpy_fk_matches_drake_plant(robot, objects):
    spec = ROBOTS[robot]
    kin = arm_kinematics(spec)
    model = SceneModel(spec, "pack_backpack", objects, {"backpack": (0.4, 0.4, 0.09)})
    lo, hi = model.joint_limits()
    np.testing.assert_allclose(lo, kin.lower)
    np.testing.assert_allclose(hi, kin.upper)
    rng = np.random.default_rng(0)
    qs = rng.uniform(np.maximum(lo, -4), np.minimum(hi, 4), size=(25, 7))
    ours, _ = kin.fk(qs)
    for q, p in zip(qs, ours):
        model.set_state(q, {})
        assert np.abs(model.ee_position() - p).max() < 1e-6


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_local_ik_refines_drake_ik(robot):
    spec = ROBOTS[robot]
    target = np.array([0.45, 0.1, 0.12])
    q0 = drake_ik(spec).solve(target, spec.rest)
    kin = arm_kinematics(spec)
    pos, rot = kin.fk(q0)
    assert np.abs(pos - target).max() < 2e-4 and rot[2, 2] < -0.999
    moved = target + [0.02, -0.015, 0.01]
    q, err = kin.solve_pointing_down(q0[None], moved[None])
    assert err[0] < 1e-5
    assert np.abs(kin.fk(q[0])[0] - moved).max() < 1e-5
    assert (q >= kin.lower).all() and (q <= kin.upper).all()
