"""Entry point of gift-executor-ray: registers the ``ray`` executor."""

from __future__ import annotations

from gift.plugins.hookspecs import hookimpl


def _make_ray_executor(**options):
    from gift_executor_ray.executor import RayExecutor  # import ray only when the executor is built

    return RayExecutor(**options)


@hookimpl
def gift_register_executors(register):
    register("ray", _make_ray_executor,
             description="Ray tasks on a cluster (address=...) or on a local Ray instance it starts")
