"""Where users meet queries: `gift align --ask N` on a real terminal session (answers on stdin, saved, not asked
again) and `gift evaluate-alignment --queries N` answered from the suite's labels; real MiniLM kernel."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gift.cli import main
from gift.core.suite import load_suite

pytestmark = pytest.mark.slow

SUITE = str(Path(__file__).parent / "data" / "mini_suite.yaml")
ALIGN = [sys.executable, "-m", "gift.cli", "align", "--suite", SUITE,
         "--train", "paintbrush", "sketchbook", "banana", "coffee mug",
         "--test", "watercolor set", "colored pencils", "toothbrush", "broomstick", "apple", "stapler",
         "--relevant", "paintbrush", "sketchbook", "--intent", "pack art supplies",
         "--kernel", "language:use_descriptions=true"]


def gift_align(args, stdin, answers):
    p = subprocess.run(ALIGN + list(args) + ["--answers", str(answers)], input=stdin, capture_output=True, text=True,
                       timeout=600, env=dict(os.environ))
    return p.returncode, p.stdout, p.stderr


def test_gift_align_asks_on_the_terminal_saves_the_answers_and_a_rerun_does_not_ask_again(tmp_path, monkeypatch,
                                                                                          capsys):
    answers = tmp_path / "answers.json"
    # the first question gets a reply it cannot understand, then a valid one; the second names a training object
    code, out, err = gift_align(["--ask", "2", "--json"], "maybe\nn\nsketchbook\n", answers)
    assert code == 0, err
    asked = [line for line in err.splitlines() if line.startswith("question ")]
    assert len(asked) == 2 and "part of the goal \"pack art supplies\"?" in asked[0]
    assert "not understood" in err and "'maybe' is not yes / no / ? nor a training object" in err
    res = json.loads(out)
    q = res["queries"]
    first, second = q["answers"][0]["object"], q["answers"][1]["object"]
    assert q["answers"] == [{"object": first, "relevant": False, "plays": None},
                            {"object": second, "relevant": True, "plays": "sketchbook"}]
    rows = {r["object"]: r for r in res["alignment"]}
    assert rows[first]["target"] == "distractor" and rows[second]["target"] == "sketchbook"
    assert rows[second]["score"] == 1.0 and "1 yes / 1 no answers" in res["threshold_rule"]
    saved = json.loads(answers.read_text())
    (entry,) = saved["scenes"].values()
    assert entry["intent"] == "pack art supplies" and set(entry["answers"]) == {first, second}
    # a rerun with the same budget asks nothing (no stdin at all) and gives the same alignment
    code, out2, err2 = gift_align(["--ask", "2", "--json"], "", answers)
    assert code == 0, err2
    assert "question" not in err2 and "using 2 saved answer(s)" in err2
    assert json.loads(out2)["alignment"] == res["alignment"]
    # in this process from here on: a larger budget asks only the new question; end of input stops with the
    # answers kept
    args = ALIGN[3:] + ["--answers", str(answers)]
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    assert main(args + ["--ask", "3"]) == 1
    err3 = capsys.readouterr().err
    assert "question 1 of 1" in err3 and "no answer on stdin" in err3
    assert len(json.loads(answers.read_text())["scenes"][next(iter(saved["scenes"]))]["answers"]) == 2
    monkeypatch.setattr(sys, "stdin", io.StringIO("?\n"))
    assert main(args + ["--ask", "3", "--abstain", "0.5"]) == 0
    out4 = capsys.readouterr().out
    assert "answers used: 3" in out4 and "[abstained: held out like a distractor]" in out4
    assert "[answered: don't know]" in out4



def test_gift_align_names_a_bad_policy_or_budget(tmp_path, capsys):
    args = ALIGN[3:] + ["--answers", str(tmp_path / "a.json")]
    assert main(args + ["--ask", "1", "--policy", "psychic"]) == 1
    assert "unknown query policy 'psychic'; registered:" in capsys.readouterr().err
    assert main(args + ["--ask", "-1"]) == 1
    assert "--ask must be >= 0" in capsys.readouterr().err
    assert main(args + ["--abstain", "2"]) == 1
    assert "--abstain must be in [0, 1]" in capsys.readouterr().err


def test_evaluate_alignment_with_queries_answered_from_the_suite_labels(tmp_path, capsys):
    out = tmp_path / "res.json"
    code = main(["evaluate-alignment", "--suite", SUITE, "--kernels", "language", "--threshold",
                 "train-calibrated,oracle", "--queries", "2", "--policy", "uncertainty", "--abstain", "0.01",
                 "--out", str(out), "--executor", "serial", "-q"])
    assert code == 0
    table = capsys.readouterr().out
    assert "| language | train-calibrated +2q uncertainty abstain 0.01 (" in table
    res = json.loads(out.read_text())
    assert res["queries"] == {"n": 2, "policy": "uncertainty", "abstain": 0.01, "threshold": "train-calibrated",
                              "rescore": True, "move": "stay", "choose": "primary"}
    suite = load_suite(SUITE)
    k = res["kernels"]["language"]
    for spec in suite.intents:
        q = k["intents"][spec.id]["queries"]
        labels = {t.object: t.relevant for t in spec.test}
        assert q["asked"] == 2 and q["threshold"] == "train-calibrated"
        assert q["rescored"] is False  # re-scoring is the default, but the MiniLM kernel cannot use answers
        for a in q["answers"]:  # the simulated human answered from the labels; the answers are kept
            assert a["relevant"] == labels[a["object"]] and q["predicted"][a["object"]] == a["relevant"]
        m = q["metrics"]["train-calibrated"]["all"]
        assert m["tp"] == sum(q["predicted"][o] and labels[o] for o in labels)
        assert m["fp"] == sum(q["predicted"][o] and not labels[o] for o in labels)
        # the scores are in the results: the same session offline gives the same record
        from gift.core.alignment import AlignmentScores
        from gift.core.queries import QueryProblem, ask, labels_answerer
        from gift.study.scenes import stable_seed

        scores = AlignmentScores.from_dict(k["intents"][spec.id]["scores"])
        st = ask(QueryProblem.of(scores, "train-calibrated", abstain=0.01), "uncertainty", labels_answerer(labels), 2,
                 seed=stable_seed("queries", spec.id))
        assert st.to_dict()["predicted"] == q["predicted"] and st.cut == q["cut"]
    pooled = k["queries"]["all"]
    assert pooled["n"] == sum(len(s.test) for s in suite.intents)
    assert pooled["tp"] == sum(k["intents"][s.id]["queries"]["metrics"]["train-calibrated"]["all"]["tp"]
                               for s in suite.intents)
    assert main(["evaluate-alignment", "--suite", SUITE, "--kernels", "language", "--queries", "1",
                 "--policy", "psychic", "-q"]) == 1
    assert "unknown query policy 'psychic'" in capsys.readouterr().err
