"""A robot arm as plain data: the description a plugin registers and a simulator builds its robot from.

A plugin registers a :class:`RobotSpec` through the ``gift_register_robots`` hook::

    @gift.hookimpl
    def gift_register_robots(register):
        register(RobotSpec(name="ur5e", urdf="ur5e.urdf", package="my_robot_pkg", base_link="base_link",
                           ee_link="tcp", rest=(0.0, -1.9, 1.9, -1.57, -1.57, 0.0)))     # under spec.name

``gift.get_robot("ur5e")`` returns the spec. Simulator plugins consume it (gift-sim-drake registers one
simulator ``drake-<name>`` per registered robot). Nothing here imports a simulator: joint limits, the
joint chain and the geometry live in the URDF, which the simulator parses.

World frame of every simulator that builds a robot from a spec: metres and radians, the table top is
the plane z = 0 and the robot works in front of its base towards +x; ``mount`` places the base link.
"""

from __future__ import annotations

import importlib.util
import math
import re
from importlib import resources
from pathlib import Path
from typing import Any

import attrs

from gift.core.errors import ValidationError

_NAME = re.compile(r"^[a-z0-9][a-z0-9_-]*$")


def _check_name(inst: Any, attribute: attrs.Attribute, value: Any) -> None:
    if not isinstance(value, str) or not _NAME.match(value):
        raise ValidationError(f"RobotSpec.name must be lower-case letters, digits, '-' or '_' (it becomes part of "
                              f"simulator names such as 'drake-<name>'), got {value!r}")


def _check_str(inst: Any, attribute: attrs.Attribute, value: Any) -> None:
    if not isinstance(value, str) or not value.strip():
        raise ValidationError(f"RobotSpec {getattr(inst, 'name', '?')!r}: {attribute.name} must be a non-empty "
                              f"string, got {value!r}")


def _floats(value: Any) -> tuple[float, ...]:
    if isinstance(value, (str, bytes)):
        raise ValidationError(f"expected a sequence of numbers, got the string {value!r}")
    try:
        return tuple(float(v) for v in value)
    except (TypeError, ValueError) as e:
        raise ValidationError(f"expected a sequence of numbers, got {value!r} ({e})") from None


@attrs.frozen
class RobotSpec:
    """One robot arm, described for a simulator.

    - ``name``: registry name (``[a-z0-9][a-z0-9_-]*``); simulators derive theirs from it (``drake-<name>``).
    - ``urdf``: the URDF file. With ``package`` set: a path relative to that importable Python package's
      directory (the file ships inside the plugin's distribution; declare it as package data). Without
      ``package``: an absolute path.
    - ``base_link``: the link welded to the world at ``mount``.
    - ``ee_link``: the end-effector frame: the tool centre point (between the fingertips), its z axis
      pointing along the approach direction (out of the gripper).
    - ``rest``: the home configuration (rad), one value per movable joint of the chain ``base_link ->
      ee_link``, in chain order; every trajectory starts near it. Its length is the arm's DoF.
    - ``mount``: pose of ``base_link`` in the world, ``(x, y, z, roll, pitch, yaw)`` in m and rad (default:
      at the origin on the table top, URDF x axis pointing over the table). Scenes are laid out around the
      origin, so keep the first joint's axis there (x = y = 0); height and angles are free.
    - ``description``: one line for ``gift plugins``.
    """

    name: str = attrs.field(validator=_check_name)
    urdf: str = attrs.field(converter=str, validator=_check_str)
    base_link: str = attrs.field(validator=_check_str)
    ee_link: str = attrs.field(validator=_check_str)
    rest: tuple[float, ...] = attrs.field(converter=_floats)
    package: str | None = attrs.field(default=None, kw_only=True)
    mount: tuple[float, ...] = attrs.field(default=(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), converter=_floats, kw_only=True)
    description: str = attrs.field(default="", kw_only=True)

    @rest.validator
    def _check_rest(self, attribute, value):
        if not value or not all(math.isfinite(v) for v in value):
            raise ValidationError(f"RobotSpec {self.name!r}: rest must be a non-empty sequence of finite joint "
                                  f"angles (rad), got {value!r}")

    @mount.validator
    def _check_mount(self, attribute, value):
        if len(value) != 6 or not all(math.isfinite(v) for v in value):
            raise ValidationError(f"RobotSpec {self.name!r}: mount must be 6 finite numbers (x, y, z in m; roll, "
                                  f"pitch, yaw in rad), got {value!r}")

    @package.validator
    def _check_package(self, attribute, value):
        if value is not None and (not isinstance(value, str) or not value.strip()):
            raise ValidationError(f"RobotSpec {self.name!r}: package must be an importable package name or None, "
                                  f"got {value!r}")
        if value is None and not Path(self.urdf).is_absolute():
            raise ValidationError(f"RobotSpec {self.name!r}: urdf {self.urdf!r} is a relative path without a "
                                  f"package; give package='your_package' (the file ships in it) or an absolute "
                                  f"path")

    @property
    def dof(self) -> int:
        """Movable joints of the chain (= ``len(rest)``)."""
        return len(self.rest)

    @property
    def urdf_path(self) -> Path:
        """The URDF file on disk (checked to exist)."""
        if self.package is None:
            path = Path(self.urdf)
        else:
            if importlib.util.find_spec(self.package) is None:
                raise ValidationError(f"robot {self.name!r}: its URDF lives in package {self.package!r}, which is not "
                                      f"importable")
            path = Path(str(resources.files(self.package).joinpath(self.urdf)))
        if not path.is_file():
            where = f" in package {self.package!r}" if self.package else ""
            hint = "; ship it as package data" if self.package else ""
            raise ValidationError(f"robot {self.name!r}: URDF file {self.urdf!r}{where} not found (looked at "
                                  f"{path}){hint}")
        return path
