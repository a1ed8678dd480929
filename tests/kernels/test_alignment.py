"""argmax-threshold: the alignment rule, the three thresholds, the error bound, batch/trajectory/state."""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.alignment import (
    NEVER,
    ArgmaxThresholdAlignment,
    best_separating_cut,
    leave_one_out_oracle,
    matrix_decision,
    oracle_cut,
    score_alignment,
    trajectory_error_bounds,
)
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, ObjectSpec, RelevanceScores
from gift.core.errors import GiftError
from gift.core.interfaces import RelevanceKernel, SimilarityKernel
from gift.core.metrics import binary_metrics
from gift.tasks import PackBackpack

TRAIN = [ObjectSpec(n) for n in ("paintbrush", "sketchbook", "banana", "coffee mug")]
TEST = [ObjectSpec(n) for n in ("molding clay", "toothbrush", "apple")]
REL = ("paintbrush", "sketchbook")


class TableKernel(SimilarityKernel):
    """A fixed similarity table by name pair (control-flow tests of the operator only)."""

    name = "table"

    def __init__(self, table: dict[tuple[str, str], float], default: float = 0.1):
        self.table, self.default, self.calls = table, default, 0

    def similarity(self, test, train, intent=None):
        self.calls += 1
        return np.array([[self.table.get((a.name, b.name), self.table.get((b.name, a.name), self.default))
                          for b in train] for a in test])


class TableRelevanceKernel(RelevanceKernel):
    """A per-object relevance table (like gift-prob): one score() per scene, leave-one-out from the same table."""

    name = "relevance-table"

    def __init__(self, p: dict[str, float]):
        self.p, self.score_calls = p, 0

    def score(self, test, train, intent=None, relevant_train=()):
        self.score_calls += 1
        rel = [b.name in (relevant_train or REL) for b in train]
        return RelevanceScores([self.p[a.name] for a in test], [self.p[b.name] for b in train], rel)


SIMS = {("molding clay", "paintbrush"): 0.7, ("molding clay", "sketchbook"): 0.5,
        ("toothbrush", "paintbrush"): 0.8, ("toothbrush", "banana"): 0.3,
        ("apple", "banana"): 0.9, ("apple", "paintbrush"): 0.6,
        ("paintbrush", "sketchbook"): 0.6, ("banana", "coffee mug"): 0.5, ("paintbrush", "banana"): 0.2}


def test_matrix_rule_targets_argmax_and_never_makes_an_object_matched_to_an_irrelevant_one_relevant():
    K = np.array([[0.7, 0.5, 0.1, 0.1],   # best: paintbrush (relevant)
                  [0.4, 0.1, 0.9, 0.1],   # best: banana (irrelevant)
                  [0.5, 0.1, 0.5, 0.1]])  # tie: goes to the relevant one
    rel = np.array([True, True, False, False])
    score, target = matrix_decision(K, rel)
    assert target.tolist() == [0, 2, 0]
    assert score[0] == pytest.approx(0.7) and score[2] == pytest.approx(0.5)
    assert score[1] == pytest.approx(0.4 - 1.0) and score[1] < 0  # below every cut in [0, 1]
    # relevance unknown: every column counts, the decision is the plain max
    score_u, _ = matrix_decision(K, np.zeros(4, dtype=bool))
    assert score_u.tolist() == pytest.approx([0.7, 0.9, 0.5])


def test_cuts():
    assert best_separating_cut([0.8, 0.9], [0.2, 0.4]) == pytest.approx(0.6)
    # overlap: 0.35 and 0.65 both reach balanced accuracy 5/6; the wider gap (0.2 .. 0.5) wins
    assert best_separating_cut([0.5, 0.7, 0.9], [0.1, 0.6, 0.2]) == pytest.approx(0.35)
    with pytest.raises(GiftError):
        best_separating_cut([], [0.1])
    s = np.array([0.9, 0.8, 0.3, 0.2, NEVER])
    y = np.array([True, True, False, True, False])
    assert oracle_cut(s, y) == pytest.approx(0.2)  # F1 6/7: every object except the NEVER one


