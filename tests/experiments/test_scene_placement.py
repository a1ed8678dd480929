"""Scenes of reproduce whose random pick of objects does not fit on the table (real Drake layout)."""

from __future__ import annotations

import logging
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor

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
ROBOTS = ("jaco", "franka")
CHECK = "test_every_scene_of_reproduce_is_placed_with_every_action_in_reach"


@pytest.fixture(scope="module")
def placement(request):
    """``{(suite, robot): Future of placement_check.placement_problems}`` for the cases this session collected,
    computed in worker processes (one per core, at most 2), in test order, so each test waits only for its own."""
    from placement_check import placement_problems

    cases = [(item.callspec.params["suite_name"], item.callspec.params["robot"]) for item in request.session.items
             if getattr(item, "originalname", None) == CHECK]
    workers = max(1, min(2, os.cpu_count() or 1, len(cases)))
    # spawn: the pytest process may hold the LM's threads; a fork would copy them half-way
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        yield {case: pool.submit(placement_problems, *case) for case in cases}


@pytest.mark.slow
@pytest.mark.parametrize("suite_name", SHIPPED)
@pytest.mark.parametrize("robot", ROBOTS)
def test_every_scene_of_reproduce_is_placed_with_every_action_in_reach(placement, suite_name, robot):
    """Training, RQ1 and RQ3 scenes of every intent, picked as reproduce picks them (its seeds): each fits on
    the table, and the planner reaches every candidate action, so every object is one the arm can act on
    (before the layout knew the arm's reach, jaco could not pick e.g. the paintbrush of art_supplies at
    (0.60, -0.40) m, the only relevant object of its scene). The check is placement_check.placement_problems."""
    problems = placement[(suite_name, robot)].result()
    assert problems == [], "\n".join(problems)
