"""The offline part of the query curves (gift_experiments.query_curves) on fixed kernel scores: every policy at
every k, random over seeds, abstention, the questions random needs, and the figure."""

from __future__ import annotations

import attrs
import numpy as np
import pytest

from gift.core.alignment import score_alignment
from gift.core.data import ObjectSpec, RelevanceScores
from gift.core.interfaces import RelevanceKernel
from gift_experiments import query_curves as qc


class Table(RelevanceKernel):
    name = "table"

    def __init__(self, test, train):
        self.test, self.train = test, train

    def score(self, test, train, intent=None, relevant_train=()):
        return RelevanceScores([self.test[o.name] for o in test], [self.train[o.name] for o in train],
                               [o.name in relevant_train for o in train])


def intent(name, test, labels):
    train = {"a": 0.8, "b": 0.7, "c": 0.3, "d": 0.2}
    scores = score_alignment(Table(test, train), [ObjectSpec(n) for n in test], [ObjectSpec(n) for n in train],
                             relevant_train=("a", "b"))
    return qc.IntentData(name, scores, labels)


DATA = [intent("one", {"x": 0.9, "y": 0.55, "z": 0.45, "w": 0.1}, {"x": True, "y": False, "z": True, "w": False}),
        intent("two", {"p": 0.6, "q": 0.52, "r": 0.4, "s": 0.35, "t": 0.05},
               {"p": False, "q": True, "r": True, "s": False, "t": False})]


def test_every_policy_at_every_k_with_random_over_seeds_and_abstention():
    sim = qc.simulate(DATA, random_seeds=4, bands=(0.06,))
    assert sim["grid"] == [0, 1, 2, 4, 8] and set(sim["curves"]) == set(qc.POLICIES) | {"random"}
    for policy, c in sim["curves"].items():
        # no question: the kernel's own train-calibrated alignment, the same for every policy
        assert c["f1"][0] == sim["curves"]["uncertainty"]["f1"][0]
        # every object answered (8 >= 5 objects per intent): every object right
        assert c["f1"][-1] == 1.0 and c["asked"] == [0, 1, 2, 4, 4.5]
        assert c["win"] == [None] * 5  # no scenes: no win rate
        assert ("f1_se" in c) == (policy == "random")
    # k = 0: one: x, y predicted (y wrong), z missed; two: p, q predicted (p wrong), r missed -> tp 2 fp 2 fn 2
    assert sim["curves"]["uncertainty"]["f1"][0] == pytest.approx(0.5)
    assert sim["per_intent"]["uncertainty"]["one"]["asked"][:2] == ["y", "z"]
    a = sim["abstention"]["0.06"]
    assert a["abstained"] == 3  # y, z (0.05 from the cut 0.5) and q (0.02)
    t = qc.target_check(sim)
    assert t["best"] in qc.POLICIES and [r["k"] for r in t["rows"]] == [1, 2, 4]


def _wrong(state, labels):
    return int(sum(state.predicted[i] != labels[t] for i, t in enumerate(state.test)))


def test_the_ceiling_asks_the_best_two_questions_and_no_policy_gets_fewer_wrong_decisions():
    sim = qc.simulate(DATA, random_seeds=3, bands=())
    b = sim["bound"]
    # one: y (fp) and z (fn) are the wrong ones; two: p (fp) and r (fn); answering them leaves nothing wrong
    assert b["k"] == 2 and b["f1"] == 1.0
    assert sorted(b["asked"]["one"]) == ["y", "z"] and sorted(b["asked"]["two"]) == ["p", "r"]
    k2 = sim["grid"].index(2)
    for policy in qc.POLICIES:
        for d in DATA:
            st = qc.session(d, policy, grid=(2,))[0]
            best, _ = qc.best_questions(d, 2)
            assert _wrong(best, d.labels) <= _wrong(st, d.labels)
        assert sim["curves"][policy]["f1"][k2] <= b["f1"]
    assert qc.simulate(DATA, random_seeds=1, bands=(), grid=(0, 1))["bound"] is None  # no k = 2 in the grid


