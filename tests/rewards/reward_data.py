"""Synthetic feature batches for the reward tests (rewards are pure math on [N, T, F] features)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from gift.core.data import FeatureBatch, FeatureSpec
from gift.core.metrics import boltzmann


def random_specs(n: int) -> tuple[FeatureSpec, ...]:
    """``n`` object-proximity columns ``obj<i>_proximity_to_box`` plus ``ee_speed``."""
    return tuple(FeatureSpec(f"obj{i}_proximity_to_box", subject=f"obj{i}", reference="box") for i in range(n)) + (
        FeatureSpec("ee_speed", kind="ee_speed"),)


def random_traces(specs: Sequence[FeatureSpec], n: int, n_steps: int, rng: np.random.Generator) -> FeatureBatch:
    """``n`` smooth random feature traces in [0, 1]: each feature moves from a start to an end value
    at a random time, plus a little noise, so the mean over time and the final value differ."""
    f = len(specs)
    start = rng.uniform(0.0, 1.0, (n, 1, f))
    end = rng.uniform(0.0, 1.0, (n, 1, f))
    onset = rng.uniform(0.1, 0.9, (n, 1, f))
    t = np.linspace(0.0, 1.0, n_steps)[None, :, None]
    ramp = 1.0 / (1.0 + np.exp(-(t - onset) / 0.05))
    noise = rng.normal(0.0, 0.02, (n, n_steps, f))
    return FeatureBatch(specs, np.clip(start + (end - start) * ramp + noise, 0.0, 1.0))


def boltzmann_demonstrations(pool: FeatureBatch, reward: Callable[[FeatureBatch], np.ndarray], n: int,
                             rng: np.random.Generator, beta: float = 1.0) -> FeatureBatch:
    """``n`` demonstrations drawn from the pool with P(ξ) ∝ exp(β R(ξ)) (a noisily rational human)."""
    p = boltzmann(reward(pool), beta)
    return pool[rng.choice(len(pool), size=n, p=p)]


def pack_traces(task, objects: Sequence[str], packed: np.ndarray, n_steps: int,
                rng: np.random.Generator) -> FeatureBatch:
    """Feature traces of the real ``task`` family (e.g. pack_backpack) for ``objects``.

    ``packed`` ``[N, n_objects]`` bool: a packed object travels from 0.3–0.6 m to ~1 cm of the container
    (its proximity, from :func:`gift.tasks.proximity`, rises to ~1); the others stay on the table.
    """
    from gift.tasks import EE_HEIGHT_SCALE, EE_SPEED_SCALE, proximity

    packed = np.asarray(packed, dtype=bool)
    n, k = packed.shape
    t = np.linspace(0.0, 1.0, n_steps)[None, :, None]
    d0 = rng.uniform(0.3, 0.6, (n, 1, k))
    d1 = np.where(packed[:, None, :], rng.uniform(0.0, 0.02, (n, 1, k)), d0 + rng.normal(0, 0.03, (n, 1, k)))
    onset = rng.uniform(0.3, 0.7, (n, 1, k))
    ramp = 1.0 / (1.0 + np.exp(-(t - onset) / 0.05))
    dist = np.abs(d0 + (d1 - d0) * ramp)
    height = np.clip(0.2 + 0.15 * np.sin(np.pi * t[..., 0]) + rng.normal(0, 0.01, (n, n_steps)), 0, None)
    speed = np.abs(np.gradient(height, axis=1)) + rng.uniform(0.0, 0.01, (n, n_steps))
    ee = np.stack([np.minimum(height / EE_HEIGHT_SCALE, 1.0), np.minimum(speed / EE_SPEED_SCALE, 1.0)], axis=-1)
    values = np.concatenate([proximity(dist), ee], axis=-1)
    return FeatureBatch(task.feature_specs(objects), values, {"task": task.name, "objects": tuple(objects)})
