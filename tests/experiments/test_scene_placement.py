"""Scenes of reproduce whose random pick of objects does not fit on the table (real Drake layout)."""

from __future__ import annotations

import logging

import numpy as np
import pytest

import gift
from gift.core.errors import PlacementError
from gift.study.scenes import place_scene
from gift.study.scenes import test_scene as make_test_scene  # not a test
from gift.suites import SUITE_DIR

pytestmark = [pytest.mark.drake]

# reading_material, first RQ1 seed of the default config: four large books do not fit the pack table
SEED = 358468397


@pytest.fixture(scope="module")
def setting():
    logging.getLogger("drake").setLevel(logging.ERROR)
    suite = gift.load_suite("gift-paper")
    spec = suite.intent("reading_material")
    rel = [t.object for t in spec.test if t.relevant]
    irr = [t.object for t in spec.test if not t.relevant]
    return gift.get_simulator("drake-jaco"), suite, spec, rel, irr


def test_a_pick_that_does_not_fit_is_replaced_by_the_next_pick_of_the_same_seed(setting):
    sim, suite, spec, rel, irr = setting
    with pytest.raises(PlacementError, match="1 random picks of 4 objects"):
        place_scene(sim, suite, spec.task, rel, irr, 4, SEED, attempts=1)
    scene = make_test_scene(sim, suite, spec, 4, SEED)
    assert len(scene.object_names) == 4
    assert scene.relevant and set(scene.object_names) - set(scene.relevant)
    assert make_test_scene(sim, suite, spec, 4, SEED).object_names == scene.object_names  # deterministic


# ----------------------------------------------------------------------------- every scene fits, in reach

#: Every suite shipped in ``gift/suites`` (what the built-in plugin registers), so a new one is checked too.
SHIPPED = sorted(p.stem for p in SUITE_DIR.glob("*.yaml"))


def _rq3_objects(spec) -> list[str]:
    """The four objects :func:`gift.study.chain.rq3` places (one relevant and three confounds)."""
    rel = [t.object for t in spec.test if t.relevant]
    conf = [t.object for t in spec.test if not t.relevant and t.confounds] or \
        [t.object for t in spec.test if not t.relevant]
    return (rel[:1] + conf[:3]) if len(conf) >= 3 else (rel[:2] + conf[:2])


@pytest.mark.slow
@pytest.mark.parametrize("suite_name", SHIPPED)
@pytest.mark.parametrize("robot", ["jaco", "franka"])
def test_every_scene_of_reproduce_is_placed_with_every_action_in_reach(suite_name, robot):
    """Training, RQ1 and RQ3 scenes of every intent, picked as reproduce picks them (its seeds): each fits on
    the table, and the planner reaches every candidate action, so every object is one the arm can act on
    (before the layout knew the arm's reach, jaco could not pick e.g. the paintbrush of art_supplies at
    (0.60, -0.40) m, the only relevant object of its scene)."""
    logging.getLogger("drake").setLevel(logging.ERROR)
    from gift.study.chain import StudyConfig, intent_seeds

    suite = gift.load_suite(suite_name)
    cfg = StudyConfig(suite=suite_name, robot=robot)
    sim = gift.get_simulator(f"drake-{robot}")
    for spec in suite.intents:
        seeds = intent_seeds(cfg, spec.id)
        rel = list(spec.relevant_train)
        irr = [o for o in spec.train_objects if o not in rel]
        scenes = [place_scene(sim, suite, spec.task, rel, irr, cfg.test_objects_per_scene, s) for s in seeds["train"]]
        scenes += [make_test_scene(sim, suite, spec, cfg.test_objects_per_scene, s) for s in seeds["rq1"]]
        if spec.task in ("pack_backpack", "store_drawer"):
            objects = _rq3_objects(spec)
            relevant = [o for o in objects if o in spec.relevant_test]
            scenes += [sim.make_scene(spec.task, suite.specs(objects), relevant, seed=s) for s in seeds["rq3"]]
        for scene in scenes:
            assert len(scene.objects) == cfg.test_objects_per_scene, (spec.id, scene.seed)
            acts, _, feasible = sim.planner.prepare(scene)  # raises GiftError when the nominal is out of reach
            assert feasible.all(), (spec.id, scene.seed, [acts.labels[a] for a in np.flatnonzero(~feasible)])
