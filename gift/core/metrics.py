"""Evaluation metrics: pairwise win rate, Boltzmann choice, alignment F1/FP/FN, AUC."""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np


def pairwise_win_rate(predicted: np.ndarray, true: np.ndarray, pairs: np.ndarray | None = None) -> float:
    """Accuracy of predicting which trajectory of each pair the human prefers.

    ``predicted``, ``true``: rewards ``[N]``; ``pairs``: ``[P, 2]`` indices (default: all pairs).
    A correct order counts 1, a predicted tie 0.5; pairs the human is indifferent about are skipped.
    """
    predicted = np.asarray(predicted, dtype=float)
    true = np.asarray(true, dtype=float)
    if pairs is None:
        i, j = np.triu_indices(len(true), k=1)
    else:
        pairs = np.asarray(pairs, dtype=np.intp)
        i, j = pairs[:, 0], pairs[:, 1]
    t = np.sign(true[i] - true[j])
    p = np.sign(predicted[i] - predicted[j])
    keep = t != 0
    if not keep.any():
        raise ValueError("pairwise_win_rate: the true rewards tie on every pair")
    t, p = t[keep], p[keep]
    return float(np.mean(np.where(p == 0, 0.5, (p == t).astype(float))))


def sample_pairs(n: int, n_pairs: int, rng: np.random.Generator) -> np.ndarray:
    """``[n_pairs, 2]`` distinct index pairs drawn uniformly from ``range(n)``."""
    i = rng.integers(0, n, size=n_pairs)
    j = (i + rng.integers(1, n, size=n_pairs)) % n
    return np.stack([i, j], axis=1)


def mean_se(values: Sequence[float]) -> tuple[float, float]:
    """Mean and standard error of the mean (0 for a single value)."""
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return float("nan"), float("nan")
    se = float(v.std(ddof=1) / np.sqrt(v.size)) if v.size > 1 else 0.0
    return float(v.mean()), se


def boltzmann(rewards: np.ndarray, beta: float = 1.0) -> np.ndarray:
    """P(ξ_k) ∝ exp(β R(ξ_k)) over the last axis of ``rewards`` ``[..., K]``."""
    z = beta * np.asarray(rewards, dtype=float)
    z = z - z.max(axis=-1, keepdims=True)
    e = np.exp(z)
    return e / e.sum(axis=-1, keepdims=True)


@attrs.frozen
class BinaryMetrics:
    tp: int
    fp: int
    tn: int
    fn: int

    @property
    def precision(self) -> float:
        return self.tp / (self.tp + self.fp) if self.tp + self.fp else 0.0

    @property
    def recall(self) -> float:
        return self.tp / (self.tp + self.fn) if self.tp + self.fn else 0.0

    @property
    def f1(self) -> float:
        d = 2 * self.tp + self.fp + self.fn
        return 2 * self.tp / d if d else 0.0

    @property
    def fp_rate(self) -> float:
        """FP as a fraction of the negatives (the paper's FP %)."""
        return self.fp / (self.fp + self.tn) if self.fp + self.tn else 0.0

    @property
    def fn_rate(self) -> float:
        """FN as a fraction of the positives (the paper's FN %)."""
        return self.fn / (self.fn + self.tp) if self.fn + self.tp else 0.0

    def as_dict(self) -> dict[str, float]:
        return {"tp": self.tp, "fp": self.fp, "tn": self.tn, "fn": self.fn, "precision": self.precision,
                "recall": self.recall, "f1": self.f1, "fp_rate": self.fp_rate, "fn_rate": self.fn_rate}


def binary_metrics(predicted: Sequence[bool], truth: Sequence[bool]) -> BinaryMetrics:
    p = np.asarray(predicted, dtype=bool)
    t = np.asarray(truth, dtype=bool)
    if p.shape != t.shape:
        raise ValueError(f"binary_metrics: {p.shape} predictions for {t.shape} labels")
    return BinaryMetrics(tp=int((p & t).sum()), fp=int((p & ~t).sum()), tn=int((~p & ~t).sum()),
                         fn=int((~p & t).sum()))


