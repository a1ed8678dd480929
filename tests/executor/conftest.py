"""Executors shared by the executor tests: one local pool and one local Ray instance per session."""

from __future__ import annotations

import pytest

from gift.core.executor import LocalExecutor, get_executor


@pytest.fixture(scope="session")
def local_executor():
    """A 2-process local pool (spawned once, reused by every test, always shut down)."""
    ex = LocalExecutor(max_workers=2)
    yield ex
    ex.close()


@pytest.fixture(scope="session")
def ray_executor():
    """The ``ray`` executor on a local Ray instance with 2 CPUs, started here and shut down at the end."""
    pytest.importorskip("ray")
    pytest.importorskip("gift_executor_ray")
    import ray

    ex = get_executor("ray", num_cpus=2)
    try:
        assert ex.max_workers == 2
        yield ex
    finally:
        ex.close()
        assert not ray.is_initialized()
