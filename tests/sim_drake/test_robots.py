"""The arms: URDFs without remote packages, numpy kinematics equal to Drake's MultibodyPlant, robot specs
checked against their URDFs with clear errors, and the example package's UR5e accepted on the plant."""

from __future__ import annotations

import re

import attrs
import numpy as np
import pytest

import gift
from gift.core.errors import GiftError, ValidationError
from gift.core.robots import RobotSpec
from gift_sim_drake.checks import check_robot_on_drake
from gift_sim_drake.plant import DrakeIK, SceneModel, drake_ik
from gift_sim_drake.robots import ROBOTS, arm_kinematics, get_robot

pytestmark = pytest.mark.drake
ARMS = {"franka": 7, "jaco": 7, "ur5e": 6}


@pytest.fixture(scope="module")
def specs(example_robot):
    return {name: gift.get_robot(name) for name in ARMS}


@pytest.mark.parametrize("robot", sorted(ARMS))
def test_urdf_is_self_contained(specs, robot):
    text = specs[robot].urdf_path.read_text()
    assert "package://" not in text and "<mesh" not in text
    assert arm_kinematics(specs[robot]).dof == ARMS[robot] == specs[robot].dof


def test_the_builtin_arms_are_registered_by_the_drake_plugin():
    for name, spec in ROBOTS.items():
        assert gift.get_robot(name) is spec
        assert gift.robot_simulator(name) == f"drake-{name}"
        assert gift.get_manager().get("robot", name).distribution == "gift-sim-drake"


@pytest.mark.parametrize("robot", sorted(ARMS))
def test_numpy_fk_matches_drake_plant(specs, robot, objects):
    spec = specs[robot]
    kin = arm_kinematics(spec)
    model = SceneModel(spec, "pack_backpack", objects, {"backpack": (0.4, 0.4, 0.09)})
    lo, hi = model.joint_limits()
    np.testing.assert_allclose(lo, kin.lower)
    np.testing.assert_allclose(hi, kin.upper)
    rng = np.random.default_rng(0)
    qs = rng.uniform(np.maximum(lo, -4), np.minimum(hi, 4), size=(25, kin.dof))
    ours, _ = kin.fk(qs)
    for q, p in zip(qs, ours):
        model.set_state(q, {})
        assert np.abs(model.ee_position() - p).max() < 1e-6


@pytest.mark.parametrize("robot", sorted(ARMS))
def test_local_ik_refines_drake_ik(specs, robot):
    spec = specs[robot]
    kin = arm_kinematics(spec)
    target = np.array([0.45, 0.1, 0.12])
    q0 = drake_ik(spec).solve(target, spec.rest)
    pos, rot = kin.fk(q0)
    assert np.abs(pos - target).max() < 2e-4 and rot[2, 2] < -0.999
    moved = target + [0.02, -0.015, 0.01]
    q, err = kin.solve_pointing_down(q0[None], moved[None])
    assert err[0] < 1e-5
    assert np.abs(kin.fk(q[0])[0] - moved).max() < 1e-5
    assert (q >= kin.lower).all() and (q <= kin.upper).all()


def test_a_mounted_arm_is_placed_alike_in_numpy_and_on_the_plant():
    base = ROBOTS["franka"]
    raised = attrs.evolve(base, name="franka-raised", mount=(-0.05, 0.02, 0.1, 0.0, 0.0, 0.3))
    q = np.asarray(base.rest)
    lifted = arm_kinematics(raised).fk(q)[0] - arm_kinematics(base).fk(q)[0]
    assert abs(lifted[2] - 0.1) < 1e-9  # a yaw and a shift in the plane keep the height difference
    model = SceneModel(raised, "pack_backpack", (), {})
    model.set_state(q, {})
    assert np.abs(model.ee_position() - arm_kinematics(raised).fk(q)[0]).max() < 1e-9
    target = np.array([0.5, -0.1, 0.15])
    sol = DrakeIK(raised).solve(target, q)
    assert np.abs(arm_kinematics(raised).fk(sol)[0] - target).max() < 2e-4


def test_ur5e_passes_the_acceptance_check_on_the_plant(example_robot):
    report = check_robot_on_drake(example_robot, seeds=(0, 1), n=6)
    assert report["dof"] == 6 and report["fk_error_m"] < 1e-9
    assert set(report["families"]) == {"pack_backpack", "store_drawer", "sweep_spill", "place_mug"}
    for family, row in report["families"].items():
        assert row["unreachable_actions"] == 0, family
        assert min(row["preferred_reward"]) > max(row["default_reward"]), family


def _edited(tmp_path, name, edit) -> RobotSpec:
    text = edit(ROBOTS["franka"].urdf_path.read_text())
    path = tmp_path / f"{name}.urdf"
    path.write_text(text)
    return attrs.evolve(ROBOTS["franka"], name=name, urdf=str(path), package=None)


