import numpy as np
import pytest

from gift.core import metrics


def test_win_rate_counts_ties_half_and_skips_indifferent_pairs():
    true = np.array([3.0, 2.0, 1.0, 1.0])
    assert metrics.pairwise_win_rate(true, true) == 1.0
    assert metrics.pairwise_win_rate(-true, true) == 0.0
    assert metrics.pairwise_win_rate(np.zeros(4), true) == 0.5
    pairs = np.array([[0, 1], [2, 3]])  # the second pair is a true tie: skipped
    assert metrics.pairwise_win_rate(np.array([1.0, 2.0, 0, 0]), true, pairs) == 0.0
    with pytest.raises(ValueError):
        metrics.pairwise_win_rate(true, np.ones(4))


def test_sample_pairs_are_distinct():
    p = metrics.sample_pairs(5, 1000, np.random.default_rng(0))
    assert p.shape == (1000, 2) and np.all(p[:, 0] != p[:, 1]) and p.max() < 5


def test_binary_metrics_auc_threshold_boltzmann_cosine():
    m = metrics.binary_metrics([1, 1, 0, 0], [1, 0, 1, 0])
    assert (m.tp, m.fp, m.tn, m.fn) == (1, 1, 1, 1) and m.f1 == 0.5 and m.fp_rate == 0.5
    assert metrics.roc_auc([0.9, 0.8, 0.1], [1, 1, 0]) == 1.0
    assert metrics.roc_auc([0.5, 0.5], [1, 0]) == 0.5
    assert np.isnan(metrics.roc_auc([0.1], [1]))
    p = metrics.boltzmann(np.array([[0.0, np.log(3.0)]]))
    assert np.allclose(p, [[0.25, 0.75]])
    assert metrics.mean_se([1.0, 3.0]) == (2.0, 1.0)
    assert np.allclose(metrics.cosine(np.eye(2), np.eye(2)), np.eye(2))