def roc_auc(scores: Sequence[float], labels: Sequence[bool]) -> float:
    """Probability that a random positive scores above a random negative (ties count 1/2)."""
    s = np.asarray(scores, dtype=float)
    y = np.asarray(labels, dtype=bool)
    pos, neg = s[y], s[~y]
    if pos.size == 0 or neg.size == 0:
        return float("nan")
    diff = pos[:, None] - neg[None, :]
    return float(((diff > 0).sum() + 0.5 * (diff == 0).sum()) / diff.size)


def cosine(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cosine similarity matrix of row vectors: ``[n, d] x [m, d] -> [n, m]``."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    a = a / np.maximum(np.linalg.norm(a, axis=-1, keepdims=True), 1e-12)
    b = b / np.maximum(np.linalg.norm(b, axis=-1, keepdims=True), 1e-12)
    return a @ b.T


# ----------------------------------------------------------------------------- alignment on labelled test objects


def subset_metrics(decision: np.ndarray, labels: np.ndarray, cut: float) -> dict[str, float]:
    """Counts and rates of ``decision >= cut`` against ``labels``, plus AUC of ``decision`` (NaN: one class)."""
    m = binary_metrics(np.asarray(decision) >= cut, labels)
    out: dict[str, float] = {"n": int(np.asarray(labels).size), **m.as_dict()}
    out["auc"] = roc_auc(decision, labels) if np.asarray(labels).size else float("nan")
    return out


def alignment_metrics(decision: np.ndarray, labels: Sequence[bool], subsets: dict[str, np.ndarray],
                      cuts: dict[str, float]) -> dict[str, dict[str, dict[str, float]]]:
    """``{threshold: {subset: metrics}}`` of one intent: ``decision`` ``[n]``, ``labels`` ``[n]``,
    ``subsets`` name -> membership mask ``[n]`` (empty subsets are left out), ``cuts`` threshold -> cut."""
    y = np.asarray(labels, dtype=bool)
    d = np.asarray(decision, dtype=float)
    return {thr: {sub: subset_metrics(d[mask], y[mask], cut) for sub, mask in subsets.items() if mask.any()}
            for thr, cut in cuts.items()}


def pooled_alignment_metrics(per_intent: Sequence[tuple[np.ndarray, np.ndarray, dict[str, np.ndarray],
                                                        dict[str, float], dict[str, dict[str, dict[str, float]]]]],
                             thresholds: Sequence[str], subsets: Sequence[str]) -> dict[str, dict[str, dict]]:
    """Metrics pooled over intents (micro: counts summed) plus the mean per-intent F1 and AUC.

    ``per_intent``: ``(decision, labels, subset masks, cuts, that intent's alignment_metrics)`` tuples.
    """
    import math

    out: dict[str, dict[str, dict]] = {}
    for thr in thresholds:
        out[thr] = {}
        for sub in subsets:
            preds, labels, f1s, aucs = [], [], [], []
            for decision, y, masks, cuts, metrics in per_intent:
                mask = masks.get(sub)
                if mask is None or not mask.any():
                    continue
                preds.append(np.asarray(decision)[mask] >= cuts[thr])
                labels.append(np.asarray(y, dtype=bool)[mask])
                f1s.append(metrics[thr][sub]["f1"])
                aucs.append(metrics[thr][sub]["auc"])
            if not labels:
                continue
            p, y_all = np.concatenate(preds), np.concatenate(labels)
            m = binary_metrics(p, y_all)
            finite = [a for a in aucs if a is not None and not math.isnan(a)]
            out[thr][sub] = {"n": int(y_all.size), **m.as_dict(), "f1_mean_intent": float(np.mean(f1s)),
                             "auc_mean_intent": float(np.mean(finite)) if finite else float("nan")}
    return out
