"""How the Drake simulator stages a task family: the :class:`MotionFamily` interface and its registry.

A task family (:class:`gift.core.interfaces.Task`) says what the human wants; its :class:`MotionFamily`
says how a Drake scene of it looks and what the robot can do there:

- :meth:`MotionFamily.layout`: a randomised :class:`~gift.core.data.Scene` (object positions, landmarks);
- :meth:`MotionFamily.actions`: the scene's finite set of candidate actions as an :class:`ActionSet`
  (end-effector keyframes per action, which object each one moves, and the intent-blind nominal action).

The planner (:class:`gift_sim_drake.motion.MotionPlanner`) turns an action set into trajectories for any
arm: Drake IK at the keyframes, perturbations, minimum-jerk joint-space blends, forward kinematics.

Motion families are registered through the ``gift_register_motions`` hook under ``drake/<task family>``::

    @gift.hookimpl
    def gift_register_motions(register):
        register("drake/stack_blocks", StackBlocksMotion)     # a MotionFamily subclass (or a factory of one)

The four families of the paper are in :mod:`gift_sim_drake.tabletop`. Tutorial:
docs/tutorials/task-plugin.md.
"""

from __future__ import annotations

import abc
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

import attrs
import numpy as np

from gift.core.data import Appearance, ObjectSpec, Scene
from gift.core.errors import GiftError, UnknownComponentError

#: Prefix of the motion registrations this simulator reads.
PREFIX = "drake/"
#: States per trajectory (steps 0..60).
N_STEPS = 61
#: An arm's reach: heights ``[H]`` (m) -> the largest distance ``[H]`` (m) from the base's vertical axis at which
#: the tool centre point gets there with the gripper pointing down (:meth:`DrakeSimulator.reach`).
Reach = Callable[[np.ndarray], np.ndarray]


@attrs.frozen
class ActionSet:
    """The candidate actions of one scene (A actions of K keyframes each).

    ``targets`` ``[A, K, 3]``: nominal tool-centre-point keyframes (m; the gripper points down at each);
    ``times`` ``[K]``: their step indices, increasing and ending at 60 (a keyframe at 0 means the trajectory starts
    there, otherwise it starts at the arm's rest posture); ``carried`` ``[A]``: index of the object each action
    moves (-1: the family's landmark itself, e.g. the mug); ``attach``/``detach``: keyframe indices of the
    grasp/contact and the release (None: held to the end); ``push``: the object follows in the table plane
    only; ``labels`` ``[A]``: what each action does; ``nominal``: the intent-blind controller's action.
    """

    targets: np.ndarray = attrs.field(eq=False)
    times: tuple[int, ...]
    carried: np.ndarray = attrs.field(eq=False)
    attach: int
    detach: int | None
    push: bool
    labels: tuple[str, ...]
    nominal: int

    def __attrs_post_init__(self) -> None:
        t = np.asarray(self.targets)
        if t.ndim != 3 or t.shape[1:] != (len(self.times), 3) or not len(t):
            raise GiftError(f"ActionSet.targets must be [A, K={len(self.times)}, 3], got shape {t.shape}")
        if not np.isfinite(t).all():
            raise GiftError("ActionSet.targets holds non-finite values")
        if list(self.times) != sorted(set(self.times)) or self.times[0] < 0 or self.times[-1] != N_STEPS - 1:
            raise GiftError(f"ActionSet.times must increase strictly from >= 0 to {N_STEPS - 1}, got {self.times}")
        if np.asarray(self.carried).shape != (len(t),) or len(self.labels) != len(t):
            raise GiftError(f"ActionSet: carried {np.asarray(self.carried).shape} and labels ({len(self.labels)}) "
                            f"need one entry per action ({len(t)})")
        if not 0 <= self.attach < len(self.times) or (self.detach is not None and
                                                       not self.attach < self.detach < len(self.times)):
            raise GiftError(f"ActionSet: attach {self.attach} / detach {self.detach} are not keyframe indices "
                            f"with attach < detach")
        if not 0 <= self.nominal < len(t):
            raise GiftError(f"ActionSet.nominal {self.nominal} is not an action index (A = {len(t)})")

    @property
    def start_from_rest(self) -> bool:
        return self.times[0] != 0


