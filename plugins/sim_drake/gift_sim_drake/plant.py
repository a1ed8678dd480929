"""Drake plants: the arm alone (for inverse kinematics) and full scenes (table, arm, landmarks, objects).

Every position is in metres in the world frame; the table top is the plane z = 0 and the arm base sits
at its mount pose (default: the origin). The built-in arms and scenes use primitive geometry only; a
robot's URDF is parsed as it is (see docs/tutorials/robot-plugin.md for what it must satisfy).
"""

from __future__ import annotations

import logging
import threading
from collections import OrderedDict
from collections.abc import Mapping, Sequence

import numpy as np

from gift.core.data import Appearance, ObjectSpec
from gift.core.errors import GiftError
from gift.core.robots import RobotSpec

logging.getLogger("drake").setLevel(logging.ERROR)

from pydrake.geometry import Box, Cylinder, Sphere  # noqa: E402
from pydrake.math import RigidTransform, RollPitchYaw  # noqa: E402
from pydrake.multibody.inverse_kinematics import InverseKinematics  # noqa: E402
from pydrake.multibody.parsing import Parser  # noqa: E402
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction, MultibodyPlant  # noqa: E402
from pydrake.multibody.tree import SpatialInertia, UnitInertia  # noqa: E402
from pydrake.solvers import Solve  # noqa: E402
from pydrake.systems.framework import DiagramBuilder  # noqa: E402

#: Table top: x from -0.3 to 1.0 m, y from -0.8 to 0.8 m, 5 cm thick, top face at z = 0.
TABLE_SIZE = (1.3, 1.6, 0.05)
TABLE_CENTER = (0.35, 0.0, -0.025)

#: The open containers: outer footprint (x, y), wall height, wall thickness (m).
CONTAINERS = {
    "backpack": {"footprint": (0.22, 0.30), "height": 0.22, "wall": 0.012, "color": (0.15, 0.35, 0.6)},
    "drawer": {"footprint": (0.30, 0.34), "height": 0.12, "wall": 0.015, "color": (0.55, 0.38, 0.22)},
}
SPILL_RADIUS = 0.09
#: Drake IK solutions kept per arm (oldest dropped first).
IK_CACHE_SIZE = 50_000
MUG = Appearance(shape="cylinder", size=(0.04, 0.10), color=(0.95, 0.95, 0.92))


def shape_of(appearance: Appearance):
    """The Drake geometry of an appearance."""
    s = appearance.size
    if appearance.shape == "box":
        return Box(*s)
    if appearance.shape == "cylinder":
        return Cylinder(s[0], s[1])
    return Sphere(s[0])


def half_height(appearance: Appearance) -> float:
    """Height (m) of an object's centre above the table when it stands on it."""
    s = appearance.size
    return {"box": s[2] / 2 if len(s) == 3 else 0.04, "cylinder": s[1] / 2 if len(s) == 2 else 0.05}.get(
        appearance.shape, s[0])


def footprint_radius(appearance: Appearance) -> float:
    """Radius (m) of a disc that covers the object's footprint on the table."""
    s = appearance.size
    if appearance.shape == "box":
        return 0.5 * float(np.hypot(s[0], s[1]))
    return s[0]


def _color(rgb, alpha=1.0) -> np.ndarray:
    return np.array([*rgb, alpha])


def _add_visual_collision(plant: MultibodyPlant, body, name: str, shape, pose: RigidTransform, rgb,
                          collide: bool = True) -> None:
    plant.RegisterVisualGeometry(body, pose, shape, f"{name}_visual", _color(rgb))
    if collide:
        plant.RegisterCollisionGeometry(body, pose, shape, f"{name}_collision", CoulombFriction(0.8, 0.6))


def mount_pose(spec: RobotSpec) -> RigidTransform:
    """The pose of the arm's base link in the world (``spec.mount``)."""
    x, y, z, roll, pitch, yaw = spec.mount
    return RigidTransform(RollPitchYaw(roll, pitch, yaw), [x, y, z])


def add_robot(plant: MultibodyPlant, spec: RobotSpec):
    """Parse the arm's URDF into ``plant`` and weld its base link at its mount pose. Returns the model instance."""
    try:
        models = Parser(plant).AddModels(str(spec.urdf_path))
    except RuntimeError as e:
        raise GiftError(f"robot {spec.name!r}: Drake cannot parse {spec.urdf_path}: {e}") from None
    if len(models) != 1:
        raise GiftError(f"robot {spec.name!r}: {spec.urdf_path} holds {len(models)} models; a robot URDF holds one")
    model = models[0]
    for link in (spec.base_link, spec.ee_link):
        if not plant.HasFrameNamed(link, model):
            raise GiftError(f"robot {spec.name!r}: {spec.urdf_path.name} has no link {link!r}")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(spec.base_link, model), mount_pose(spec))
    return model


