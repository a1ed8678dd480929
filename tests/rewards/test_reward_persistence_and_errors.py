"""Save/load round trips, and clear errors for bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from reward_data import random_specs, random_traces

import gift
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, FeatureSpec
from gift.core.errors import GiftError, ValidationError
from gift_rewards import LinearMaxEntReward, NeuralMaxEntReward, NotFittedError, load_reward

SPECS = random_specs(3)


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(0)
    return random_traces(SPECS, 60, 15, rng), random_traces(SPECS, 300, 15, rng), random_traces(SPECS, 200, 15, rng)


@pytest.fixture(scope="module", params=[LinearMaxEntReward, NeuralMaxEntReward])
def fitted(request, data):
    demos, alternatives, _ = data
    opts = {"max_epochs": 50} if request.param is NeuralMaxEntReward else {}
    return request.param(metadata={"task": "synthetic", "seed": 0}, **opts).fit(demos, alternatives)


def test_saved_reward_reloads_to_identical_scores(fitted, data, tmp_path):
    test = data[2]
    path = tmp_path / "reward.json"
    fitted.save(path)

    for loaded in (type(fitted).load(path), load_reward(path)):
        assert type(loaded) is type(fitted)
        assert loaded.feature_specs == fitted.feature_specs
        assert loaded.hyperparameters() == fitted.hyperparameters()
        assert loaded.metadata == {"task": "synthetic", "seed": 0}
        assert loaded.fit_info["n_demonstrations"] == 60
        np.testing.assert_array_equal(loaded.score(test), fitted.score(test))
        alignment = Alignment({"obj0": "obj2", "obj1": DISTRACTOR, "obj2": "obj0"})
        np.testing.assert_array_equal(loaded.score_aligned(test, alignment), fitted.score_aligned(test, alignment))

    doc = json.loads(path.read_text())
    assert doc["model"] == fitted.name
    assert [s["name"] for s in doc["feature_specs"]] == [s.name for s in SPECS]


def test_linear_weights_are_saved_by_name(data, tmp_path):
    model = LinearMaxEntReward().fit(*data[:2])
    model.save(tmp_path / "r.json")
    params = json.loads((tmp_path / "r.json").read_text())["params"]
    assert dict(zip(params["names"], params["theta"])) == model.weights


def test_load_rejects_wrong_kind_and_bad_files(data, tmp_path):
    path = tmp_path / "linear.json"
    LinearMaxEntReward().fit(*data[:2]).save(path)
    with pytest.raises(ValidationError, match="holds a 'maxent-linear' reward, not 'maxent-neural'"):
        NeuralMaxEntReward.load(path)
    with pytest.raises(ValidationError, match="no such reward file"):
        load_reward(tmp_path / "missing.json")
    (tmp_path / "junk.json").write_text("{not json")
    with pytest.raises(ValidationError, match="invalid JSON"):
        load_reward(tmp_path / "junk.json")
    doc = json.loads(path.read_text())
    doc["params"]["theta"] = doc["params"]["theta"][:-1]
    (tmp_path / "short.json").write_text(json.dumps(doc))
    with pytest.raises(ValidationError, match=r"short.json: malformed 'maxent-linear' reward file: theta has shape"):
        load_reward(tmp_path / "short.json")


@pytest.mark.parametrize("name", ["maxent-linear", "maxent-neural"])
def test_use_before_fit_is_a_clear_error(name, data, tmp_path):
    model = gift.get_reward_model(name)
    with pytest.raises(NotFittedError, match=f"reward '{name}' is not fitted yet"):
        model.score(data[2])
    with pytest.raises(NotFittedError):
        model.save(tmp_path / "x.json")
    assert not (tmp_path / "x.json").exists()


@pytest.mark.parametrize("name", ["maxent-linear", "maxent-neural"])
def test_fit_rejects_bad_batches(name, data):
    demos, alternatives, _ = data
    model = gift.get_reward_model(name, **({"max_epochs": 5} if name == "maxent-neural" else {}))

    with pytest.raises(ValidationError, match=r"fit\(alternatives\): the batch holds no trajectories"):
        model.fit(demos, alternatives[np.arange(0)])
    bad = demos.values.copy()
    bad[4, 7, 1] = np.nan
    with pytest.raises(ValidationError, match=r"fit\(demonstrations\): 1 non-finite value\(s\); first at "
                                              r"trajectory 4, time step 7, feature 'obj1_proximity_to_box'"):
        model.fit(FeatureBatch(SPECS, bad), alternatives)
    other = FeatureBatch(SPECS[:3] + (FeatureSpec("ee_height", kind="ee_height"),), alternatives.values)
    with pytest.raises(ValidationError, match=r"different feature columns \(only in demonstrations: "
                                              r"\['ee_speed'\]; only in alternatives: \['ee_height'\]\)"):
        model.fit(demos, other)
    with pytest.raises(ValidationError, match="expected a FeatureBatch, got ndarray"):
        model.fit(demos.values, alternatives)
    assert not model.is_fitted  # nothing half-fitted is left behind
    # alternatives with the same columns in another order are fine
    order = [2, 0, 3, 1]
    model.fit(demos, FeatureBatch([SPECS[i] for i in order], alternatives.values[..., order]))
    assert model.feature_specs == SPECS


def test_score_rejects_bad_batches(fitted, data):
    test = data[2]
    with pytest.raises(ValidationError, match=r"score\(features\): the batch holds no trajectories"):
        fitted.score(test[np.arange(0)])
    bad = test.values.copy()
    bad[0, -1, 3] = np.inf
    with pytest.raises(ValidationError, match=r"trajectory 0, time step 14, feature 'ee_speed' \(= inf\)"):
        fitted.score(FeatureBatch(SPECS, bad))
    renamed = FeatureBatch(SPECS[:3] + (FeatureSpec("stapler_proximity_to_box", subject="stapler"),),
                           test.values)
    with pytest.raises(ValidationError, match=r"column\(s\) \['stapler_proximity_to_box'\] are not features "
                                              r"of this reward.*score_aligned"):
        fitted.score(renamed)
    with pytest.raises(ValidationError, match=r"lack the continuous column\(s\) \['ee_speed'\]"):
        fitted.score(FeatureBatch(SPECS[:3], test.values[..., :3]))


def test_score_aligned_rejects_bad_alignments(fitted, data):
    test = data[2]
    with pytest.raises(ValidationError, match=r"maps \{'obj0': 'pencil'\} to objects this reward was not "
                                              r"trained on"):
        fitted.score_aligned(test, Alignment({"obj0": "pencil"}))
    drawer = FeatureBatch((FeatureSpec("cup_proximity_to_drawer", subject="cup", reference="drawer"),) + SPECS[3:],
                          test.values[..., 2:])
    with pytest.raises(ValidationError, match=r"test column\(s\) \['cup_proximity_to_drawer \(cup -> obj0\)'\] "
                                              r"have no counterpart of the same kind and reference"):
        fitted.score_aligned(drawer, Alignment({"cup": "obj0"}))
    with pytest.raises(ValidationError, match="expected an Alignment, got dict"):
        fitted.score_aligned(test, {"obj0": "obj1"})
    with pytest.raises(ValidationError, match=r"score_aligned\(features\): the test features lack the "
                                              r"continuous column\(s\) \['ee_speed'\]"):
        fitted.score_aligned(FeatureBatch(SPECS[:3], test.values[..., :3]), Alignment({"obj0": "obj0"}))


def test_bad_hyperparameters_are_named():
    with pytest.raises(ValidationError, match="maxent-linear: l2 must be a finite number >= 0"):
        gift.get_reward_model("maxent-linear", l2=-1)
    with pytest.raises(ValidationError, match="maxent-neural: val_fraction must be in"):
        gift.get_reward_model("maxent-neural", val_fraction=1.5)
    with pytest.raises(GiftError):
        gift.get_reward_model("maxent-neural", hidden=())
