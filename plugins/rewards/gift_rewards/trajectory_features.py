"""φ(ξ): time-aggregated features of whole trajectories, and input checks for feature batches.

For every per-time-step feature ``x`` the linear reward reads two numbers:

- ``mean:x`` — the mean of ``x`` over the T steps (proportional to the sum over time for a fixed T, so it
  expresses cumulative terms such as the place-mug cost "closeness to a relevant object summed over time");
- ``final:x`` — ``x`` at the last step (the end state: is the object in the backpack, away from the spill).

So φ maps ``[N, T, F]`` to ``[N, 2F]``: the F means first, then the F final values.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gift.core.data import FeatureBatch
from gift.core.errors import ValidationError

AGGREGATES = ("mean", "final")


def aggregate(values: np.ndarray) -> np.ndarray:
    """φ for a batch: ``[N, T, F]`` -> ``[N, 2F]`` (means over time, then last-step values)."""
    return np.concatenate([values.mean(axis=1), values[:, -1, :]], axis=1)


def aggregate_names(names: Sequence[str]) -> tuple[str, ...]:
    """Names of the φ components for feature ``names``: ``mean:<name>``..., then ``final:<name>``..."""
    return tuple(f"{agg}:{n}" for agg in AGGREGATES for n in names)


def check_batch(batch: FeatureBatch, what: str) -> None:
    """Raise :class:`ValidationError` unless ``batch`` is a non-empty FeatureBatch of finite values.

    ``what`` names the argument in the message (e.g. ``"fit(demonstrations)"``).
    """
    if not isinstance(batch, FeatureBatch):
        raise ValidationError(f"{what}: expected a FeatureBatch, got {type(batch).__name__}")
    n, t, f = batch.values.shape
    if n == 0:
        raise ValidationError(f"{what}: the batch holds no trajectories")
    if t == 0:
        raise ValidationError(f"{what}: the trajectories have no time steps")
    if f == 0:
        raise ValidationError(f"{what}: the batch has no feature columns")
    if np.isfinite(np.sum(batch.values)):  # one pass, no temporary: the common, clean case
        return
    finite = np.isfinite(batch.values)
    if not finite.all():
        i, step, col = np.argwhere(~finite)[0]
        count = int((~finite).sum())
        raise ValidationError(f"{what}: {count} non-finite value(s); first at trajectory {i}, time step {step}, "
                              f"feature {batch.names[col]!r} (= {batch.values[i, step, col]})")
