"""``scripts/cut_distribution_probe.py`` on a committed evaluation result: the rule at the scale's boundary and the
recorded cut reproduce the run's own train-calibrated F1, the label-free rules place other cuts, and the
``--overview`` path re-scores a run with the kernel's code and scores it the same way (real MiniLM)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import script_module  # this directory: scripts/ files as modules

ROOT = Path(__file__).resolve().parents[2]
RESULT = ROOT / "docs" / "results" / "data" / "front_half" / "gift-dev29-inferred.json"


def test_the_boundary_rule_reproduces_the_recorded_f1():
    mod = script_module.load_script("cut_distribution_probe")
    out = mod.probe(str(RESULT))
    recorded = json.loads(RESULT.read_text(encoding="utf-8"))["kernels"]["gift-prob"]["overall"]
    assert out["recorded"] == pytest.approx(recorded["train-calibrated"]["all"]["f1"], abs=5e-4)
    assert out["boundary"] == out["recorded"]  # a run at the prior cut 1/2
    assert set(out) == set(mod.RULES)


def test_otsu_splits_two_clusters_between_them():
    mod = script_module.load_script("cut_distribution_probe")
    cut = mod.otsu(np.array([0.1, 0.15, 0.2, 0.7, 0.8]))
    assert 0.2 < cut < 0.7


@pytest.mark.slow  # MiniLM
def test_the_overview_path_rescores_a_run_like_the_file_path(monkeypatch):
    mod = script_module.load_script("cut_distribution_probe")
    monkeypatch.syspath_prepend(str(ROOT / "scripts"))
    import results_overview  # the module probe_overview imports

    one = [r for r in results_overview.RUNS if r.suite == "gift-dev29" and r.source == "inferred"]
    assert len(one) == 1
    monkeypatch.setattr(results_overview, "RUNS", tuple(one))
    out = mod.probe_overview(skip={"gift-paper"})
    # this run was made at the prototype reference, so re-scoring it changes nothing
    assert {r: v[0] for r, v in out["inferred"].items()} == mod.probe(str(RESULT))
