"""`gift reproduce --queries N`: the chain asks the simulated human after the alignment and measures the win
rate of the re-scored alignment next to the kernel's own (real Drake scenes, MaxEnt IRL, MiniLM)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gift.cli import main
from gift.core.suite import load_suite

pytestmark = [pytest.mark.slow, pytest.mark.drake]

SUITE = str(Path(__file__).parents[1] / "kernels" / "data" / "mini_suite.yaml")


def test_reproduce_with_queries_adds_a_row_per_kernel_scored_on_the_scenes_trajectories(tmp_path):
    out = tmp_path / "run"
    code = main(["reproduce", "--suite", SUITE, "--intents", "valuables", "--kernels", "language",
                 "--intent-source", "ground-truth", "--queries", "2", "--policy", "error-bound", "--sanity-reps", "0",
                 "--no-rq3", "--seeds", "2", "--pairs", "40", "--train-scenes", "2", "--trajectories", "4",
                 "--thresholds", "train-calibrated,oracle", "--out", str(out), "--executor", "serial", "-q"])
    assert code == 0
    res = json.loads((out / "results.json").read_text())
    row = "language +2q error-bound"
    assert res["config"]["queries"] == 2 and res["config"]["query_policy"] == "error-bound"
    rq1 = res["rq1"]["valuables"]
    assert set(rq1) == {"language", row, "oracle-labels"}
    assert 0.0 <= rq1[row]["mean"] <= 1.0 and len(rq1[row]["per_seed"]) == 2
    q = res["alignment"]["valuables"]["language"]["queries"]
    assert q["bound_over"] == "trajectories" and q["asked"] == 2 and q["error_bound"] >= 0.0
    labels = {t.object: t.relevant for t in load_suite(SUITE).intent("valuables").test}
    for a in q["answers"]:
        assert a["relevant"] == labels[a["object"]] and q["predicted"][a["object"]] == labels[a["object"]]
        assert (q["mapping"][a["object"]] != "distractor") == labels[a["object"]]
    rq2 = res["rq2"]["valuables"][row]
    assert set(rq2) == {"train-calibrated"} and rq2["train-calibrated"]["all"]["n"] == len(labels)
    report = (out / "report.md").read_text()
    assert row in report  # the row is in the win-rate and F1 tables of the report
