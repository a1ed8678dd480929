"""What the MaxEnt IRL rewards share: input checks, column matching by name, aligned scoring, save/load.

The MaxEnt IRL objective of both models (Ziebart et al.; the sample-based form of guided cost learning):

    L(θ) = mean_{ξ ∈ D} R_θ(ξ) − log Σ_{ξ_j ∈ U} w_j exp(R_θ(ξ_j)) − λ · ‖θ‖²

with D the demonstrations, U = D ∪ A the demonstrations plus the sample set A of alternative
trajectories, and importance weights ``w_j = 1 / (|U| q(ξ_j))``. gift uses a uniform proposal
``q = 1/|U|`` over that union (every sample weighs the same), so log w_j is a constant; it is kept in the
formula so that the reported log-likelihood is the log of a normalised p_θ.

A saved reward is one JSON file (floats written with full precision, so a reload scores identically)::

    {"format": "gift-reward", "version": 1, "model": "maxent-linear", "feature_specs": [...],
     "hyperparameters": {...}, "params": {...}, "fit_info": {...}, "metadata": {...}}
"""

from __future__ import annotations

import abc
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import attrs
import numpy as np

from gift.core.alignment import AlignmentPlan, plan_alignment
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, FeatureSpec
from gift.core.errors import GiftError, ValidationError
from gift.core.interfaces import RewardModel
from gift.core.serialization import to_jsonable
from gift_rewards.trajectory_features import check_batch

FORMAT = "gift-reward"
FORMAT_VERSION = 1


class NotFittedError(GiftError):
    """A reward was used (scored, saved, asked for its columns) before :meth:`fit` or :meth:`load`."""


def uniform_log_weights(n: int) -> float:
    """log w_j of the uniform proposal over a sample set of ``n`` trajectories: ``-log n``."""
    return -float(np.log(n))


