"""Alignment: f_ω on objects (the argmax-threshold rule and its thresholds) and on trajectories' features.

This module is the one place where the paper's alignment lives:

- :func:`score_alignment` runs a kernel once over a test scene and returns :class:`AlignmentScores`
  (K, a decision score per test object, the matched training object, and what the training-set
  thresholds need); :meth:`AlignmentScores.threshold` picks a cut, :meth:`AlignmentScores.alignment`
  turns it into an :class:`~gift.core.data.Alignment` (test object -> training object or DISTRACTOR).
- :class:`ArgmaxThresholdAlignment` is the registered ``argmax-threshold`` operator built on it.
- :func:`align_features` applies an alignment to a batch of trajectories (f_ω(ξ')), a remapping of
  feature columns; :func:`trajectory_error_bounds` is the paper's bound per aligned trajectory.

The alignment rule (every kernel follows it)
--------------------------------------------
Let ``rel`` be the training objects the intent makes relevant (``relevant_train``; empty = unknown).

- A :class:`~gift.core.interfaces.SimilarityKernel` (vision, language, lm-no-intent, gift) gives
  ``K = similarity(test, train, intent)`` ``[n_test, n_train]``: the paper's rule. The target of test
  object i is ``j* = argmax_j K[i, j]`` over *all* training objects (ties go to a relevant one); i is
  aligned to ``j*`` when ``K[i, j*] >= threshold``, else it is a DISTRACTOR. It is predicted *relevant*
  when aligned to a relevant training object. Its **decision score** is ``K[i, j*]`` when ``j*`` is
  relevant (or ``rel`` is empty), and ``max_{j in rel} K[i, j] - 1`` (in [-1, 0], below every cut) when
  the best match is an irrelevant training object: the threshold can never make it relevant, and such
  objects still rank among themselves (AUC) by their similarity to the relevant ones.
- A :class:`~gift.core.interfaces.RelevanceKernel` (``gift-prob``) scores every object once per scene
  (:meth:`~gift.core.interfaces.RelevanceKernel.score`): a relevance ``r_i`` in [0, 1] per test object
  (the decision score) and the same score for each training object left out of the others. Its K puts
  ``r_i`` in the relevant columns; the target is the relevant training object with the highest K
  (the first one, since they tie) when ``r_i`` reaches the threshold, else DISTRACTOR.

Predicted relevant = aligned to a relevant training object = ``decision score >= threshold``.

Thresholds (``threshold=``)
---------------------------
- a float in [0, 1]: fixed;
- ``"non-oracle"`` (the paper's): the mean of K over pairs of distinct training objects (for a
  relevance kernel, K of the training objects from their leave-one-out relevance);
- ``"train-calibrated"``: leave-one-out over the training objects. Each training object t is scored as
  if it were a test object against the *other* training objects (``rel`` minus t), relevant ones are
  positives and the others negatives, and the cut is the midpoint that best separates them (highest
  balanced accuracy; ties: the widest gap). No test label is used. Matrix kernels reuse
  ``K(train, train)`` with the diagonal masked; relevance kernels return the scores from their one
  pass. A relevant object with no relevant partner left is not a usable positive. With no positive or
  no negative left it falls back to the kernel's prior cut (below) when it has one, else to
  ``non-oracle``, and says so in the note. A relevance kernel whose
  scores are calibrated probabilities with the training evidence already folded in
  (``RelevanceScores.cut``, e.g. gift-prob with ``calibration="pooled"``) gives the cut itself: 1/2. A
  relevance kernel whose scale has a boundary of its own (``RelevanceScores.prior_cut``, e.g. gift-prob's
  1/2 at the scene's mean) has the leave-one-out cut averaged with it, ``w * prior + (1 - w) * loo``
  (``prior_weight``): a few training objects place a cut noisily (docs/results/front_half.md).
- ``"oracle"``: the cut that maximises F1 on the labelled test objects (``test_labels``): an upper bound.

f_ω on trajectories
-------------------
Alignment renames the *semantic* components of every state (which object sits in which feature slot)
and keeps continuous components (end-effector features) as they are. Since a feature of a test object
``x`` becomes the same feature of its training counterpart ``f_ω(x)``, aligning a batch is a remapping
of feature columns: no new simulation and no per-state loop.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import Any, ClassVar

import attrs
import numpy as np

from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, FeatureSpec, Intent, ObjectSpec, RelevanceScores
from gift.core.errors import GiftError
from gift.core.interfaces import AlignmentOperator, RelevanceKernel, SimilarityKernel
from gift.core.metrics import binary_metrics


# ============================================================================= f_ω on features


@attrs.frozen
class AlignmentPlan:
    """Precomputed column map from test features ``[F_test]`` to training features ``[F_train]``.

    ``pairs``: ``(test column, train column)``; several test objects mapped to one training object are
    combined by maximum (the training slot is "present" as much as its closest stand-in). Training
    columns with no test counterpart are 0: the object is absent.
    """

    train_specs: tuple[FeatureSpec, ...]
    src: np.ndarray  # [P] test column indices
    dst: np.ndarray  # [P] train column indices
    one_to_one: bool

    def apply(self, values: np.ndarray) -> np.ndarray:
        """``[N, T, F_test]`` -> ``[N, T, F_train]``."""
        out = np.zeros(values.shape[:-1] + (len(self.train_specs),), dtype=values.dtype)
        if self.one_to_one:
            out[..., self.dst] = values[..., self.src]
        else:
            for s, d in zip(self.src.tolist(), self.dst.tolist()):
                np.maximum(out[..., d], values[..., s], out=out[..., d])
        return out


def plan_alignment(test_specs: Sequence[FeatureSpec], mapping: dict[str, str],
                   train_specs: Sequence[FeatureSpec]) -> AlignmentPlan:
    """Build the column map for ``mapping`` (test object -> training object or DISTRACTOR)."""
    return _plan(tuple(test_specs), tuple(sorted(mapping.items())), tuple(train_specs))


@lru_cache(maxsize=256)
def _plan(test_specs: tuple[FeatureSpec, ...], mapping: tuple[tuple[str, str], ...],
          train_specs: tuple[FeatureSpec, ...]) -> AlignmentPlan:
    m = dict(mapping)
    train_index = {}
    for j, spec in enumerate(train_specs):
        key = (spec.subject, spec.role) if spec.semantic else (None, spec.name)
        train_index[key] = j
    src, dst = [], []
    for i, spec in enumerate(test_specs):
        if spec.semantic:
            target = m.get(spec.subject, DISTRACTOR)
            if target == DISTRACTOR:
                continue
            j = train_index.get((target, spec.role))
        else:
            j = train_index.get((None, spec.name))
        if j is not None:
            src.append(i)
            dst.append(j)
    dst_arr = np.asarray(dst, dtype=np.intp)
    return AlignmentPlan(tuple(train_specs), np.asarray(src, dtype=np.intp), dst_arr,
                         one_to_one=len(set(dst)) == len(dst))


def align_features(features: FeatureBatch, alignment: Alignment,
                   train_specs: Sequence[FeatureSpec]) -> FeatureBatch:
    """f_ω(ξ') for a batch: test features ``[N, T, F_test]`` -> aligned ``[N, T, F_train]``."""
    plan = plan_alignment(features.specs, dict(alignment.mapping), train_specs)
    return FeatureBatch(tuple(train_specs), plan.apply(features.values),
                        {**features.meta, "aligned_by": alignment.kernel})


def align_state(values: np.ndarray, test_specs: Sequence[FeatureSpec], alignment: Alignment,
                train_specs: Sequence[FeatureSpec]) -> np.ndarray:
    """f_ω(s') for a single state's features ``[F_test]`` -> ``[F_train]``."""
    plan = plan_alignment(test_specs, dict(alignment.mapping), train_specs)
    return plan.apply(np.asarray(values, dtype=float)[None, None])[0, 0]


# ============================================================================= f_ω on objects

THRESHOLDS = ("oracle", "non-oracle", "train-calibrated")

#: Decision score of an object that can never be aligned (no relevant training object exists for it).
NEVER = -1.0


def _check_matrix(K: Any, n_test: int, n_train: int, kernel: SimilarityKernel, what: str) -> np.ndarray:
    K = np.asarray(K, dtype=float)
    name = getattr(kernel, "name", type(kernel).__name__)
    if K.shape != (n_test, n_train):
        raise GiftError(f"kernel {name!r} returned a {K.shape} matrix for {what}; expected [{n_test}, {n_train}]")
    if K.size and (not np.all(np.isfinite(K)) or K.min() < -1e-9 or K.max() > 1 + 1e-9):
        raise GiftError(f"kernel {name!r} returned values outside [0, 1] for {what} "
                        f"(min {np.nanmin(K):.3g}, max {np.nanmax(K):.3g})")
    return np.clip(K, 0.0, 1.0)


def _check_vector(r: Any, n: int, kernel: SimilarityKernel, what: str) -> np.ndarray:
    r = np.asarray(r, dtype=float).reshape(-1)
    name = getattr(kernel, "name", type(kernel).__name__)
    if r.shape != (n,) or (r.size and (not np.all(np.isfinite(r)) or r.min() < -1e-9 or r.max() > 1 + 1e-9)):
        raise GiftError(f"kernel {name!r}: the relevance of {what} must be [{n}] values in [0, 1], got {r}")
    return np.clip(r, 0.0, 1.0)


def matrix_decision(K: np.ndarray, rel_mask: np.ndarray, valid: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The paper's rule on a similarity matrix: ``(decision score [n], target column [n])``.

    ``rel_mask`` ``[n_train]`` marks the relevant columns (all False = relevance unknown: every column
    counts as relevant); ``valid`` ``[n, n_train]`` masks columns a row may not use (leave-one-out).
    """
    n, m = K.shape
    valid = np.ones_like(K, dtype=bool) if valid is None else valid
    rel = rel_mask if rel_mask.any() else np.ones(m, dtype=bool)
    Kv = np.where(valid, K, -np.inf)
    # argmax with ties going to a relevant column: a tiny bonus that cannot reorder distinct values
    target = np.argmax(Kv + 1e-12 * rel[None, :], axis=1) if m else np.zeros(n, dtype=int)
    best = Kv[np.arange(n), target] if m else np.full(n, -np.inf)
    best_rel = np.where(valid & rel[None, :], K, -np.inf).max(axis=1) if m else np.full(n, -np.inf)
    score = np.where(rel[target], best, best_rel - 1.0)
    score = np.where(np.isfinite(score), score, NEVER)
    return np.maximum(score, NEVER), target


def best_separating_cut(positives: Sequence[float], negatives: Sequence[float]) -> float:
    """The cut (``score >= cut`` positive) with the highest balanced accuracy; ties: the widest gap.

    Candidates are midpoints between consecutive distinct scores and points just outside the range.
    """
    p = np.asarray(positives, dtype=float)
    n = np.asarray(negatives, dtype=float)
    if p.size == 0 or n.size == 0:
        raise GiftError("best_separating_cut needs at least one positive and one negative score")
    values = np.unique(np.concatenate([p, n]))
    gaps = np.diff(values)
    cands = np.concatenate([[values[0] - 1e-6], (values[:-1] + values[1:]) / 2, [values[-1] + 1e-6]])
    widths = np.concatenate([[0.0], gaps, [0.0]])
    bacc = np.array([((p >= c).mean() + (n < c).mean()) / 2 for c in cands])
    order = np.lexsort((-widths, -bacc))  # primary: balanced accuracy, secondary: gap width
    return float(cands[order[0]])


def oracle_cut(scores: Sequence[float], labels: Sequence[bool]) -> float:
    """The cut maximising F1 of ``score >= cut`` on the labels, among cuts in [0, 1] (NEVER stays out)."""
    s = np.asarray(scores, dtype=float)
    y = np.asarray(labels, dtype=bool)
    cands = np.unique(np.concatenate([s[s >= 0.0], [1.0 + 1e-9]]))
    f1 = [binary_metrics(s >= c, y).f1 for c in cands]
    # among equally good cuts take the highest: the fewest aligned objects for the same F1
    best = max(range(len(cands)), key=lambda k: (f1[k], cands[k]))
    return float(cands[best])


def middle_f1_cut(scores: np.ndarray, labels: np.ndarray) -> float:
    """The F1-best cut on these labels placed between scores: candidates are midpoints of neighbouring scores in
    [0, 1] and points just outside them; of equally good candidates the middle one (the median)."""
    v = np.unique(scores[scores >= 0.0])
    if v.size == 0:
        return 1.0 + 1e-9
    cands = np.concatenate([[v[0] - 1e-6], (v[:-1] + v[1:]) / 2, [v[-1] + 1e-6]])
    f1 = np.array([binary_metrics(scores >= c, labels).f1 for c in cands])
    tied = cands[np.isclose(f1, f1.max())]
    return float(tied[(tied.size - 1) // 2])


def leave_one_out_oracle(scores: Sequence[float], labels: Sequence[bool]) -> np.ndarray:
    """``[n]`` bool: object i is predicted relevant iff its score reaches the F1-best cut of the other ``n - 1``
    objects and their labels (placed between their scores; of equal cuts the middle one). What a cut chosen with
    labels does out of sample, against the in-sample maximum of :func:`oracle_cut`."""
    s = np.asarray(scores, dtype=float)
    y = np.asarray(labels, dtype=bool)
    if s.shape != y.shape or s.ndim != 1:
        raise GiftError(f"leave_one_out_oracle needs one label per score, got shapes {s.shape} and {y.shape}")
    keep = ~np.eye(s.size, dtype=bool)
    return np.array([s[i] >= middle_f1_cut(s[keep[i]], y[keep[i]]) for i in range(s.size)], dtype=bool)


@attrs.frozen
class AlignmentScores:
    """Everything the kernel said about one test scene, before a threshold is chosen.

    ``K`` ``[n_test, n_train]``; ``decision`` ``[n_test]`` (predicted relevant iff ``>= threshold``);
    ``aligned`` ``[n_test]`` (mapped to ``target`` iff ``>= threshold``, else DISTRACTOR: ``K`` at the
    target for matrix kernels, the relevance for relevance kernels); ``target`` ``[n_test]`` training
    column of the match;
    ``train_mean``: mean of K over distinct training pairs (None if not computed); ``loo_scores`` /
    ``loo_labels`` ``[m]``: leave-one-out decision scores of the training objects and whether each is
    relevant (None if not computed); ``relevant_mask`` ``[m]``: the training columns the decisions treat
    as relevant (a relevance kernel's own guess when ``relevant_train`` is empty; for a matrix kernel
    without ``relevant_train`` all False: every column counts; None if not recorded).
    :meth:`to_dict` / :meth:`from_dict` keep them as JSON, so a scene can be re-thresholded (or re-scored
    with answers, :mod:`gift.core.queries`) without running the kernel again.
    """

    test: tuple[str, ...]
    train: tuple[str, ...]
    relevant_train: tuple[str, ...]
    K: np.ndarray = attrs.field(eq=False)
    decision: np.ndarray = attrs.field(eq=False)
    target: np.ndarray = attrs.field(eq=False)
    aligned: np.ndarray = attrs.field(eq=False)
    kernel: str = ""
    train_mean: float | None = None
    loo_scores: np.ndarray | None = attrs.field(default=None, eq=False)
    loo_labels: np.ndarray | None = attrs.field(default=None, eq=False)
    #: the kernel's LM answers completed by default during this pass (see MappingKernel.fallbacks)
    fallbacks: tuple[str, ...] = ()
    #: JSON-able notes of a relevance kernel's pass (e.g. the category asked about, term weights)
    details: Mapping[str, Any] = attrs.field(factory=dict, eq=False)
    #: the cut a calibrated relevance kernel's probabilities call for (train-calibrated uses it), or None
    natural_cut: float | None = None
    #: a relevance kernel's prior cut and its weight in the train-calibrated cut (RelevanceScores.prior_cut)
    prior_cut: float | None = None
    prior_weight: float = 0.5
    relevant_mask: np.ndarray | None = attrs.field(default=None, eq=False)
    #: True when the scores come from a RelevanceKernel (K = relevance in the relevant columns)
    relevance_kernel: bool = False

    _ARRAYS: ClassVar[tuple[str, ...]] = ("K", "decision", "target", "aligned", "loo_scores", "loo_labels",
                                          "relevant_mask")

    def to_dict(self) -> dict[str, Any]:
        """JSON-able form (arrays as lists); :meth:`from_dict` reads it back."""
        out: dict[str, Any] = {"test": list(self.test), "train": list(self.train),
                               "relevant_train": list(self.relevant_train), "kernel": self.kernel,
                               "train_mean": self.train_mean, "fallbacks": list(self.fallbacks),
                               "details": dict(self.details), "relevance_kernel": self.relevance_kernel,
                               "natural_cut": self.natural_cut, "prior_cut": self.prior_cut,
                               "prior_weight": self.prior_weight}
        for name in self._ARRAYS:
            v = getattr(self, name)
            out[name] = None if v is None else np.asarray(v).tolist()
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "AlignmentScores":
        """Read what :meth:`to_dict` wrote (a GiftError names a missing field)."""
        missing = [k for k in ("test", "train", "K", "decision", "target", "aligned") if k not in d]
        if missing:
            raise GiftError(f"alignment scores: fields {missing} are missing")
        n, m = len(d["test"]), len(d["train"])
        dtypes = {"target": np.intp, "loo_labels": bool, "relevant_mask": bool}
        arrays = {k: (None if d.get(k) is None else np.asarray(d[k], dtype=dtypes.get(k, float)))
                  for k in cls._ARRAYS}
        arrays["K"] = arrays["K"].reshape(n, m)
        return cls(test=tuple(d["test"]), train=tuple(d["train"]), relevant_train=tuple(d.get("relevant_train", ())),
                   kernel=d.get("kernel", ""), train_mean=d.get("train_mean"), fallbacks=tuple(d.get("fallbacks", ())),
                   details=dict(d.get("details") or {}), relevance_kernel=bool(d.get("relevance_kernel", False)),
                   natural_cut=d.get("natural_cut"), prior_cut=d.get("prior_cut"),
                   prior_weight=float(d.get("prior_weight", 0.5)), **arrays)

    def with_relevance(self, relevance: Sequence[float], train_loo: Sequence[float]) -> "AlignmentScores":
        """The same scene scored by other relevances (a term of the kernel, another intent candidate):
        ``relevance`` ``[n_test]`` and ``train_loo`` ``[n_train]`` in [0, 1], with the relevant columns,
        the targets' rule and the thresholds' evidence rebuilt as :func:`score_alignment` builds them.
        Only for the scores of a relevance kernel; a view has no natural cut (its scores are not the kernel's
        calibrated probabilities), so its train-calibrated cut is placed on its training scores; it keeps the
        kernel's prior cut (views are on the kernel's relevance scale)."""
        if not self.relevance_kernel or self.relevant_mask is None:
            raise GiftError(f"with_relevance needs the scores of a relevance kernel; {self.kernel!r} gave a matrix")
        r = _check_vector(relevance, len(self.test), self.kernel, "the test objects (view)")
        t = _check_vector(train_loo, len(self.train), self.kernel, "the held-out training objects (view)")
        return _relevance_scores(self.test, self.train, self.relevant_train, self.kernel, r, t, self.relevant_mask,
                                 want_train=self.train_mean is not None,
                                 calibrated=self.loo_scores is not None, details=self.details,
                                 fallbacks=self.fallbacks, prior=(self.prior_cut, self.prior_weight))

    def threshold(self, strategy: str | float, test_labels: Mapping[str, bool] | None = None
                  ) -> tuple[float, str]:
        """``(cut, note)`` for a strategy (see the module docstring). ``note`` says how it was chosen."""
        if isinstance(strategy, (int, float)) and not isinstance(strategy, bool):
            if not 0.0 <= float(strategy) <= 1.0:
                raise GiftError(f"a fixed alignment threshold must be in [0, 1], got {strategy}")
            return float(strategy), "fixed"
        if strategy == "oracle":
            if test_labels is None:
                raise GiftError("the oracle threshold needs test labels (test_labels={object: relevant}); "
                                "it is an upper bound for evaluation, not for deployment")
            missing = [t for t in self.test if t not in test_labels]
            if missing:
                raise GiftError(f"oracle threshold: no label for test objects {missing}")
            return oracle_cut(self.decision, [bool(test_labels[t]) for t in self.test]), "oracle (test labels)"
        if strategy == "non-oracle":
            if self.train_mean is None:
                raise GiftError("non-oracle threshold: K(train, train) was not computed; pass "
                                "need=('non-oracle',) to score_alignment")
            return self.train_mean, "mean K over training pairs"
        if strategy == "train-calibrated":
            if self.natural_cut is not None and self.relevant_train:
                return float(self.natural_cut), ("the kernel's calibrated probabilities (a pooled prior updated with "
                                                 "the relevant training objects): 1/2")
            if not self.relevant_train:
                if self.train_mean is None:
                    raise GiftError("the train-calibrated threshold needs the relevant training objects "
                                    "(relevant_train / --relevant) to tell positives from negatives")
                return self.train_mean, "fallback to non-oracle: no relevant training object is known"
            if self.loo_scores is None:
                raise GiftError("train-calibrated threshold: leave-one-out scores were not computed; pass "
                                "need=('train-calibrated',) to score_alignment")
            usable = self.loo_scores > NEVER
            pos = self.loo_scores[usable & self.loo_labels]
            neg = self.loo_scores[usable & ~self.loo_labels]
            if pos.size == 0 or neg.size == 0:
                if self.prior_cut is not None and self.prior_weight > 0.0:
                    return float(self.prior_cut), (f"the kernel's prior cut {self.prior_cut:g} alone: leave-one-out "
                                                   f"gave {pos.size} positive and {neg.size} negative scores")
                if self.train_mean is None:
                    raise GiftError("train-calibrated threshold: the training objects give no positive or no "
                                    "negative leave-one-out score, and no K(train, train) mean to fall back on")
                return self.train_mean, (f"fallback to non-oracle: leave-one-out gave {pos.size} positive and "
                                         f"{neg.size} negative scores")
            cut = float(np.clip(best_separating_cut(pos, neg), 0.0, 1.0))
            note = f"leave-one-out over {pos.size} relevant / {neg.size} other training objects"
            if self.prior_cut is None or self.prior_weight == 0.0:
                return cut, note
            w = self.prior_weight
            return (w * self.prior_cut + (1.0 - w) * cut,
                    f"{note} ({cut:.3f}), averaged with the kernel's prior cut {self.prior_cut:g} (weight {w:g})")
        raise GiftError(f"unknown threshold {strategy!r}; use one of {THRESHOLDS} or a number in [0, 1]")

    def alignment(self, cut: float) -> Alignment:
        """The Alignment for a cut: aligned iff ``aligned >= cut``; scores = K at the matched object."""
        mapping, scores = {}, {}
        for i, name in enumerate(self.test):
            k = float(self.K[i, self.target[i]]) if self.train else 0.0
            mapping[name] = self.train[self.target[i]] if self.train and self.aligned[i] >= cut else DISTRACTOR
            scores[name] = k
        return Alignment(mapping=mapping, scores=scores, threshold=float(cut), kernel=self.kernel)

    def predicted_relevant(self, cut: float) -> np.ndarray:
        """``[n_test]`` bool: aligned to a relevant training object."""
        return self.decision >= cut


def score_alignment(kernel: SimilarityKernel, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                    intent: Intent | None = None, *, relevant_train: Sequence[str] = (),
                    need: Sequence[str] = THRESHOLDS) -> AlignmentScores:
    """Run the kernel once over a test scene; everything every threshold in ``need`` requires.

    A :class:`~gift.core.interfaces.RelevanceKernel` is asked :meth:`~RelevanceKernel.score` once (test
    relevance, leave-one-out training relevance). A matrix kernel is asked ``similarity(test + train,
    train)`` once when ``need`` has a training-set threshold (the training rows give K(train, train)),
    else ``similarity(test, train)``: an LM kernel spends no extra calls on the thresholds.
    """
    test, train = tuple(test), tuple(train)
    names = [o.name for o in train]
    unknown = [r for r in relevant_train if r not in names]
    if unknown:
        raise GiftError(f"relevant_train names {unknown}, which are not training objects {names}")
    if len({o.name for o in test}) != len(test):
        raise GiftError(f"duplicate test object names: {[o.name for o in test]}")
    kname = getattr(kernel, "name", type(kernel).__name__)
    rel_mask = np.array([n in set(relevant_train) for n in names], dtype=bool)
    need = set(need)
    want_train = ("non-oracle" in need or "train-calibrated" in need) and len(train) > 1
    n_fallbacks = len(getattr(kernel, "fallbacks", ()))
    if isinstance(kernel, RelevanceKernel):
        rs = kernel.score(test, train, intent, tuple(relevant_train))
        return _from_relevance(kernel, rs, test, train, tuple(relevant_train), need, n_fallbacks)
    train_mean = loo_scores = loo_labels = None
    rows = test + train if want_train else test
    K_all = _check_matrix(kernel.similarity(rows, train, intent), len(rows), len(train), kernel,
                          "the test objects" + (" and the training objects" if want_train else ""))
    K, Ktt = K_all[:len(test)], (K_all[len(test):] if want_train else None)
    decision, target = matrix_decision(K, rel_mask)
    aligned = K[np.arange(len(test)), target] if len(train) else np.zeros(len(test))
    if Ktt is not None:
        train_mean = float(Ktt[~np.eye(len(train), dtype=bool)].mean())
        if "train-calibrated" in need and relevant_train:
            loo_labels = rel_mask.copy()
            loo_scores, _ = matrix_decision(Ktt, rel_mask, valid=~np.eye(len(train), dtype=bool))
    fallbacks = tuple(getattr(kernel, "fallbacks", ()))[n_fallbacks:]  # LM answers completed by default
    return AlignmentScores(test=tuple(o.name for o in test), train=tuple(names),
                           relevant_train=tuple(relevant_train), K=K, decision=decision, target=target,
                           aligned=aligned, kernel=kname, train_mean=train_mean, loo_scores=loo_scores,
                           loo_labels=loo_labels, fallbacks=fallbacks, relevant_mask=rel_mask)


def rescore_alignment(kernel: SimilarityKernel, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                      intent: Intent | None = None, *, relevant_train: Sequence[str] = (),
                      answers: Mapping[str, bool], need: Sequence[str] = THRESHOLDS) -> AlignmentScores | None:
    """The scene of :func:`score_alignment` scored again with the human's ``answers`` (test object name ->
    part of the goal?) as evidence (:meth:`RelevanceKernel.score_with_answers`); None when the kernel cannot
    use answers (a matrix kernel, or a relevance kernel that does not implement it)."""
    test, train = tuple(test), tuple(train)
    names = {o.name for o in test}
    unknown = [a for a in answers if a not in names]
    if unknown:
        raise GiftError(f"answers about {unknown}, which are not test objects {sorted(names)}")
    if not isinstance(kernel, RelevanceKernel) or not answers:
        return None
    n_fallbacks = len(getattr(kernel, "fallbacks", ()))
    rs = kernel.score_with_answers(test, train, intent, tuple(relevant_train), dict(answers))
    if rs is None:
        return None
    return _from_relevance(kernel, rs, test, train, tuple(relevant_train), set(need), n_fallbacks)


def _from_relevance(kernel: SimilarityKernel, rs: RelevanceScores, test: tuple[ObjectSpec, ...],
                    train: tuple[ObjectSpec, ...], relevant_train: tuple[str, ...], need: set[str] | Sequence[str],
                    n_fallbacks: int) -> AlignmentScores:
    """:class:`AlignmentScores` of one :class:`RelevanceScores` pass, its shapes checked."""
    kname = getattr(kernel, "name", type(kernel).__name__)
    decision = _check_vector(rs.relevance, len(test), kernel, "the test objects")
    train_r = _check_vector(rs.train_loo, len(train), kernel, "the held-out training objects")
    mask = np.asarray(rs.relevant, dtype=bool)
    if mask.shape != (len(train),):
        raise GiftError(f"kernel {kname!r}: RelevanceScores.relevant must be [{len(train)}] booleans")
    fallbacks = tuple(getattr(kernel, "fallbacks", ()))[n_fallbacks:]
    want_train = ("non-oracle" in need or "train-calibrated" in need) and len(train) > 1
    return _relevance_scores(tuple(o.name for o in test), tuple(o.name for o in train), relevant_train, kname,
                             decision, train_r, mask, want_train=want_train,
                             calibrated="train-calibrated" in need and bool(relevant_train),
                             details=dict(rs.details), fallbacks=fallbacks, natural_cut=rs.cut,
                             prior=(rs.prior_cut, rs.prior_weight))


def _relevance_scores(test: tuple[str, ...], train: tuple[str, ...], relevant_train: tuple[str, ...], kname: str,
                      decision: np.ndarray, train_r: np.ndarray, mask: np.ndarray, *, want_train: bool,
                      calibrated: bool, details: Mapping[str, Any], fallbacks: tuple[str, ...],
                      natural_cut: float | None = None, prior: tuple[float | None, float] = (None, 0.5)
                      ) -> AlignmentScores:
    """:class:`AlignmentScores` of one relevance pass (the relevance kernels' rule of the module docstring)."""
    K = np.where(mask[None, :], decision[:, None], 0.0)
    target = np.argmax(np.where(mask[None, :], K, -np.inf), axis=1) if len(train) else np.zeros(len(test), int)
    train_mean = loo_scores = loo_labels = None
    if want_train:
        Ktt = np.where(mask[None, :], train_r[:, None], 0.0)
        train_mean = float(Ktt[~np.eye(len(train), dtype=bool)].mean())
        if calibrated:
            rel_mask = np.array([n in set(relevant_train) for n in train], dtype=bool)
            loo_labels = rel_mask.copy()
            # a relevant object with no relevant partner left cannot be scored as a positive
            lonely = rel_mask & (rel_mask.sum() < 2)
            loo_scores = np.where(lonely, NEVER, train_r)
    return AlignmentScores(test=test, train=train, relevant_train=relevant_train, K=K, decision=decision,
                           target=target, aligned=decision, kernel=kname, train_mean=train_mean,
                           loo_scores=loo_scores, loo_labels=loo_labels, fallbacks=fallbacks, details=dict(details),
                           relevant_mask=mask.copy(), relevance_kernel=True, natural_cut=natural_cut,
                           prior_cut=prior[0], prior_weight=prior[1])


def trajectory_error_bounds(features: FeatureBatch, alignment: Alignment, lipschitz: float = 1.0) -> np.ndarray:
    """The paper's bound L · Σ_t (1 − K(f_ω(s'_t), s'_t | ω)) for each of N test trajectories: ``[N]``.

    ``features`` are the *test* features ``[N, T, F]``. The dissimilarity of state t is the largest
    ``1 − K`` over the aligned objects that are present in it — an object whose semantic features are
    all 0 at t (absent or far) contributes nothing to a reward linear in those features, so its
    alignment cannot change that state's reward. Distractors are dropped, not aligned: they add 0.
    Tighter than :meth:`Alignment.error_bound`, which charges every step for every aligned object.
    """
    if lipschitz < 0:
        raise GiftError(f"the Lipschitz constant must be >= 0, got {lipschitz}")
    gaps = np.zeros(len(features.specs))
    for f, spec in enumerate(features.specs):
        if spec.semantic and alignment.target(spec.subject) != DISTRACTOR:
            gaps[f] = 1.0 - float(alignment.scores.get(spec.subject, 1.0))
    present = features.values != 0.0  # [N, T, F]
    per_state = np.max(np.where(present, gaps, 0.0), axis=-1, initial=0.0)  # [N, T]
    return lipschitz * per_state.sum(axis=-1)


@attrs.frozen
class AlignedFeatures:
    """f_ω(ξ') for N test trajectories: aligned ``features`` ``[N, T, F_train]`` and ``error_bounds`` ``[N]``."""

    features: FeatureBatch
    error_bounds: np.ndarray = attrs.field(eq=False)
    alignment: Alignment


class ArgmaxThresholdAlignment(AlignmentOperator):
    """argmax over training objects; DISTRACTOR below ``threshold`` (oracle, non-oracle, train-calibrated, float)."""

    name: ClassVar[str] = "argmax-threshold"

    def __init__(self, threshold: str | float = "non-oracle", lipschitz: float = 1.0) -> None:
        if isinstance(threshold, str):
            try:
                threshold = float(threshold)
            except ValueError:
                if threshold not in THRESHOLDS:
                    raise GiftError(f"unknown threshold {threshold!r}; use one of {THRESHOLDS} or a number "
                                    f"in [0, 1]") from None
        if not isinstance(threshold, str) and not 0.0 <= float(threshold) <= 1.0:
            raise GiftError(f"a fixed alignment threshold must be in [0, 1], got {threshold}")
        self.threshold = threshold
        self.lipschitz = float(lipschitz)
        #: how the last threshold was chosen (for reports)
        self.last_note = ""

    def __repr__(self) -> str:
        return f"ArgmaxThresholdAlignment(threshold={self.threshold!r})"

    def align(self, kernel: SimilarityKernel, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
              intent: Intent | None = None, *, relevant_train: Sequence[str] = (),
              test_labels: Mapping[str, bool] | None = None) -> Alignment:
        """Map every test object to a training object or DISTRACTOR (``test_labels`` only for oracle)."""
        need = () if not isinstance(self.threshold, str) else (self.threshold,)
        if self.threshold == "train-calibrated":
            need = ("train-calibrated", "non-oracle")
        scores = score_alignment(kernel, test, train, intent, relevant_train=relevant_train, need=need)
        cut, self.last_note = scores.threshold(self.threshold, test_labels)
        return scores.alignment(cut)

    def transform(self, features: FeatureBatch, alignment: Alignment,
                  train_specs: Sequence[FeatureSpec]) -> AlignedFeatures:
        """Apply f_ω to a batch (a trajectory is a batch of one; a state a trajectory of one step).

        Continuous components (features with no subject) pass through unchanged.
        """
        return AlignedFeatures(features=align_features(features, alignment, train_specs),
                               error_bounds=trajectory_error_bounds(features, alignment, self.lipschitz),
                               alignment=alignment)