def test_leave_one_out_oracle_decides_each_object_by_the_cut_of_the_others():
    # separable: every object's cut from the others still separates, so the out-of-sample F1 is the oracle's
    s = np.array([0.9, 0.8, 0.7, 0.3, 0.2, 0.1])
    y = np.array([True, True, True, False, False, False])
    assert leave_one_out_oracle(s, y).tolist() == y.tolist()
    # in sample, the cut 0.4 takes every object (F1 6/8); left out, the lowest positive meets the cuts of the
    # other four, where just below 0.5 and 0.85 both give F1 2/3; of two tied cuts the lower is the middle one
    s = np.array([0.9, 0.8, 0.6, 0.5, 0.4])
    y = np.array([True, False, False, True, True])
    assert oracle_cut(s, y) == pytest.approx(0.4)
    p = leave_one_out_oracle(s, y)
    assert p.tolist() == [True, True, True, True, False]
    assert binary_metrics(p, y).f1 < binary_metrics(s >= oracle_cut(s, y), y).f1
    assert p.shape == (5,) and p.dtype == bool
    with pytest.raises(GiftError):
        leave_one_out_oracle([0.1, 0.2], [True])


def test_three_thresholds_on_one_scoring_and_train_calibrated_ignores_test_labels():
    k = TableKernel(SIMS)
    sc = score_alignment(k, TEST, TRAIN, relevant_train=REL)
    assert k.calls == 1  # one call: test and training rows against the training objects
    mean_cut, note = sc.threshold("non-oracle")
    Ktt = k.similarity(TRAIN, TRAIN)
    assert mean_cut == pytest.approx(Ktt[~np.eye(4, dtype=bool)].mean())
    cal, note = sc.threshold("train-calibrated")
    assert "leave-one-out" in note
    # loo: paintbrush and sketchbook match each other (0.6); banana matches coffee mug (0.5, irrelevant) -> NEVER side
    assert sc.loo_scores[0] == pytest.approx(0.6) and sc.loo_scores[1] == pytest.approx(0.6)
    assert sc.loo_scores[2] < 0 and sc.loo_scores[3] < 0
    labels_a = {"molding clay": True, "toothbrush": False, "apple": False}
    labels_b = {"molding clay": False, "toothbrush": True, "apple": True}
    assert sc.threshold("oracle", labels_a)[0] != sc.threshold("oracle", labels_b)[0]
    assert sc.threshold("train-calibrated", labels_b) == sc.threshold("train-calibrated", labels_a)
    al = sc.alignment(cal)
    assert al.mapping["apple"] == "banana"  # 0.9 to an irrelevant training object: aligned, not relevant
    assert al.relevant(REL)["apple"] is False
    assert al.mapping["molding clay"] == "paintbrush"
    # toothbrush best matches paintbrush at 0.8: a FP the threshold cannot fix for a surface kernel
    assert al.relevant(REL)["toothbrush"] is True
    oracle = sc.threshold("oracle", labels_a)[0]
    # toothbrush (0.8) scores above molding clay (0.7): even the oracle cut cannot separate them
    assert oracle == pytest.approx(0.7)
    assert sc.alignment(oracle).relevant(REL) == {"molding clay": True, "toothbrush": True, "apple": False}
    with pytest.raises(GiftError, match="test labels"):
        sc.threshold("oracle")
    with pytest.raises(GiftError, match="unknown threshold"):
        sc.threshold("median")


def test_relevance_kernels_use_their_relevance_and_leave_one_out():
    p = {"molding clay": 0.8, "toothbrush": 0.3, "apple": 0.1,
         "paintbrush": 0.9, "sketchbook": 0.7, "banana": 0.2, "coffee mug": 0.4}
    k = TableRelevanceKernel(p)
    sc = score_alignment(k, TEST, TRAIN, relevant_train=REL)
    assert sc.decision.tolist() == pytest.approx([0.8, 0.3, 0.1])
    assert sc.loo_scores.tolist() == pytest.approx([0.9, 0.7, 0.2, 0.4])
    assert k.score_calls == 1  # one pass: the test scene and the held-out training objects together
    # K: the relevance in the relevant columns; the non-oracle cut from the training objects' scores
    assert np.allclose(sc.K, [[0.8, 0.8, 0, 0], [0.3, 0.3, 0, 0], [0.1, 0.1, 0, 0]])
    Ktt = np.array([[v if j < 2 else 0.0 for j in range(4)] for v in (0.9, 0.7, 0.2, 0.4)])
    assert sc.train_mean == pytest.approx(Ktt[~np.eye(4, dtype=bool)].mean())
    cut, _ = sc.threshold("train-calibrated")
    assert cut == pytest.approx((0.4 + 0.7) / 2)
    al = sc.alignment(cut)
    assert al.mapping == {"molding clay": "paintbrush", "toothbrush": DISTRACTOR, "apple": DISTRACTOR}
    # a single relevant training object has no relevant partner: fall back to non-oracle, and say so
    sc1 = score_alignment(k, TEST, TRAIN, relevant_train=("paintbrush",))
    assert k.score_calls == 2
    cut1, note1 = sc1.threshold("train-calibrated")
    assert "fallback" in note1 and cut1 == pytest.approx(sc1.train_mean)


