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


def _check_ray(quick: bool = False):
    from gift.doctor import check_import, pip_fix

    return check_import("ray", ["ray"], fix=pip_fix("-e plugins/executor_ray"), what="the ray executor")


@hookimpl
def gift_register_doctor_checks(register):
    register("ray", _check_ray, description="ray imports (the ray executor)")
