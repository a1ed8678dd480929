"""``gift doctor`` checks of gift-sim-drake: Drake itself and EGL for headless renders."""

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
