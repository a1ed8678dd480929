"""The Drake simulator, one per registered robot (``drake-franka``, ``drake-jaco``, ``drake-<robot>``):
:class:`gift.core.interfaces.Simulator` on a real Drake ``MultibodyPlant`` (scenes, trajectories, features,
renders)."""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from gift.core.data import FeatureBatch, ObjectSpec, Scene, TrajectoryBatch
from gift.core.errors import GiftError
from gift.core.interfaces import Simulator, Task
from gift.core.robots import RobotSpec
from gift_sim_drake.families import N_STEPS, check_scene, supported_families
from gift_sim_drake.features import compute_features, resolve_task
from gift_sim_drake.motion import GENERATORS, MotionPlanner
from gift_sim_drake.robots import arm_kinematics, get_robot, simulator_name
from gift_sim_drake.scenes import layout


def as_object_specs(objects: Sequence[ObjectSpec | str]) -> tuple[ObjectSpec, ...]:
    """Objects given as :class:`ObjectSpec` or bare names (which get the default appearance)."""
    out = []
    for i, o in enumerate(objects):
        if isinstance(o, str):
            o = ObjectSpec(o)
        if not isinstance(o, ObjectSpec):
            raise GiftError(f"object {i} must be an ObjectSpec or a name, got {type(o).__name__}")
        out.append(o)
    return tuple(out)


#: Heights (m) at which an arm's reach is computed; :meth:`DrakeSimulator.reach` interpolates between them.
REACH_HEIGHTS = np.arange(0.0, 0.81, 0.05)


@lru_cache(maxsize=None)
def _reach_curve(robot: RobotSpec) -> np.ndarray:
    """The arm's reach with the gripper pointing down at :data:`REACH_HEIGHTS`, from its kinematics (m)."""
    return arm_kinematics(robot).reach_pointing_down(REACH_HEIGHTS, np.asarray(robot.rest))


class DrakeSimulator(Simulator):
    """Tabletop scenes of the task families for one arm, on Drake.

    ``DrakeSimulator(robot)``: ``robot`` is a registered robot's name or a :class:`~gift.core.robots.RobotSpec`
    (``gift.get_simulator("drake-<robot>")`` builds it for a registered one).

    - ``make_scene(task, objects, relevant, seed)``: a randomised layout from the family's motion family
      (:mod:`gift_sim_drake.families`; the paper's four in :mod:`gift_sim_drake.tabletop`), objects to be
      picked within this arm's :meth:`reach`;
      ``scene.landmarks`` holds the family's landmarks (``backpack``/``drawer``: the place point inside the
      container; ``spill``: the spill's centre on the table; ``mug``: the mug's start, and ``mug_goal``).
    - ``generate(scene, generator, n, seed)``: ``generator`` in ``("preferred", "default", "random")``
      (:mod:`gift_sim_drake.motion`); every trajectory acts on one thing, named in ``meta["acted_on"]``.
    - ``features(trajectories, task)``: the family's feature columns ``[N, 61, F]``.
    - ``render_object(obj, size)``: ``[3, size, size, 3]`` uint8 views, cached on disk.
    - ``replay(scene, clips, ...)``: trajectories of the scene in Drake's Meshcat (:mod:`gift_sim_drake.viewer`).
    """

    n_steps = N_STEPS
    generators = GENERATORS

    def __init__(self, robot: str | RobotSpec, render_cache_dir: str | None = None) -> None:
        self.robot = get_robot(robot)
        self.name = simulator_name(self.robot.name)
        self.dof = arm_kinematics(self.robot).dof
        self.planner = MotionPlanner(self.robot)
        self.render_cache_dir = render_cache_dir

    @property
    def families(self) -> tuple[str, ...]:
        """Task families with a registered Drake motion family."""
        return tuple(supported_families())

    def make_scene(self, task: str, objects: Sequence[ObjectSpec | str], relevant: Sequence[str] = (),
                   seed: int = 0) -> Scene:
        family = resolve_task(task)  # unknown names: UnknownComponentError listing the registered families
        return layout(family.name, as_object_specs(objects), tuple(relevant), int(seed), reach=self.reach)

    def reach(self, heights: np.ndarray) -> np.ndarray:
        """How far this arm reaches with the gripper pointing down: per height ``[H]`` (m), the largest distance
        ``[H]`` (m) from the base's vertical axis, from its kinematics
        (:meth:`~gift_sim_drake.kinematics.ArmKinematics.reach_pointing_down`, computed once per arm)."""
        return np.interp(np.asarray(heights, dtype=float), REACH_HEIGHTS, _reach_curve(self.robot))

    def generate(self, scene: Scene, generator: str = "preferred", n: int = 1, seed: int = 0) -> TrajectoryBatch:
        return self.planner.generate(scene, generator, n, seed)

    def features(self, trajectories: TrajectoryBatch, task: str | Task) -> FeatureBatch:
        return compute_features(trajectories, task)

    def scene_model(self, scene: Scene):
        """A Drake diagram of ``scene`` (:class:`gift_sim_drake.plant.SceneModel`): table, this arm, the
        landmarks and the objects as free bodies, e.g. to check a trajectory state on the real plant."""
        from gift_sim_drake.plant import SceneModel

        check_scene(scene)
        return SceneModel(self.robot, scene.task, scene.objects, scene.landmarks)

    def replay(self, scene: Scene, clips, **options):
        """Record trajectories of ``scene`` in Drake's Meshcat (:func:`gift_sim_drake.viewer.replay`): a
        :class:`~gift_sim_drake.viewer.Replay` with a live localhost URL and ``static_html()``."""
        from gift_sim_drake.viewer import replay

        return replay(self.robot, scene, clips, **options)

    def render_object(self, obj: ObjectSpec, size: int = 224) -> np.ndarray:
        from gift_sim_drake.render import render_object

        return render_object(obj, size=size, cache_dir=self.render_cache_dir)

    def __repr__(self) -> str:
        return f"DrakeSimulator({self.robot.name!r})"
