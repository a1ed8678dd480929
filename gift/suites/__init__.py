"""Benchmark suites shipped with gift (a built-in plugin registering them by name)."""

from __future__ import annotations

from pathlib import Path

from gift.plugins.hookspecs import hookimpl

SUITE_DIR = Path(__file__).parent


@hookimpl
def gift_register_suites(register):
    for path in sorted(SUITE_DIR.glob("*.yaml")):
        register(path.stem, str(path), description=f"suite file {path.name}")
