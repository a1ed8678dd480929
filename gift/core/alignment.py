"""f_ω(ξ'): applying an object alignment to trajectories' features.

Alignment renames the *semantic* components of every state (which object sits in which feature slot)
and keeps continuous components (end-effector features) as they are. Since a feature of a test object
``x`` becomes the same feature of its training counterpart ``f_ω(x)``, aligning a batch is a remapping
of feature columns: no new simulation and no per-state loop.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import attrs
import numpy as np

from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, FeatureSpec


@attrs.frozen
class AlignmentPlan:
    """Precomputed column map from test features ``[F_test]`` to training features ``[F_train]``.

    ``pairs``: ``(test column, train column)``; several test objects mapped to one training object are
    combined by maximum (the training slot is "present" as much as its closest stand-in). Training
    columns with no test counterpart are 0: the object is absent.
    """

    train_specs: tuple[FeatureSpec, ...]
    src: np.ndarray  # [P] test column indices
    dst: np.ndarray  # [P] train column indices
    one_to_one: bool

    def apply(self, values: np.ndarray) -> np.ndarray:
        """``[N, T, F_test]`` -> ``[N, T, F_train]``."""
        out = np.zeros(values.shape[:-1] + (len(self.train_specs),), dtype=values.dtype)
        if self.one_to_one:
            out[..., self.dst] = values[..., self.src]
        else:
            for s, d in zip(self.src.tolist(), self.dst.tolist()):
                np.maximum(out[..., d], values[..., s], out=out[..., d])
        return out


def plan_alignment(test_specs: Sequence[FeatureSpec], mapping: dict[str, str],
                   train_specs: Sequence[FeatureSpec]) -> AlignmentPlan:
    """Build the column map for ``mapping`` (test object -> training object or DISTRACTOR)."""
    return _plan(tuple(test_specs), tuple(sorted(mapping.items())), tuple(train_specs))


@lru_cache(maxsize=256)
def _plan(test_specs: tuple[FeatureSpec, ...], mapping: tuple[tuple[str, str], ...],
          train_specs: tuple[FeatureSpec, ...]) -> AlignmentPlan:
    m = dict(mapping)
    train_index = {}
    for j, spec in enumerate(train_specs):
        key = (spec.subject, spec.role) if spec.semantic else (None, spec.name)
        train_index[key] = j
    src, dst = [], []
    for i, spec in enumerate(test_specs):
        if spec.semantic:
            target = m.get(spec.subject, DISTRACTOR)
            if target == DISTRACTOR:
                continue
            j = train_index.get((target, spec.role))
        else:
            j = train_index.get((None, spec.name))
        if j is not None:
            src.append(i)
            dst.append(j)
    dst_arr = np.asarray(dst, dtype=np.intp)
    return AlignmentPlan(tuple(train_specs), np.asarray(src, dtype=np.intp), dst_arr,
                         one_to_one=len(set(dst)) == len(dst))


def align_features(features: FeatureBatch, alignment: Alignment,
                   train_specs: Sequence[FeatureSpec]) -> FeatureBatch:
    """f_ω(ξ') for a batch: test features ``[N, T, F_test]`` -> aligned ``[N, T, F_train]``."""
    plan = plan_alignment(features.specs, dict(alignment.mapping), train_specs)
    return FeatureBatch(tuple(train_specs), plan.apply(features.values),
                        {**features.meta, "aligned_by": alignment.kernel})


def align_state(values: np.ndarray, test_specs: Sequence[FeatureSpec], alignment: Alignment,
                train_specs: Sequence[FeatureSpec]) -> np.ndarray:
    """f_ω(s') for a single state's features ``[F_test]`` -> ``[F_train]``."""
    plan = plan_alignment(test_specs, dict(alignment.mapping), train_specs)
    return plan.apply(np.asarray(values, dtype=float)[None, None])[0, 0]