class MaxEntReward(RewardModel):
    """Base of the MaxEnt IRL rewards. Subclasses implement :meth:`_fit`, :meth:`_score` and the params."""

    name: ClassVar[str]

    def __init__(self, *, metadata: Mapping[str, Any] | None = None) -> None:
        self._specs: tuple[FeatureSpec, ...] | None = None
        self.metadata: dict[str, Any] = dict(metadata or {})
        #: Numbers about the last fit (iterations, final objective, sizes).
        self.fit_info: dict[str, Any] = {}

    # ------------------------------------------------------------------ subclass hooks

    @abc.abstractmethod
    def _fit(self, demonstrations: np.ndarray, alternatives: np.ndarray) -> dict[str, Any]:
        """Learn from ``[N_d, T, F]`` and ``[N_a, T', F]`` (columns = :attr:`feature_specs`); return fit info."""

    @abc.abstractmethod
    def _score(self, values: np.ndarray) -> np.ndarray:
        """R_θ of ``[N, T, F]`` values in training column order: ``[N]``."""

    @abc.abstractmethod
    def hyperparameters(self) -> dict[str, Any]:
        """Constructor options (JSON-serialisable) that rebuild this model."""

    @abc.abstractmethod
    def _params_to_json(self) -> dict[str, Any]:
        """The learned parameters as JSON-serialisable lists."""

    @abc.abstractmethod
    def _params_from_json(self, params: Mapping[str, Any]) -> None:
        """Restore what :meth:`_params_to_json` wrote."""

    # ------------------------------------------------------------------ RewardModel

    @property
    def is_fitted(self) -> bool:
        return self._specs is not None

    @property
    def feature_specs(self) -> tuple[FeatureSpec, ...]:
        if self._specs is None:
            raise NotFittedError(f"reward {self.name!r} is not fitted yet: call fit() or load() first")
        return self._specs

    @property
    def feature_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.feature_specs)

    def fit(self, demonstrations: FeatureBatch, alternatives: FeatureBatch) -> "MaxEntReward":
        """Learn θ so that ``demonstrations`` ``[N_d, T, F]`` are likely against ``alternatives`` ``[N_a, T', F]``.

        Both batches must hold the same feature columns (in any order); the demonstrations' order is kept.
        """
        check_batch(demonstrations, f"{self.name}.fit(demonstrations)")
        check_batch(alternatives, f"{self.name}.fit(alternatives)")
        if set(demonstrations.names) != set(alternatives.names):
            only_d = sorted(set(demonstrations.names) - set(alternatives.names))
            only_a = sorted(set(alternatives.names) - set(demonstrations.names))
            raise ValidationError(f"{self.name}.fit: demonstrations and alternatives have different feature "
                                  f"columns (only in demonstrations: {only_d}; only in alternatives: {only_a})")
        specs = tuple(demonstrations.specs)
        alt = alternatives if alternatives.names == demonstrations.names else alternatives.reindex(specs)
        self._specs = specs
        try:
            info = self._fit(np.asarray(demonstrations.values), np.asarray(alt.values))
        except BaseException:
            self._specs = None
            raise
        self.fit_info = {"n_demonstrations": len(demonstrations), "n_alternatives": len(alternatives),
                         "proposal": "uniform over demonstrations ∪ alternatives", **info}
        return self

    def score(self, features: FeatureBatch) -> np.ndarray:
        """R_θ(ξ) for N trajectories ``[N, T, F]``: ``[N]``.

        Columns are matched by name. A training column the batch lacks is 0 when it is about an object
        (the object is absent); a missing continuous column (end effector) or a column the reward was
        not trained on is an error (test scenes go through :meth:`score_aligned`).
        """
        where = f"{self.name}.score(features)"
        check_batch(features, where)
        return self._score(self._training_columns(features, where))

    def score_aligned(self, features: FeatureBatch, alignment: Alignment) -> np.ndarray:
        """R̃_θ(ξ' | ω) = R_θ(f_ω(ξ')) for N test trajectories ``[N, T, F_test]``: ``[N]``.

        f_ω is the core's feature-column remap (:func:`gift.core.alignment.plan_alignment`, the plan behind
        :func:`~gift.core.alignment.align_features`) applied to the whole batch at once: no per-state loop.
        """
        where = f"{self.name}.score_aligned(features)"
        check_batch(features, where)
        if not isinstance(alignment, Alignment):
            raise ValidationError(f"{where}: expected an Alignment, got {type(alignment).__name__}")
        train_subjects = {s.subject for s in self.feature_specs if s.semantic}
        bad = {k: v for k, v in alignment.mapping.items() if v != DISTRACTOR and v not in train_subjects}
        if bad:
            raise ValidationError(f"{where}: the alignment maps {bad} to objects this reward was not trained on "
                                  f"(training objects: {sorted(train_subjects)})")
        roles = {(s.subject, s.role) for s in self.feature_specs if s.semantic}
        unmatched = [f"{s.name} ({s.subject} -> {alignment.target(s.subject)})" for s in features.specs
                     if s.semantic and alignment.target(s.subject) != DISTRACTOR
                     and (alignment.target(s.subject), s.role) not in roles]
        if unmatched:
            raise ValidationError(f"{where}: test column(s) {unmatched} have no counterpart of the same kind and "
                                  f"reference among the reward's columns {list(self.feature_names)} "
                                  f"(features of another task?)")
        test_names = set(features.names)
        missing = [s.name for s in self.feature_specs if not s.semantic and s.name not in test_names]
        if missing:
            raise ValidationError(f"{where}: the test features lack the continuous column(s) {missing} "
                                  f"the reward was trained on (test columns: {list(features.names)})")
        plan = plan_alignment(features.specs, dict(alignment.mapping), self.feature_specs)
        return self._score_aligned(np.asarray(features.values), plan)

    def _score_aligned(self, values: np.ndarray, plan: AlignmentPlan) -> np.ndarray:
        """R_θ(f_ω(ξ')) of test values ``[N, T, F_test]`` under the core's column ``plan``: ``[N]``.

        Default: apply the remap to the whole batch (as :func:`align_features` does), then score.
        Subclasses may fold the remap into their parameters instead.
        """
        return self._score(plan.apply(values))

    def _training_columns(self, features: FeatureBatch, where: str) -> np.ndarray:
        """``[N, T, F_train]`` values of ``features`` in training column order."""
        specs = self.feature_specs
        if features.names == tuple(s.name for s in specs):
            return np.asarray(features.values)
        known = {s.name for s in specs}
        unknown = [n for n in features.names if n not in known]
        if unknown:
            raise ValidationError(f"{where}: column(s) {unknown} are not features of this reward (trained on "
                                  f"{sorted(known)}); score a new scene through score_aligned(features, alignment)")
        have = set(features.names)
        missing = [s.name for s in specs if not s.semantic and s.name not in have]
        if missing:
            raise ValidationError(f"{where}: the features lack the continuous column(s) {missing} "
                                  f"the reward was trained on")
        return np.asarray(features.reindex(specs).values)

    # ------------------------------------------------------------------ persistence

    def save(self, path: str | Path) -> None:
        """Write weights, feature specs, hyperparameters, fit info and metadata to one JSON file."""
        doc = {"format": FORMAT, "version": FORMAT_VERSION, "model": self.name,
               "feature_specs": [attrs.asdict(s) for s in self.feature_specs],
               "hyperparameters": self.hyperparameters(), "params": self._params_to_json(),
               "fit_info": _jsonable(self.fit_info), "metadata": _jsonable(self.metadata)}
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps(doc, indent=1, allow_nan=False))
        tmp.replace(path)

    @classmethod
    def load(cls, path: str | Path) -> "MaxEntReward":
        """Read what :meth:`save` wrote (the file must hold a reward of this class's ``name``)."""
        doc = read_reward_file(path)
        if doc["model"] != cls.name:
            raise ValidationError(f"{path}: holds a {doc['model']!r} reward, not {cls.name!r} "
                                  f"(use gift_rewards.load_reward to load any kind)")
        try:
            model = cls(**doc["hyperparameters"], metadata=doc.get("metadata") or {})
            model._specs = tuple(FeatureSpec(**s) for s in doc["feature_specs"])
            model._params_from_json(doc["params"])
        except (TypeError, KeyError, ValueError) as e:
            raise ValidationError(f"{path}: malformed {cls.name!r} reward file: {e}") from e
        model.fit_info = dict(doc.get("fit_info") or {})
        return model


def read_reward_file(path: str | Path) -> dict[str, Any]:
    """The JSON document of a saved reward, with its header checked."""
    p = Path(path)
    if not p.is_file():
        raise ValidationError(f"{p}: no such reward file")
    try:
        doc = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise ValidationError(f"{p}: not a gift reward file (invalid JSON: {e})") from e
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise ValidationError(f"{p}: not a gift reward file (format field is not {FORMAT!r})")
    if doc.get("version") != FORMAT_VERSION:
        raise ValidationError(f"{p}: reward file version {doc.get('version')!r}; this gift reads {FORMAT_VERSION}")
    for key in ("model", "feature_specs", "hyperparameters", "params"):
        if key not in doc:
            raise ValidationError(f"{p}: reward file lacks the field {key!r}")
    return doc


def _jsonable(value: Any) -> Any:
    return to_jsonable(value, nonfinite="string")