def add_table(plant: MultibodyPlant) -> None:
    body = plant.world_body()
    _add_visual_collision(plant, body, "table", Box(*TABLE_SIZE), RigidTransform(TABLE_CENTER), (0.75, 0.7, 0.62))


def add_container(plant: MultibodyPlant, kind: str, center: Sequence[float]) -> None:
    """An open box (floor and four walls) standing on the table, centred at ``center`` (x, y)."""
    c = CONTAINERS[kind]
    fx, fy = c["footprint"]
    h, w = c["height"], c["wall"]
    x, y = float(center[0]), float(center[1])
    body = plant.world_body()
    parts = {
        "floor": ((fx, fy, w), (x, y, w / 2)),
        "wall_front": ((w, fy, h), (x - fx / 2 + w / 2, y, h / 2)),
        "wall_back": ((w, fy, h), (x + fx / 2 - w / 2, y, h / 2)),
        "wall_left": ((fx, w, h), (x, y + fy / 2 - w / 2, h / 2)),
        "wall_right": ((fx, w, h), (x, y - fy / 2 + w / 2, h / 2)),
    }
    for part, (size, pos) in parts.items():
        _add_visual_collision(plant, body, f"{kind}_{part}", Box(*size), RigidTransform(pos), c["color"])


def add_known_landmarks(plant: MultibodyPlant, landmarks: Mapping[str, Sequence[float]]) -> None:
    """Draw the landmarks this module knows by name: the :data:`CONTAINERS` and the ``spill``."""
    for name, pos in landmarks.items():
        if name in CONTAINERS:
            add_container(plant, name, pos)
        elif name == "spill":
            add_spill(plant, pos)


def add_spill(plant: MultibodyPlant, center: Sequence[float]) -> None:
    """A flat disc of liquid on the table (visual only)."""
    pose = RigidTransform([float(center[0]), float(center[1]), 0.001])
    _add_visual_collision(plant, plant.world_body(), "spill", Cylinder(SPILL_RADIUS, 0.002), pose,
                          (0.45, 0.3, 0.15), collide=False)


def add_free_object(plant: MultibodyPlant, name: str, appearance: Appearance, mass: float = 0.2):
    """A free rigid body with the appearance's geometry. Returns the body."""
    instance = plant.AddModelInstance(name)
    body = plant.AddRigidBody(name, instance, SpatialInertia(mass, np.zeros(3), UnitInertia.SolidSphere(0.04)))
    _add_visual_collision(plant, body, name, shape_of(appearance), RigidTransform(), appearance.color)
    return body


class SceneModel:
    """A Drake diagram of one scene: table, arm (welded at its mount), landmarks and the scene's objects as
    free bodies.

    ``bodies[name]`` gives each object's body (and the carried landmark's, e.g. ``"mug"``). The task's motion
    family (:mod:`gift_sim_drake.families`) draws the static landmarks; a task without one gets the
    containers and the spill drawn by name. Use :meth:`set_state` to pose the arm and the objects, then query
    ``plant``/``plant_context``. With ``meshcat`` (a ``pydrake.geometry.Meshcat``) the diagram also holds a
    ``MeshcatVisualizer`` (``visualizer``) that draws the scene on every publish (see
    :mod:`gift_sim_drake.viewer`).
    """

    def __init__(self, spec: RobotSpec, task: str, objects: Sequence[ObjectSpec],
                 landmarks: Mapping[str, Sequence[float]], meshcat=None) -> None:
        from gift_sim_drake.families import motion_family, supported_families

        family = motion_family(task) if task in supported_families() else None
        builder = DiagramBuilder()
        self.plant, self.scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
        self.robot = add_robot(self.plant, spec)
        self.spec = spec
        add_table(self.plant)
        if family is not None:
            family.add_landmarks(self.plant, landmarks)
        else:
            add_known_landmarks(self.plant, landmarks)
        self.bodies = {o.name: add_free_object(self.plant, f"object_{i}", o.appearance)
                       for i, o in enumerate(objects)}
        if family is not None and family.carried_landmark is not None:
            self.bodies[family.landmark] = add_free_object(self.plant, family.landmark, family.carried_landmark)
        self.plant.Finalize()
        self.visualizer = None
        if meshcat is not None:
            from pydrake.geometry import MeshcatVisualizer

            self.visualizer = MeshcatVisualizer.AddToBuilder(builder, self.scene_graph, meshcat)
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()
        self.plant_context = self.plant.GetMyMutableContextFromRoot(self.context)
        self.ee_frame = self.plant.GetFrameByName(spec.ee_link, self.robot)

    def set_state(self, q: np.ndarray, object_positions: Mapping[str, Sequence[float]]) -> None:
        """Arm joints ``q`` ``[dof]`` (rad) and object centres (m, upright)."""
        self.plant.SetPositions(self.plant_context, self.robot, np.asarray(q, dtype=float))
        for name, pos in object_positions.items():
            self.plant.SetFreeBodyPose(self.plant_context, self.bodies[name], RigidTransform(np.asarray(pos)))

    def ee_position(self) -> np.ndarray:
        return self.ee_frame.CalcPoseInWorld(self.plant_context).translation().copy()

    def body_position(self, name: str) -> np.ndarray:
        return self.plant.EvalBodyPoseInWorld(self.plant_context, self.bodies[name]).translation().copy()

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]:
        return (self.plant.GetPositionLowerLimits()[self._robot_slice()],
                self.plant.GetPositionUpperLimits()[self._robot_slice()])

    def _robot_slice(self) -> np.ndarray:
        idx = [self.plant.get_joint(j).position_start() for j in self.plant.GetJointIndices(self.robot)
               if self.plant.get_joint(j).num_positions() == 1]
        return np.asarray(idx)


