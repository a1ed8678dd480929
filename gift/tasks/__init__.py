"""The four task families of the paper, as simulator-independent definitions (a built-in plugin).

A family fixes its landmarks, its feature columns for any set of object names, and the ground-truth
reward the simulated human maximises given which objects are relevant. Simulators (e.g. the Drake
plugin) generate trajectories for these families; suites name them in ``task:``.

Features (all per time step, in [0, 1]):

- ``<object>_proximity_to_<landmark>`` (pack, store, sweep) or ``mug_proximity_to_<object>`` (place mug):
  1 when the two touch, 0 when far apart or either is absent (:func:`proximity`).
- ``ee_height``: end-effector height above the table, 1 at :data:`EE_HEIGHT_SCALE` metres or more.
- ``ee_speed``: end-effector displacement over the step, 1 at :data:`EE_SPEED_SCALE` metres or more.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gift.core.data import FeatureBatch, FeatureSpec, proximity_feature
from gift.core.interfaces import Task
from gift.plugins.hookspecs import hookimpl

#: Distance (m) at which proximity has fallen to exp(-1) ≈ 0.37.
PROXIMITY_SCALE = 0.15
EE_HEIGHT_SCALE = 0.5
EE_SPEED_SCALE = 0.05

EE_FEATURES = (
    FeatureSpec("ee_height", "height of the robot's end effector above the table (1 = 0.5 m or higher)",
                kind="ee_height"),
    FeatureSpec("ee_speed", "distance the end effector moved during this time step (1 = 5 cm or more)",
                kind="ee_speed"),
)


def proximity(distance: np.ndarray, present: np.ndarray | bool = True) -> np.ndarray:
    """Proximity in [0, 1] from distances in metres: ``exp(-(d / PROXIMITY_SCALE)^2)``, 0 where absent."""
    p = np.exp(-np.square(np.asarray(distance, dtype=float) / PROXIMITY_SCALE))
    return np.where(present, p, 0.0)


class _ContainerTask(Task):
    """Put the relevant objects into the landmark container, leave the others out."""

    container: str = ""

    def feature_specs(self, objects: Sequence[str]) -> tuple[FeatureSpec, ...]:
        return tuple(proximity_feature(o, self.container, subject=o) for o in objects) + EE_FEATURES

    def ground_truth_reward(self, features: FeatureBatch, relevant: Sequence[str]) -> np.ndarray:
        rel = set(relevant)
        final = features.values[:, -1, :]
        sign = np.array([(1.0 if s.subject in rel else -1.0) if s.semantic else 0.0 for s in features.specs])
        return final @ sign


class PackBackpack(_ContainerTask):
    """Pack objects into an open backpack."""

    name = "pack_backpack"
    description = "The robot arm picks objects from a table and may put them into an open backpack."
    landmarks = ("backpack",)
    container = "backpack"


class StoreDrawer(_ContainerTask):
    """Store objects in an open drawer."""

    name = "store_drawer"
    description = "The robot arm picks objects from a table and may store them in an open drawer."
    landmarks = ("drawer",)
    container = "drawer"


class PlaceMug(Task):
    """Carry a full mug to a goal, keeping it away from the objects the human cares about."""

    name = "place_mug"
    description = "The robot arm carries a mug full of coffee across a table with objects on it to a goal spot."
    landmarks = ("mug",)

    def feature_specs(self, objects: Sequence[str]) -> tuple[FeatureSpec, ...]:
        return tuple(proximity_feature("mug", o, subject=o) for o in objects) + EE_FEATURES

    def ground_truth_reward(self, features: FeatureBatch, relevant: Sequence[str]) -> np.ndarray:
        rel = set(relevant)
        near = np.array([1.0 if s.semantic and s.subject in rel else 0.0 for s in features.specs])
        speed = np.array([1.0 if s.name == "ee_speed" else 0.0 for s in features.specs])
        # closeness to relevant objects summed over time, plus a small cost of path length
        return -(features.values @ near).sum(axis=1) - 0.1 * (features.values @ speed).sum(axis=1)


class SweepSpill(Task):
    """Sweep objects on the table; the relevant ones should end up away from the spill."""

    name = "sweep_spill"
    description = "The robot arm sweeps objects across a table that has a liquid spill on it."
    landmarks = ("spill",)

    def feature_specs(self, objects: Sequence[str]) -> tuple[FeatureSpec, ...]:
        return tuple(proximity_feature(o, "spill", subject=o) for o in objects) + EE_FEATURES

    def ground_truth_reward(self, features: FeatureBatch, relevant: Sequence[str]) -> np.ndarray:
        rel = set(relevant)
        w = np.array([1.0 if s.semantic and s.subject in rel else 0.0 for s in features.specs])
        return -(features.values[:, -1, :] @ w)


TASKS = (PlaceMug, SweepSpill, PackBackpack, StoreDrawer)


@hookimpl
def gift_register_tasks(register):
    for cls in TASKS:
        register(cls.name, cls, description=cls.__doc__.strip().splitlines()[0])
