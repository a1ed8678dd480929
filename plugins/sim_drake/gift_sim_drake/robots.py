"""The arms: the two this package ships (Franka Panda, Kinova Jaco2 7-DoF) and any a plugin registers.

Robots are :class:`gift.core.robots.RobotSpec` values registered through the ``gift_register_robots`` hook
(:mod:`gift_sim_drake.plugin` registers :data:`ROBOTS`); the Drake plugin builds the simulator
``drake-<name>`` for every registered robot. A base sits at its mount pose (default: the world origin on the
table top, the arm facing +x); ``ee_link`` is the tool centre point with its z axis along the approach
direction. What a URDF must satisfy: docs/tutorials/robot-plugin.md.
"""

from __future__ import annotations

import hashlib
import logging
from functools import lru_cache

import numpy as np

from gift.core.errors import GiftError, ValidationError
from gift.core.robots import RobotSpec
from gift_sim_drake.kinematics import ArmKinematics

logging.getLogger("drake").setLevel(logging.ERROR)

#: The arms of this package (URDFs in ``gift_sim_drake/robots``), registered by :mod:`gift_sim_drake.plugin`.
ROBOTS: dict[str, RobotSpec] = {
    "franka": RobotSpec("franka", "robots/panda.urdf", "panda_link0", "panda_ee",
                        rest=(0.0, -0.26, 0.0, -2.43, 0.0, 2.17, 0.785), package="gift_sim_drake",
                        description="Franka Panda (7-DoF)"),
    "jaco": RobotSpec("jaco", "robots/jaco.urdf", "j2s7s300_link_base", "j2s7s300_ee",
                      rest=(0.0, 2.76, 0.0, 4.63, 0.0, 1.87, 0.0), package="gift_sim_drake",
                      description="Kinova Jaco2 7-DoF (j2s7s300)"),
}


def simulator_name(robot: str) -> str:
    """The registered name of the Drake simulator of ``robot``: ``drake-<robot>``."""
    return f"drake-{robot}"


def get_robot(robot: str | RobotSpec) -> RobotSpec:
    """The registered robot ``robot`` (or the spec itself), checked against its URDF (:func:`check_robot`)."""
    if isinstance(robot, str):
        import gift

        robot = gift.get_robot(robot)  # unknown names: UnknownComponentError listing the registered robots
    if not isinstance(robot, RobotSpec):
        raise GiftError(f"expected a robot name or a gift.core.robots.RobotSpec, got {type(robot).__name__}")
    check_robot(robot)
    return robot


def arm_kinematics(spec: RobotSpec) -> ArmKinematics:
    """The batched numpy kinematics of ``spec``'s chain (read from its URDF once)."""
    return _kinematics(spec)


@lru_cache(maxsize=None)
def _kinematics(spec: RobotSpec) -> ArmKinematics:
    path = spec.urdf_path  # a missing file: its own ValidationError
    try:
        return ArmKinematics.from_urdf(path, spec.base_link, spec.ee_link, spec.mount)
    except GiftError as e:
        raise GiftError(f"robot {spec.name!r}: {e}") from None


@lru_cache(maxsize=None)
def check_robot(spec: RobotSpec) -> None:
    """Check what needs no Drake: the URDF file exists, holds a chain ``base_link -> ee_link`` of revolute /
    continuous joints, and ``rest`` has one angle per joint, inside the limits. Raises a clear error."""
    kin = arm_kinematics(spec)
    if len(spec.rest) != kin.dof:
        raise ValidationError(f"robot {spec.name!r}: rest has {len(spec.rest)} angles but the chain "
                              f"{spec.base_link} -> {spec.ee_link} of {spec.urdf_path.name} has {kin.dof} movable "
                              f"joints {list(kin.joint_names)}")
    rest = np.asarray(spec.rest)
    out = np.flatnonzero((rest < kin.lower) | (rest > kin.upper))
    if out.size:
        raise ValidationError(f"robot {spec.name!r}: rest is outside the joint limits at "
                              + ", ".join(f"{kin.joint_names[i]} ({rest[i]:.3f} not in [{kin.lower[i]:.3f}, "
                                          f"{kin.upper[i]:.3f}])" for i in out))


@lru_cache(maxsize=None)
def robot_fingerprint(spec: RobotSpec) -> str:
    """A hash of the spec and its URDF's bytes (16 hex digits): what a cached trajectory depends on."""
    digest = hashlib.sha256(repr(spec).encode())
    digest.update(spec.urdf_path.read_bytes())
    return digest.hexdigest()[:16]


def clip_to_limits(spec: RobotSpec, q: np.ndarray) -> np.ndarray:
    k = arm_kinematics(spec)
    return np.clip(q, k.lower, k.upper)
