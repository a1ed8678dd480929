"""Demonstrations of a family that borrows a built-in family's motions: sample, then keep the best.

A simulator's ``preferred`` generator optimises the reward of the scene's own family; for a family that
reuses another family's motions we instead draw ``random`` trajectories in the borrowed family's scene
and keep the ``n`` with the highest ground-truth reward of *our* family.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np

from gift.core.data import FeatureBatch, ObjectSpec, Scene, TrajectoryBatch
from gift.core.errors import ValidationError
from gift.core.interfaces import Simulator, Task


@attrs.frozen
class Demonstrations:
    """Preferred and alternative trajectories of one scene with their features ``[N, T, F]``."""

    scene: Scene
    preferred: TrajectoryBatch
    preferred_features: FeatureBatch
    alternatives: TrajectoryBatch
    alternative_features: FeatureBatch


def sample_demonstrations(simulator: Simulator, family: Task, objects: Sequence[ObjectSpec],
                          relevant: Sequence[str], *, n: int = 8, pool: int = 64, seed: int = 0) -> Demonstrations:
    """``n`` best of ``pool`` random trajectories under ``family``'s reward; all ``pool`` are alternatives."""
    if not 1 <= n <= pool:
        raise ValidationError(f"sample_demonstrations: need 1 <= n <= pool, got n={n}, pool={pool}")
    pattern = getattr(family, "motion_pattern", family.name)
    scene = simulator.make_scene(pattern, objects, relevant, seed)
    samples = simulator.generate(scene, "random", pool, seed)
    features = simulator.features(samples, family)
    reward = family.ground_truth_reward(features, sorted(relevant))  # [pool]
    best = np.argsort(-reward, kind="stable")[:n]
    return Demonstrations(scene, _select(samples, best), features[best], samples, features)


def _select(batch: TrajectoryBatch, index: np.ndarray) -> TrajectoryBatch:
    """``batch[index]`` with the per-trajectory lists of ``meta`` (e.g. ``acted_on``) selected too."""
    n = len(batch)
    meta = {k: ([v[i] for i in index] if isinstance(v, list) and len(v) == n else v) for k, v in batch.meta.items()}
    return attrs.evolve(batch[index], meta=meta)
