"""Trajectory generation on the real plant: the built-in arms and the example UR5e, all four families."""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.data import ObjectSpec
from gift.core.errors import GiftError
from gift_sim_drake.motion import N_STEPS
from gift_sim_drake.plant import SceneModel
from gift_sim_drake.simulator import DrakeSimulator

from sim_drake_catalog import FAMILIES, RELEVANT, ROBOTS

pytestmark = pytest.mark.drake
CASES = [(r, f) for r in ROBOTS for f in FAMILIES]


@pytest.fixture(scope="module")
def generated(simulators, objects):
    """(robot, family) -> (scene, {generator: batch}) for scene seed 7, 12 trajectories each."""
    out = {}
    for robot, family in CASES:
        sim = simulators[robot]
        scene = sim.make_scene(family, objects, RELEVANT, seed=7)
        out[robot, family] = scene, {g: sim.generate(scene, g, 12, seed=1) for g in ("preferred", "default", "random")}
    return out


@pytest.mark.parametrize("robot,family", CASES)
def test_shapes_and_joint_limits_on_the_plant(generated, simulators, objects, robot, family):
    scene, batches = generated[robot, family]
    model = SceneModel(simulators[robot].robot, family, objects, scene.landmarks)
    lo, hi = model.joint_limits()
    for gen, b in batches.items():
        assert b.joint_positions.shape == (12, N_STEPS, simulators[robot].dof)
        assert b.object_positions.shape == (12, N_STEPS, 4, 3)
        assert (b.joint_positions >= lo).all() and (b.joint_positions <= hi).all(), gen
        assert b.ee_positions[..., 2].min() > 0.0  # never through the table
        assert b.meta["robot"] == simulators[robot].robot.name and b.meta["generator"] == gen
        # the stored end-effector path is the plant's forward kinematics
        for i, t in [(0, 0), (3, 25), (11, 60)]:
            model.set_state(b.joint_positions[i, t], {})
            assert np.abs(model.ee_position() - b.ee_positions[i, t]).max() < 1e-6


@pytest.mark.parametrize("robot,family", [c for c in CASES if c[1] in ("pack_backpack", "store_drawer")])
def test_pack_and_store_end_in_the_container(generated, simulators, objects, robot, family):
    scene, batches = generated[robot, family]
    mark = gift.get_task(family).landmarks[0]
    container = np.asarray(scene.landmarks[mark])
    model = SceneModel(simulators[robot].robot, family, objects, scene.landmarks)
    for b in batches.values():
        for i in range(len(b)):
            model.set_state(b.joint_positions[i, -1], {})
            assert np.linalg.norm(model.ee_position() - container) < 0.02
            k = b.object_names.index(b.meta["acted_on"][i])
            assert np.linalg.norm(b.object_positions[i, -1, k] - container) < 0.03


@pytest.mark.parametrize("robot,family", CASES)
def test_carried_object_follows_the_gripper(generated, simulators, objects, robot, family):
    scene, batches = generated[robot, family]
    model = SceneModel(simulators[robot].robot, family, objects, scene.landmarks)
    b = batches["random"]
    for i in range(len(b)):
        acted = b.meta["acted_on"][i]
        if acted == "mug":
            path, (on, off), xy_only = b.landmark_positions[i, :, 0], (0, 60), False
        else:
            k = b.object_names.index(acted)
            path = b.object_positions[i, :, k]
            (on, off), xy_only = ((22, 46), True) if family == "sweep_spill" else ((20, 60), False)
            assert np.allclose(path[:on], path[0])  # untouched before the grasp / contact
            assert np.allclose(path[off:], path[off])  # left where it was released
            others = [j for j in range(len(b.object_names)) if j != k]
            assert np.allclose(b.object_positions[i, :, others], b.object_positions[i, :1, others])
        dims = slice(0, 2) if xy_only else slice(0, 3)
        offsets = []
        for t in range(on, off + 1, 5):
            model.set_state(b.joint_positions[i, t], {acted: path[t]})
            offsets.append(model.body_position(acted)[dims] - model.ee_position()[dims])
        offsets = np.array(offsets)
        assert np.abs(offsets - offsets[0]).max() < 1e-6  # rigidly attached on the real plant
        assert np.linalg.norm(offsets[0]) < 0.15  # held at its centre, or pushed from its side
        assert np.linalg.norm(path[off] - path[0]) > 0.1  # and it really moved