def test_robot_specs_that_do_not_fit_their_urdf_get_clear_errors(tmp_path):
    franka = ROBOTS["franka"]
    with pytest.raises(ValidationError, match=r"rest has 6 angles but the chain panda_link0 -> panda_ee of panda.urdf "
                                              r"has 7 movable joints"):
        get_robot(attrs.evolve(franka, rest=franka.rest[:6]))
    with pytest.raises(ValidationError, match=r"rest is outside the joint limits at panda_joint4 \(0.500 not in "
                                              r"\[-3.072, -0.070\]\)"):
        get_robot(attrs.evolve(franka, rest=(0.0, -0.26, 0.0, 0.5, 0.0, 2.17, 0.785)))
    with pytest.raises(GiftError, match=r"no end-effector link 'gripper_tip'; links: \["):
        get_robot(attrs.evolve(franka, name="tipless", ee_link="gripper_tip"))
    with pytest.raises(ValidationError, match=r"URDF file '/nowhere/arm.urdf' not found"):
        get_robot(attrs.evolve(franka, name="nowhere", urdf="/nowhere/arm.urdf", package=None))
    sliding = _edited(tmp_path, "sliding", lambda t: t.replace(
        '<joint name="panda_joint7" type="revolute">', '<joint name="panda_joint7" type="prismatic">'))
    with pytest.raises(GiftError, match=r"joint 'panda_joint7' has type 'prismatic'; only revolute, continuous and "
                                        r"fixed joints"):
        get_robot(sliding)
    # a movable finger off the chain: numpy sees 7 joints, Drake 8 positions
    finger = _edited(tmp_path, "finger", lambda t: t.replace("</robot>", (
        '<link name="finger"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" '
        'izz="1e-4"/></inertial></link><joint name="finger_joint" type="prismatic"><parent link="panda_hand"/>'
        '<child link="finger"/><axis xyz="0 1 0"/><limit lower="0" upper="0.04" effort="10" velocity="0.1"/>'
        '</joint></robot>')))
    with pytest.raises(GiftError, match=r"Drake finds 8 joint positions in finger.urdf but rest has 7; every movable "
                                        r"joint must lie on the chain panda_link0 -> panda_ee"):
        DrakeIK(get_robot(finger))


def test_continuous_joints_have_no_limits_in_numpy_and_on_the_plant(tmp_path):
    spinning = _edited(tmp_path, "spinning", lambda t: re.sub(
        r'(<joint name="panda_joint7" type=")revolute(">(?:(?!</joint>).)*?)<limit[^>]*/>',
        r'\1continuous\2<limit effort="12" velocity="2.61"/>', t, flags=re.S))
    kin = arm_kinematics(get_robot(spinning))
    assert kin.lower[6] == -np.inf and kin.upper[6] == np.inf and np.isfinite(kin.lower[:6]).all()
    model = SceneModel(spinning, "pack_backpack", (), {})
    lo, hi = model.joint_limits()
    assert lo[6] == -np.inf and hi[6] == np.inf
    q = np.asarray(spinning.rest) + [0, 0, 0, 0, 0, 0, 7.0]  # beyond 2 pi
    model.set_state(q, {})
    assert np.abs(model.ee_position() - kin.fk(q)[0]).max() < 1e-9


@pytest.mark.parametrize("robot", sorted(ARMS))
def test_reach_from_the_kinematics_agrees_with_drake_ik(specs, robot):
    """The reach the layouts keep objects within: inside it (less the layout's margin) Drake's IK reaches the
    point pointing down, in several directions; 3 cm beyond it, it does not."""
    from gift_sim_drake.scenes import REACH_MARGIN

    spec = specs[robot]
    heights = np.array([0.05, 0.25, 0.35])
    reach = arm_kinematics(spec).reach_pointing_down(heights, np.asarray(spec.rest))
    assert (reach > 0.5).all() and (np.diff(reach) <= 0.01).all()  # further down, not less far
    ik = drake_ik(spec)
    for z, r in zip(heights, reach):
        for angle in (-0.6, 0.0, 0.8):
            direction = np.array([np.cos(angle), np.sin(angle)])
            ik.solve([*(direction * (r - REACH_MARGIN)), z], spec.rest)
            with pytest.raises(GiftError, match="no .* configuration"):
                ik.solve([*(direction * (r + 0.03)), z], spec.rest)


def test_gift_doctor_checks_every_registered_robot(monkeypatch):
    import types

    from gift.plugins.manager import GiftPluginManager
    from gift_sim_drake.doctor import check_robots

    @gift.hookimpl
    def gift_register_robots(register):
        register(ROBOTS["franka"])
        register(attrs.evolve(ROBOTS["jaco"], name="jaco-six", rest=ROBOTS["jaco"].rest[:6]))

    manager = GiftPluginManager()
    manager.register_plugin(types.SimpleNamespace(gift_register_robots=gift_register_robots), name="arms",
                            distribution="my-arms")
    monkeypatch.setattr(gift, "get_manager", lambda: manager.load([]))
    checks = {c.name: c for c in check_robots()}
    assert checks["robot franka"].status == "ok" and "7-DoF chain" in checks["robot franka"].detail
    bad = checks["robot jaco-six"]
    assert bad.status == "fail" and "rest has 6 angles but the chain" in bad.detail
    assert "my-arms" in bad.fix and "GIFT_DISABLE_PLUGINS=arms" in bad.fix
