"""Randomised tabletop scenes (positions in metres, table top at z = 0, the arm at the origin facing +x).

:func:`layout` builds a scene of any task family with a registered motion family
(:func:`gift_sim_drake.families.motion_family`), given the arm's reach; the layouts of the paper's four
families are in :mod:`gift_sim_drake.tabletop`. :func:`place_apart` and :func:`nearest_object` are the
helpers they share, for third-party families too.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from gift.core.data import ObjectSpec, Scene
from gift.core.errors import PlacementError
from gift_sim_drake.families import Reach, motion_family

#: Margin (m) kept inside the arm's reach: the grasp perturbation (1 cm) and the gap between the local-IK reach
#: (:meth:`gift_sim_drake.kinematics.ArmKinematics.reach_pointing_down`) and Drake's IK (up to 2 cm).
REACH_MARGIN = 0.03


def layout(task: str, objects: Sequence[ObjectSpec], relevant: Sequence[str], seed: int,
           reach: Reach | None = None) -> Scene:
    """A randomised scene of ``task`` holding ``objects`` (its motion family's :meth:`layout`).

    ``reach``: the arm's reach, heights ``[H]`` (m) -> largest distance ``[H]`` (m) from the base's vertical
    axis at which the gripper gets there pointing down (:meth:`DrakeSimulator.reach`); families place the
    objects the arm must pick within it. None: no reach check.
    """
    return motion_family(task).layout(objects, relevant, int(seed), reach=reach)


def place_apart(rng: np.random.Generator, radii: np.ndarray, sample: Callable[[np.random.Generator], np.ndarray],
                what: str, restarts: int = 200, tries: int = 60,
                fits: Callable[[int, np.ndarray], bool] | None = None) -> np.ndarray:
    """Rejection-sample non-overlapping xy positions ``[n, 2]`` for footprint ``radii`` ``[n]`` (m), largest
    objects first, restarting the whole layout when one does not fit; ``sample(rng)`` proposes one point,
    ``fits(i, p)`` (if given) says whether object ``i`` may stand at ``p``. Raises :class:`PlacementError`
    naming the ``what`` region when no layout is found."""
    order = np.argsort(-radii, kind="stable")
    for _ in range(restarts):
        out: dict[int, np.ndarray] = {}
        for i in order:
            for _ in range(tries):
                p = sample(rng)
                if fits is not None and not fits(int(i), p):
                    continue
                if all(np.hypot(*(p - q)) >= radii[i] + radii[j] + 0.015 for j, q in out.items()):
                    out[int(i)] = p
                    break
            else:
                break
        if len(out) == len(radii):
            return np.array([out[i] for i in range(len(radii))]).reshape(len(radii), 2)
    where = f"the {what} region" + (" within the arm's reach" if fits is not None else "")
    raise PlacementError(f"cannot place {len(radii)} objects of these sizes (footprint radii "
                         f"{np.round(radii, 3).tolist()} m) in {where} without overlap; use fewer or smaller objects")


def nearest_object(positions: np.ndarray, point: Sequence[float]) -> int:
    """Index of the object ``positions`` ``[n, 3]`` nearest to ``point`` in the table plane (-1 when n = 0)."""
    if len(positions) == 0:
        return -1
    d = np.hypot(*(positions[:, :2] - np.asarray(point)[:2]).T)
    return int(np.argmin(d))
