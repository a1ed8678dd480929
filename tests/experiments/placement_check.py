"""Every reproduce scene of one suite on one robot, placed and planned as reproduce does (real Drake plant).

A module of its own, not a test file, so that test_scene_placement.py can run it in worker processes (each
suite and robot is independent, and Drake's inverse kinematics runs on one core)."""

from __future__ import annotations

import logging

import numpy as np

import gift
from gift.study.scenes import place_scene
from gift.study.scenes import test_scene as make_test_scene  # not a test


def placement_problems(suite_name: str, robot: str) -> list[str]:
    """What does not fit or is out of reach in the training, RQ1 and RQ3 scenes of every intent, picked with
    reproduce's seeds; ``[]`` when every scene fits on the table and the planner reaches every candidate action."""
    logging.getLogger("drake").setLevel(logging.ERROR)
    from gift.study.chain import StudyConfig, intent_seeds, rq3_objects

    suite = gift.load_suite(suite_name)
    cfg = StudyConfig(suite=suite_name, robot=robot)
    sim = gift.get_simulator(f"drake-{robot}")
    problems: list[str] = []
    for spec in suite.intents:
        try:
            seeds = intent_seeds(cfg, spec.id)
            rel = list(spec.relevant_train)
            irr = [o for o in spec.train_objects if o not in rel]
            scenes = [place_scene(sim, suite, spec.task, rel, irr, cfg.test_objects_per_scene, s)
                      for s in seeds["train"]]
            scenes += [make_test_scene(sim, suite, spec, cfg.test_objects_per_scene, s) for s in seeds["rq1"]]
            if spec.task in ("pack_backpack", "store_drawer"):
                objects = rq3_objects(spec)
                relevant = [o for o in objects if o in spec.relevant_test]
                scenes += [sim.make_scene(spec.task, suite.specs(objects), relevant, seed=s) for s in seeds["rq3"]]
            for scene in scenes:
                if len(scene.objects) != cfg.test_objects_per_scene:
                    problems.append(f"{spec.id}, seed {scene.seed}: {len(scene.objects)} objects placed, "
                                    f"not {cfg.test_objects_per_scene}")
                acts, _, feasible = sim.planner.prepare(scene)  # raises GiftError when the nominal is out of reach
                if not feasible.all():
                    problems.append(f"{spec.id}, seed {scene.seed}: out of reach: "
                                    f"{[acts.labels[a] for a in np.flatnonzero(~feasible)]}")
        except Exception as e:  # noqa: BLE001 - reported as this intent's problem, with its type
            problems.append(f"{spec.id}: {type(e).__name__}: {e}")
    return problems
