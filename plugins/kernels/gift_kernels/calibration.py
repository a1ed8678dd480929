"""A calibration of gift-prob's terms that means the same in every intent.

gift-prob scores each object with two terms: ``lm``, the embedded LM's log-odds that the object is one of
the goal's category, and ``language``, a contrastive MiniLM similarity to the relevant training objects.
Z-scoring them per intent puts every intent on its own scale, and three to six training objects are too
few to place a cut on that scale. :class:`TermCalibration` instead maps the raw terms to a probability
with one logistic model fitted once on the test objects of pooled development intents
(``scripts/fit_gift_prob_calibration.py``; the fitted file ships as ``gift_kernels/data/gift_prob_calibration.json``
and records what it was fitted on). Each intent then updates that model with its own leave-one-out
training objects (:meth:`TermCalibration.update`: a MAP logistic regression whose Gaussian prior is the
pooled model, of scale ``prior_sd`` per standardized coefficient), and an object is relevant when its
posterior probability reaches 1/2.

Features are standardized with the pooled means and standard deviations (fixed constants, not per intent).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from gift.core.errors import GiftError

TERMS = ("lm", "language")
PACKAGED = "gift_prob_calibration.json"


def _array(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=float).reshape(-1)


def fit_logistic(X: np.ndarray, y: np.ndarray, prior_mean: np.ndarray | None = None, prior_sd: float = 1e3,
                 iters: int = 100) -> np.ndarray:
    """MAP logistic regression ``[w_1, ..., w_d, b]`` of ``y`` ``[n]`` on ``X`` ``[n, d]`` under a Gaussian prior
    ``N(prior_mean, prior_sd^2)`` on every coefficient and the intercept (Newton's method)."""
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)
    Xb = np.hstack([X, np.ones((len(X), 1))])
    m = np.zeros(Xb.shape[1]) if prior_mean is None else _array(prior_mean)
    w = m.copy()
    lam = 1.0 / float(prior_sd) ** 2
    for _ in range(iters):
        p = 1.0 / (1.0 + np.exp(-np.clip(Xb @ w, -50, 50)))
        g = Xb.T @ (p - y) + lam * (w - m)
        H = Xb.T @ (Xb * (p * (1 - p))[:, None]) + lam * np.eye(len(w))
        step = np.linalg.solve(H, g)
        w = w - step
        if np.abs(step).max() < 1e-10:
            break
    return w


@attrs.frozen
class TermCalibration:
    """``P(relevant | x) = σ(coef · (x − mean) / sd + intercept)`` for term values ``x`` (:data:`TERMS` order).

    ``prior_sd``: how far one intent's training objects may move each standardized coefficient
    (:meth:`update`); ``fitted_on``: what the pooled model was fitted on (suites, intents, objects, commit).
    """

    mean: np.ndarray = attrs.field(converter=_array, eq=False)
    sd: np.ndarray = attrs.field(converter=_array, eq=False)
    coef: np.ndarray = attrs.field(converter=_array, eq=False)
    intercept: float = attrs.field(converter=float)
    prior_sd: float = attrs.field(default=1.0, converter=float)
    terms: tuple[str, ...] = attrs.field(default=TERMS, converter=tuple)
    fitted_on: Mapping[str, Any] = attrs.field(factory=dict, eq=False)

    def __attrs_post_init__(self) -> None:
        d = len(self.terms)
        if not (self.mean.shape == self.sd.shape == self.coef.shape == (d,)):
            raise GiftError(f"TermCalibration: mean, sd and coef need {d} values (terms {self.terms})")
        if np.any(self.sd <= 0) or self.prior_sd <= 0:
            raise GiftError("TermCalibration: standard deviations and prior_sd must be positive")

    def standardize(self, X: np.ndarray) -> np.ndarray:
        return (np.asarray(X, dtype=float) - self.mean) / self.sd

    def probability(self, X: np.ndarray) -> np.ndarray:
        """``[n]`` probabilities for term values ``X`` ``[n, d]``."""
        z = self.standardize(X) @ self.coef + self.intercept
        return 1.0 / (1.0 + np.exp(-np.clip(z, -50, 50)))

    def update(self, X: np.ndarray, y: Sequence[bool]) -> "TermCalibration":
        """The intent's model: the pooled one as the prior, updated with labelled objects ``X`` ``[n, d]``."""
        y = np.asarray(y, dtype=bool)
        if len(y) == 0 or y.all() or not y.any():
            return self
        w = fit_logistic(self.standardize(X), y, prior_mean=np.append(self.coef, self.intercept),
                         prior_sd=self.prior_sd)
        return attrs.evolve(self, coef=w[:-1], intercept=float(w[-1]))

    @classmethod
    def fit(cls, X: np.ndarray, y: Sequence[bool], *, prior_sd: float = 1.0, fitted_on: Mapping[str, Any] = (),
            terms: Sequence[str] = TERMS) -> "TermCalibration":
        """The pooled model: standardize ``X`` ``[n, d]`` with its own mean and sd, then a (nearly flat-prior)
        logistic regression on ``y``."""
        X = np.asarray(X, dtype=float)
        mean, sd = X.mean(axis=0), X.std(axis=0)
        sd = np.where(sd > 1e-9, sd, 1.0)
        w = fit_logistic((X - mean) / sd, np.asarray(y, dtype=float), prior_sd=10.0)
        return cls(mean, sd, w[:-1], float(w[-1]), prior_sd, tuple(terms), dict(fitted_on or {}))

    def to_dict(self) -> dict[str, Any]:
        return {"terms": list(self.terms), "mean": self.mean.tolist(), "sd": self.sd.tolist(),
                "coef": self.coef.tolist(), "intercept": self.intercept, "prior_sd": self.prior_sd,
                "fitted_on": dict(self.fitted_on)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "TermCalibration":
        try:
            return cls(d["mean"], d["sd"], d["coef"], d["intercept"], d.get("prior_sd", 1.0),
                       tuple(d.get("terms", TERMS)), d.get("fitted_on", {}))
        except (KeyError, TypeError, ValueError) as e:
            raise GiftError(f"not a gift-prob calibration ({type(e).__name__}: {e})") from None

    @classmethod
    def load(cls, path: str | Path | None = None) -> "TermCalibration":
        """From ``path``, or the one shipped with gift-kernels."""
        try:
            text = (Path(path).read_text(encoding="utf-8") if path is not None
                    else (resources.files("gift_kernels") / "data" / PACKAGED).read_text(encoding="utf-8"))
            return cls.from_dict(json.loads(text))
        except (OSError, ValueError) as e:
            where = path or f"gift_kernels/data/{PACKAGED}"
            raise GiftError(f"cannot read the gift-prob calibration {where}: {e}") from None
