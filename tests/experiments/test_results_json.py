"""``results.json`` and every other JSON gift writes is strict JSON: an undefined number is ``null``, never ``NaN``.

The AUC of a subset whose test objects are all relevant (or all irrelevant) is not defined; strict parsers
(``jq``, JavaScript, Go) reject a bare ``NaN``. The report's tables and figures read the ``null`` as missing.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gift.core.serialization import dumps, finite_values, to_jsonable, write_json
from gift_experiments.report import f1_table, headline_table, win_rate_table, write_report


def strict_loads(text: str):
    def reject(constant: str):
        raise AssertionError(f"not strict JSON: bare {constant}")

    return json.loads(text, parse_constant=reject)


def _metrics(f1: float, auc: float) -> dict:
    return {"n": 4, "tp": 1, "fp": 1, "tn": 1, "fn": 1, "precision": 0.5, "recall": 0.5, "f1": f1,
            "fp_rate": 0.5, "fn_rate": 0.5, "auc": auc}


def results_with_undefined_numbers() -> dict:
    nan = float("nan")
    return {
        "config": {"suite": "gift-paper", "seeds": 2},
        "rq1": {"art_supplies": {"language": {"mean": 0.7, "se": 0.01, "per_seed": [0.69, 0.71]},
                                 "vision": {"mean": np.float64(0.6), "se": 0.02, "per_seed": np.array([0.58, 0.62])}},
                "valuables": {"language": {"mean": nan, "se": nan, "per_seed": []},
                              "vision": {"mean": 0.55, "se": 0.0, "per_seed": [0.55]}}},
        "rq2": {"art_supplies": {"language": {"train-calibrated": {"all": _metrics(0.5, 0.75), "R": _metrics(0.4, nan),
                                                                   "lang": _metrics(0.0, np.float32("nan"))}}},
                "valuables": {"language": {"train-calibrated": {"all": _metrics(0.6, nan)}}}},
        "timing": {"align language": 1.5},
    }


def test_results_json_is_strict_and_writes_null_for_undefined_numbers(tmp_path):
    write_report(results_with_undefined_numbers(), tmp_path)
    text = (tmp_path / "results.json").read_text()
    saved = strict_loads(text)
    assert "NaN" not in text and "Infinity" not in text
    assert saved["rq2"]["art_supplies"]["language"]["train-calibrated"]["R"]["auc"] is None
    assert saved["rq2"]["art_supplies"]["language"]["train-calibrated"]["lang"]["auc"] is None
    assert saved["rq2"]["art_supplies"]["language"]["train-calibrated"]["all"]["auc"] == 0.75
    assert saved["rq1"]["valuables"]["language"]["mean"] is None
    assert saved["rq1"]["art_supplies"]["vision"]["per_seed"] == [0.58, 0.62]
    # the report reads its own results.json back: nulls are missing values, not errors
    report = write_report(saved, tmp_path / "again")
    assert (tmp_path / "again" / "win_rate.png").exists() and (tmp_path / "again" / "f1_train-calibrated.png").exists()
    assert "## RQ1" in report.read_text()


def test_tables_and_means_skip_nulls():
    saved = strict_loads(dumps(results_with_undefined_numbers()))
    table = win_rate_table(saved)
    mean_row = table.splitlines()[-1]
    assert "| valuables | 0.550 ± 0.000 | – |" in table  # columns: vision, language
    assert mean_row == "| **mean** | 0.575 | 0.700 |"  # language: only the defined 0.7
    f1 = f1_table(saved, "train-calibrated")
    assert "| valuables | 0.60 |" in f1 and "0.50 (AUC 0.75)" in f1
    head = headline_table({"franka": saved}, "train-calibrated")
    assert "| language | 0.700 | 0.550 |" in head


def test_the_strict_writer_refuses_what_strict_json_cannot_hold(tmp_path):
    assert dumps({"a": float("inf"), "b": [np.nan]}) == '{"a": null, "b": [null]}'
    assert dumps({"a": float("-inf")}, nonfinite="string") == '{"a": "-inf"}'
    with pytest.raises(ValueError, match=r"non-finite number at \$\.x\[1\]"):
        dumps({"x": [1.0, float("nan")]}, nonfinite="keep")
    path = write_json(tmp_path / "r.json", {"v": np.array([1.0, np.nan])})
    assert strict_loads(path.read_text()) == {"v": [1.0, None]}
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]  # no temporary file left behind
    before = path.read_text()
    with pytest.raises(ValueError):
        write_json(path, {"v": float("nan")}, nonfinite="keep")
    assert path.read_text() == before  # a failed write leaves the previous file as it was
    assert finite_values([1, None, float("nan"), 2.5, True, float("inf"), np.float32(0.5)]) == [1.0, 2.5, 0.5]
    assert to_jsonable(np.array([np.inf]), nonfinite="null") == [None]
    assert math.isinf(to_jsonable(np.array([np.inf]))[0])  # "keep" still keeps


def test_cli_json_outputs_are_strict(tmp_path, capsys):
    """``gift evaluate-alignment --out/--json`` on a suite whose S_R subset has one class (AUC undefined)."""
    from gift.cli import main

    pytest.importorskip("sentence_transformers")
    suite = tmp_path / "one-class.yaml"
    suite.write_text(
        "suite: one-class\n"
        "objects: {paintbrush: {}, sketchbook: {}, banana: {}, watercolor set: {}, toothbrush: {}}\n"
        "intents:\n"
        "  - {id: art, task: pack_backpack, text: pack art supplies, train_objects: [paintbrush, sketchbook, banana],\n"
        "     relevant_train: [paintbrush, sketchbook],\n"
        "     test: [{object: watercolor set, relevant: true},\n"
        "            {object: toothbrush, relevant: false, confounds: [lang]}]}\n")
    out = tmp_path / "res.json"
    assert main(["evaluate-alignment", "--suite", str(suite), "--kernels", "language", "--threshold", "non-oracle",
                 "--out", str(out), "--json", "--quiet", "--executor", "serial"]) == 0
    printed = strict_loads(capsys.readouterr().out)
    saved = strict_loads(out.read_text())
    assert saved["kernels"]["language"]["intents"]["art"]["metrics"]["non-oracle"]["R"]["auc"] is None
    assert printed["kernels"] == saved["kernels"]
