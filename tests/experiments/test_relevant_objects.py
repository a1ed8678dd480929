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


@pytest.mark.parametrize("intent_id", ["cloth_items", "breakables"])
def test_the_objects_the_human_steers_the_mug_around_are_inferred(setting, intent_id):
    """place_mug: the simulated human carries the full mug low and steers it around the relevant objects,
    towards the others (the layout puts the two kinds on opposite sides of the straight carry). The objects
    every preferred carry keeps further from than every default carry are the relevant ones."""
    from gift.tasks import EE_HEIGHT_SCALE
    from gift_sim_drake.tabletop import MUG_RAISED

    pairs, spec = demonstrations(setting, intent_id)
    res = infer_relevant_objects(pairs, spec.train_objects)
    assert res.modes == {"proximity:mug": "passing"}
    observed = [o for o in spec.train_objects if o not in res.unobserved]
    assert set(res.relevant) == set(spec.relevant_train) & set(observed), res.scores
    assert res.separates and not res.undetermined and res.informative == res.scenes
    assert all(res.scores[o] < 0.3 for o in res.irrelevant), res.scores
    assert all(res.evidence[o].approached == 0 for o in spec.relevant_train)
    assert sum(res.evidence[o].approached for o in res.irrelevant) > 0
    height = [s.name for s in pairs[0].preferred.specs].index("ee_height")
    lowest_raised = min(h for _, h in MUG_RAISED)
    for pair in pairs:  # low carries only (0.18 m, +-2 cm): never raised over the table
        assert pair.preferred.values[:, height].max() * EE_HEIGHT_SCALE < lowest_raised - 0.05


@pytest.fixture(scope="module")
def embedded_lm():
    gift_llm = pytest.importorskip("gift_llm")
    return gift_llm.get_default_lm()


@pytest.mark.parametrize("intent_id", ["toiletries", "baking_tools", "leather_goods", "cloth_items"])
def test_the_inferred_objects_name_a_class_on_the_embedded_model(setting, embedded_lm, intent_id):
    """One intent per family, end to end without labels: Drake demonstrations -> inferred relevant objects ->
    the embedded model names the kind of object from them (no goal text: the easy question) -> that
    category's yes/no log-odds rank the test objects. The category is a class, not one of the objects.
    Measured (LM-only test AUC): toiletries 0.96, baking_tools 0.94, leather_goods 0.77, cloth_items 0.59."""
    from gift.core.data import Intent
    from gift.core.metrics import roc_auc
    from gift_kernels.lm_kernels import GiftProbKernel

    suite, _ = setting
    pairs, spec = demonstrations(setting, intent_id)
    res = infer_relevant_objects(pairs, spec.train_objects)
    assert set(res.relevant) == set(spec.relevant_train), res.scores
    alone = [o for o in spec.train_objects if o not in res.relevant]
    kernel = GiftProbKernel(lm=embedded_lm, combine="none")
    category = kernel.category(None, list(res.relevant), alone)
    assert category and not any(o.lower() in category.lower() for o in spec.train_objects), category
    test = suite.specs(spec.test_objects)
    lo = kernel.log_odds(test, Intent(text=category, source="inferred"), [category] * len(test))
    assert roc_auc(lo, [t.relevant for t in spec.test]) > 0.5, (category, lo)
