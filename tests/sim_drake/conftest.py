"""Shared fixtures: the Drake simulators of the built-in arms and of the example robot package
(examples/gift-example-robot, registered from its source tree) and a 4-object catalog, built once per session."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from sim_drake_catalog import OBJECTS, ROBOTS

EXAMPLE_ROBOT = Path(__file__).resolve().parents[2] / "examples" / "gift-example-robot"


@pytest.fixture(scope="session")
def example_robot():
    """The UR5e of gift-example-robot, registered through its own hook (unless the package is installed)."""
    import gift
    from gift.plugins.manager import reset_manager

    manager = gift.get_manager()
    added = "ur5e" not in manager.names("robot")
    if added:
        sys.path.insert(0, str(EXAMPLE_ROBOT))
        import gift_example_robot.plugin

        manager.register_plugin(gift_example_robot.plugin, name="example_robot", distribution="gift-example-robot")
    yield gift.get_robot("ur5e")
    if added:
        sys.path.remove(str(EXAMPLE_ROBOT))
        reset_manager()


@pytest.fixture(scope="session")
def simulators(example_robot):
    import gift

    return {name: gift.get_simulator(name) for name in ROBOTS}


@pytest.fixture(scope="session")
def objects():
    return OBJECTS
