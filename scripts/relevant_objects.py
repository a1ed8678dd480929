"""Accuracy of the relevant training objects inferred from demonstrations, on every intent of every suite.

    .venv/bin/python scripts/relevant_objects.py [--suites gift-paper,tests/kernels/data/lm_dev_suite.yaml,gift-dev]
        [--robots jaco,franka] [--out docs/results/relevant_objects.md]

For each suite, robot and intent, the demonstration pairs are generated exactly as ``gift reproduce``
generates them (:func:`gift.study.scenes.training_set` with the study's sizes and ``intent_seeds``), then
:func:`gift.core.demonstrations.infer_relevant_objects` decides the relevant training objects from them
alone; the suite's ``relevant_train`` is used only to score the result. Prints one table per suite and
robot (truth, inferred, wrong, no evidence, posteriors) and a summary; ``--out`` also writes it as
Markdown with the commit, suite hashes and sizes that made it.

Also reports, per place_mug-like scene (a simulator exposing ``planner.nominal_rewards``), whether the
demonstrated action depends on the relevant set at all.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import logging
import subprocess
import sys
from pathlib import Path

import attrs
import numpy as np

import gift
from gift.core.demonstrations import infer_relevant_objects
from gift.suites import SUITE_DIR

ROOT = Path(__file__).resolve().parents[1]


def _dev_number(name: str) -> int:
    """``gift-dev`` 1, ``gift-devN`` N: the development suites in the order they were written."""
    return int(name.removeprefix("gift-dev") or 1)


#: ``gift-paper``, ``lm-dev`` and every development suite shipped in ``gift/suites`` (what the built-in plugin
#: registers), so a new suite needs no entry here.
DEFAULT_SUITES = ("gift-paper", "tests/kernels/data/lm_dev_suite.yaml") + tuple(
    sorted((p.stem for p in SUITE_DIR.glob("gift-dev*.yaml")), key=_dev_number))


def _commit() -> str:
    """The checked-out commit, ``+dirty`` when tracked files outside docs/ differ from it."""
    try:
        out = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no", "--", ".",
                                ":!docs"], capture_output=True, text=True, check=True).stdout.strip()
        return out + ("+dirty" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def _suite_label(suite) -> str:
    path = Path(suite.path).resolve()
    return f"`{suite.name}` (`{path.relative_to(ROOT)}`)" if path.is_relative_to(ROOT) else f"`{suite.name}`"


def _depends_on_relevance(sim, scene) -> bool | None:
    """Whether the best demonstrated action of ``scene`` changes with the relevant set (None: cannot tell)."""
    planner = getattr(sim, "planner", None)
    if planner is None or not hasattr(planner, "nominal_rewards"):
        return None
    from gift_sim_drake.motion import TIE_TOLERANCE

    best = set()
    for r in range(1, len(scene.objects) + 1):
        for sub in itertools.combinations(scene.object_names, r):
            rewards = planner.nominal_rewards(attrs.evolve(scene, relevant=frozenset(sub)))
            best.add(tuple(np.flatnonzero(rewards >= rewards.max() - TIE_TOLERANCE)))
    return len(best) > 1


def evaluate(suite_name: str, robot: str) -> list[dict]:
    """One row per intent: truth, result and per-object outcome."""
    from gift.study.chain import StudyConfig, intent_seeds, simulator_name
    from gift.study.scenes import training_set

    cfg = StudyConfig(suite=suite_name, robot=robot)
    sim = gift.get_simulator(simulator_name(robot))
    suite = gift.load_suite(suite_name)
    rows = []
    for spec in suite.intents:
        pairs = training_set(sim, gift.get_task(spec.task), suite, spec, seeds=intent_seeds(cfg, spec.id)["train"],
                             demos=cfg.demos_per_scene, alternatives=cfg.alternatives_per_scene,
                             objects_per_scene=cfg.test_objects_per_scene).pairs()
        res = infer_relevant_objects(pairs, spec.train_objects)
        truth = set(spec.relevant_train)
        no_evidence = set(res.unobserved) | set(res.undetermined)
        wrong = [o for o in spec.train_objects if o not in no_evidence and (o in truth) != (o in res.relevant)]
        lenient_wrong = [o for o in spec.train_objects if (o in truth) != (o in res.relevant)]
        informative = sum(e.chosen for e in res.evidence.values())
        scenes = {id(p.scene): p.scene for p in pairs}.values()
        passing = any(m == "passing" for m in res.modes.values())
        depends = [_depends_on_relevance(sim, s) for s in scenes] if passing else []
        rows.append({"suite": suite.name, "robot": robot, "intent": spec.id, "task": spec.task,
                     "objects": list(spec.train_objects), "truth": sorted(truth), "result": res,
                     "wrong": wrong, "lenient_wrong": lenient_wrong, "no_evidence": sorted(no_evidence),
                     "pairs": len(pairs), "informative": informative, "depends": depends})
    return rows


def _names(names) -> str:
    return ", ".join(names) if names else "–"


def table(rows: list[dict]) -> list[str]:
    out = [("| intent | task | relevant (suite) | inferred relevant | wrong | no evidence | informative pairs | "
            "posterior P(relevant) |"), "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        res = r["result"]
        post = ", ".join(f"{o} {res.scores[o]:.2f}" for o in r["objects"] if o in res.scores)
        unobs = [f"{o} (unobserved)" for o in res.unobserved]
        undet = [f"{o} (undetermined)" for o in res.undetermined]
        out.append(f"| `{r['intent']}` | `{r['task']}` | {_names(r['truth'])} | {_names(res.relevant)} | "
                   f"{_names(r['wrong'])} | {_names(unobs + undet)} | {r['informative']:g} / {r['pairs']} | {post} |")
    return out


def summary(rows: list[dict]) -> list[str]:
    def count(sel):
        n = sum(len(r["objects"]) for r in sel)
        wrong = sum(len(r["wrong"]) for r in sel)
        none = sum(len(r["no_evidence"]) for r in sel)
        lenient = sum(len(r["lenient_wrong"]) for r in sel)
        return n, n - wrong - none, wrong, none, n - lenient

    out = [("| robot | families | training objects | right | wrong | no evidence | right / all | "
            "membership right / all |"), "|---|---|---|---|---|---|---|---|"]
    robots = sorted({r["robot"] for r in rows}, key=[r["robot"] for r in rows].index)
    for robot in robots + ["both"]:
        sel_r = [r for r in rows if robot in ("both", r["robot"])]
        for label, sel in (("all four", sel_r), ("without place_mug", [r for r in sel_r if r["task"] != "place_mug"])):
            n, right, wrong, none, member = count(sel)
            out.append(f"| {robot} | {label} | {n} | {right} | {wrong} | {none} | {right / n:.1%} | "
                       f"{member / n:.1%} |")
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("--suites", default=",".join(DEFAULT_SUITES))
    p.add_argument("--robots", default="jaco,franka")
    p.add_argument("--out", default=None, help="also write the Markdown report here")
    args = p.parse_args(argv)
    logging.getLogger("drake").setLevel(logging.ERROR)
    suites = [s for s in args.suites.split(",") if s]
    robots = [r for r in args.robots.split(",") if r]
    from gift.study.chain import StudyConfig

    cfg = StudyConfig()
    rows: list[dict] = []
    lines = [(f"Generated by `scripts/relevant_objects.py` at commit `{_commit()}`; reproduce sizes: "
              f"{cfg.train_scenes} training scenes per intent, {cfg.demos_per_scene} preferred/default pairs per "
              f"scene, {cfg.test_objects_per_scene} objects per scene; scene seeds `intent_seeds`."), ""]
    for suite_name in suites:
        suite = gift.load_suite(suite_name)
        digest = hashlib.sha256(Path(suite.path).read_bytes()).hexdigest()[:12]
        for robot in robots:
            part = evaluate(suite_name, robot)
            rows += part
            lines += [f"### {_suite_label(suite)}, drake-{robot} (suite sha256 `{digest}`)", "", *table(part), ""]
    depends = [d for r in rows for d in r["depends"] if d is not None]
    lines += ["### Summary", "", *summary(rows), ""]
    if depends:
        lines += [(f"place_mug training scenes whose best demonstrated action changes with the relevant set at "
                   f"all: {sum(depends)} of {len(depends)}."), ""]
    text = "\n".join(lines)
    print(text)
    if args.out:
        out = Path(args.out)
        head = out.read_text(encoding="utf-8").split("<!-- generated -->")[0] if out.exists() else ""
        out.write_text(head + "<!-- generated -->\n" + text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
