"""Per-time-step features of trajectory batches, vectorized over ``[N, T, ...]``, and their text form.

The columns are exactly ``task.feature_specs(objects)`` of the task family; values use the core's
:func:`gift.tasks.proximity` and scale constants so every simulator computes the same features. Nothing
here needs Drake: features are a function of the positions stored in a :class:`TrajectoryBatch`.
"""

from __future__ import annotations

import numpy as np

from gift.core.data import FeatureBatch, TrajectoryBatch
from gift.core.errors import GiftError
from gift.core.interfaces import Task
from gift.tasks import EE_HEIGHT_SCALE, EE_SPEED_SCALE, proximity


def resolve_task(task: str | Task) -> Task:
    """A task family instance from its registered name (or the instance itself)."""
    if isinstance(task, Task):
        return task
    import gift

    return gift.get_task(task)


def compute_features(trajectories: TrajectoryBatch, task: str | Task) -> FeatureBatch:
    """Features ``[N, T, F]`` of ``trajectories`` for the family ``task``.

    - ``proximity`` columns: :func:`gift.tasks.proximity` of the distance (m) between the feature's
      subject and reference, each looked up among the batch's objects, then its landmarks; a position
      holding NaN means the thing is absent (proximity 0).
    - ``ee_height``: end-effector height over :data:`EE_HEIGHT_SCALE`, clipped to [0, 1].
    - ``ee_speed``: end-effector displacement since the previous step over :data:`EE_SPEED_SCALE`,
      clipped to [0, 1] (0 at the first step).
    """
    family = resolve_task(task)
    specs = family.feature_specs(trajectories.object_names)
    n, t = trajectories.joint_positions.shape[:2]
    ee = trajectories.ee_positions
    where = {name: trajectories.object_positions[:, :, i] for i, name in enumerate(trajectories.object_names)}
    for i, name in enumerate(trajectories.landmark_names):
        where.setdefault(name, trajectories.landmark_positions[:, :, i])
    values = np.empty((n, t, len(specs)))
    for j, spec in enumerate(specs):  # a handful of columns, each vectorized over [N, T]
        if spec.kind == "proximity":
            for who in (spec.subject, spec.reference):
                if who not in where:
                    raise GiftError(f"feature {spec.name!r} of task {family.name!r} needs the position of {who!r}, "
                                    f"which this trajectory batch lacks (objects {list(trajectories.object_names)}, "
                                    f"landmarks {list(trajectories.landmark_names)})")
            diff = where[spec.subject] - where[spec.reference]
            dist = np.sqrt(np.einsum("ntk,ntk->nt", diff, diff))
            absent = np.isnan(dist)
            values[..., j] = proximity(np.where(absent, np.inf, dist), ~absent) if absent.any() else proximity(dist)
        elif spec.kind == "ee_height":
            values[..., j] = np.clip(ee[..., 2] / EE_HEIGHT_SCALE, 0.0, 1.0)
        elif spec.kind == "ee_speed":
            step = np.zeros((n, t))
            step[:, 1:] = np.linalg.norm(np.diff(ee, axis=1), axis=-1)
            values[..., j] = np.clip(step / EE_SPEED_SCALE, 0.0, 1.0)
        else:
            raise GiftError(f"feature {spec.name!r} of task {family.name!r} has kind {spec.kind!r}; the Drake "
                            f"simulator computes kinds 'proximity', 'ee_height' and 'ee_speed'")
    return FeatureBatch(specs, values, {"task": family.name, **{k: v for k, v in trajectories.meta.items()
                                                                if k in ("robot", "generator", "seed")}})


def describe_features(features: FeatureBatch) -> str:
    """One line per feature column: ``- name: description``."""
    return "\n".join(f"- {s.name}: {s.description}" for s in features.specs)


def trace_text(features: FeatureBatch, index: int, *, every: int = 1, decimals: int = 2,
               columns: list[str] | None = None) -> str:
    """The feature trace of trajectory ``index`` for an LM prompt: the feature descriptions, then one line
    per time step (``Timestep t: name: value, ...``) as written by :meth:`FeatureTrace.to_text`."""
    if not 0 <= index < len(features):
        raise GiftError(f"trace_text: trajectory index {index} out of range for a batch of {len(features)}")
    shown = features if columns is None else features.reindex([s for s in features.specs if s.name in columns])
    return (f"Features (per time step):\n{describe_features(shown)}\n"
            f"{shown.trace(index).to_text(decimals=decimals, every=every)}")
