"""Active alignment queries and abstention (gift.core.queries): the update rules, each built-in policy, the
session driver and the query_policy plugin kind, on fixed score arrays (the real kernel: tests/kernels)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gift
from gift.core.alignment import AlignmentScores, align_features, best_separating_cut, score_alignment
from gift.core.data import DISTRACTOR, FeatureBatch, FeatureSpec, ObjectSpec, RelevanceScores
from gift.core.errors import GiftError
from gift.core.interfaces import QueryPolicy, RelevanceKernel, SimilarityKernel
from gift.core.queries import (
    DEFAULT_CHOOSE,
    DEFAULT_MOVE,
    Answer,
    QueryProblem,
    answered_cut,
    ask,
    asking,
    belief,
    labels_answerer,
    parse_reply,
    resolve,
)
from gift.plugins.manager import GiftPluginManager

TRAIN = ("a", "b", "c", "d")  # a, b relevant
TEST = ("x", "y", "z", "w")
LABELS = {"x": True, "y": False, "z": True, "w": False}


class FixedRelevance(RelevanceKernel):
    """Relevance from fixed tables (the arrays a relevance kernel would return), with optional details."""

    name = "fixed-relevance"
    uses_intent = False

    def __init__(self, test, train, details=None, guess=None):
        self.test, self.train, self.details, self.guess = test, train, details or {}, guess

    def score(self, test, train, intent=None, relevant_train=()):
        rel = [o.name in relevant_train for o in train] if relevant_train else self.guess
        return RelevanceScores([self.test[o.name] for o in test], [self.train[o.name] for o in train], rel,
                               self.details)


class FixedMatrix(SimilarityKernel):
    name = "fixed-matrix"

    def __init__(self, K):
        self.K = np.asarray(K, float)

    def similarity(self, test, train, intent=None):
        return self.K[: len(test)]


def objs(names):
    return [ObjectSpec(n) for n in names]


def scores_of(test_r=None, train_r=None, relevant=("a", "b"), details=None, guess=None) -> AlignmentScores:
    test_r = test_r or {"x": 0.9, "y": 0.55, "z": 0.45, "w": 0.1}
    train_r = train_r or {"a": 0.8, "b": 0.7, "c": 0.3, "d": 0.2}
    k = FixedRelevance(test_r, train_r, details, guess)
    return score_alignment(k, objs(test_r), objs(TRAIN), relevant_train=relevant)


def test_answers_are_fixed_and_join_the_leave_one_out_evidence_of_the_train_calibrated_cut():
    s = scores_of()
    p = QueryProblem.of(s, move="nearest")
    st0 = resolve(p)
    assert st0.cut == pytest.approx(0.5) and st0.predicted.tolist() == [True, True, False, False]
    # "no" about y (0.55): a negative next to the training negatives 0.2, 0.3 -> cut between 0.55 and 0.7
    st1 = st0.assume(Answer("y", False))
    assert st1.cut == pytest.approx(best_separating_cut([0.8, 0.7], [0.3, 0.2, 0.55])) == pytest.approx(0.625)
    assert "1 relevant" not in st1.note and "0 yes / 1 no answers" in st1.note
    assert st1.alignment.target("y") == DISTRACTOR and not st1.predicted[1]
    # "yes" about z (0.45): the classes overlap; the best balanced accuracy with the widest gap is 0.375
    st2 = st1.assume(Answer("z", True))
    assert st2.cut == pytest.approx(0.375)
    assert st2.predicted.tolist() == [True, False, True, False]
    assert st2.alignment.target("z") == "a" and st2.alignment.scores["z"] == 1.0  # vouched for: K = 1
    assert st2.decision.tolist() == [0.9, -1.0, 1.0, 0.1]  # predicted == decision >= cut
    assert (st2.decision >= st2.cut).tolist() == st2.predicted.tolist()
    # "don't know" fixes nothing and moves nothing, but the object is not asked again
    st3 = st2.assume(Answer("w", None))
    assert st3.cut == st2.cut and st3.asked.tolist() == [False, True, True, True]
    with pytest.raises(GiftError, match="answered twice"):
        st3.assume(Answer("y", True))
    with pytest.raises(GiftError, match="not a test object"):
        st3.assume(Answer("q", True))


def test_the_cut_moves_only_as_far_as_the_answers_require():
    # two relevant training objects on top (0.8, 0.78), a hard negative answered "no" at 0.6, unasked
    # relevant test objects at 0.7 and 0.65 between them
    s = scores_of(test_r={"x": 0.7, "y": 0.6, "z": 0.65, "w": 0.1}, train_r={"a": 0.8, "b": 0.78, "c": 0.3, "d": 0.2})
    assert s.threshold("train-calibrated")[0] == pytest.approx(0.54)  # the widest gap: (0.3 + 0.78) / 2
    no = [Answer("y", False)]
    nearest = resolve(QueryProblem.of(s, move="nearest"), no)
    assert nearest.cut == pytest.approx(0.625)  # just past y, below z (0.65)
    assert nearest.predicted.tolist() == [True, False, True, False]
    widest = resolve(QueryProblem.of(s, move="widest"), no)
    assert widest.cut == pytest.approx(0.69) and widest.predicted.tolist() == [True, False, False, False]
    # an answer the cut already gets right moves nothing
    assert resolve(QueryProblem.of(s, move="nearest"), [Answer("w", False), Answer("x", True)]).cut == \
        pytest.approx(0.54)
    assert resolve(QueryProblem.of(s, move="widest"), [Answer("x", True)]).cut == pytest.approx(0.5)
    with pytest.raises(GiftError, match="unknown cut move 'far'"):
        QueryProblem.of(s, move="far")


def test_move_answers_keeps_the_cut_without_answers_and_moves_it_only_for_answers_it_gets_wrong():
    """move="answers": the anchor is the cut without answers (its training evidence and prior as they were);
    only the answers decide whether and how far it moves, one class of answers being enough."""
    s = scores_of(test_r={"x": 0.7, "y": 0.6, "z": 0.65, "w": 0.1}, train_r={"a": 0.8, "b": 0.78, "c": 0.3, "d": 0.2})
    problem = QueryProblem.of(s, move="answers")
    assert resolve(problem, [Answer("x", True), Answer("w", False)]).cut == pytest.approx(0.54)  # both right
    assert resolve(problem, [Answer("y", False)]).cut == pytest.approx(0.625)  # just past the "no", below z
    # a "yes" far below: the answers alone pull the cut just under it (the training evidence, which "nearest"
    # weighs again, would keep it at 0.54)
    low_yes = resolve(problem, [Answer("w", True)])
    assert low_yes.cut == pytest.approx(0.1, abs=1e-5) and low_yes.predicted.tolist() == [True, True, True, True]
    assert resolve(QueryProblem.of(s, move="nearest"), [Answer("w", True)]).cut == pytest.approx(0.54)
    assert "moved only as far as 1 yes / 0 no answers require" in low_yes.note


def test_move_stay_keeps_the_cut_without_answers_and_only_fixes_the_answered_objects():
    s = scores_of(test_r={"x": 0.7, "y": 0.6, "z": 0.65, "w": 0.1}, train_r={"a": 0.8, "b": 0.78, "c": 0.3, "d": 0.2})
    problem = QueryProblem.of(s, move="stay")
    cut0 = s.threshold("train-calibrated")[0]
    st = resolve(problem, [Answer("y", False), Answer("w", True)])  # both wrong at the cut without answers
    assert st.cut == pytest.approx(cut0) and "not moved by the 1 yes / 1 no answers" in st.note
    assert st.predicted.tolist() == [True, False, True, True]  # y and w fixed, x and z as without answers
    assert st.alignment.target("y") == DISTRACTOR and st.alignment.scores["w"] == 1.0
    # with the same answers, "nearest" lifts the cut just past the "no" at 0.6
    assert resolve(QueryProblem.of(s, move="nearest"), [Answer("y", False)]).cut > 0.6 > cut0
    # it is the default
    assert QueryProblem.of(s).move == DEFAULT_MOVE == "stay"
    assert resolve(QueryProblem.of(s), [Answer("y", False), Answer("w", True)]).to_dict() == st.to_dict()


def test_answers_do_not_move_fixed_or_non_oracle_cuts_but_still_fix_the_answered_objects():
    s = scores_of()
    for strategy in (0.5, "non-oracle"):
        st = resolve(QueryProblem.of(s, strategy), [Answer("x", False), Answer("w", True)])
        assert st.cut == s.threshold(strategy)[0]
        assert "not moved by answers" in st.note
        assert st.predicted.tolist() == [False, s.decision[1] >= st.cut, s.decision[2] >= st.cut, True]


def test_answers_alone_place_the_cut_when_no_relevant_training_object_is_known():
    s = scores_of(relevant=(), guess=[True, True, False, False])  # the kernel's own guess of the mask
    assert s.loo_scores is None and s.relevant_mask.tolist() == [True, True, False, False]
    base, note = s.threshold("train-calibrated")
    assert "fallback" in note
    one = answered_cut(s, "train-calibrated", [Answer("x", True)], move="nearest")
    assert one[0] == base and "no second class yet" in one[1]
    cut, note = answered_cut(s, "train-calibrated", [Answer("x", True), Answer("y", False)], move="nearest")
    assert cut == pytest.approx((0.9 + 0.55) / 2) and "0 relevant / 0 other" in note


def test_replies_yes_no_dont_know_and_the_training_object_it_plays():
    s = scores_of()
    assert parse_reply("x", "Yes", s) == Answer("x", True)
    assert parse_reply("x", " n ", s) == Answer("x", False) == parse_reply("x", "distractor", s)
    assert parse_reply("x", "?", s) == Answer("x", None) == parse_reply("x", None, s)
    assert parse_reply("x", True, s) == Answer("x", True)
    assert parse_reply("x", "B", s) == Answer("x", True, "b")  # plays a relevant training object
    assert parse_reply("x", "c", s) == Answer("x", False, "c")  # plays one the goal leaves alone
    with pytest.raises(GiftError, match=r"'zebra' is not yes / no / \? nor a training object \(a, b, c, d\)"):
        parse_reply("x", "zebra", s)
    with pytest.raises(GiftError, match="not a test object"):
        parse_reply("q", True, s)
    with pytest.raises(GiftError, match="needs relevant"):
        Answer("x", None, "a")
    st = resolve(QueryProblem.of(s), [parse_reply("w", "b", s), parse_reply("x", "c", s)])
    assert st.alignment.target("w") == "b" and st.predicted[3]
    assert st.alignment.target("x") == "c" and not st.predicted[0]  # aligned, but not as part of the goal


def test_a_yes_on_a_matrix_kernel_goes_to_the_best_relevant_training_object():
    K = [[0.2, 0.1, 0.9, 0.0],  # x: best match c (irrelevant); best relevant: a
         [0.6, 0.7, 0.1, 0.0]]
    s = score_alignment(FixedMatrix(K + [[0.5] * 4] * 4), objs(["x", "y"]), objs(TRAIN), relevant_train=("a", "b"))
    assert not s.relevance_kernel and s.decision[0] < 0  # below every cut
    st = resolve(QueryProblem.of(s, 0.5), [Answer("x", True)])
    assert st.alignment.target("x") == "a" and st.alignment.target("y") == "b"


def test_abstention_flags_objects_in_the_band_and_drops_their_features_like_a_distractor():
    s = scores_of()
    st = resolve(QueryProblem.of(s, abstain=0.06, move="nearest"))
    assert st.cut == pytest.approx(0.5) and st.abstained == ("y", "z")  # |0.55 - 0.5|, |0.45 - 0.5| < 0.06
    assert st.alignment.target("y") == DISTRACTOR and not st.predicted[1] and st.decision[1] == -1.0
    assert st.alignment.target("x") == "a"
    d = st.to_dict()
    assert d["n_abstained"] == 2 and d["abstained"] == ["y", "z"]
    assert d["move"] == "nearest" and d["choose"] == "primary"  # the rules that made it
    # its semantic columns are dropped by f_ω, exactly as a distractor's; it adds nothing to the bound
    specs = [FeatureSpec(f"{o}_near", subject=o) for o in ("x", "y")]
    tspecs = [FeatureSpec(f"{o}_near", subject=o) for o in TRAIN]
    out = align_features(FeatureBatch(specs, np.ones((1, 2, 2))), st.alignment, tspecs).values
    assert out[0, :, 0].tolist() == [1.0, 1.0] and out[..., 1:].sum() == 0.0  # x -> a; y nowhere
    assert st.error_bound() == pytest.approx(0.1)  # only x is aligned
    # an answered object is never flagged; here the answer also moves the cut away from y
    st = st.assume(Answer("z", True))
    assert st.cut == pytest.approx(0.375) and st.abstained == () and st.predicted.tolist() == [True, True, True,
                                                                                                 False]
    with pytest.raises(GiftError, match="abstention band"):
        QueryProblem.of(s, abstain=1.5)


def test_answers_choose_among_intent_candidates():
    primary = scores_of()  # predicts x, y
    other = primary.with_relevance([0.2, 0.9, 0.1, 0.95], [0.8, 0.7, 0.3, 0.2])  # predicts y, w
    p = QueryProblem.of(primary, candidates={"other": other}, choose="answers")
    assert resolve(p).chosen == "primary"
    st = resolve(p, [Answer("w", True)])  # primary had w wrong, the other right
    assert st.chosen == "other" and st.mistakes == {"primary": 1, "other": 0}
    assert st.predicted.tolist() == [False, True, False, True]
    st = resolve(p, [Answer("w", True), Answer("x", True)])  # one mistake each: the earlier one
    assert st.chosen == "primary"
    # candidates a kernel reports in its details
    s = scores_of(details={"candidates": {"metal items": {"relevance": [0.2, 0.9, 0.1, 0.95],
                                                           "train_loo": [0.8, 0.7, 0.3, 0.2]}}})
    assert list(QueryProblem.of(s).candidates) == ["primary", "metal items"]
    # gift-prob's list of verified candidate goals: the chosen one is the kernel's own; one without test scores
    # (verified on the training objects only) is no view
    listed = [{"goal": "pack art supplies", "chosen": True, "lm_test": [1] * 4, "lm_train": [1] * 4},
              {"goal": "store metal items", "chosen": False, "lm_test": [-2.0, 3.0, -3.0, 4.0],
               "lm_train": [2.0, 1.5, -1.0, -2.0]},
              {"goal": "tidy up", "chosen": False}]
    p = QueryProblem.of(scores_of(details={"candidates": listed}), choose="answers")
    assert list(p.candidates) == ["primary", "store metal items"]
    assert resolve(p, [Answer("w", True)]).chosen == "store metal items"
    with pytest.raises(GiftError, match="3 test / 4 training scores for 4 / 4"):
        QueryProblem.of(scores_of(details={"candidates": [{"goal": "g", "test": [1, 2, 3], "train": [1] * 4}]}))
    with pytest.raises(GiftError, match="another scene"):
        QueryProblem.of(primary, candidates={"bad": scores_of(test_r={"x": 0.1, "q": 0.2, "z": 0.3, "w": 0.4})})


def test_choose_primary_keeps_the_kernels_own_candidate_whatever_the_answers_say():
    primary = scores_of()  # predicts x, y
    other = primary.with_relevance([0.2, 0.9, 0.1, 0.95], [0.8, 0.7, 0.3, 0.2])  # predicts y, w
    p = QueryProblem.of(primary, candidates={"other": other})  # the default
    assert p.choose == DEFAULT_CHOOSE == "primary"
    st = resolve(p, [Answer("w", True)])  # the answer contradicts the primary, not the other
    assert st.chosen == "primary" and st.mistakes == {"primary": 1, "other": 0}  # still charged, for reports
    assert st.predicted.tolist() == [True, True, False, True]  # primary's decisions, w fixed by its answer
    assert "other" in st.view_beliefs()  # the other candidate stays a view for the policies
    with pytest.raises(GiftError, match="unknown candidate choice 'best'"):
        QueryProblem.of(primary, choose="best")


def test_uncertainty_asks_nearest_the_cut_and_re_ranks_after_each_answer():
    s = scores_of()
    states = list(asking(QueryProblem.of(s), "uncertainty", labels_answerer(LABELS), 4))
    asked = [a.object for a in states[-1].answers]
    # cut 0.5: y and z are both 0.05 away -> the first in the scene; "no" moves the cut to 0.625, and
    # z (0.45) is then the nearest
    assert asked[0] == "y" and asked[1] == "z" and sorted(asked) == sorted(TEST)
    assert [len(st.answers) for st in states] == [0, 1, 2, 3, 4]
    assert states[-1].predicted.tolist() == [LABELS[t] for t in TEST]  # all answered: all right


def test_disagreement_asks_where_the_kernels_terms_disagree_and_degrades_to_uncertainty():
    terms = {"lm": {"relevance": [0.9, 0.6, 0.2, 0.1], "train_loo": [0.8, 0.7, 0.3, 0.2]},
             "language": {"relevance": [0.9, 0.5, 0.9, 0.1], "train_loo": [0.8, 0.7, 0.3, 0.2]}}
    s = scores_of(details={"terms": terms})
    st = resolve(QueryProblem.of(s))
    views = st.view_beliefs()
    assert set(views) == {"lm", "language"}
    assert np.argmax(np.ptp(np.stack(list(views.values())), axis=0)) == 2
    pol = gift.get_query_policy("disagreement")
    assert pol.choose(st, np.random.default_rng(0)) == "z"  # the terms disagree on z most
    # raw terms (gift-prob reports log-odds and cosines) are put on the relevance scale: same order
    raw = {"lm": {"test": [4.0, 1.0, -3.0, -5.0], "train": [3.0, 2.0, -2.0, -4.0]},
           "language": {"test": [0.4, 0.1, 0.4, -0.2], "train": [0.3, 0.2, -0.1, -0.2]}}
    st_raw = resolve(QueryProblem.of(scores_of(details={"terms": raw})))
    v = st_raw.view_beliefs()
    assert np.argsort(v["lm"]).tolist() == [3, 2, 1, 0] and pol.choose(st_raw, np.random.default_rng(0)) == "z"
    plain = resolve(QueryProblem.of(scores_of()))  # no terms, one candidate: the nearest the cut
    assert plain.view_beliefs() == {}
    assert pol.choose(plain, np.random.default_rng(0)) == gift.get_query_policy("uncertainty").choose(
        plain, np.random.default_rng(0)) == "y"


def test_error_bound_policy_weighs_the_objects_by_their_presence_in_the_scenes_trajectories():
    s = scores_of()
    pol = gift.get_query_policy("error-bound")
    # no trajectories: one state per object; x (1 - K = 0.1) and y (0.45) are aligned
    st = resolve(QueryProblem.of(s))
    assert st.error_bound() == pytest.approx(0.1 + 0.45)
    pr = pol.priority(st, np.random.default_rng(0))
    # y (0.55): "yes" keeps the cut and vouches for y (bound 0.1); "no" lifts the cut past it (bound 0.1)
    assert pr[1] == pytest.approx(0.45)
    # x (0.9): either answer leaves the cut and removes x's 0.1
    assert pr[0] == pytest.approx(0.1)
    # z (0.45): "yes" lowers the cut to 0.375 (y stays aligned, bound 0.55); "no" keeps it: nothing gained
    assert pr[2] == pytest.approx(0.0) and pr[3] == pytest.approx(0.0)
    assert pol.choose(st, np.random.default_rng(0)) == "y"
    # trajectories where only x is ever near: asking about y cannot lower their bound
    specs = [FeatureSpec(f"{o}_near", subject=o) for o in TEST]
    values = np.zeros((3, 5, 4))
    values[:, :, 0] = 0.5
    st = resolve(QueryProblem.of(s, trajectories=[FeatureBatch(specs, values)]))
    assert st.error_bounds().tolist() == pytest.approx([0.5] * 3)  # 5 steps x (1 - 0.9)
    pr = pol.priority(st, np.random.default_rng(0))
    assert pol.choose(st, np.random.default_rng(0)) == "x"
    assert pr[0] == pytest.approx(1.5) and abs(pr[1]) < 1e-12


def test_random_policy_is_seeded_and_never_asks_twice():
    s = scores_of()
    order = lambda seed: [a.object for a in ask(QueryProblem.of(s), "random", labels_answerer(LABELS), 4,
                                                seed=seed).answers]
    assert order(3) == order(3) and sorted(order(3)) == sorted(TEST)
    assert len({tuple(order(k)) for k in range(8)}) > 1


def test_a_python_callback_session_with_saved_answers_and_early_stop():
    s = scores_of()
    seen = []

    def human(obj):
        seen.append(obj)
        return "yes" if LABELS[obj] else "no"

    st = ask(QueryProblem.of(s), "uncertainty", human, 2, answers=[Answer("y", False)])
    assert "y" not in seen and len(seen) == 2 and len(st.answers) == 3  # saved answers do not count
    st = ask(QueryProblem.of(s), "uncertainty", human, 10)  # only 4 objects: stops when all are asked
    assert len(st.answers) == 4
    with pytest.raises(GiftError, match="integer >= 0"):
        ask(QueryProblem.of(s), "uncertainty", human, -1)
    with pytest.raises(GiftError, match="no query_policy named 'psychic'"):
        ask(QueryProblem.of(s), "psychic", human, 1)
    with pytest.raises(GiftError, match="not yes / no"):
        ask(QueryProblem.of(s), "uncertainty", lambda o: "perhaps", 1)


def test_alignment_scores_round_trip_through_json_and_re_threshold_the_same():
    s = scores_of(details={"category": "art supplies"})
    back = AlignmentScores.from_dict(json.loads(json.dumps(s.to_dict())))
    for name in ("K", "decision", "target", "aligned", "loo_scores", "loo_labels", "relevant_mask"):
        assert np.array_equal(getattr(back, name), getattr(s, name)), name
    assert back.relevance_kernel and back.details == {"category": "art supplies"}
    for th in ("train-calibrated", "non-oracle", 0.3):
        assert back.threshold(th) == s.threshold(th)
    assert resolve(QueryProblem.of(back), [Answer("y", False)]).to_dict() == \
        resolve(QueryProblem.of(s), [Answer("y", False)]).to_dict()
    with pytest.raises(GiftError, match="missing"):
        AlignmentScores.from_dict({"test": []})
    with pytest.raises(GiftError, match="relevance kernel"):
        score_alignment(FixedMatrix([[0.5] * 4] * 6), objs(["x", "y"]), objs(TRAIN)).with_relevance([0.1, 0.2],
                                                                                                   [0.1] * 4)


def test_belief_is_one_half_at_the_cut_and_linear_to_each_end():
    assert belief([0.0, 0.25, 0.5, 0.75, 1.0], 0.5).tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert belief([-1.0, 0.2, 0.6], 0.4).tolist() == pytest.approx([0.0, 0.25, 0.5 + 0.5 * 0.2 / 0.6])
    assert belief([0.0, 1.0], 1.0).tolist() == [0.0, 0.5] and belief([0.0, 0.5], 0.0).tolist() == [0.5, 0.75]


class AskLast(QueryPolicy):
    """A third-party policy: the last object of the scene not asked yet."""

    name = "ask-last"

    def priority(self, state, rng):
        return np.arange(len(state.test), dtype=float)


class Broken(QueryPolicy):
    name = "broken"

    def priority(self, state, rng):
        return np.zeros(2)


def test_query_policies_are_plugins_and_bad_priorities_are_named():
    names = {c["name"] for c in gift.list_components("query_policy")["query_policy"]}
    assert {"uncertainty", "disagreement", "error-bound", "expected-error", "random"} <= names

    class Plugin:
        @gift.hookimpl
        def gift_register_query_policies(self, register):
            register(AskLast)

    pm = GiftPluginManager().load(entry_points=[])
    pm.register_plugin(Plugin(), name="third-party")
    policy = pm.create("query_policy", "ask-last")
    st = ask(QueryProblem.of(scores_of()), policy, labels_answerer(LABELS), 2)
    assert [a.object for a in st.answers] == ["w", "z"]
    with pytest.raises(GiftError, match="'broken' returned"):
        ask(QueryProblem.of(scores_of()), Broken(), labels_answerer(LABELS), 1)


class AnswerAware(FixedRelevance):
    """Fixed tables, and with answers a second fixed table (what a kernel that re-scores would return)."""

    name = "answer-aware"

    def __init__(self, test, train, again):
        super().__init__(test, train)
        self.again, self.calls = again, []

    def score_with_answers(self, test, train, intent, relevant_train, answers):
        self.calls.append(dict(answers))
        return RelevanceScores([self.again[o.name] for o in test], [self.train[o.name] for o in train],
                               [o.name in relevant_train for o in train])


def test_rule_5_a_kernel_that_uses_answers_re_scores_the_scene_once_per_set_of_answers():
    from gift.core.queries import align_with_queries, kernel_rescorer

    first = {"x": 0.9, "y": 0.55, "z": 0.45, "w": 0.1}
    again = {"x": 0.9, "y": 0.2, "z": 0.8, "w": 0.1}  # with the answers, z looks relevant and y does not
    train = {"a": 0.8, "b": 0.7, "c": 0.3, "d": 0.2}
    k = AnswerAware(first, train, again)
    rescore = kernel_rescorer(k, objs(TEST), objs(TRAIN), relevant_train=("a", "b"))
    assert rescore is not None
    s = score_alignment(k, objs(TEST), objs(TRAIN), relevant_train=("a", "b"))
    p = QueryProblem.of(s, rescore=rescore)
    st0 = resolve(p)
    assert not st0.rescored and st0.predicted.tolist() == [True, True, False, False] and k.calls == []
    st1 = resolve(p, [Answer("x", True)])
    assert st1.rescored and k.calls == [{"x": True}]
    assert st1.predicted.tolist() == [True, False, True, False]  # y and z decided by the re-scored table
    assert st1.to_dict()["rescored"] is True
    resolve(p, [Answer("x", True)])
    assert k.calls == [{"x": True}]  # kept per set of answers
    # a policy's "what if" re-thresholds the current scores without asking the kernel again
    what_if = st1.assume(Answer("y", False))
    assert what_if.rescored and k.calls == [{"x": True}]
    # "don't know" is no evidence: no re-scoring
    assert not resolve(p, [Answer("y", None)]).rescored and k.calls == [{"x": True}]
    # the session driver: by default every real answer re-scores; with rescore=False answers only re-threshold
    k.calls.clear()
    st = align_with_queries(k, objs(TEST), objs(TRAIN), relevant_train=("a", "b"), answer=labels_answerer(LABELS),
                            n=2, policy="uncertainty")
    assert st.rescored and len(k.calls) == 2 and len(k.calls[1]) == 2
    k.calls.clear()
    st = align_with_queries(k, objs(TEST), objs(TRAIN), relevant_train=("a", "b"), answer=labels_answerer(LABELS),
                            n=2, policy="uncertainty", rescore=False)
    assert not st.rescored and k.calls == []


def test_rule_5_rescore_when_contradicted_re_scores_only_once_an_answer_contradicts_the_first_decisions():
    first = {"x": 0.9, "y": 0.55, "z": 0.45, "w": 0.1}  # decided yes, yes, no, no at the cut 0.5
    again = {"x": 0.9, "y": 0.2, "z": 0.8, "w": 0.1}
    train = {"a": 0.8, "b": 0.7, "c": 0.3, "d": 0.2}
    k = AnswerAware(first, train, again)
    from gift.core.queries import kernel_rescorer

    s = score_alignment(k, objs(TEST), objs(TRAIN), relevant_train=("a", "b"))
    p = QueryProblem.of(s, rescore=kernel_rescorer(k, objs(TEST), objs(TRAIN), relevant_train=("a", "b")),
                        rescore_when="contradicted")
    agree = resolve(p, [Answer("x", True), Answer("w", False)])  # both as the kernel decided: no re-scoring
    assert not agree.rescored and k.calls == [] and agree.predicted.tolist() == [True, True, False, False]
    assert not p.contradicted([("x", True), ("w", False)]) and p.contradicted([("z", True)])
    st = resolve(p, [Answer("x", True), Answer("z", True)])  # z contradicts: re-scored with every answer
    assert st.rescored and k.calls == [{"x": True, "z": True}] and st.predicted.tolist() == [True, False, True, False]
    assert resolve(QueryProblem.of(s, rescore=p.rescore), [Answer("x", True)]).rescored  # "always", the default
    with pytest.raises(GiftError, match="unknown rescore_when 'sometimes'"):
        QueryProblem.of(s, rescore_when="sometimes")


def test_expected_error_asks_the_object_whose_answer_re_scores_the_others_most_and_is_uncertainty_without_it():
    first = {"x": 0.9, "y": 0.55, "z": 0.45, "w": 0.3}
    train = {"a": 0.8, "b": 0.7, "c": 0.2, "d": 0.1}
    settled = {"x": 0.95, "y": 0.05, "z": 0.95, "w": 0.3}  # an answer about w settles y and z

    def rescore(answers):
        table = settled if "w" in answers else first
        return score_alignment(FixedRelevance(table, train), objs(TEST), objs(TRAIN), relevant_train=("a", "b"))

    s = score_alignment(FixedRelevance(first, train), objs(TEST), objs(TRAIN), relevant_train=("a", "b"))
    pol = gift.get_query_policy("expected-error")
    st = resolve(QueryProblem.of(s, rescore=rescore))
    p = st.belief()
    pr = pol.priority(st, np.random.default_rng(0))
    # by its definition: the mistakes expected now minus those expected after each answer, weighed by p
    left = lambda b: float(np.minimum(b, 1 - b).sum())
    for i, t in enumerate(TEST):
        after = [resolve(st.problem, [Answer(t, said)]).belief() for said in (True, False)]
        assert pr[i] == pytest.approx(left(p) - (p[i] * left(after[0]) + (1 - p[i]) * left(after[1])))
    nearest = gift.get_query_policy("uncertainty").choose(st, np.random.default_rng(0))
    assert nearest == "z" and pol.choose(st, np.random.default_rng(0)) == "w"  # not the nearest to the cut
    # answers that only fix their object: the gain is the object's own min(p, 1 - p), ranked as uncertainty
    plain = resolve(QueryProblem.of(s))
    pr = pol.priority(plain, np.random.default_rng(0))
    assert pr == pytest.approx(np.minimum(plain.belief(), 1 - plain.belief()))
    assert pol.choose(plain, np.random.default_rng(0)) == "z"
    # only the `width` objects nearest the cut are evaluated; the others rank below them
    narrow = gift.get_query_policy("expected-error", width=1).priority(st, np.random.default_rng(0))
    assert np.argmax(narrow) == TEST.index("z") and (np.delete(narrow, 2) < narrow[2]).all()
    with pytest.raises(GiftError, match="width must be an integer >= 1"):
        gift.get_query_policy("expected-error", width=0)


def test_rule_5_kernels_that_cannot_use_answers_only_re_threshold_and_bad_rescores_fail_clearly():
    from gift.core.queries import kernel_rescorer

    assert kernel_rescorer(FixedRelevance({"x": 0.5}, {"a": 0.5}), objs(["x"]), objs(["a"])) is None
    assert kernel_rescorer(FixedMatrix(np.ones((1, 1))), objs(["x"]), objs(["a"])) is None
    s = scores_of()
    p = QueryProblem.of(s, rescore=lambda answers: None)  # the kernel declined: the first scores decide
    assert not resolve(p, [Answer("x", True)]).rescored
    other = scores_of(test_r={"q": 0.5})
    bad = QueryProblem.of(s, rescore=lambda answers: other)
    with pytest.raises(GiftError, match="expected AlignmentScores of the test objects"):
        resolve(bad, [Answer("x", True)])
    with pytest.raises(GiftError, match="not test objects"):
        from gift.core.alignment import rescore_alignment

        rescore_alignment(AnswerAware({"x": 0.5}, {"a": 0.5}, {"x": 0.5}), objs(["x"]), objs(["a"]),
                          answers={"nope": True})
