"""``maxent-linear``: R_θ(ξ) = θ · φ(ξ), learned by MaxEnt IRL with scipy's L-BFGS (numpy only).

φ is :func:`gift_rewards.trajectory_features.aggregate` (mean over time and final step of every
feature), so θ has 2F entries; :attr:`LinearMaxEntReward.weights` names them ``mean:<feature>`` and
``final:<feature>``. The objective and its proposal are described in :mod:`gift_rewards.maxent_irl`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from scipy.optimize import minimize
from scipy.special import logsumexp, softmax

from gift.core.alignment import AlignmentPlan
from gift.core.errors import GiftError, ValidationError
from gift_rewards.maxent_irl import MaxEntReward, uniform_log_weights
from gift_rewards.trajectory_features import aggregate, aggregate_names


def maxent_objective(theta: np.ndarray, phi_demo: np.ndarray, phi_all: np.ndarray, log_w: np.ndarray | float,
                     l2: float) -> tuple[float, np.ndarray]:
    """Negative regularised MaxEnt log-likelihood and its gradient for a linear reward.

    ``theta`` ``[D]``; ``phi_demo`` ``[N_d, D]``; ``phi_all`` ``[N_u, D]`` (the normalising sample set);
    ``log_w`` log importance weights ``[N_u]`` or a constant. Returns ``(−L(θ), −∇L(θ))``.
    """
    logits = phi_all @ theta + log_w
    p = softmax(logits)
    ll = float(np.mean(phi_demo @ theta) - logsumexp(logits))
    grad = phi_demo.mean(axis=0) - p @ phi_all
    return -(ll - l2 * float(theta @ theta)), -(grad - 2.0 * l2 * theta)


class LinearMaxEntReward(MaxEntReward):
    """Linear MaxEnt IRL reward on time-aggregated features.

    ``l2``: weight λ of the ‖θ‖² penalty; ``max_iter``: L-BFGS iteration cap; ``tol``: its gradient tolerance.
    """

    name: ClassVar[str] = "maxent-linear"

    def __init__(self, *, l2: float = 1e-3, max_iter: int = 500, tol: float = 1e-8,
                 metadata: Mapping[str, Any] | None = None) -> None:
        super().__init__(metadata=metadata)
        if not (np.isfinite(l2) and l2 >= 0):
            raise ValidationError(f"maxent-linear: l2 must be a finite number >= 0, got {l2!r}")
        if int(max_iter) < 1:
            raise ValidationError(f"maxent-linear: max_iter must be >= 1, got {max_iter!r}")
        self.l2, self.max_iter, self.tol = float(l2), int(max_iter), float(tol)
        self.theta: np.ndarray | None = None

    def hyperparameters(self) -> dict[str, Any]:
        return {"l2": self.l2, "max_iter": self.max_iter, "tol": self.tol}

    @property
    def weights(self) -> dict[str, float]:
        """θ named by φ component: ``{"mean:<feature>": w, ..., "final:<feature>": w, ...}``."""
        if self.theta is None:
            self.feature_specs  # raises NotFittedError
        return dict(zip(aggregate_names(self.feature_names), self.theta.tolist()))

    def _fit(self, demonstrations: np.ndarray, alternatives: np.ndarray) -> dict[str, Any]:
        phi_demo = aggregate(demonstrations)
        phi_all = np.concatenate([phi_demo, aggregate(alternatives)], axis=0)
        log_w = uniform_log_weights(len(phi_all))
        res = minimize(maxent_objective, np.zeros(phi_all.shape[1]), args=(phi_demo, phi_all, log_w, self.l2),
                       jac=True, method="L-BFGS-B", options={"maxiter": self.max_iter, "gtol": self.tol})
        if not np.all(np.isfinite(res.x)):
            raise GiftError(f"maxent-linear: L-BFGS diverged ({res.message})")
        self.theta = np.asarray(res.x, dtype=float)
        return {"objective": -float(res.fun), "iterations": int(res.nit), "converged": bool(res.success),
                "optimizer_message": str(res.message)}

    def _score(self, values: np.ndarray) -> np.ndarray:
        return _linear_returns(values, self.theta)

    def _score_aligned(self, values: np.ndarray, plan: AlignmentPlan) -> np.ndarray:
        """θ · φ(f_ω(ξ')) without building the aligned batch when the remap is one-to-one.

        φ works column by column (mean over time, last step), so φ(f_ω(ξ')) is φ(ξ') with its columns
        remapped: moving θ onto the test columns gives the same number from one pass over the test values.
        """
        if not plan.one_to_one:  # several test objects share a training slot: combined by max per state
            return super()._score_aligned(values, plan)
        f_train, f_test = len(self.feature_specs), values.shape[2]
        theta = np.zeros(2 * f_test)
        theta[plan.src] = self.theta[:f_train][plan.dst]
        theta[f_test + plan.src] = self.theta[f_train:][plan.dst]
        return _linear_returns(values, theta)

    def _params_to_json(self) -> dict[str, Any]:
        return {"theta": self.theta.tolist(), "names": list(aggregate_names(self.feature_names))}

    def _params_from_json(self, params: Mapping[str, Any]) -> None:
        theta = np.asarray(params["theta"], dtype=float)
        if theta.shape != (2 * len(self.feature_specs),):
            raise ValueError(f"theta has shape {theta.shape}, expected ({2 * len(self.feature_specs)},)")
        self.theta = theta


def _linear_returns(values: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """θ · φ(ξ) for ``values`` ``[N, T, F]`` and ``theta`` ``[2F]``, as one matrix-vector product.

    θ · (mean_t x_t, x_T) = Σ_t w_t · x_t with w_t = θ_mean / T, plus θ_final at t = T: a single pass
    over the contiguous ``[N, T·F]`` values (cheaper than reducing over the time axis first).
    """
    n, t, f = values.shape
    w = np.repeat(theta[None, :f] / t, t, axis=0)
    w[-1] += theta[f:]
    return np.ascontiguousarray(values).reshape(n, t * f) @ w.ravel()