class MotionFamily(abc.ABC):
    """Scenes and candidate actions of one task family on the Drake table (world frame: metres, table top at
    z = 0, the arm's base at the origin facing +x; the families of the paper use x in 0.28..0.70 m,
    |y| <= 0.5 m, heights up to 0.4 m).

    - ``task``: the task family (a registered :class:`~gift.core.interfaces.Task`) this stages;
    - ``landmark``: the landmark whose position trajectory batches record (``landmark_positions``);
    - ``required_landmarks``: the landmarks a scene must hold (default: ``(landmark,)``);
    - ``carried_landmark``: the geometry of the landmark when the actions carry it (``carried == -1``), so
      that :class:`gift_sim_drake.plant.SceneModel` adds it as a free body; None when it stays put.
    """

    task: ClassVar[str]
    landmark: ClassVar[str]
    required_landmarks: ClassVar[tuple[str, ...]] = ()
    carried_landmark: ClassVar[Appearance | None] = None

    @abc.abstractmethod
    def layout(self, objects: Sequence[ObjectSpec], relevant: Sequence[str], seed: int,
               reach: Reach | None = None) -> Scene:
        """A randomised scene of ``objects`` (deterministic in ``seed``) for an arm with this ``reach`` (None:
        unknown; keep what the arm must reach within it, e.g. with
        :func:`gift_sim_drake.scenes.place_apart`'s ``fits``); raise
        :class:`~gift.core.errors.PlacementError` when they do not fit."""

    @abc.abstractmethod
    def actions(self, scene: Scene) -> ActionSet:
        """The candidate actions of ``scene`` (a scene :meth:`layout` made)."""

    def perturb(self, targets: np.ndarray, acts: ActionSet, rng: np.random.Generator, scale: float) -> np.ndarray:
        """Per-trajectory variations of the chosen actions' keyframes ``targets`` ``[n, K, 3]`` (a copy, may be
        changed in place), drawn from ``rng``; ``scale`` multiplies every amplitude. The planner re-solves the
        perturbed keyframes from the nominal IK solutions, so keep the moves small (centimetres).

        Default: every keyframe of a trajectory shifted by one offset, uniform in +-1 cm in x and y."""
        return targets + rng.uniform(-0.01, 0.01, size=(len(targets), 1, 3)) * [1, 1, 0] * scale

    def needed_landmarks(self) -> tuple[str, ...]:
        return self.required_landmarks or (self.landmark,)

    def add_landmarks(self, plant: Any, landmarks: Mapping[str, Sequence[float]]) -> None:
        """Add the scene's static landmarks to a Drake ``MultibodyPlant`` (default: the containers of
        :data:`gift_sim_drake.plant.CONTAINERS` and the spill, by name; other names are not drawn)."""
        from gift_sim_drake.plant import add_known_landmarks

        add_known_landmarks(plant, landmarks)


def motion_family(task: str) -> MotionFamily:
    """The registered motion family of ``task`` (``drake/<task>``), or a clear error naming the supported ones."""
    import gift

    manager = gift.get_manager()
    try:
        comp = manager.get("motion", PREFIX + task)
    except UnknownComponentError:
        raise GiftError(f"the Drake simulator has no motion generator for task family {task!r}; it supports "
                        f"{supported_families()} (register one as 'drake/{task}' through gift_register_motions)"
                        ) from None
    family = comp.create()
    if not isinstance(family, MotionFamily):
        raise GiftError(f"motion 'drake/{task}' of plugin {comp.plugin!r} built a {type(family).__name__}, not a "
                        f"gift_sim_drake.families.MotionFamily")
    if family.task != task:
        raise GiftError(f"motion 'drake/{task}' of plugin {comp.plugin!r} stages task {family.task!r}")
    return family


def supported_families() -> list[str]:
    """Task families with a registered Drake motion family."""
    import gift

    return sorted(n[len(PREFIX):] for n in gift.get_manager().names("motion") if n.startswith(PREFIX))


def check_scene(scene: Scene) -> MotionFamily:
    """The motion family of ``scene``, after checking it has what motion needs (else a clear error)."""
    family = motion_family(scene.task)
    need = family.needed_landmarks()
    missing = [k for k in need if k not in scene.landmarks]
    if missing or np.asarray(scene.positions).shape != (len(scene.objects), 3) or not scene.objects:
        raise GiftError(f"this {scene.task} scene (seed {scene.seed}) lacks object positions or the landmarks "
                        f"{list(need)} (missing {missing}); build scenes with the simulator's make_scene")
    return family
