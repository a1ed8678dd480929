"""``maxent-neural``: an MLP reward per time step summed over time, learned by MaxEnt IRL in torch (CPU).

One MLP reads a state's standardised features ``s_t`` ``[F]`` and gives two numbers, a running reward
``r_run(s_t)`` and a terminal reward ``r_end(s_t)``. The per-step reward is
``r_t = r_run(s_t) / T + [t = T] · r_end(s_t)`` and R_ψ(ξ) = Σ_t r_t: the nonlinear counterpart of the
linear model's "mean over time + final step" features, so both models can express the same rewards.

Training maximises the MaxEnt objective of :mod:`gift_rewards.maxent_irl` (uniform proposal, L2 on the
weight matrices) with full-batch Adam in float32 on ``threads`` CPU threads (1 by default: this small net
gains nothing from more, and loses much on a busy machine). ``torch.manual_seed(seed)`` fixes the
initialisation, and training stops early when the log-likelihood of held-out demonstrations (normalised
over held-out alternatives) has not improved for ``patience`` epochs; the best epoch's weights are kept.

torch is imported lazily (only :meth:`NeuralMaxEntReward.fit` needs it); scoring runs in numpy (float64 on
the learned float32 weights), so a loaded reward scores without torch and identically after a reload.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from gift.core.errors import GiftError, ValidationError
from gift_rewards.maxent_irl import MaxEntReward, uniform_log_weights

#: Trajectories per block when scoring (bounds the memory of the hidden activations).
SCORE_BLOCK = 2048


def _import_torch():
    try:
        import torch
    except ImportError as e:  # pragma: no cover - torch is installed by scripts/setup.sh
        raise GiftError("maxent-neural needs torch to fit (pip install torch==2.13.0); "
                        "maxent-linear works without it") from e
    return torch


class NeuralMaxEntReward(MaxEntReward):
    """MLP MaxEnt IRL reward.

    ``hidden``: widths of the tanh hidden layers; ``l2``: weight of the squared weights' penalty;
    ``lr``: Adam step size; ``max_epochs``/``patience``: training length and early-stopping patience;
    ``val_fraction``: share of demonstrations and alternatives held out for early stopping (no split when
    fewer than ``min_val_demos`` demonstrations would be held out); ``seed``: torch and split seed;
    ``threads``: torch CPU threads during :meth:`fit`.
    """

    name: ClassVar[str] = "maxent-neural"

    def __init__(self, *, hidden: Sequence[int] = (32, 32), l2: float = 1e-3, lr: float = 1e-2,
                 max_epochs: int = 600, patience: int = 40, val_fraction: float = 0.2, min_val_demos: int = 2,
                 seed: int = 0, threads: int = 1, metadata: Mapping[str, Any] | None = None) -> None:
        super().__init__(metadata=metadata)
        hidden = tuple(int(h) for h in hidden)
        if not hidden or any(h < 1 for h in hidden):
            raise ValidationError(f"maxent-neural: hidden must be positive layer widths, got {hidden!r}")
        if not (np.isfinite(l2) and l2 >= 0):
            raise ValidationError(f"maxent-neural: l2 must be a finite number >= 0, got {l2!r}")
        if not (0.0 <= val_fraction < 1.0):
            raise ValidationError(f"maxent-neural: val_fraction must be in [0, 1), got {val_fraction!r}")
        if int(threads) < 1:
            raise ValidationError(f"maxent-neural: threads must be >= 1, got {threads!r}")
        if int(max_epochs) < 1 or int(patience) < 1 or not lr > 0:
            raise ValidationError(f"maxent-neural: need max_epochs >= 1, patience >= 1 and lr > 0, got "
                                  f"{max_epochs!r}, {patience!r}, {lr!r}")
        self.hidden, self.l2, self.lr = hidden, float(l2), float(lr)
        self.max_epochs, self.patience = int(max_epochs), int(patience)
        self.val_fraction, self.min_val_demos, self.seed = float(val_fraction), int(min_val_demos), int(seed)
        self.threads = int(threads)
        self.layers: list[tuple[np.ndarray, np.ndarray]] = []  # (W [out, in], b [out]) per layer
        self.mean: np.ndarray | None = None  # [F] feature standardisation
        self.std: np.ndarray | None = None

    def hyperparameters(self) -> dict[str, Any]:
        return {"hidden": list(self.hidden), "l2": self.l2, "lr": self.lr, "max_epochs": self.max_epochs,
                "patience": self.patience, "val_fraction": self.val_fraction,
                "min_val_demos": self.min_val_demos, "seed": self.seed, "threads": self.threads}

    # ------------------------------------------------------------------ training

    def _fit(self, demonstrations: np.ndarray, alternatives: np.ndarray) -> dict[str, Any]:
        torch = _import_torch()
        threads = torch.get_num_threads()
        torch.set_num_threads(self.threads)
        try:
            return self._train(torch, demonstrations, alternatives)
        finally:
            torch.set_num_threads(threads)

    def _train(self, torch, demonstrations: np.ndarray, alternatives: np.ndarray) -> dict[str, Any]:
        torch.manual_seed(self.seed)
        rng = np.random.default_rng(self.seed)
        f = demonstrations.shape[2]
        states = np.concatenate([demonstrations.reshape(-1, f), alternatives.reshape(-1, f)], axis=0)
        self.mean = states.mean(axis=0)
        std = states.std(axis=0)
        self.std = np.where(std > 1e-8, std, 1.0)

        d_train, d_val = _split(demonstrations, self.val_fraction, rng, self.min_val_demos)
        a_train, a_val = _split(alternatives, self.val_fraction if d_val is not None else 0.0, rng, 1)
        if d_val is not None and a_val is None:  # too few alternatives to hold some out: share them
            a_val = a_train

        widths = (f, *self.hidden)
        mods: list[Any] = []
        for w_in, w_out in zip(widths[:-1], widths[1:]):
            mods += [torch.nn.Linear(w_in, w_out), torch.nn.Tanh()]
        mods.append(torch.nn.Linear(widths[-1], 2))
        net = torch.nn.Sequential(*mods).float()
        linears = [m for m in net if isinstance(m, torch.nn.Linear)]

        def tensor(x: np.ndarray):
            return torch.from_numpy(((x - self.mean) / self.std).astype(np.float32))

        def returns(x):  # [N, T, F] -> R [N]
            out = net(x)
            return out[..., 0].mean(dim=1) + out[:, -1, 1]

        def log_lik(d, a):
            r_d = returns(d)
            r_all = torch.cat([r_d, returns(a)])
            return r_d.mean() - torch.logsumexp(r_all + uniform_log_weights(len(r_all)), dim=0)

        td, ta = tensor(d_train), tensor(a_train)
        vd = tensor(d_val) if d_val is not None else None
        va = tensor(a_val) if d_val is not None else None
        opt = torch.optim.Adam(net.parameters(), lr=self.lr)
        best, best_epoch, best_state, epoch = -math.inf, 0, None, 0
        for epoch in range(1, self.max_epochs + 1):
            opt.zero_grad()
            penalty = sum((m.weight ** 2).sum() for m in linears)
            loss = -log_lik(td, ta) + self.l2 * penalty
            loss.backward()
            opt.step()
            with torch.no_grad():
                score = float(log_lik(vd, va)) if vd is not None else -float(loss)
            if not math.isfinite(score):
                raise GiftError(f"maxent-neural: training diverged at epoch {epoch} (lr={self.lr})")
            if score > best + 1e-6:
                best, best_epoch = score, epoch
                best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
            elif epoch - best_epoch >= self.patience:
                break
        net.load_state_dict(best_state)
        self.layers = [(m.weight.detach().numpy().astype(np.float64), m.bias.detach().numpy().astype(np.float64))
                       for m in linears]
        return {"epochs": epoch, "best_epoch": best_epoch, "early_stopped": epoch < self.max_epochs,
                "selection": "held-out log-likelihood" if vd is not None else "training objective",
                "best_selection_value": best, "n_validation_demonstrations": 0 if d_val is None else len(d_val)}

    # ------------------------------------------------------------------ scoring

    def _score(self, values: np.ndarray) -> np.ndarray:
        out = np.empty(len(values))
        for lo in range(0, len(values), SCORE_BLOCK):
            h = (values[lo:lo + SCORE_BLOCK] - self.mean) / self.std
            for w, b in self.layers[:-1]:
                h = np.tanh(h @ w.T + b)
            w, b = self.layers[-1]
            out[lo:lo + SCORE_BLOCK] = (h @ w[0] + b[0]).mean(axis=1) + h[:, -1, :] @ w[1] + b[1]
        return out

    # ------------------------------------------------------------------ persistence

    def _params_to_json(self) -> dict[str, Any]:
        return {"layers": [{"weight": w.tolist(), "bias": b.tolist()} for w, b in self.layers],
                "feature_mean": self.mean.tolist(), "feature_std": self.std.tolist()}

    def _params_from_json(self, params: Mapping[str, Any]) -> None:
        f = len(self.feature_specs)
        self.layers = [(np.asarray(layer["weight"], dtype=float), np.asarray(layer["bias"], dtype=float))
                       for layer in params["layers"]]
        self.mean = np.asarray(params["feature_mean"], dtype=float)
        self.std = np.asarray(params["feature_std"], dtype=float)
        widths = (f, *self.hidden, 2)
        shapes = [w.shape for w, _ in self.layers]
        if shapes != list(zip(widths[1:], widths[:-1])) or self.mean.shape != (f,) or self.std.shape != (f,):
            raise ValueError(f"layer shapes {shapes} do not fit {f} features and hidden widths {self.hidden}")


def _split(values: np.ndarray, fraction: float, rng: np.random.Generator,
           min_held_out: int) -> tuple[np.ndarray, np.ndarray | None]:
    """Random (train, held-out) split of trajectories ``[N, T, F]``; no split when too few would be held out."""
    n_val = int(round(fraction * len(values)))
    if n_val < min_held_out or len(values) - n_val < 1:
        return values, None
    perm = rng.permutation(len(values))
    return values[perm[n_val:]], values[perm[:n_val]]
