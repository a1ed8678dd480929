"""evaluate-alignment and align: real MiniLM on a suite file, the CLI, failure isolation."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import gift
from gift.cli import main
from gift.core.suite import load_suite
from gift.study.chain import REPORT_SUBSETS
from gift.study.components import parse_spec
from gift.study.sweeps import evaluate_alignment

pytestmark = pytest.mark.slow

SUITE = str(Path(__file__).parent / "data" / "mini_suite.yaml")


def test_evaluation_reports_every_subset_threshold_and_intent_and_keeps_going_after_a_failure():
    res = evaluate_alignment(SUITE, ["language", "language:use_descriptions=true", "no-such-kernel"])
    assert res["suite"] == "kernels-mini" and res["thresholds"] == ["oracle", "non-oracle", "train-calibrated"]
    assert "no such" not in json.dumps(res["kernels"]["language"]["errors"])
    assert res["kernels"]["no-such-kernel"]["errors"]["*"].startswith("UnknownComponentError")
    suite = load_suite(SUITE)
    for name in ("language", "language:use_descriptions=true"):
        k = res["kernels"][name]
        assert not k["errors"] and set(k["intents"]) == {"art_supplies", "valuables"}
        for thr in res["thresholds"]:
            union = k["overall"][thr]["all"]
            assert union["n"] == sum(len(s.test) for s in suite.intents)
            assert union["tp"] + union["fn"] == sum(len(s.relevant_test) for s in suite.intents)
            assert set(k["overall"][thr]) == set(REPORT_SUBSETS)  # the mini suite has every subset
        # the oracle cut is an upper bound of F1 on each intent
        for r in k["intents"].values():
            f1 = {t: r["metrics"][t]["all"]["f1"] for t in res["thresholds"]}
            assert f1["oracle"] >= max(f1["non-oracle"], f1["train-calibrated"]) - 1e-12
            assert 0.0 <= r["metrics"]["oracle"]["all"]["auc"] <= 1.0
    # each kernel records every option it ran with, defaults included, as built from its spec
    assert res["kernels"]["language"]["configuration"] == "LanguageKernel(use_descriptions=False, names=True)"
    assert "use_descriptions=True" in res["kernels"]["language:use_descriptions=true"]["configuration"]
    # the language confound of the paper: toothbrush matches paintbrush by name
    obj = res["kernels"]["language"]["intents"]["art_supplies"]["objects"]
    assert obj["toothbrush"]["match"] == "paintbrush"
    json.dumps(res)  # everything is JSON-able


def test_train_calibrated_uses_no_test_label(tmp_path):
    text = Path(SUITE).read_text().replace("{object: toothbrush, relevant: false", "{object: toothbrush, relevant: true")
    flipped = tmp_path / "flipped.yaml"
    flipped.write_text(text)
    a = evaluate_alignment(SUITE, ["language"], thresholds=["train-calibrated", "oracle"])
    b = evaluate_alignment(str(flipped), ["language"], thresholds=["train-calibrated", "oracle"])
    ca = a["kernels"]["language"]["intents"]["art_supplies"]["thresholds"]
    cb = b["kernels"]["language"]["intents"]["art_supplies"]["thresholds"]
    assert ca["train-calibrated"] == cb["train-calibrated"]
    ma = a["kernels"]["language"]["intents"]["art_supplies"]["metrics"]["train-calibrated"]["all"]
    mb = b["kernels"]["language"]["intents"]["art_supplies"]["metrics"]["train-calibrated"]["all"]
    assert (ma["tp"], ma["fp"]) != (mb["tp"], mb["fp"])  # the labels did change, the cut did not


def test_cli_evaluate_alignment_json_and_table(tmp_path, capsys):
    out = tmp_path / "res.json"
    code = main(["evaluate-alignment", "--suite", SUITE, "--kernels", "language", "--threshold", "non-oracle",
                 "--intents", "valuables", "--out", str(out), "-q"])
    assert code == 0
    table = capsys.readouterr().out
    assert "| language | non-oracle | " in table and "| language | valuables | " in table
    saved = json.loads(out.read_text())
    assert list(saved["kernels"]["language"]["intents"]) == ["valuables"]
    assert main(["evaluate-alignment", "--suite", SUITE, "--kernels", "language", "--threshold", "median",
                 "-q"]) == 1
    assert "unknown threshold" in capsys.readouterr().err
    assert main(["evaluate-alignment", "--suite", str(tmp_path / "nope.yaml"), "--kernels", "language"]) == 1
    assert "nope.yaml" in capsys.readouterr().err


def test_cli_align_refuses_objects_outside_any_catalog_unless_allowed(capsys, tmp_path):
    # a name no catalog has would silently be a grey 8 cm cube without a description
    code = main(["align", "--train", "paintbrush", "flibbertigibbet", "--test", "zzyzx_thing", "--kernel", "vision"])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert "unknown objects 'flibbertigibbet', 'zzyzx_thing': not in the catalog of any registered suite" in err
    assert "--allow-unknown" in err
    assert main(["align", "--train", "paintbrush", "banana", "--test", "tooth brush", "--kernel", "vision"]) == 1
    assert "'tooth brush' (did you mean 'toothbrush'" in capsys.readouterr().err
    # with --suite FILE, only that file's catalog counts
    assert main(["align", "--train", "paintbrush", "banana", "--test", "molding clay", "--kernel", "language",
                 "--suite", SUITE]) == 1
    assert f"unknown object 'molding clay'" in (err := capsys.readouterr().err) and SUITE in err
    assert main(["align", "--train", "paintbrush", "banana", "--test", "sketchbook", "--relevant", "sketchbook",
                 "--kernel", "language"]) == 1
    assert "--relevant ['sketchbook']: not among the --train objects" in capsys.readouterr().err

    # an object no registered suite holds (suites grow: this precondition names the clash instead of the
    # warning silently disappearing, as "glue stick" and "tuning fork" did)
    from gift_kernels.cli import lookup_objects

    assert lookup_objects(["theremin"], None)[1] == ["theremin"], "pick another made-up object: a suite now has it"
    code = main(["align", "--train", "paintbrush", "sketchbook", "banana", "--test", "toothbrush", "theremin",
                 "--relevant", "paintbrush", "sketchbook", "--kernel", "language", "--threshold", "0.5", "--json",
                 "--allow-unknown"])
    assert code == 0
    captured = capsys.readouterr()
    assert "warning: 1 object(s) in no catalog" in captured.err and "theremin" in captured.err
    out = json.loads(captured.out)
    assert out["unknown_objects"]["names"] == ["theremin"]
    rows = {r["object"]: r for r in out["alignment"]}
    assert rows["toothbrush"]["target"] == "paintbrush" and rows["toothbrush"]["relevant"] is True
    assert out["threshold"] == 0.5 and np.array(out["similarity"]["K"]).shape == (2, 3)
    assert 0.0 <= out["error_bound_per_state"] <= 1.0
    assert main(["align", "--train", "a", "--test", "a", "--kernel", "language"]) == 1
    assert "both training and test" in capsys.readouterr().err
    assert main(["align", "--train", "a", "--test", "b", "--kernel", "language", "--threshold", "oracle"]) == 1


def test_kernel_specs():
    assert parse_spec("language:use_descriptions=true") == ("language", {"use_descriptions": True})
    assert parse_spec("gift:samples=3:temperature=0.7") == ("gift", {"samples": 3, "temperature": 0.7})
    with pytest.raises(gift.GiftError, match="key=value"):
        parse_spec("gift:samples")
