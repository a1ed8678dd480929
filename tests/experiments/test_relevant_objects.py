"""The relevant training objects inferred from real Drake demonstrations, one test per task family.

Demonstration pairs are made the way ``gift reproduce`` makes them, at its sizes (4 training scenes of 6
pairs; :func:`gift.study.scenes.training_set` with the study's seeds) but with a single random
alternative per scene, since the inference does not read them: a few seconds per intent. At 3 scenes of 4 pairs the
leather wallet of ``leather_goods`` is pushed in a single pair (the belt is the better push in the scenes
holding both) and its posterior stays at 0.47, so the reduced size would test luck, not the rule.
:func:`gift.core.demonstrations.infer_relevant_objects` sees only the pairs and the training object names.
Intents of the ``gift-dev`` suite.
"""

from __future__ import annotations

import logging

import pytest

import gift
from gift.core.data import DemonstrationPair
from gift.core.demonstrations import infer_relevant_objects
from gift.study.chain import StudyConfig, intent_seeds
from gift.study.scenes import training_set

pytestmark = [pytest.mark.slow, pytest.mark.drake]

ROBOT = "jaco"
SCENES, PAIRS = StudyConfig().train_scenes, StudyConfig().demos_per_scene


@pytest.fixture(scope="module")
def setting():
    logging.getLogger("drake").setLevel(logging.ERROR)
    return gift.load_suite("gift-dev"), gift.get_simulator(f"drake-{ROBOT}")


def demonstrations(setting, intent_id: str) -> tuple[list[DemonstrationPair], object]:
    suite, sim = setting
    spec = suite.intent(intent_id)
    cfg = StudyConfig(suite="gift-dev", train_scenes=SCENES)
    ts = training_set(sim, gift.get_task(spec.task), suite, spec, seeds=intent_seeds(cfg, intent_id)["train"],
                      demos=PAIRS, alternatives=1, objects_per_scene=cfg.test_objects_per_scene)
    return ts.pairs(), spec


@pytest.mark.parametrize("intent_id", ["toiletries", "baking_tools", "leather_goods"])
def test_the_objects_the_human_acts_on_are_inferred(setting, intent_id):
    """pack_backpack, store_drawer, sweep_spill: packed / stored / swept objects are the relevant ones."""
    pairs, spec = demonstrations(setting, intent_id)
    res = infer_relevant_objects(pairs, spec.train_objects)
    assert set(res.modes.values()) == {"acting"}
    observed = [o for o in spec.train_objects if o not in res.unobserved]
    assert set(res.relevant) == set(spec.relevant_train) & set(observed), res.scores
    assert res.separates and not res.undetermined
    assert all(res.scores[o] > 0.9 for o in res.relevant) and all(res.scores[o] < 0.3 for o in res.irrelevant)


def test_place_mug_demonstrations_single_out_no_object_so_none_is_claimed(setting):
    """place_mug: the Drake planner's preferred carry rises over the whole table whatever the relevant set,
    so every demonstration keeps the mug further from every object than every default carry does. Such a
    deviation cannot tell which object it was for: nothing is claimed, every object is undetermined."""
    pairs, spec = demonstrations(setting, "cloth_items")
    res = infer_relevant_objects(pairs, spec.train_objects)
    assert res.modes == {"proximity:mug": "passing"}
    assert res.relevant == () and res.informative == 0
    assert set(res.undetermined) == set(spec.train_objects) - set(res.unobserved)
    for pair in pairs:  # the reason: every object is further from the preferred carry than from the default
        present = [j for j, s in enumerate(pair.preferred.specs) if s.subject in pair.scene.object_names]
        assert (pair.preferred.values[:, present].sum(0) < pair.default.values[:, present].sum(0)).all()
