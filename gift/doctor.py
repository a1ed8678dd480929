"""``gift doctor``: check the install and print what is missing, each with the command that fixes it.

The core checks Python, the plugins that failed to load, the cache directories and a C/C++ compiler;
each plugin adds checks of what it needs through the ``gift_register_doctor_checks`` hook::

    from gift.doctor import Check

    @gift.hookimpl
    def gift_register_doctor_checks(register):
        register("my-backend", check_my_backend, description="my_backend's library is importable")

    def check_my_backend(quick: bool = False) -> Check:
        ...

A check is called as ``check(quick=...)`` (``quick``: skip slow verification such as re-hashing a model
file) and returns one :class:`Check` or a list of them. ``fail`` means something required is missing or
broken (``gift doctor`` exits with 1); ``warn`` means an optional feature will not work.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import json
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import attrs

STATUSES = ("ok", "warn", "fail")


@attrs.frozen
class Check:
    """One finding: ``status`` is ``ok``, ``warn`` (optional feature unavailable) or ``fail`` (required)."""

    name: str
    status: str = attrs.field(validator=attrs.validators.in_(STATUSES))
    detail: str = ""
    fix: str = ""

    def as_dict(self) -> dict[str, str]:
        return attrs.asdict(self)


def pip_fix(requirement: str) -> str:
    """The fix for a missing Python package: the setup script, or the one pip command (repository root)."""
    return f"bash scripts/setup.sh   (or: .venv/bin/pip install -c constraints.txt {requirement})"


def check_import(name: str, modules: Iterable[str], *, fix: str, required: bool = True,
                 what: str = "") -> Check:
    """``ok`` with the distribution versions when every module imports, else ``fail`` / ``warn`` with ``fix``."""
    found = []
    for mod in modules:
        try:
            importlib.import_module(mod)
        except Exception as e:  # noqa: BLE001 - ImportError, or a broken install raising anything on import
            why = f"cannot import {mod}: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}"
            return Check(name, "fail" if required else "warn", f"{why}{f' ({what})' if what else ''}", fix)
        found.append(mod)
    return Check(name, "ok", ", ".join(f"{m} {_version_of(m)}".strip() for m in found))


def _version_of(module: str) -> str:
    top = module.split(".")[0]
    for dist in importlib.metadata.packages_distributions().get(top, []):
        try:
            return importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            continue
    return ""


# ----------------------------------------------------------------------------- core checks


def check_python(quick: bool = False) -> Check:
    v = sys.version_info
    text = f"{v.major}.{v.minor}.{v.micro} ({sys.executable})"
    if (v.major, v.minor) != (3, 11):
        return Check("python", "fail", f"{text}; gift needs 3.11",
                     "apt-get install python3.11 python3.11-venv, then rm -rf .venv && bash scripts/setup.sh")
    return Check("python", "ok", text)


def check_plugins(manager: Any) -> list[Check]:
    """One ``fail`` per plugin that failed to load (``manager.failed``); ``ok`` listing the loaded ones."""
    out = []
    for name, why in sorted(manager.failed.items()):
        dist = manager.failed_distributions.get(name, "?")
        missing = why.split("No module named ", 1)[1].strip("'\" ") if "No module named " in why else ""
        fix = (f"install the module it imports ({missing}) or reinstall {dist!r}" if missing
               else f"reinstall {dist!r}")
        out.append(Check(f"plugin {name}", "fail", f"distribution {dist!r} failed to load: {why}",
                         f"{fix} (bash scripts/setup.sh for gift's own); or skip it: GIFT_DISABLE_PLUGINS={name}"))
    loaded = [n for n, _ in manager.pm.list_name_plugin() if not n.startswith("gift.")]
    out.append(Check("plugins", "ok", f"{len(loaded)} loaded: {', '.join(sorted(loaded)) or 'none'}"))
    return out


def check_cache_dirs(quick: bool = False) -> list[Check]:
    """The cache root (``$GIFT_CACHE_DIR`` or the user cache dir) and its existing sub-directories are writable."""
    from gift.core.paths import cache_root

    root = cache_root()
    dirs = [root] + (sorted(p for p in root.iterdir() if p.is_dir()) if root.is_dir() else [])
    bad = []
    for d in dirs:
        try:
            d.mkdir(parents=True, exist_ok=True)
            with tempfile.NamedTemporaryFile(dir=d, prefix=".gift-doctor-"):
                pass
        except OSError as e:
            bad.append(f"{d}: {type(e).__name__}: {e.strerror or e}")
    if bad:
        return [Check("cache directories", "fail", "not writable: " + "; ".join(bad),
                      f"make them writable, or point GIFT_CACHE_DIR at a writable directory (now "
                      f"{'GIFT_CACHE_DIR=' + os.environ['GIFT_CACHE_DIR'] if os.environ.get('GIFT_CACHE_DIR') else 'unset'})")]
    return [Check("cache directories", "ok", f"{root} ({len(dirs) - 1} sub-directories) writable")]


def check_compiler(quick: bool = False) -> Check:
    missing = [c for c in ("cc", "c++") if shutil.which(c) is None]
    if missing:
        return Check("C/C++ compiler", "warn", f"{' and '.join(missing)} not found: needed only to compile "
                     f"llama-cpp-python when pip's cache holds no built wheel", "apt-get install build-essential")
    return Check("C/C++ compiler", "ok", f"{shutil.which('cc')}, {shutil.which('c++')}")


def check_constraints(quick: bool = False) -> Check | None:
    """Installed versions against constraints.txt of the clone gift runs from (None outside a clone)."""
    path = Path(__file__).resolve().parents[1] / "constraints.txt"
    if not path.is_file():
        return None
    differ, absent = [], 0
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if "==" not in line:
            continue
        name, pinned = (s.strip() for s in line.split("==", 1))
        try:
            have = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            absent += 1  # not every set installs every pinned package
            continue
        if have != pinned:
            differ.append(f"{name} {have} (pinned {pinned})")
    if differ:
        return Check("pinned versions", "warn", f"{len(differ)} differ from {path}: {', '.join(differ[:8])}"
                     + (" ..." if len(differ) > 8 else ""), "bash scripts/setup.sh (it installs the pinned versions)")
    return Check("pinned versions", "ok", f"installed packages match {path.name} ({absent} pinned ones not installed)")


#: The core's checks, run after the plugin check (:func:`check_plugins`) and before the plugins' own.
CORE_CHECKS: tuple[tuple[str, Callable[..., Any]], ...] = (
    ("python", check_python), ("cache directories", check_cache_dirs), ("C/C++ compiler", check_compiler),
    ("pinned versions", check_constraints),
)


# ----------------------------------------------------------------------------- running


def _as_list(name: str, value: Any) -> list[Check]:
    if value is None:
        return []
    items = [value] if isinstance(value, Check) else list(value)
    for c in items:
        if not isinstance(c, Check):
            return [Check(name, "fail", f"the check returned {type(c).__name__}, not gift.doctor.Check",
                          "fix the plugin's gift_register_doctor_checks")]
    return items


def run_checks(manager: Any = None, *, quick: bool = False) -> list[Check]:
    """Every check: the core's, then each plugin's (a check that raises is reported as ``fail``)."""
    if manager is None:
        from gift.plugins.manager import get_manager

        manager = get_manager()
    checks: list[tuple[str, str, Callable[..., Any]]] = [("gift", n, fn) for n, fn in CORE_CHECKS]
    checks += [(c.distribution, c.name, c.factory) for c in manager.components("doctor_check")]
    results: list[Check] = check_plugins(manager)
    for dist, name, fn in checks:
        try:
            results += _as_list(name, fn(quick=quick))
        except Exception as e:  # noqa: BLE001 - a broken check must not hide the others
            results.append(Check(name, "fail", f"the check of {dist!r} raised {type(e).__name__}: {e}",
                                 f"report it; reinstall {dist!r}"))
    return results


def format_report(results: Iterable[Check]) -> str:
    results = list(results)
    width = max((len(r.name) for r in results), default=0)
    label = {"ok": "ok  ", "warn": "warn", "fail": "FAIL"}
    lines = []
    for r in results:
        lines.append(f"{label[r.status]}  {r.name:<{width}}  {r.detail}")
        if r.status != "ok" and r.fix:
            lines.append(f"      {'':<{width}}  fix: {r.fix}")
    fails = sum(r.status == "fail" for r in results)
    warns = sum(r.status == "warn" for r in results)
    if fails:
        lines.append(f"{fails} required item(s) missing or broken, {warns} warning(s): see the fixes above")
    else:
        lines.append(f"the install is complete ({warns} optional item(s) missing)" if warns
                     else "the install is complete")
    return "\n".join(lines)


def configure(parser: Any) -> None:
    parser.add_argument("--json", action="store_true", help="machine-readable output")
    parser.add_argument("--quick", action="store_true",
                        help="trust recorded checksums instead of re-hashing the 1.1 GB embedded model")


def run(args: Any) -> int:
    """``gift doctor``: exit 0 when everything required is there, 1 otherwise."""
    results = run_checks(quick=bool(getattr(args, "quick", False)))
    if getattr(args, "json", False):
        print(json.dumps({"checks": [r.as_dict() for r in results],
                          "ok": not any(r.status == "fail" for r in results)}, indent=2))
    else:
        print(format_report(results))
    return 1 if any(r.status == "fail" for r in results) else 0
