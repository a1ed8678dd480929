"""Built-in plugin: registers the ``serial`` and ``local`` executors (see :mod:`gift.core.executor`)."""

from __future__ import annotations

from gift.core.executor import LocalExecutor, SerialExecutor
from gift.plugins.hookspecs import hookimpl


@hookimpl
def gift_register_executors(register):
    register("serial", SerialExecutor, description="one item after the other in the calling process (reference)")
    register("local", LocalExecutor,
             description="process pool on this machine (spawn; max_workers defaults to the CPU count); the default")