def test_scenes_are_re_scored_with_the_answers_by_default_and_only_re_thresholded_with_rescore_false():
    """Rule 5 is on by default, as in ``align_with_queries``: a scene whose kernel can re-score is asked
    again after each answer; ``rescore=False`` only re-thresholds; the ceiling of re-thresholding is not
    reported for re-scored runs."""
    asked = []

    def again(answers):  # a kernel that, told anything, gets every object of intent "one" right
        asked.append(dict(answers))
        return intent("one", {"x": 0.9, "y": 0.1, "z": 0.9, "w": 0.1}, DATA[0].labels).scores

    one = attrs.evolve(DATA[0], rescore=again)
    sim = qc.simulate([one], random_seeds=1, bands=(), grid=(0, 1, 2))
    assert asked and all(len(a) in (1, 2) for a in asked)
    assert sim["curves"]["uncertainty"]["f1"] == [0.5, 1.0, 1.0] and sim["bound"] is None
    assert sim["rescored_intents"] == ["one"]
    n = len(asked)
    plain = qc.simulate([one], random_seeds=1, bands=(), grid=(0, 1, 2), rescore=False)
    assert len(asked) == n  # never asked again
    assert plain["curves"]["uncertainty"]["f1"][:2] == [0.5, pytest.approx(2 / 3)] and plain["bound"]["f1"] == 1.0
    assert plain["rescored_intents"] == []


def test_a_kernel_that_gives_no_re_scoring_is_reported_as_not_re_scored_and_keeps_the_ceiling():
    """A re-scorer that returns None (a kernel without ``score_with_answers``, or ``gift-prob`` with nothing to
    re-weigh): answers only re-threshold, the run says no intent was re-scored, and the ceiling is reported."""
    calls = []
    one = attrs.evolve(DATA[0], rescore=lambda answers: calls.append(dict(answers)))
    sim = qc.simulate([one], random_seeds=1, bands=(), grid=(0, 1, 2))
    plain = qc.simulate([DATA[0]], random_seeds=1, bands=(), grid=(0, 1, 2))
    assert calls and sim["rescored_intents"] == []
    assert sim["curves"]["uncertainty"]["f1"] == plain["curves"]["uncertainty"]["f1"]
    assert sim["bound"] == plain["bound"] and sim["bound"]["f1"] == 1.0


def test_questions_random_needs_are_interpolated_on_the_grid():
    grid = [0, 1, 2, 4, 8]
    assert qc.queries_to_reach(grid, [0.5, 0.6, 0.7, 0.9, 1.0], 0.8) == pytest.approx(3.0)
    assert qc.queries_to_reach(grid, [0.5, 0.6, 0.7, 0.9, 1.0], 0.5) == 0.0
    assert qc.queries_to_reach(grid, [0.5, 0.6, 0.7, 0.9, 0.95], 0.99) is None


def test_the_figure_draws_every_run(tmp_path):
    sim = qc.simulate(DATA, random_seeds=2, bands=())
    path = qc.figure({"suite A": sim, "suite B": sim}, tmp_path / "curves.png", title="t")
    assert path.stat().st_size > 10_000 and path.read_bytes()[:4] == b"\x89PNG"
    assert np.isfinite(sim["curves"]["random"]["f1_se"][1])


def test_a_run_with_some_of_the_policies_draws_and_reports_only_those(tmp_path):
    sim = qc.simulate(DATA, random_seeds=2, bands=(), policies=("disagreement",))
    assert set(sim["curves"]) == {"disagreement", "random"}
    assert qc.ran_policies(sim["curves"]) == ("disagreement",)
    assert qc.target_check(sim)["best"] == "disagreement"
    path = qc.figure({"suite A": sim}, tmp_path / "curves.png")
    assert path.stat().st_size > 10_000
