"""gift-executor-ray: the ``ray`` executor (:class:`RayExecutor`) and a cluster-wide LM concurrency limit."""

from gift_executor_ray.executor import RayExecutor, RayRateLimit

__all__ = ["RayExecutor", "RayRateLimit"]
