"""``scripts/oracle_gap.py`` on a committed evaluation result: the recorded cut's F1, labelled cuts out of sample."""

from __future__ import annotations

from pathlib import Path

import pytest
import script_module  # this directory: scripts/ files as modules

ROOT = Path(__file__).resolve().parents[2]
RESULT = ROOT / "docs" / "results" / "data" / "front_half" / "gift-dev5-inferred.json"


def load_script():
    return script_module.load_script("oracle_gap")


def test_gap_reproduces_the_recorded_f1_and_orders_the_labelled_cuts():
    mod = load_script()
    res, kernel, rows = mod.intents_of(str(RESULT))
    assert kernel == "gift-prob" and len(rows) == len(res["kernels"]["gift-prob"]["intents"])
    g = mod.gap(rows, splits=20)
    recorded = res["kernels"]["gift-prob"]["overall"]
    assert g["train_calibrated"] == pytest.approx(recorded["train-calibrated"]["all"]["f1"])
    assert g["oracle"] == pytest.approx(recorded["oracle"]["all"]["f1"])
    # out of sample a labelled cut cannot beat the in-sample maximum on the same objects
    assert g["leave_one_out"] <= g["oracle"] + 1e-12 and g["half_labelled"] <= g["half_oracle"] + 1e-12
    assert g["test_objects"] == sum(len(r[1]) for r in rows)

