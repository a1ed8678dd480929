"""report.html from older or partial results.json files (no Drake, no LM, no browser: the page is written and
says what is missing), and the label placement of the similarity scatter PNG."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import attrs
import numpy as np
import pytest

import gift
from gift_experiments.html_report import write_html_report
from gift_experiments.report import place_labels

ROOT = Path(__file__).resolve().parents[2]
DEMO = Path(__file__).parent / "data" / "demo_before_alignments"  # gift demo at commit b13a016
FRANKA = ROOT / "docs" / "results" / "reproduce" / "franka" / "results.json"


def _sections(page: str) -> list[str]:
    return re.findall(r'<section id="([^"]+)">', page)


def test_committed_demo_results_give_a_page_with_every_section(tmp_path):
    """The results.json of the committed demo predates per-object alignments and LM records."""
    out = tmp_path / "demo"
    shutil.copytree(DEMO, out)
    page = write_html_report(json.loads((out / "results.json").read_text()), out, render=False).read_text()
    assert _sections(page) == ["run", "headline", "intent-art_supplies", "views", "rq3", "sanity", "lm-calls",
                               "failures", "timing", "figures"]
    assert 'class="section-error"' not in page
    # the 22 test objects of gift-paper's art_supplies, labelled from the suite, without renders or decisions
    assert page.count('class="object-row"') == 22
    assert page.count("no render") == 22
    assert "No LM call record" in page and "RQ3 did not run" in page
    assert "The person wanted to pick up the sketchbook" in page and "pack art supplies" in page
    assert page.count("<img") == 4  # the four PNG figures of the folder, inlined
    assert not re.search(r'(src|href)="https?:', page)  # nothing fetched


def test_partial_results_and_intent_candidates(tmp_path):
    results = {"config": {"suite": "gift-paper", "robot": "jaco", "thresholds": ["train-calibrated"]},
               "intents": {"valuables": {"text": "pack the valuable things", "source": "inferred",
                                         "candidates": [{"text": "pack the valuable things", "score": 0.71},
                                                        "pack the jewellery"]}},
               "errors": ["valuables/gift: LM answers completed by default: 'ring' unmapped"]}
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page
    assert "<b>Candidates</b>" in page and "pack the jewellery" in page and "score 0.710" in page
    assert "No win rates or alignment scores" in page
    assert "&#x27;ring&#x27; unmapped" in page  # the failure, escaped
    assert page.count('class="object-row"') == len(gift.load_suite("gift-paper").intent("valuables").test)


def test_the_category_and_the_ladder_gift_prob_asked_about_are_shown(tmp_path):
    """gift-prob's details (the goal's category, the ladder's rungs, the term weights) reach the intent's
    section; a kernel without them adds nothing."""
    block = {"cut": 0.5, "note": "boundary", "mapping": {}, "scores": {}}
    details = {"category": "necklaces", "ladder": {"categories": ["diamond jewelry", "pearl jewelry",
                                                                  "things for decoration"]},
               "weights": {"lm": 0.43, "language": 0.57}}
    results = {"config": {"suite": "gift-paper", "robot": "jaco", "thresholds": ["train-calibrated"]},
               "intents": {"valuables": {"text": "store the pearl necklace", "source": "inferred"}},
               "alignment": {"valuables": {"gift-prob": {"thresholds": {"train-calibrated": block},
                                                         "details": details},
                                           "language": {"thresholds": {"train-calibrated": block}}}}}
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page
    assert page.count('class="kernel-category"') == 1
    assert "one of the <q>necklaces</q>" in page
    assert "<q>diamond jewelry</q> &rarr; <q>pearl jewelry</q> &rarr; <q>things for decoration</q>" in page
    assert "lm 0.43, language 0.57" in page


def test_a_broken_section_is_reported_and_the_rest_is_written(tmp_path):
    results = {"config": {"thresholds": ["oracle"]}, "rq1": {"x": {"vision": {"mean": "not a number"}}},
               "timing": {"total": 3.0}}
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert page.count('class="section-error"') == 1 and '<section id="timing">' in page


@pytest.mark.parametrize("intent", ["art_supplies", "electronics"])
def test_scatter_labels_do_not_overlap(tmp_path, intent):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.text import Text

    block = json.loads(FRANKA.read_text())["scatter"][intent]
    pts = block["points"]
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    xs = np.array([p["language"] for p in pts] + [1.0])
    ys = np.array([p["vision"] for p in pts] + [1.0])
    ax.scatter(xs, ys)
    ax.set_xlim(xs.min() - 0.05, xs.max() + 0.05)
    ax.set_ylim(ys.min() - 0.05, ys.max() + 0.05)
    fig.tight_layout()
    texts = place_labels(ax, xs, ys, [p["object"] for p in pts] + ["anchor"])
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    boxes = [Text.get_window_extent(t, r) for t in texts]  # the text alone, not the leader line
    frame = ax.get_window_extent(r)
    assert len(boxes) == len(pts) + 1
    for i, a in enumerate(boxes):
        assert frame.x0 <= a.x0 and a.x1 <= frame.x1 and frame.y0 <= a.y0 and a.y1 <= frame.y1
        for b in boxes[i + 1:]:
            assert not a.overlaps(b), texts[i].get_text()
    plt.close(fig)


def test_recording_sets_the_record_file_for_the_block_only(tmp_path, monkeypatch):
    import os

    from gift_experiments.lm_calls import recording

    monkeypatch.delenv("GIFT_LM_RECORD", raising=False)
    monkeypatch.delenv("GIFT_LM", raising=False)
    out = tmp_path / "run"
    out.mkdir()
    (out / "lm_calls.jsonl").write_text('{"old": 1}\n')
    with recording(out) as path:
        assert os.environ["GIFT_LM_RECORD"] == str(path) and path == (out / "lm_calls.jsonl").resolve()
        assert path.read_text() == ""  # the calls of this invocation only
    assert "GIFT_LM_RECORD" not in os.environ
    # replaying the folder's own record: the file is kept, and not recorded over
    path.write_text('{"recorded": 1}\n')
    with recording(out, lm=f"replay:{out / 'lm_calls.jsonl'}"):
        assert "GIFT_LM_RECORD" not in os.environ and path.read_text() == '{"recorded": 1}\n'
    # the user's own record file wins
    monkeypatch.setenv("GIFT_LM_RECORD", str(tmp_path / "mine.jsonl"))
    with recording(out) as p:
        assert p == tmp_path / "mine.jsonl" and path.read_text() == '{"recorded": 1}\n'


def test_undefined_numbers_of_strict_json_show_as_missing(tmp_path):
    """results.json writes an undefined number (a one-class subset's AUC, an empty mean) as null."""
    from test_results_json import results_with_undefined_numbers

    from gift.core.serialization import to_jsonable

    results = to_jsonable(results_with_undefined_numbers(), nonfinite="null")
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page and "–" in page
    assert 'data-plot="win-rate"' in page


MINI = ROOT / "tests" / "kernels" / "data" / "mini_suite.yaml"


def fixed_kernel(rescored_details=None):
    """Scripted relevance kernel with fixed scores; with ``rescored_details`` it also re-scores with answers
    (the scores reversed, those details attached) and records each set of answers in ``.answers``."""
    from gift.core.data import RelevanceScores
    from gift.core.interfaces import RelevanceKernel

    class Fixed(RelevanceKernel):
        name = "fixed"

        def __init__(self):
            self.answers = []

        def score(self, test, train, intent=None, relevant_train=()):
            return RelevanceScores([0.1 + 0.4 * (i % 3) for i in range(len(test))],
                                   [0.8 if o.name in relevant_train else 0.2 for o in train],
                                   [o.name in relevant_train for o in train])

    class Rescoring(Fixed):
        name = "rescoring"

        def score_with_answers(self, test, train, intent, relevant_train, answers):
            self.answers.append(dict(answers))
            first = self.score(test, train, intent, relevant_train)
            return RelevanceScores(first.relevance[::-1], first.train_loo, first.relevant, dict(rescored_details))

    return Fixed() if rescored_details is None else Rescoring()


def results_with_queries() -> dict:
    """A study of one intent of the mini suite whose ``language`` row asked the simulated human 2 questions
    (:func:`gift.study.chain.query_stage` on fixed kernel scores; no kernel, no LM, no Drake)."""
    from gift.core.alignment import score_alignment
    from gift.core.serialization import to_jsonable
    from gift.study.chain import StudyConfig, query_label, query_stage

    suite = gift.load_suite(str(MINI))
    spec = suite.intent("valuables")
    scores = score_alignment(fixed_kernel(), suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                             relevant_train=spec.relevant_train)
    cfg = StudyConfig(suite=str(MINI), kernels=("language",), queries=2, query_policy="uncertainty",
                      thresholds=("train-calibrated",))
    q = query_stage(cfg, spec, scores)
    row = query_label("language", cfg)
    q0 = query_stage(attrs.evolve(cfg, queries=0), spec, scores)  # the kernel's own alignment
    before = {k: q0[k] for k in ("cut", "note", "mapping", "scores", "metrics")}
    results = {"config": {"suite": str(MINI), "robot": "franka", "kernels": ["language"], "queries": 2,
                          "query_policy": "uncertainty", "thresholds": ["train-calibrated"]},
               "alignment": {"valuables": {"language": {"thresholds": {"train-calibrated": before},
                                                         "scores": scores.to_dict(), "queries": q}}},
               "rq2": {"valuables": {"language": {"train-calibrated": q0["metrics"]["train-calibrated"]},
                                     row: {"train-calibrated": q["metrics"]["train-calibrated"]}}},
               "rq1": {"valuables": {"language": {"mean": 0.61, "se": 0.02, "per_seed": [0.6, 0.62]},
                                     row: {"mean": 0.7, "se": 0.01, "per_seed": [0.69, 0.71]},
                                     "oracle-labels": {"mean": 0.8, "se": 0.0, "per_seed": [0.8, 0.8]}}}}
    return to_jsonable(results, nonfinite="null")


def test_questions_asked_section_shows_policy_answers_and_before_after_plots(tmp_path):
    results = results_with_queries()
    q = results["alignment"]["valuables"]["language"]["queries"]
    row = "language +2q uncertainty"
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page
    assert _sections(page)[:3] == ["run", "headline", "queries"]
    section = page.split('<section id="queries">', 1)[1].split("</section>", 1)[0]
    assert "<h2>Questions asked</h2>" in section and f"<code>{row}</code>" in section and "uncertainty" in section
    f1_before = results["rq2"]["valuables"]["language"]["train-calibrated"]["all"]["f1"]
    f1_after = q["metrics"]["train-calibrated"]["all"]["f1"]
    assert f"{f1_before:.3f} → <b>{f1_after:.3f}</b>" in section and "0.610 → <b>0.700</b>" in section
    assert section.count('class="query-row"') == 1 and q["asked"] == 2
    for a in q["answers"]:  # the objects asked, in order, with the simulated human's answer
        word = "yes, relevant" if a["relevant"] else "no, not relevant"
        assert f'<li data-object="{a["object"]}"><b>{a["object"]}</b>: {word}' in section
    assert 'data-plot="queries-f1"' in section and 'data-plot="queries-win"' in section
    assert f"valuables / {row}: F1 {f1_after:.3f} (train-calibrated threshold), after 2 question(s): " in section
    assert "<title>valuables / language: win rate 0.610 ± 0.020, before the questions</title>" in section
    assert 'data-plot="query-curve' not in section  # no curves file
    assert not re.search(r'(src|href)="https?:', page)


def test_a_kernel_that_re_scores_with_the_answers_shows_its_new_ladder(tmp_path):
    """``query_rescore``: the study's session lets a kernel that implements ``score_with_answers`` score the
    scene again (fixed tables here; the real gift-prob: tests/kernels/test_queries_lm.py), the record names the
    ladder it named again, and report.html shows it under the answers."""
    from gift.core.alignment import score_alignment
    from gift.core.serialization import to_jsonable
    from gift.study.chain import StudyConfig, query_stage, rescorer

    suite = gift.load_suite(str(MINI))
    spec = suite.intent("valuables")
    kernel = fixed_kernel({"ladder": {"categories": ["jewelry", "small valuables"]}})
    scores = score_alignment(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                             relevant_train=spec.relevant_train)
    cfg = StudyConfig(suite=str(MINI), kernels=("language",), queries=2, query_policy="uncertainty",
                      thresholds=("train-calibrated",))
    assert cfg.query_rescore is True  # on by default
    off = attrs.evolve(cfg, query_rescore=False)
    assert rescorer(off, suite, spec, kernel, None, spec.relevant_train) is None
    q = query_stage(cfg, spec, scores, rescore=rescorer(cfg, suite, spec, kernel, None, spec.relevant_train))
    assert q["rescored"] is True and q["rescored_ladder"] == ["jewelry", "small valuables"]
    assert [len(a) for a in kernel.answers] == [1, 2]  # once per answer
    results = results_with_queries()
    results["alignment"]["valuables"]["language"]["queries"] = to_jsonable(q, nonfinite="null")
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert "re-scored with the answers; ladder named again: jewelry &gt; small valuables" in page


def test_answers_weighed_as_evidence_report_a_re_scoring_but_no_new_ladder(tmp_path):
    """gift-prob's default re-scoring (``rescore_with="evidence"``) keeps its first ladder: the record names no
    re-named ladder and report.html says only that the scene was re-scored."""
    from gift.core.alignment import score_alignment
    from gift.core.serialization import to_jsonable
    from gift.study.chain import StudyConfig, query_stage, rescorer

    suite = gift.load_suite(str(MINI))
    spec = suite.intent("valuables")
    kernel = fixed_kernel({"ladder": {"categories": ["jewelry"]}, "evidence": {"yes": [], "no": []}})
    scores = score_alignment(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                             relevant_train=spec.relevant_train)
    cfg = StudyConfig(suite=str(MINI), kernels=("language",), queries=2, query_policy="uncertainty",
                      thresholds=("train-calibrated",))
    q = query_stage(cfg, spec, scores, rescore=rescorer(cfg, suite, spec, kernel, None, spec.relevant_train))
    assert q["rescored"] is True and q["rescored_ladder"] == []
    results = results_with_queries()
    results["alignment"]["valuables"]["language"]["queries"] = to_jsonable(q, nonfinite="null")
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert '<small class="rescored">re-scored with the answers</small>' in page
    assert "ladder named again" not in page


def test_no_questions_no_section(tmp_path):
    results = results_with_queries()
    del results["alignment"]["valuables"]["language"]["queries"]
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert "queries" not in _sections(page) and "Questions asked" not in page
    assert 'class="section-error"' not in page


CURVES = {"command": "python scripts/query_curves.py --suites mini",
          "runs": {"mini | ground-truth": {
              "grid": [0, 1, 2],
              "curves": {"uncertainty": {"f1": [0.5, 0.7, 0.9], "win": [0.6, 0.65, 0.7], "asked": [0, 1, 2]},
                         "random": {"f1": [0.5, 0.55, 0.6], "f1_se": [0.0, 0.02, 0.03],
                                    "win": [None, None, None], "asked": [0, 1, 2]}}}}}


def test_query_curves_from_gift_report(tmp_path):
    """``gift report OUT --query-curves FILE``: the curves per policy (random with its band) in the section,
    kept in OUT for later regenerations; a run without questions gets the section for the curves alone."""
    from gift.cli import main

    results = results_with_queries()
    del results["alignment"]["valuables"]["language"]["queries"]
    (tmp_path / "results.json").write_text(json.dumps(results))
    (tmp_path / "curves.json").write_text(json.dumps(CURVES))
    assert main(["report", str(tmp_path), "--no-render", "--query-curves", str(tmp_path / "curves.json")]) == 0
    page = (tmp_path / "report.html").read_text()
    assert 'class="section-error"' not in page and "queries" in _sections(page)
    section = page.split('<section id="queries">', 1)[1].split("</section>", 1)[0]
    assert 'class="query-row"' not in section and "python scripts/query_curves.py --suites mini" in section
    assert section.count('data-plot="query-curve-f1"') == 1 and section.count('data-plot="query-curve-win"') == 1
    assert section.count('class="band"') == 1  # random's ± s.e. on F1; its win rate is undefined: no curve
    assert ("<title>mini | ground-truth: random, 2 question(s) per intent: alignment F1 (pooled) 0.600 ± 0.030 "
            "(s.e. over seeds)</title>") in section
    assert section.count('class="curve"') == 3  # F1: uncertainty, random; win rate: uncertainty
    # kept in the folder: regenerating without the option draws them again
    assert main(["report", str(tmp_path), "--no-render"]) == 0
    assert 'data-plot="query-curve-f1"' in (tmp_path / "report.html").read_text()
    bad = tmp_path / "bad.json"
    bad.write_text('{"x": 1}')
    assert main(["report", str(tmp_path), "--no-render", "--query-curves", str(bad)]) != 0


def test_the_kernels_as_built_are_in_the_run_section(tmp_path):
    """A result whose alignment records carry ``configuration`` (``repr`` of the kernel as built) shows them;
    the committed Franka run predates the record and shows none."""
    results = json.loads(FRANKA.read_text())
    page = write_html_report(results, tmp_path / "old", render=False).read_text()
    assert "kernels as built" not in page
    for rec in results["alignment"]["valuables"].values():
        rec["configuration"] = "LanguageKernel(use_descriptions=False, names=True)"
    page = write_html_report(results, tmp_path / "new", render=False).read_text()
    assert "kernels as built" in page and "LanguageKernel(use_descriptions=False, names=True)" in page


def test_the_answers_per_build_of_the_lm_runtime_are_listed_in_the_usage_line(tmp_path):
    results = {"config": {"suite": "gift-paper", "robot": "jaco", "thresholds": ["train-calibrated"]},
               "manifest": {"lm": {"identity": "llamacpp:m.gguf",
                                   "usage": {"requests": 3, "hits": 3, "latency_s": 0.25,
                                             "made_by": {"0.3.36; CPU : AVX512 = 1": 2, "unrecorded": 1}}}}}
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page
    assert "LM usage of the run: requests 3, hits 3, latency_s 0.2" in page
    assert "made_by (0.3.36; CPU : AVX512 = 1: 2; unrecorded: 1)" in page
