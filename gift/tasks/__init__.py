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
#: place_mug: weight of the mug's height (``ee_height`` summed over time) in the simulated human's reward; at
#: 1, a step with the mug 0.5 m up costs as much as a step with it touching a relevant object.
MUG_HEIGHT_COST = 1.0
#: place_mug: weight of the path length (``ee_speed`` summed over time) in the simulated human's reward.
MUG_PATH_COST = 0.1

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
    """Carry a full mug to a goal, keeping it away from the objects the human cares about.

    The simulated human (:meth:`ground_truth_reward`) carries a full mug the way a person does: low, and
    steering around the relevant objects. Its reward, per trajectory, is minus

    - the mug's closeness to the relevant objects (their ``mug_proximity_to_<object>``), summed over time;
    - :data:`MUG_HEIGHT_COST` times the mug's height (``ee_height``) summed over time: lifting a full mug is
      effort and risks a spill, so a carry raised over the whole table is not worth it;
    - :data:`MUG_PATH_COST` times the path length (``ee_speed`` summed over time).

    Irrelevant objects cost nothing: the human passes them as close as the route around the relevant ones
    takes it.
    """

    name = "place_mug"
    description = "The robot arm carries a mug full of coffee across a table with objects on it to a goal spot."
    landmarks = ("mug",)

    def feature_specs(self, objects: Sequence[str]) -> tuple[FeatureSpec, ...]:
        return tuple(proximity_feature("mug", o, subject=o) for o in objects) + EE_FEATURES

    def ground_truth_reward(self, features: FeatureBatch, relevant: Sequence[str]) -> np.ndarray:
        rel = set(relevant)
        w = np.array([1.0 if s.semantic and s.subject in rel else
                      MUG_HEIGHT_COST if s.name == "ee_height" else MUG_PATH_COST if s.name == "ee_speed" else 0.0
                      for s in features.specs])
        return -(features.values @ w).sum(axis=1)


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
