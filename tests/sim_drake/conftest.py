"""Shared fixtures: the two Drake simulators and a 4-object catalog, built once per session."""

from __future__ import annotations

import pytest
from sim_drake_catalog import OBJECTS, ROBOTS


@pytest.fixture(scope="session")
def simulators():
    import gift

    return {name: gift.get_simulator(name) for name in ROBOTS}


@pytest.fixture(scope="session")
def objects():
    return OBJECTS
