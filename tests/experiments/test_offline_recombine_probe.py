"""``scripts/offline_recombine_probe.py`` on a committed evaluation result (no LM, no MiniLM): the saved decisions are
recomputed from the saved terms, the kinds of test object let in are the run's own counts, and the LM veto only
ever takes objects out."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import script_module  # this directory: scripts/ files as modules

from gift.study.sweeps import recorded_suite

ROOT = Path(__file__).resolve().parents[2]
NAME = "gift-dev23-inferred.json"
RESULT = ROOT / "docs" / "results" / "data" / "front_half" / NAME


@pytest.fixture(scope="module")
def probe():
    return script_module.load_script("offline_recombine_probe")


@pytest.fixture(scope="module")
def run():
    return json.loads(RESULT.read_text(encoding="utf-8"))


def test_the_kinds_let_in_are_the_runs_own_counts(probe, run):
    counts = probe.kinds(run, recorded_suite(run, NAME), "gift-prob")
    intents = run["kernels"]["gift-prob"]["intents"].values()
    tc = [r["metrics"]["train-calibrated"] for r in intents]
    assert counts["named-alike"]["in"] == sum(m["lang"]["fp"] for m in tc)
    assert counts["look-alike"]["in"] == sum(m["vis"]["fp"] for m in tc)
    assert counts["member"]["in"] == sum(m["all"]["tp"] for m in tc)
    assert counts["member"]["n"] == sum(m["all"]["tp"] + m["all"]["fn"] for m in tc)
    assert counts["member"]["in"] + sum(counts[k]["in"] for k in probe.KINDS[1:]) == \
        sum(m["all"]["tp"] + m["all"]["fp"] for m in tc)
    assert sum(c["n"] for c in counts.values()) == sum(len(r["scores"]["test"]) for r in intents)
    for c in counts.values():
        assert 0 <= c["in"] <= c["n"] and 0 <= c["lm"] <= c["n"] and 0 <= c["minilm"] <= c["n"]


def test_the_saved_decisions_are_recomputed_and_the_veto_only_takes_objects_out(probe, run):
    suite = recorded_suite(run, NAME)
    saved = probe.scored(run, suite, "gift-prob")  # stops if a recomputed decision differs from the saved one
    assert probe.f1(saved) == pytest.approx(run["kernels"]["gift-prob"]["overall"]["train-calibrated"]["all"]["f1"])
    loose, strict = (probe.scored(run, suite, "gift-prob", combine=probe.lm_veto(level)) for level in (-1e9, 0.0))
    assert loose == saved  # a veto below every object changes nothing
    tp, fp, fn = strict
    assert tp + fn == saved[0] + saved[2] and tp <= saved[0] and fp <= saved[1]