class DrakeIK:
    """Drake ``InverseKinematics`` on the arm alone: reach a point with the gripper pointing down.

    Solutions are cached by (target rounded to 0.1 mm, initial guess); the solver is deterministic, so a
    target always gets the same joint vector.
    """

    def __init__(self, spec: RobotSpec, *, position_tolerance: float = 1e-4, angle_tolerance: float = 1e-3,
                 max_step: float = 1.6) -> None:
        self.spec = spec
        self.plant = MultibodyPlant(0.0)
        self.robot = add_robot(self.plant, spec)
        self.plant.Finalize()
        if self.plant.num_positions() != len(spec.rest):
            raise GiftError(f"robot {spec.name!r}: Drake finds {self.plant.num_positions()} joint positions in "
                            f"{spec.urdf_path.name} but rest has {len(spec.rest)}; every movable joint must lie on "
                            f"the chain {spec.base_link} -> {spec.ee_link} (make gripper fingers fixed joints)")
        self.ee = self.plant.GetFrameByName(spec.ee_link)
        self.position_tolerance = position_tolerance
        self.angle_tolerance = angle_tolerance
        self.max_step = max_step
        self._cache: OrderedDict[tuple, np.ndarray] = OrderedDict()
        self._lock = threading.Lock()

    def solve(self, target: Sequence[float], guess: Sequence[float]) -> np.ndarray:
        """Joint vector ``[dof]`` placing the tool centre point at ``target`` (m), approach axis down."""
        target = np.asarray(target, dtype=float)
        guess = np.asarray(guess, dtype=float)
        key = (tuple(np.round(target, 4)), tuple(np.round(guess, 6)))
        with self._lock:
            hit = self._cache.get(key)
        if hit is not None:
            return hit.copy()
        # first near the guess (same branch: no 2 pi wraps, no elbow flips), then from the rest posture
        result, q = None, None
        for start in (guess, np.asarray(self.spec.rest, dtype=float)):
            result, q = self._solve_once(target, start)
            if result.is_success():
                break
        if not result.is_success():
            raise GiftError(f"Drake IK found no {self.spec.name} configuration reaching {target.round(3).tolist()} "
                            f"with the gripper pointing down (solver {result.get_solver_id().name()}); the target is "
                            f"probably outside the arm's workspace")
        sol = np.asarray(result.GetSolution(q), dtype=float)
        with self._lock:
            self._cache[key] = sol
            while len(self._cache) > IK_CACHE_SIZE:
                self._cache.popitem(last=False)
        return sol.copy()

    def _solve_once(self, target: np.ndarray, guess: np.ndarray):
        ik = InverseKinematics(self.plant)
        tol = self.position_tolerance
        ik.AddPositionConstraint(self.ee, np.zeros(3), self.plant.world_frame(), target - tol, target + tol)
        ik.AddAngleBetweenVectorsConstraint(self.ee, np.array([0.0, 0.0, 1.0]), self.plant.world_frame(),
                                            np.array([0.0, 0.0, -1.0]), 0.0, self.angle_tolerance)
        prog = ik.get_mutable_prog()
        q = ik.q()
        lo = np.maximum(self.plant.GetPositionLowerLimits(), guess - self.max_step)
        hi = np.minimum(self.plant.GetPositionUpperLimits(), guess + self.max_step)
        prog.AddBoundingBoxConstraint(lo, hi, q)
        prog.AddQuadraticErrorCost(np.eye(len(guess)), guess, q)
        prog.SetInitialGuess(q, guess)
        return Solve(prog), q


_IK: dict[RobotSpec, DrakeIK] = {}
_IK_LOCK = threading.Lock()


def drake_ik(spec: RobotSpec) -> DrakeIK:
    """The process-wide IK solver of an arm (its plant is built once)."""
    with _IK_LOCK:
        if spec not in _IK:
            _IK[spec] = DrakeIK(spec)
        return _IK[spec]
