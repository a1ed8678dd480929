"""The arms: URDFs without remote packages, numpy kinematics equal to Drake's MultibodyPlant."""

from __future__ import annotations

import numpy as np
import pytest

from gift_sim_drake.plant import SceneModel, drake_ik
from gift_sim_drake.robots import ROBOTS

pytestmark = pytest.mark.drake


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_urdf_is_self_contained(robot):
    text = ROBOTS[robot].urdf_path.read_text()
    assert "package://" not in text and "<mesh" not in text
    assert ROBOTS[robot].kinematics.dof == 7


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_numpy_fk_matches_drake_plant(robot, objects):
    spec = ROBOTS[robot]
    kin = spec.kinematics
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
    pos, rot = spec.kinematics.fk(q0)
    assert np.abs(pos - target).max() < 2e-4 and rot[2, 2] < -0.999
    moved = target + [0.02, -0.015, 0.01]
    q, err = spec.kinematics.solve_pointing_down(q0[None], moved[None])
    assert err[0] < 1e-5
    assert np.abs(spec.kinematics.fk(q[0])[0] - moved).max() < 1e-5
    assert (q >= spec.kinematics.lower).all() and (q <= spec.kinematics.upper).all()


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_reach_from_the_kinematics_agrees_with_drake_ik(robot):
    """The reach the layouts keep objects within: inside it (less the layout's margin) Drake's IK reaches the
    point pointing down, in several directions; 3 cm beyond it, it does not."""
    from gift.core.errors import GiftError
    from gift_sim_drake.scenes import REACH_MARGIN

    spec = ROBOTS[robot]
    heights = np.array([0.05, 0.25, 0.35])
    reach = spec.kinematics.reach_pointing_down(heights, spec.rest)
    assert (reach > 0.5).all() and (np.diff(reach) <= 0.01).all()  # further down, not less far
    ik = drake_ik(spec)
    for z, r in zip(heights, reach):
        for angle in (-0.6, 0.0, 0.8):
            direction = np.array([np.cos(angle), np.sin(angle)])
            ik.solve([*(direction * (r - REACH_MARGIN)), z], spec.rest)
            with pytest.raises(GiftError, match="no .* configuration"):
                ik.solve([*(direction * (r + 0.03)), z], spec.rest)
