"""``scripts/recombine_terms.py`` on a committed evaluation result: the default re-combination reproduces the saved
gift-prob decisions and F1 (real MiniLM), an after-LM option changes them, bad input is refused by name."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import script_module  # this directory: scripts/ files as modules

ROOT = Path(__file__).resolve().parents[2]
RESULT = ROOT / "docs" / "results" / "data" / "front_half" / "gift-dev5-inferred.json"

pytestmark = pytest.mark.slow  # MiniLM


def load_script():
    return script_module.load_script("recombine_terms")


def test_the_default_reproduces_the_run_and_the_description_option_changes_it():
    mod = load_script()
    variants = [mod.parse_variant("default"), mod.parse_variant("embed_text=description")]
    out = mod.rescore(str(RESULT), variants)
    recorded = json.loads(RESULT.read_text(encoding="utf-8"))["kernels"]["gift-prob"]["overall"]
    # every intent of this run has 2+ inferred relevant objects, so the recorded cut is the prior 1/2 throughout
    assert mod.f1(out["default"]["tc"]) == pytest.approx(recorded["train-calibrated"]["all"]["f1"])
    assert mod.f1(out["default"]["oracle"]) == pytest.approx(recorded["oracle"]["all"]["f1"])
    # a run made before the default changed: identified as name+description by reproducing its decisions
    assert out["default"]["options"]["embed_text"] == "name+description"
    desc = out["embed_text=description"]
    assert not np.array_equal(desc["tc"], out["default"]["tc"]) or desc["auc"] != out["default"]["auc"]
    assert out["default"]["lang"][1] == desc["lang"][1] > 0  # the same named-alike distractors, counted
    # per intent: the recorded train-calibrated F1 of each intent, and a table with the surface kernels beside it
    intents = json.loads(RESULT.read_text(encoding="utf-8"))["kernels"]["gift-prob"]["intents"]
    assert out["default"]["intents"] == pytest.approx(
        {i: r["metrics"]["train-calibrated"]["all"]["f1"] for i, r in intents.items()})
    text = mod.per_intent_table(str(RESULT), out, ["default", "embed_text=description"])
    assert "| intent | default | embed_text=description | language | vision |" in text
    assert len([ln for ln in text.splitlines() if ln.startswith("| ") and "intent" not in ln]) == len(intents)
    # what made the numbers: the run's commit, suite and model hashes, as recorded in the file
    manifest = json.loads(RESULT.read_text(encoding="utf-8"))["manifest"]
    note = mod.provenance([str(RESULT)])
    assert f"commit `{manifest['git']['commit'][:7]}`" in note and manifest["suite"]["sha256"][:12] in note
    assert manifest["lm"]["model_sha256"][:12] in note


def test_questions_on_the_rescored_scenes_match_the_query_curves_of_the_same_run():
    """``--queries``: on the run's own options, F1 after k `uncertainty` questions is the one the committed query
    curves measured for this suite (`scripts/query_curves.py`, real chain); answers only fix their objects, so
    F1 never falls with more questions."""
    mod = load_script()
    variants = [mod.parse_variant("default"), mod.parse_variant("embed_text=description")]
    out = mod.rescore(str(RESULT), variants)
    curves = json.loads((ROOT / "docs" / "results" / "queries" / "curves.json").read_text(encoding="utf-8"))
    run = curves["runs"]["gift-dev5 | inferred"]
    counts = mod.after_queries(out, "default", run["grid"], "uncertainty")
    assert [mod.f1(c) for c in counts] == pytest.approx(run["curves"]["uncertainty"]["f1"])
    assert np.array_equal(counts[0], out["default"]["tc"])
    desc = [mod.f1(c) for c in mod.after_queries(out, "embed_text=description", [0, 1, 2, 4], "uncertainty")]
    assert desc == sorted(desc) and desc[0] == pytest.approx(mod.f1(out["embed_text=description"]["tc"]))
    text = mod.queries_table({str(RESULT): out}, ["default"], [0, 2], "uncertainty")
    assert "| gift-dev5-inferred.json | default | 0.841 | 0.920 |" in text


def test_a_file_not_made_by_this_gift_prob_and_bad_variants_are_refused(tmp_path):
    mod = load_script()
    res = json.loads(RESULT.read_text(encoding="utf-8"))
    rec = next(iter(res["kernels"]["gift-prob"]["intents"].values()))
    rec["scores"]["decision"] = [min(1.0, d + 0.1) for d in rec["scores"]["decision"]]
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(res), encoding="utf-8")
    with pytest.raises(SystemExit, match="reproduces the saved decisions"):
        mod.rescore(str(path), [mod.parse_variant("default")])
    with pytest.raises(SystemExit, match="options that act after the LM"):
        mod.parse_variant("template=kind")
    with pytest.raises(SystemExit, match="none of the kernels"):
        mod.rescore(str(RESULT), [mod.parse_variant("default")], kernel="gift")
    with pytest.raises(SystemExit, match="--queries: comma-separated whole numbers"):
        mod.main([str(RESULT), "--queries", "0,two"])
    with pytest.raises(SystemExit, match="--queries: comma-separated whole numbers >= 0"):
        mod.main([str(RESULT), "--queries", "-1"])
