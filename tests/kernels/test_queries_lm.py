"""Each query policy on the real `gift-prob` kernel (embedded LM on llama.cpp, reduced: one intent, six test
objects), with answers simulated from the suite's labels. The kernel runs once; every session re-scores."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import gift
from gift.core.alignment import score_alignment
from gift.core.data import DISTRACTOR, Intent
from gift.core.metrics import binary_metrics
from gift.core.queries import (Answer, QueryProblem, align_with_queries, answered_cut, ask, asking, belief,
                               kernel_rescorer, labels_answerer, resolve)
from gift.core.suite import load_suite

pytestmark = [pytest.mark.slow, pytest.mark.lm]

SUITE = str(Path(__file__).parent / "data" / "lm_dev_suite.yaml")
TEST = ["colored pencils", "crayons", "toothbrush", "apple", "paint roller", "hairbrush"]
KSPEC = "gift-prob:ladder=always:rescore_with=ladder"


@pytest.fixture(scope="module")
def scene():
    gift_llm = pytest.importorskip("gift_llm")
    lm = gift_llm.get_default_lm()
    suite = load_suite(SUITE)
    spec = suite.intent("art_supplies")
    kernel = gift.get_kernel("gift-prob", lm=lm)
    test, train = suite.specs(TEST), suite.specs(spec.train_objects)
    intent = Intent(text=spec.text, source="ground-truth")
    scores = score_alignment(kernel, test, train, intent, relevant_train=spec.relevant_train)
    labels = {t.object: t.relevant for t in spec.test if t.object in TEST}
    return kernel, test, train, intent, spec, scores, labels


def f1(state, labels):
    return binary_metrics(state.predicted, [labels[t] for t in state.test]).f1


def test_the_real_kernel_reports_the_terms_the_disagreement_policy_reads(scene):
    *_, scores, labels = scene
    terms = scores.details["terms"]
    assert set(terms) == {"lm", "language"}
    for view in terms.values():
        assert len(view["test"]) == len(TEST) and len(view["train"]) == 4
    st = resolve(QueryProblem.of(scores))
    views = st.view_beliefs()
    assert set(views) == {"lm", "language"} and all(v.shape == (len(TEST),) for v in views.values())
    # the LM's log-odds order the test objects the same way its view does
    lm = np.asarray(terms["lm"]["test"])
    assert np.array_equal(np.argsort(lm, kind="stable"), np.argsort(views["lm"], kind="stable")) or \
        len(set(np.round(lm, 9))) < len(lm)


@pytest.mark.parametrize("policy", ["uncertainty", "disagreement", "error-bound", "random"])
def test_each_policy_asks_about_the_real_scores_and_the_answers_re_score_the_scene(scene, policy):
    *_, scores, labels = scene
    problem = QueryProblem.of(scores)
    before = resolve(problem)
    states = list(asking(problem, policy, labels_answerer(labels), 2, seed=1))
    after = states[-1]
    asked = [a.object for a in after.answers]
    assert len(asked) == 2 == len(set(asked))
    # what the policy asked first, recomputed from the kernel's numbers by its own definition
    d, cut = scores.decision, before.cut
    if policy == "uncertainty":
        assert asked[0] == TEST[int(np.argmin(np.round(np.abs(d - cut), 12)))]
    elif policy == "disagreement":
        views = []
        for view in scores.details["terms"].values():  # each term on the relevance scale: sigmoid(z-score)
            raw = np.array(view["test"] + view["train"])
            r = 1 / (1 + np.exp(-(raw - raw.mean()) / raw.std()))
            v = scores.with_relevance(r[: len(TEST)], r[len(TEST):])
            views.append(belief(v.decision, answered_cut(v, "train-calibrated", ())[0]))
        spread = np.ptp(np.stack(views), axis=0)
        assert spread[TEST.index(asked[0])] == pytest.approx(spread.max())
    elif policy == "error-bound":
        gain = gift.get_query_policy("error-bound").priority(before, np.random.default_rng(0))
        assert gain[TEST.index(asked[0])] == pytest.approx(gain.max())
    # answered objects are fixed to the human's answer; the cut is the train-calibrated cut with them
    for a in after.answers:
        i = TEST.index(a.object)
        assert a.relevant == labels[a.object] and after.predicted[i] == labels[a.object]
        assert (after.alignment.target(a.object) in ("paintbrush", "sketchbook")) == labels[a.object]
        assert after.alignment.target(a.object) == DISTRACTOR or after.alignment.scores[a.object] == 1.0
    assert after.cut == pytest.approx(answered_cut(scores, "train-calibrated", after.answers)[0])
    # the state after each answer is the scene re-scored, without the kernel (no new LM question)
    assert [len(s.answers) for s in states] == [0, 1, 2]
    everything = ask(problem, policy, labels_answerer(labels), len(TEST), seed=1)
    assert f1(everything, labels) == 1.0  # every object answered: every object right


def test_a_python_callback_on_the_real_kernel_without_new_lm_questions(scene):
    kernel, test, train, intent, spec, scores, labels = scene
    calls_before = kernel.calls
    asked = []

    def human(obj):
        asked.append(obj)
        return labels[obj]

    st = align_with_queries(kernel, test, train, intent, relevant_train=spec.relevant_train, answer=human, n=2,
                            abstain=0.02)
    assert kernel.calls == calls_before  # the kernel's answers are remembered: no LM call for the session
    assert len(asked) == 2 and [a.object for a in st.answers] == asked
    assert f1(st, labels) >= f1(resolve(QueryProblem.of(scores, abstain=0.02)), labels)
    assert all(abs(scores.decision[TEST.index(t)] - st.cut) < 0.02 for t in st.abstained)


def test_answers_re_name_the_real_ladder_and_re_score_the_scene(scene, monkeypatch):
    """Rule 5 on the real kernel: with the ladder on (an inferred intent), each answer names the ladder again
    with the answered objects and every object is asked about the new rungs."""
    from gift_kernels.lm_kernels import _zscore

    kernel, test, train, _, spec, _, labels = scene
    inferred = Intent(text=spec.text, source="inferred")  # gift-prob's ladder is on for inferred intents
    first = score_alignment(kernel, test, train, inferred, relevant_train=spec.relevant_train)
    assert first.details["ladder"]["categories"]
    monkeypatch.setattr(kernel, "rescore_with", "ladder")  # the default is "evidence" (the next test)
    rescore = kernel_rescorer(kernel, test, train, inferred, relevant_train=spec.relevant_train)
    calls = kernel.calls
    states = list(asking(QueryProblem.of(first, rescore=rescore), "uncertainty", labels_answerer(labels), 2))
    assert kernel.calls > calls  # a new ladder call and new yes/no questions
    assert [s.rescored for s in states] == [False, True, True]
    after = states[-1]
    lad = after.scores.details["ladder"]
    yes = [a.object for a in after.answers if a.relevant]
    no = [a.object for a in after.answers if not a.relevant]
    assert lad["answers"] == {"yes": [t for t in TEST if t in yes], "no": [t for t in TEST if t in no]}
    assert lad["categories_before"] == first.details["ladder"]["categories"] and lad["train_held_out"] is False
    # the LM term is the mean of the z-scored goal term (unchanged) and the log-odds under the new rungs
    goal = np.asarray(lad["goal"])
    assert np.allclose(goal, first.details["ladder"]["goal"])
    rungs = [np.asarray(t["test"] + t["train"]) for t in lad["terms"]]
    assert len(rungs) == len(lad["categories"]) >= 1
    lm = np.mean([_zscore(v) for v in [goal, *rungs]], axis=0)
    assert np.allclose(after.scores.details["terms"]["lm"]["test"], lm[: len(TEST)])
    # answered objects are fixed; the unasked ones are decided by the re-scored scene at the state's cut
    for i, t in enumerate(TEST):
        a = after.answer_of(t)
        want = labels[t] if a is not None else after.scores.decision[i] >= after.cut
        assert after.predicted[i] == want
    # the same answers again: every LM answer is remembered
    calls = kernel.calls
    again = ask(QueryProblem.of(first, rescore=rescore), "uncertainty", labels_answerer(labels), 2)
    assert kernel.calls == calls and np.array_equal(again.predicted, after.predicted)


def test_answers_as_evidence_re_score_the_real_scene_without_asking_the_lm(scene):
    """rescore_with="evidence" on the real kernel (an inferred intent: the ladder and MiniLM on): the answers
    re-weigh the ladder's categories and the MiniLM references with no new LM question; the check's AUCs are
    the training objects' in-sample log-odds pooled with the answered objects', and no object is its own
    MiniLM reference."""
    from gift.core.metrics import roc_auc

    kernel, test, train, _, spec, _, labels = scene
    inferred = Intent(text=spec.text, source="inferred")
    first = score_alignment(kernel, test, train, inferred, relevant_train=spec.relevant_train)
    assert kernel.rescore_with == "evidence"  # the default
    rescore = kernel_rescorer(kernel, test, train, inferred, relevant_train=spec.relevant_train)
    calls = kernel.calls
    states = list(asking(QueryProblem.of(first, rescore=rescore), "uncertainty", labels_answerer(labels), 2))
    assert kernel.calls == calls  # nothing new asked of the LM
    assert [s.rescored for s in states] == [False, True, True]
    after = states[-1]
    det = after.scores.details
    answered = {a.object: a.relevant for a in after.answers}
    assert det["evidence"] == {"yes": [t for t in TEST if answered.get(t) is True],
                               "no": [t for t in TEST if answered.get(t) is False]}
    # the check: each category's AUC over the training objects (in-sample) and the answered test objects
    lad = det["ladder"]
    assert lad["categories"] == first.details["ladder"]["categories"]  # no category named again
    idx = [TEST.index(t) for t in TEST if t in answered]
    rel = np.asarray(first.relevant_mask, dtype=bool)
    cats = [det["category"], *lad["categories"]]
    views = [np.asarray(lad["goal"])] + [np.asarray(t["test"] + t["train"]) for t in lad["terms"]]
    for c, v, auc in zip(cats, views, lad["check"]["in_sample_auc"]):
        lo_train = kernel.log_odds(train, inferred, [c] * len(train))
        want = roc_auc(np.concatenate([lo_train, v[idx]]), np.concatenate([rel, [answered[TEST[i]] for i in idx]]))
        assert auc == pytest.approx(want)
    assert kernel.calls == calls  # the in-sample questions were remembered from the first scoring
    # MiniLM (the default reference, "prototype"): mean similarity to the relevant training and answered objects
    # less that to the others, never to itself
    refs = list(train) + [test[i] for i in idx]
    ref_rel = np.concatenate([rel, [answered[TEST[i]] for i in idx]])
    sim = np.asarray(kernel.language.similarity(list(test), refs), dtype=float)
    for j, i in enumerate(idx):
        sim[i, len(train) + j] = np.nan
    assert kernel.embed_reference == "prototype"
    want = np.nanmean(np.where(ref_rel, sim, np.nan), axis=1) - np.nanmean(np.where(~ref_rel, sim, np.nan), axis=1)
    assert np.allclose(det["terms"]["language"]["test"], want)
    for i, t in enumerate(TEST):
        a = after.answer_of(t)
        assert after.predicted[i] == (labels[t] if a is not None else after.scores.decision[i] >= after.cut)


def test_expected_error_looks_ahead_with_the_real_kernels_re_scoring_without_asking_the_lm(scene):
    """``expected-error`` on the real kernel (an inferred intent, answers weighed as evidence): each object it
    weighs is resolved with a "yes" and a "no", each re-scoring the real scene; no LM question is asked."""
    kernel, test, train, _, spec, _, labels = scene
    inferred = Intent(text=spec.text, source="inferred")
    first = score_alignment(kernel, test, train, inferred, relevant_train=spec.relevant_train)
    problem = QueryProblem.of(first, rescore=kernel_rescorer(kernel, test, train, inferred,
                                                             relevant_train=spec.relevant_train))
    calls = kernel.calls
    before = resolve(problem)
    pol = gift.get_query_policy("expected-error")
    gain = pol.priority(before, np.random.default_rng(0))
    p = before.belief()
    left = lambda b: float(np.minimum(b, 1 - b).sum())
    for i, t in enumerate(TEST):  # width 6: every object of this scene is weighed, by the policy's definition
        yes, no = (resolve(problem, [Answer(t, said)]) for said in (True, False))
        assert yes.rescored and no.rescored
        assert gain[i] == pytest.approx(left(p) - (p[i] * left(yes.belief()) + (1 - p[i]) * left(no.belief())))
    states = list(asking(problem, pol, labels_answerer(labels), 2))
    assert kernel.calls == calls  # every re-scoring weighed the answers as evidence: no LM question
    assert states[1].answers[0].object == TEST[int(np.argmax(np.round(gain, 12)))] or \
        np.isclose(gain[TEST.index(states[1].answers[0].object)], gain.max())
    after = states[-1]
    assert len({a.object for a in after.answers}) == 2 and after.rescored
    for a in after.answers:
        assert after.predicted[TEST.index(a.object)] == labels[a.object]


def test_evaluate_alignment_queries_re_score_with_the_real_ladder_unless_told_not_to(tmp_path, capsys):
    """``gift evaluate-alignment --queries 1`` on one intent with gift-prob's ladder on and
    ``rescore_with=ladder``: the answer re-names the ladder (rule 5; re-scoring is the default); with
    ``--no-rescore`` the session only re-thresholds the same first scores."""
    from gift.cli import main

    runs = {}
    for flag in ([], ["--no-rescore"]):
        out = tmp_path / f"res{len(flag)}.json"  # res0: re-scoring (the default), res1: --no-rescore
        assert main(["evaluate-alignment", "--suite", SUITE, "--kernels", KSPEC, "--intents",
                     "art_supplies", "--threshold", "train-calibrated", "--queries", "1", "--out", str(out),
                     "--executor", "serial", "-q"] + flag) == 0
        runs[not flag] = json.loads(out.read_text())
    on, off = runs[True], runs[False]
    assert on["queries"]["rescore"] is True and off["queries"]["rescore"] is False
    q_on = on["kernels"][KSPEC]["intents"]["art_supplies"]["queries"]
    q_off = off["kernels"][KSPEC]["intents"]["art_supplies"]["queries"]
    assert q_on["rescored"] is True and q_off["rescored"] is False
    assert q_on["rescored_ladder"] and q_off["rescored_ladder"] == []
    assert q_on["answers"] == q_off["answers"]  # the same first question, from the same first scores
    labels = {t.object: t.relevant for t in load_suite(SUITE).intent("art_supplies").test}
    (a,) = q_on["answers"]
    assert a["relevant"] == labels[a["object"]] and q_on["predicted"][a["object"]] == a["relevant"]
    # without re-scoring, the session is the offline one on the saved scores
    from gift.core.alignment import AlignmentScores
    from gift.study.scenes import stable_seed

    scores = AlignmentScores.from_dict(off["kernels"][KSPEC]["intents"]["art_supplies"]["scores"])
    st = ask(QueryProblem.of(scores, "train-calibrated"), "uncertainty", labels_answerer(labels), 1,
             seed=stable_seed("queries", "art_supplies"))
    assert st.to_dict()["predicted"] == q_off["predicted"]
