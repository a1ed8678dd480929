"""The two arms: Franka Panda and Kinova Jaco2 (7-DoF spherical wrist), as URDFs of this package.

Both bases sit at the world origin on the table top (z = 0, the arm faces +x). ``ee_link`` is the tool
centre point with its z axis along the approach direction.
"""

from __future__ import annotations

import logging
from functools import lru_cache
from importlib import resources
from pathlib import Path

import attrs
import numpy as np

from gift.core.errors import UnknownComponentError
from gift_sim_drake.kinematics import ArmKinematics

logging.getLogger("drake").setLevel(logging.ERROR)


@attrs.frozen
class RobotSpec:
    """An arm: its URDF file (in ``gift_sim_drake/robots``), chain ends, and a rest posture (rad)."""

    name: str
    urdf: str
    base_link: str
    ee_link: str
    rest: tuple[float, ...]

    @property
    def urdf_path(self) -> Path:
        return Path(str(resources.files("gift_sim_drake") / "robots" / self.urdf))

    @property
    def kinematics(self) -> ArmKinematics:
        return _kinematics(self)


ROBOTS: dict[str, RobotSpec] = {
    "franka": RobotSpec("franka", "panda.urdf", "panda_link0", "panda_ee",
                        rest=(0.0, -0.26, 0.0, -2.43, 0.0, 2.17, 0.785)),
    "jaco": RobotSpec("jaco", "jaco.urdf", "j2s7s300_link_base", "j2s7s300_ee",
                      rest=(0.0, 2.76, 0.0, 4.63, 0.0, 1.87, 0.0)),
}


def get_robot(name: str) -> RobotSpec:
    try:
        return ROBOTS[name]
    except KeyError:
        raise UnknownComponentError(f"no robot {name!r} in gift_sim_drake; robots: {sorted(ROBOTS)}") from None


@lru_cache(maxsize=None)
def _kinematics(spec: RobotSpec) -> ArmKinematics:
    return ArmKinematics.from_urdf(spec.urdf_path, spec.base_link, spec.ee_link)


def clip_to_limits(spec: RobotSpec, q: np.ndarray) -> np.ndarray:
    k = spec.kinematics
    return np.clip(q, k.lower, k.upper)
