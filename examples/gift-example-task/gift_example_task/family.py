"""``pack_backpack_low``: pack the relevant objects into the backpack and carry them low.

The human of this family wants the same objects packed as in ``pack_backpack`` but dislikes objects
being lifted high over the table (they might fall). Ground-truth reward of N trajectories ``[N]``::

    R*(ξ) = Σ_o ±proximity_T(o, backpack)  −  LIFT_PENALTY · max_t ee_height_t

with + for relevant and − for irrelevant objects o at the last step T (the ``pack_backpack`` reward of
the core) and ``ee_height`` the core's end-effector height feature in [0, 1] (1 = 0.5 m or higher).

Simulation: a Drake scene of this family is a ``pack_backpack`` scene (same landmark, same pick-and-place
motions), named by :attr:`PackBackpackLow.motion_pattern`; only the features' meaning for the human and
the reward differ. :func:`gift_example_task.demos.sample_demonstrations` picks the demonstrations.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from gift.core.data import FeatureBatch, FeatureSpec
from gift.core.errors import ValidationError
from gift.core.interfaces import Task
from gift.tasks import PackBackpack

#: Weight of the highest end-effector height (in units of the ee_height feature) in the reward.
LIFT_PENALTY = 2.0


class PackBackpackLow(Task):
    """Pack objects into an open backpack, carrying them as low as possible."""

    name: ClassVar[str] = "pack_backpack_low"
    description: ClassVar[str] = ("The robot arm picks objects from a table and may put them into an open "
                                  "backpack; the person dislikes objects being lifted high.")
    landmarks: ClassVar[tuple[str, ...]] = ("backpack",)
    #: The built-in family whose scenes and motions a simulator uses for this family.
    motion_pattern: ClassVar[str] = PackBackpack.name

    def __init__(self, lift_penalty: float = LIFT_PENALTY) -> None:
        if not (np.isfinite(lift_penalty) and lift_penalty >= 0):
            raise ValidationError(f"{self.name}: lift_penalty must be a finite number >= 0, got {lift_penalty!r}")
        self.lift_penalty = float(lift_penalty)
        self._packing = PackBackpack()

    def feature_specs(self, objects: Sequence[str]) -> tuple[FeatureSpec, ...]:
        """``<object>_proximity_to_backpack`` per object, then ``ee_height`` and ``ee_speed``."""
        return self._packing.feature_specs(objects)

    def ground_truth_reward(self, features: FeatureBatch, relevant: Sequence[str]) -> np.ndarray:
        """R*(ξ) of N trajectories ``[N]`` (see the module docstring)."""
        if "ee_height" not in features.names:
            raise ValidationError(f"{self.name}: the features lack the 'ee_height' column; got {features.names}")
        height = features.values[..., features.names.index("ee_height")]  # [N, T]
        return self._packing.ground_truth_reward(features, relevant) - self.lift_penalty * height.max(axis=1)
