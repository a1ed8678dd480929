"""Batched numpy kinematics of a serial arm, read from the same URDF that Drake parses.

:class:`ArmKinematics` walks the chain ``base link -> ee link`` of a URDF: fixed transforms (``origin``)
and revolute joints (``axis``). Forward kinematics runs over any batch shape ``[..., dof]`` at once, which
is what makes trajectory generation fast; a test checks it against Drake's ``MultibodyPlant`` to 1e-6 m.
Units: metres and radians, positions in the world frame (the base link placed at the robot's mount pose;
at the origin by default).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from functools import cached_property
from pathlib import Path

import attrs
import numpy as np

from gift.core.errors import GiftError


def _rpy_matrix(rpy) -> np.ndarray:
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def _homogeneous(xyz, rpy) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = _rpy_matrix(rpy)
    t[:3, 3] = xyz
    return t


def _floats(text: str | None, default: str) -> np.ndarray:
    return np.array([float(v) for v in (text or default).split()])


@attrs.frozen
class ArmKinematics:
    """The kinematic chain of one arm: ``dof`` revolute joints between fixed transforms.

    ``origins[i]``: 4x4 transform from the previous joint's frame (the world, for ``i = 0``) to joint ``i``'s
    frame (the mount pose and fixed joints folded in); ``axes[i]``: unit rotation axis of joint ``i`` in its
    own frame; ``tool``: joint ``dof-1``'s frame to the end-effector frame. ``lower``/``upper``: joint limits
    ``[dof]`` in radians (infinite for URDF ``continuous`` joints).
    """

    joint_names: tuple[str, ...]
    origins: np.ndarray = attrs.field(eq=False)  # [dof, 4, 4]
    axes: np.ndarray = attrs.field(eq=False)  # [dof, 3]
    tool: np.ndarray = attrs.field(eq=False)  # [4, 4]
    lower: np.ndarray = attrs.field(eq=False)
    upper: np.ndarray = attrs.field(eq=False)
    base_link: str = ""
    ee_link: str = ""

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    @classmethod
    def from_urdf(cls, path: str | Path, base_link: str, ee_link: str,
                  mount: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)) -> "ArmKinematics":
        """Read the chain from ``base_link`` to ``ee_link`` of the URDF at ``path``; ``mount`` is the base link's
        pose in the world ``(x, y, z, roll, pitch, yaw)``."""
        try:
            root = ET.parse(path).getroot()
        except (ET.ParseError, OSError) as e:
            raise GiftError(f"{path}: cannot read the URDF: {e}") from None
        links = {link.get("name") for link in root.findall("link")}
        for what, name in (("base link", base_link), ("end-effector link", ee_link)):
            if name not in links:
                raise GiftError(f"{path}: no {what} {name!r}; links: {sorted(links)}")
        by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
        chain = []
        link = ee_link
        while link != base_link:
            joint = by_child.get(link)
            if joint is None:
                raise GiftError(f"{path}: no joint chain from {base_link!r} to {ee_link!r} (stuck at {link!r})")
            chain.append(joint)
            link = joint.find("parent").get("link")
        chain.reverse()
        names, origins, axes, lower, upper = [], [], [], [], []
        pending = _homogeneous(mount[:3], mount[3:]) if any(mount) else np.eye(4)
        for joint in chain:
            origin = joint.find("origin")
            t = _homogeneous(_floats(origin.get("xyz") if origin is not None else None, "0 0 0"),
                             _floats(origin.get("rpy") if origin is not None else None, "0 0 0"))
            pending = pending @ t
            kind = joint.get("type")
            if kind == "fixed":
                continue
            if kind not in ("revolute", "continuous"):
                raise GiftError(f"{path}: joint {joint.get('name')!r} has type {kind!r}; only revolute, continuous "
                                f"and fixed joints are supported between the base and the end effector")
            axis = _floats(joint.find("axis").get("xyz") if joint.find("axis") is not None else None, "1 0 0")
            limit = joint.find("limit")
            if kind == "revolute" and (limit is None or limit.get("lower") is None or limit.get("upper") is None):
                raise GiftError(f"{path}: revolute joint {joint.get('name')!r} needs <limit lower=.. upper=..>")
            names.append(joint.get("name"))
            origins.append(pending)
            axes.append(axis / np.linalg.norm(axis))
            lower.append(float(limit.get("lower")) if kind == "revolute" else -np.inf)
            upper.append(float(limit.get("upper")) if kind == "revolute" else np.inf)
            pending = np.eye(4)
        if not names:
            raise GiftError(f"{path}: the chain from {base_link!r} to {ee_link!r} has no movable joint")
        return cls(tuple(names), np.array(origins), np.array(axes), pending, np.array(lower), np.array(upper),
                   base_link, ee_link)

    @cached_property
    def _z_chain(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The chain rewritten so every joint turns about its local z axis: ``(rot [dof, 3, 3],
        trans [dof, 3], tool_rot [3, 3], tool_trans [3])`` (each joint frame is turned by a constant
        rotation taking z onto the joint's axis; the next origin undoes it)."""
        align = []
        for axis in self.axes:
            v = np.cross([0.0, 0.0, 1.0], axis)
            c = float(axis[2])
            if np.linalg.norm(v) < 1e-12:
                align.append(np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0]))
                continue
            k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
            align.append(np.eye(3) + k + k @ k / (1.0 + c))
        rots, trans = [], []
        undo = np.eye(3)
        for i in range(self.dof):
            o = self.origins[i]
            rots.append(undo @ o[:3, :3] @ align[i])
            trans.append(undo @ o[:3, 3])
            undo = align[i].T
        return np.array(rots), np.array(trans), undo @ self.tool[:3, :3], undo @ self.tool[:3, 3]

    def frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Chain quantities for ``q`` ``[..., dof]``.

        Returns ``(joint_pos [..., dof, 3], joint_axis [..., dof, 3], ee_pos [..., 3], ee_rot [..., 3, 3])``,
        all in the base frame (joint axes as world unit vectors).
        """
        q = np.asarray(q, dtype=float)
        if q.shape[-1] != self.dof:
            raise GiftError(f"joint positions must end in dof={self.dof}, got shape {q.shape}")
        shape = q.shape[:-1]
        qf = q.reshape(-1, self.dof)
        m = qf.shape[0]
        rots, trans, tool_rot, tool_trans = self._z_chain
        # the rotation as its three columns [m, 3] each: only elementwise products, no tiny matmuls
        cols = [np.broadcast_to(e, (m, 3)) for e in np.eye(3)]
        pos = np.zeros((m, 3))
        jpos = np.empty((m, self.dof, 3))
        jaxis = np.empty((m, self.dof, 3))
        cos, sin = np.cos(qf)[:, :, None], np.sin(qf)[:, :, None]

        def times_const(cols, r):
            return [cols[0] * r[0, j] + cols[1] * r[1, j] + cols[2] * r[2, j] for j in range(3)]

        for i in range(self.dof):
            t = trans[i]
            pos = pos + cols[0] * t[0] + cols[1] * t[1] + cols[2] * t[2]
            x, y, z = times_const(cols, rots[i])
            jpos[:, i] = pos
            jaxis[:, i] = z
            c, s = cos[:, i], sin[:, i]
            cols = [c * x + s * y, c * y - s * x, z]
        pos = pos + cols[0] * tool_trans[0] + cols[1] * tool_trans[1] + cols[2] * tool_trans[2]
        rot = np.stack(times_const(cols, tool_rot), axis=-1)
        return (jpos.reshape(shape + (self.dof, 3)), jaxis.reshape(shape + (self.dof, 3)), pos.reshape(shape + (3,)),
                rot.reshape(shape + (3, 3)))

    def fk(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """End-effector position ``[..., 3]`` (m) and rotation ``[..., 3, 3]`` for ``q`` ``[..., dof]``."""
        _, _, pos, rot = self.frames(q)
        return pos, rot

    def solve_pointing_down(self, q0: np.ndarray, targets: np.ndarray, *, iterations: int = 20,
                            damping: float = 1e-3, tol: float = 1e-5) -> tuple[np.ndarray, np.ndarray]:
        """Local IK, batched: move ``q0`` ``[M, dof]`` so that the end effector reaches ``targets`` ``[M, 3]``
        with its approach axis (ee z) pointing straight down.

        Damped least squares on the 6-row task (position, approach axis), clipped to the joint limits.
        Meant for small moves away from a solution Drake's IK found. Returns ``(q [M, dof], error [M])``
        where ``error`` is the position error in metres plus the axis error (|z_ee - (0, 0, -1)|).
        """
        q = np.array(q0, dtype=float)
        targets = np.asarray(targets, dtype=float)
        down = np.array([0.0, 0.0, -1.0])
        err = np.full(q.shape[0], np.inf)
        for _ in range(iterations):
            jpos, jaxis, pos, rot = self.frames(q)
            z = rot[..., :, 2]
            r = np.concatenate([targets - pos, down - z], axis=-1)  # [M, 6]
            err = np.linalg.norm(r[:, :3], axis=-1) + np.linalg.norm(r[:, 3:], axis=-1)
            active = err > tol
            if not active.any():
                break
            jp = np.cross(jaxis, pos[:, None, :] - jpos)  # [M, dof, 3]
            jz = np.cross(jaxis, z[:, None, :])
            jac = np.concatenate([jp, jz], axis=-1).transpose(0, 2, 1)  # [M, 6, dof]
            jjt = jac @ jac.transpose(0, 2, 1) + damping * np.eye(6)
            dq = (jac.transpose(0, 2, 1) @ np.linalg.solve(jjt, r[..., None]))[..., 0]
            q = np.where(active[:, None], np.clip(q + dq, self.lower, self.upper), q)
        _, _, pos, rot = self.frames(q)
        err = np.linalg.norm(targets - pos, axis=-1) + np.linalg.norm(down - rot[..., :, 2], axis=-1)
        return q, err

    def reach_pointing_down(self, heights: np.ndarray, start: np.ndarray, *, step: float = 0.01,
                            tol: float = 1e-4) -> np.ndarray:
        """How far the arm reaches with the gripper pointing down: per height ``[H]`` (m), the largest distance
        (m) from the base's vertical axis at which the tool centre point gets there, ``[H]``.

        Continuation along +x: from the posture ``start`` ``[dof]`` (e.g. the rest posture), local IK
        (:meth:`solve_pointing_down`) reaches 0.3 m out, then follows the target outward in ``step`` increments
        until the residual exceeds ``tol`` (so the answer is at most ``step`` short). Assumes the first joint turns
        the arm about the vertical axis through the base at the origin, so the reach is the same in every
        direction; 0 where even 0.3 m is out of reach.
        """
        heights = np.atleast_1d(np.asarray(heights, dtype=float))
        q = np.tile(np.asarray(start, dtype=float), (len(heights), 1))
        reach = np.zeros(len(heights))
        ok = np.ones(len(heights), dtype=bool)
        for i, r in enumerate(np.arange(0.3, 2.0, step)):
            targets = np.column_stack([np.full(len(heights), r), np.zeros(len(heights)), heights])
            moved, err = self.solve_pointing_down(q, targets, iterations=100 if i == 0 else 30, tol=tol / 10)
            ok &= err < tol
            q = np.where(ok[:, None], moved, q)
            reach = np.where(ok, r, reach)
            if not ok.any():
                break
        return reach
