"""The example family on the real Drake simulator, tested with gift's plugin-author fixtures."""

import numpy as np
import pytest

import gift
from gift.core.errors import ValidationError
from gift_example_task import PackBackpackLow, sample_demonstrations


@pytest.fixture
def drake(gift_plugin_manager):
    if "drake-franka" not in gift_plugin_manager.names("simulator"):
        pytest.skip("the drake-franka simulator (gift-sim-drake) is not registered in this environment")
    return gift.get_simulator("drake-franka")


def test_family_is_discovered_through_its_entry_point(gift_plugin_manager):
    component = gift_plugin_manager.get("task", "pack_backpack_low")
    assert component.distribution == "gift-example-task"
    assert isinstance(gift.get_task("pack_backpack_low"), PackBackpackLow)


def test_reward_prefers_packing_relevant_objects_low(tiny_objects):
    train, _, _ = tiny_objects
    family = PackBackpackLow()
    specs = family.feature_specs([o.name for o in train])
    values = np.zeros((3, 5, len(specs)))
    values[:, -1, 0] = 1.0  # paintbrush (relevant) ends in the backpack in all three
    values[1, 2, -2] = 0.9  # trajectory 1 lifts high on the way
    values[2, -1, 2] = 1.0  # trajectory 2 also packs the banana (irrelevant)
    r = family.ground_truth_reward(gift.FeatureBatch(specs, values), ["paintbrush", "sketchbook"])
    assert r[0] > r[1] and r[0] > r[2]
    np.testing.assert_allclose(r[0] - r[1], 2.0 * 0.9)


def test_missing_height_feature_is_a_clear_error():
    family = PackBackpackLow()
    specs = family.feature_specs(["cup"])[:1]
    with pytest.raises(ValidationError, match="ee_height"):
        family.ground_truth_reward(gift.FeatureBatch(specs, np.zeros((1, 2, 1))), ["cup"])


@pytest.mark.drake
def test_drake_demonstrations_pack_relevant_objects_and_carry_low(drake, tiny_objects):
    train, _, _ = tiny_objects
    relevant = ["paintbrush", "sketchbook"]
    family = gift.get_task("pack_backpack_low")
    demos = sample_demonstrations(drake, family, train, relevant, n=6, pool=48, seed=3)
    assert demos.preferred_features.names == tuple(s.name for s in family.feature_specs([o.name for o in train]))
    assert set(demos.preferred.meta["acted_on"]) <= set(relevant)  # only relevant objects get packed
    height = demos.alternative_features.names.index("ee_height")
    best_height = demos.preferred_features.values[..., height].max(axis=1).mean()
    pool_height = demos.alternative_features.values[..., height].max(axis=1).mean()
    assert best_height < pool_height
    # the built-in family's preferred generator ignores the lift: our demonstrations are lower on average
    builtin = drake.generate(demos.scene, "preferred", 6, seed=3)
    builtin_height = drake.features(builtin, family).values[..., height].max(axis=1).mean()
    assert best_height <= builtin_height



@pytest.mark.drake
def test_its_own_drake_motions_let_the_preferred_generator_carry_low(drake, tiny_objects):
    train, _, _ = tiny_objects
    relevant = ["paintbrush", "sketchbook"]
    family = gift.get_task("pack_backpack_low")
    scene = drake.make_scene("pack_backpack_low", train, relevant, seed=3)  # staged by drake/pack_backpack_low
    usual_scene = drake.make_scene("pack_backpack", train, relevant, seed=3)  # same layout, the usual motions
    assert np.array_equal(usual_scene.positions, scene.positions)
    low = drake.generate(scene, "preferred", 6, seed=0)
    usual = drake.generate(usual_scene, "preferred", 6, seed=0)
    assert set(low.meta["acted_on"]) <= set(relevant)
    assert all(label.endswith("carried low") for label in low.meta["action_labels"])
    f_low, f_usual = drake.features(low, family), drake.features(usual, family)
    height = f_low.names.index("ee_height")
    grasped = 20  # the grasp keyframe's step: from here on the object is carried
    assert f_low.values[:, grasped:, height].max() < f_usual.values[:, grasped:, height].max(axis=1).min()
    # (the start posture, 0.3 m high, is the same for both: it bounds the whole trajectory's highest point)
    assert family.ground_truth_reward(f_low, relevant).mean() > family.ground_truth_reward(f_usual, relevant).mean()