@pytest.mark.parametrize("robot,family", CASES)
def test_preferred_and_default_differ_in_the_intent_features(generated, simulators, robot, family):
    scene, batches = generated[robot, family]
    sim, task = simulators[robot], gift.get_task(family)
    feats = {g: sim.features(b, family) for g, b in batches.items()}
    rewards = {g: task.ground_truth_reward(f, RELEVANT) for g, f in feats.items()}
    assert rewards["preferred"].min() > rewards["default"].max()
    assert rewards["preferred"].mean() >= rewards["random"].mean()
    cols = [j for j, s in enumerate(feats["preferred"].specs) if s.subject in RELEVANT]
    gap = np.abs(feats["preferred"].values[..., cols].mean(0) - feats["default"].values[..., cols].mean(0))
    assert gap.max() > 0.3
    # default is intent-blind: it acts on an irrelevant object (or carries the mug straight)
    assert all(a not in RELEVANT for a in batches["default"].meta["acted_on"])
    if family != "place_mug":
        assert all(a in RELEVANT for a in batches["preferred"].meta["acted_on"])


@pytest.mark.parametrize("robot", ROBOTS)
def test_same_seed_same_data_bit_for_bit(simulators, objects, robot):
    import gift_sim_drake.plant as plant

    for family in FAMILIES:
        a_scene = simulators[robot].make_scene(family, objects, RELEVANT, seed=11)
        a = simulators[robot].generate(a_scene, "random", 20, seed=5)
        plant._IK.clear()  # a fresh simulator and IK cache must give the same bits
        fresh = DrakeSimulator(simulators[robot].robot.name)
        b_scene = fresh.make_scene(family, objects, RELEVANT, seed=11)
        b = fresh.generate(b_scene, "random", 20, seed=5)
        assert np.array_equal(a_scene.positions, b_scene.positions) and a_scene.landmarks == b_scene.landmarks
        for name in ("joint_positions", "ee_positions", "object_positions", "landmark_positions"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), (family, name)
        c = fresh.generate(b_scene, "random", 20, seed=6)
        assert not np.array_equal(a.joint_positions, c.joint_positions)
        other = fresh.make_scene(family, objects, RELEVANT, seed=12)
        assert not np.array_equal(other.positions, a_scene.positions)


def test_any_object_names_and_relevance(simulators):
    sim = simulators["drake-franka"]
    objs = [ObjectSpec("zorb"), ObjectSpec("quux widget"), ObjectSpec("blip")]
    for family in FAMILIES:
        scene = sim.make_scene(family, objs, ["quux widget"], seed=2)
        b = sim.generate(scene, "preferred", 4, seed=0)
        f = sim.features(b, family)
        assert f.names == tuple(s.name for s in gift.get_task(family).feature_specs(scene.object_names))
        if family != "place_mug":
            assert set(b.meta["acted_on"]) == {"quux widget"}
        assert "quux_widget_proximity_to_" + gift.get_task(family).landmarks[0] in f.names or family == "place_mug"


def test_bad_input_gets_clear_errors(simulators, objects):
    sim = simulators["drake-jaco"]
    with pytest.raises(gift.UnknownComponentError, match="no task named 'juggle'"):
        sim.make_scene("juggle", objects, [], seed=0)
    scene = sim.make_scene("pack_backpack", objects, RELEVANT, seed=0)
    with pytest.raises(GiftError, match="unknown trajectory generator 'best'"):
        sim.generate(scene, "best", 3, seed=0)
    with pytest.raises(GiftError, match="n must be a positive integer"):
        sim.generate(scene, "default", 0, seed=0)
    with pytest.raises(GiftError, match="at most 6 objects"):
        sim.make_scene("sweep_spill", [ObjectSpec(f"o{i}") for i in range(7)], [], seed=0)
    with pytest.raises(gift.core.errors.ValidationError, match="not in the scene"):
        sim.make_scene("pack_backpack", objects, ["unicorn"], seed=0)
    with pytest.raises(GiftError, match="lacks object positions or the landmarks"):
        sim.generate(gift.Scene("place_mug", objects), "default", 2, seed=0)


def test_scene_model_poses_a_generated_state(simulators, objects):
    sim = simulators["drake-franka"]
    scene = sim.make_scene("place_mug", objects, RELEVANT, seed=4)
    b = sim.generate(scene, "preferred", 2, seed=0)
    model = sim.scene_model(scene)
    state = {name: b.object_positions[1, 30, i] for i, name in enumerate(b.object_names)}
    model.set_state(b.joint_positions[1, 30], {**state, "mug": b.landmark_positions[1, 30, 0]})
    assert np.abs(model.ee_position() - b.ee_positions[1, 30]).max() < 1e-6
    assert np.abs(model.body_position("mug") - b.landmark_positions[1, 30, 0]).max() < 1e-9