def test_operator_thresholds_and_errors():
    k = TableKernel(SIMS)
    op = gift.get_alignment_operator("argmax-threshold", threshold="train-calibrated")
    al = op.align(k, TEST, TRAIN, relevant_train=REL)
    assert isinstance(al, Alignment) and set(al.mapping) == {o.name for o in TEST}
    assert all(0.0 <= v <= 1.0 for v in al.scores.values())
    fixed = ArgmaxThresholdAlignment(threshold=0.75).align(k, TEST, TRAIN, relevant_train=REL)
    assert fixed.mapping == {"molding clay": DISTRACTOR, "toothbrush": "paintbrush", "apple": "banana"}
    assert ArgmaxThresholdAlignment("0.75").threshold == 0.75
    oracle = ArgmaxThresholdAlignment("oracle").align(k, TEST, TRAIN, relevant_train=REL,
                                                       test_labels={"molding clay": True, "toothbrush": False,
                                                                    "apple": False})
    assert oracle.relevant(REL)["molding clay"] is True
    with pytest.raises(GiftError, match="unknown threshold"):
        ArgmaxThresholdAlignment("smart")
    with pytest.raises(GiftError, match=r"\[0, 1\]"):
        ArgmaxThresholdAlignment(1.5)
    # no relevant training object known (e.g. demonstrations that single out none): the paper's cut, said so
    op = ArgmaxThresholdAlignment("train-calibrated")
    unknown = op.align(k, TEST, TRAIN)
    assert "no relevant training object" in op.last_note
    assert unknown.threshold == pytest.approx(score_alignment(k, TEST, TRAIN).threshold("non-oracle")[0])
    with pytest.raises(GiftError, match="not training objects"):
        ArgmaxThresholdAlignment().align(k, TEST, TRAIN, relevant_train=("unicorn",))


class BadKernel(SimilarityKernel):
    name = "bad"

    def similarity(self, test, train, intent=None):
        return np.full((len(test), len(train)), 1.7)


def test_kernel_output_is_checked_with_a_clear_error():
    with pytest.raises(GiftError, match=r"kernel 'bad' returned values outside \[0, 1\]"):
        score_alignment(BadKernel(), TEST, TRAIN)


def test_batch_trajectory_and_state_alignment_with_error_bounds():
    task = PackBackpack()
    rng = np.random.default_rng(0)
    test_specs = task.feature_specs(["molding clay", "toothbrush"])
    train_specs = task.feature_specs(["paintbrush", "sketchbook", "banana"])
    n, t = 4, 6
    values = rng.random((n, t, len(test_specs)))
    values[1, :, 0] = 0.0          # trajectory 1: molding clay absent all along
    values[2, :3, 0] = 0.0         # trajectory 2: absent for the first 3 steps
    feats = FeatureBatch(test_specs, values)
    al = Alignment({"molding clay": "paintbrush", "toothbrush": DISTRACTOR},
                   scores={"molding clay": 0.75, "toothbrush": 0.4}, threshold=0.5, kernel="table")
    op = ArgmaxThresholdAlignment(lipschitz=2.0)
    out = op.transform(feats, al, train_specs)
    assert out.features.values.shape == (n, t, len(train_specs))
    cont = [i for i, s in enumerate(test_specs) if not s.semantic]
    cont_train = [i for i, s in enumerate(train_specs) if not s.semantic]
    assert np.array_equal(out.features.values[..., cont_train], values[..., cont])  # continuous untouched
    assert np.array_equal(out.features.values[..., 0], values[..., 0])              # clay -> paintbrush slot
    assert out.error_bounds.tolist() == pytest.approx([2 * 0.25 * t, 0.0, 2 * 0.25 * 3, 2 * 0.25 * t])
    # never above the core's looser bound (every step charged)
    assert (out.error_bounds <= al.error_bound(lipschitz=2.0, n_steps=t) + 1e-12).all()
    # one trajectory (a batch of one) and one state give the same as the batch
    one = op.transform(feats[3], al, train_specs)
    assert np.array_equal(one.features.values[0], out.features.values[3])
    assert one.error_bounds.tolist() == pytest.approx([out.error_bounds[3]])
    state = FeatureBatch(test_specs, values[3:4, 2:3])
    st = op.transform(state, al, train_specs)
    assert np.array_equal(st.features.values[0, 0], out.features.values[3, 2])
    assert trajectory_error_bounds(state, al, 1.0).tolist() == pytest.approx([0.25])
