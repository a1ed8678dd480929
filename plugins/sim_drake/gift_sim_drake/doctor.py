"""``gift doctor`` checks of gift-sim-drake: Drake itself, EGL for headless renders, and every registered robot."""

from __future__ import annotations

import ctypes

from gift.doctor import Check, check_import


def check_drake(quick: bool = False) -> Check:
    return check_import("drake", ["pydrake.all"], what="the drake-franka and drake-jaco simulators",
                        fix="bash scripts/setup.sh   (or: .venv/bin/pip install -c constraints.txt --no-deps drake; "
                            "--no-deps: drake declares Mosek, which gift never uses)")


def check_egl(quick: bool = False) -> Check:
    """The EGL loader (libEGL.so.1) and Mesa's EGL driver (libEGL_mesa.so.0) load: Drake renders headless."""
    problems = []
    for lib, pkg in (("libEGL.so.1", "libegl1"), ("libEGL_mesa.so.0", "libegl-mesa0")):
        try:
            ctypes.CDLL(lib)
        except OSError as e:
            problems.append((lib, pkg, str(e)))
    if problems:
        return Check("EGL (headless renders)", "fail",
                     "; ".join(f"{lib} cannot be loaded ({why})" for lib, _, why in problems)
                     + ": the vision kernel's Drake renders fail",
                     f"apt-get install {' '.join(pkg for _, pkg, _ in problems)}")
    return Check("EGL (headless renders)", "ok", "libEGL.so.1 and libEGL_mesa.so.0 load")


def check_robots(quick: bool = False) -> list[Check]:
    """Each registered robot (any plugin's): its URDF file is there, holds the chain base -> end effector, and
    the rest posture fits the chain's joints and limits (:func:`gift_sim_drake.robots.check_robot`; no Drake)."""
    import gift
    from gift.core.errors import GiftError
    from gift_sim_drake.robots import arm_kinematics, check_robot

    out = []
    manager = gift.get_manager()
    for name in manager.names("robot"):
        comp = manager.get("robot", name)
        try:
            check_robot(comp.factory)
        except GiftError as e:
            out.append(Check(f"robot {name}", "fail", str(e),
                             f"fix the robot's URDF or RobotSpec in {comp.distribution} (docs/tutorials/robot-plugin.md), "
                             f"or disable its plugin with GIFT_DISABLE_PLUGINS={comp.plugin}"))
            continue
        dof = arm_kinematics(comp.factory).dof
        out.append(Check(f"robot {name}", "ok", f"{dof}-DoF chain, rest posture within the limits "
                                                f"[{comp.distribution}]"))
    return out
