"""The prior cut of a relevance kernel (RelevanceScores.prior_cut): how the train-calibrated threshold averages
it with the leave-one-out cut, that it survives JSON and views, anchors the answered cut, and fails clearly."""

from __future__ import annotations

import json

import pytest

from gift.core.alignment import AlignmentScores, best_separating_cut, score_alignment
from gift.core.data import ObjectSpec, RelevanceScores
from gift.core.errors import ValidationError
from gift.core.interfaces import RelevanceKernel
from gift.core.queries import Answer, answered_cut

TRAIN = {"a": 0.9, "b": 0.8, "c": 0.3, "d": 0.1}  # a, b relevant
TEST = {"x": 0.7, "y": 0.55, "z": 0.45, "w": 0.1}


class Fixed(RelevanceKernel):
    name = "fixed-prior"

    def __init__(self, **prior):
        self.prior = prior

    def score(self, test, train, intent=None, relevant_train=()):
        return RelevanceScores([TEST[o.name] for o in test], [TRAIN[o.name] for o in train],
                               [o.name in relevant_train for o in train], **self.prior)


def scores(**prior) -> AlignmentScores:
    return score_alignment(Fixed(**prior), [ObjectSpec(n) for n in TEST], [ObjectSpec(n) for n in TRAIN],
                           relevant_train=("a", "b"), need=("train-calibrated", "non-oracle"))


LOO = best_separating_cut([0.9, 0.8], [0.3, 0.1])  # 0.55


def test_the_train_calibrated_cut_averages_the_leave_one_out_cut_with_the_prior():
    assert scores().threshold("train-calibrated")[0] == pytest.approx(LOO)  # no prior: unchanged
    for w in (0.25, 0.5, 1.0):
        cut, note = scores(prior_cut=0.6, prior_weight=w).threshold("train-calibrated")
        assert cut == pytest.approx(w * 0.6 + (1 - w) * LOO)
        assert f"({LOO:.3f}), averaged with the kernel's prior cut 0.6 (weight {w:g})" in note
    assert scores(prior_cut=0.6, prior_weight=0.0).threshold("train-calibrated")[0] == pytest.approx(LOO)
    # the other strategies ignore it
    s = scores(prior_cut=0.6)
    assert s.threshold("non-oracle") == scores().threshold("non-oracle") and s.threshold(0.3) == (0.3, "fixed")


def test_the_prior_survives_json_and_views_and_old_records_read_without_it():
    s = scores(prior_cut=0.6, prior_weight=0.25)
    back = AlignmentScores.from_dict(json.loads(json.dumps(s.to_dict())))
    assert (back.prior_cut, back.prior_weight) == (0.6, 0.25)
    assert back.threshold("train-calibrated") == s.threshold("train-calibrated")
    view = s.with_relevance([0.6, 0.5, 0.4, 0.3], [0.9, 0.7, 0.3, 0.2])
    assert (view.prior_cut, view.prior_weight) == (0.6, 0.25)
    old = s.to_dict()
    del old["prior_cut"], old["prior_weight"]  # a record written before the prior existed
    assert AlignmentScores.from_dict(old).threshold("train-calibrated")[0] == pytest.approx(LOO)


def test_answers_move_the_cut_from_the_averaged_one_with_move_nearest_and_leave_it_by_default():
    s = scores(prior_cut=0.5)
    anchor = s.threshold("train-calibrated")[0]
    assert anchor == pytest.approx(0.5 * 0.5 + 0.5 * LOO) == pytest.approx(0.525)
    assert answered_cut(s, "train-calibrated", ())[0] == pytest.approx(anchor)
    # a "yes" the averaged cut already gets right (x, 0.7) moves nothing
    assert answered_cut(s, "train-calibrated", [Answer("x", True)], move="nearest")[0] == pytest.approx(anchor)
    # a "yes" below it (z, 0.45) lowers the cut just past z; a "no" above it (y, 0.55) lifts it just past y
    cut, note = answered_cut(s, "train-calibrated", [Answer("z", True)], move="nearest")
    assert cut == pytest.approx(0.375) and "1 yes / 0 no answers" in note
    assert answered_cut(s, "train-calibrated", [Answer("y", False)], move="nearest")[0] == pytest.approx(0.625)
    # the default (move="stay"): the averaged cut, whatever the answers say
    for answers in ([Answer("z", True)], [Answer("y", False)], [Answer("z", True), Answer("y", False)]):
        assert answered_cut(s, "train-calibrated", answers)[0] == pytest.approx(anchor)


def test_without_a_leave_one_out_cut_the_prior_cut_stands_alone_not_the_mean_over_training_pairs():
    # one relevant training object: no usable positive is left for the leave-one-out cut
    def one(**prior):
        return score_alignment(Fixed(**prior), [ObjectSpec(n) for n in TEST], [ObjectSpec(n) for n in TRAIN],
                               relevant_train=("a",), need=("train-calibrated", "non-oracle"))
    cut, note = one(prior_cut=0.6, prior_weight=0.25).threshold("train-calibrated")
    assert cut == 0.6 and "prior cut 0.6 alone: leave-one-out gave 0 positive and 3 negative" in note
    # no prior (or weight 0): the old fallback to the mean over training pairs, said so
    for prior in ({}, {"prior_cut": 0.6, "prior_weight": 0.0}):
        cut, note = one(**prior).threshold("train-calibrated")
        assert cut == one().threshold("non-oracle")[0] and note.startswith("fallback to non-oracle")


@pytest.mark.parametrize("bad", [{"prior_cut": 1.5}, {"prior_cut": -0.1}, {"prior_weight": 2.0},
                                 {"prior_cut": "half"}])
def test_a_prior_outside_the_unit_interval_is_refused_by_name(bad):
    with pytest.raises(ValidationError, match=f"RelevanceScores.{next(iter(bad))} must be a number in"):
        RelevanceScores([0.5], [0.5], [True], **bad)
