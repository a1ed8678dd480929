"""``ray``: run gift sweeps as Ray tasks, on a cluster or on a local Ray instance.

    ex = RayExecutor()                                  # starts a local Ray instance (all cores)
    ex = RayExecutor(num_cpus=2)                        # ... with 2 CPUs
    ex = RayExecutor(address="auto")                    # joins the cluster this node belongs to
    ex = RayExecutor(address="ray://head:10001")        # Ray client to a remote head node
    results = ex.map(fn, items)                         # same results, same order as 'serial'

Chunks of items run as Ray tasks through :func:`gift.core.executor.run_chunk`, the same per-item loop
the built-in executors use, so the determinism contract of :mod:`gift.core.executor` holds here too.
If Ray was already initialised by the caller, the executor uses that connection and leaves it open;
otherwise it shuts down what it started on :meth:`RayExecutor.close`.

Workers must be able to import ``fn``'s module: a local instance started here passes the driver's
``sys.path`` to its workers as ``PYTHONPATH``; on a cluster install gift and your plugins on every node
(or pass a ``runtime_env``).
"""

from __future__ import annotations

import asyncio
import os
import sys
from collections.abc import Callable, Iterable
from typing import Any, ClassVar

import ray

from gift.core.executor import (
    ConcurrencyLimit,
    Executor,
    ExecutorError,
    assemble,
    check_picklable,
    chunk_bounds,
    run_chunk,
)
from gift.core.errors import ValidationError

_remote_chunk = ray.remote(run_chunk)


def driver_pythonpath() -> str:
    """The driver's ``sys.path`` directories (then ``$PYTHONPATH``) as one ``PYTHONPATH`` string."""
    entries = [p for p in sys.path if p and os.path.isdir(p)]
    entries += [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p and p not in entries]
    return os.pathsep.join(entries)


class RayExecutor(Executor):
    """Ray tasks, one per chunk of items; at most ``max_workers`` chunks in flight.

    ``address``: cluster to join (``"auto"``, ``"host:6379"``, ``"ray://host:10001"``); ``None`` starts a
    local Ray instance. ``num_cpus``: CPUs of that local instance (default all cores; ignored with an
    address). ``max_workers``: chunks in flight (default: the cluster's CPUs / ``cpus_per_task``).
    ``runtime_env``, ``namespace`` and ``init_options`` go to ``ray.init``.
    """

    name: ClassVar[str] = "ray"

    def __init__(self, address: str | None = None, num_cpus: int | None = None, max_workers: int | None = None, *,
                 cpus_per_task: float = 1.0, namespace: str = "gift", runtime_env: dict | None = None,
                 init_options: dict | None = None) -> None:
        for label, value in (("num_cpus", num_cpus), ("max_workers", max_workers)):
            if value is not None and (not isinstance(value, int) or isinstance(value, bool) or value < 1):
                raise ExecutorError(f"executor 'ray': {label} must be a positive integer, got {value!r}")
        if not cpus_per_task > 0:
            raise ExecutorError(f"executor 'ray': cpus_per_task must be > 0, got {cpus_per_task!r}")
        self.address, self.num_cpus, self._max_workers = address, num_cpus, max_workers
        self.cpus_per_task, self.namespace = float(cpus_per_task), namespace
        self.runtime_env, self.init_options = runtime_env, dict(init_options or {})
        self._owns_ray = False
        self.started_local_instance = False

    # ------------------------------------------------------------------ connection
    def _ensure(self) -> None:
        if ray.is_initialized():
            return
        options: dict[str, Any] = {"namespace": self.namespace, "include_dashboard": False,
                                   "log_to_driver": True, "configure_logging": False}
        runtime_env = dict(self.runtime_env or {})
        if self.address:
            options["address"] = self.address
        else:
            options["num_cpus"] = self.num_cpus or self._max_workers or os.cpu_count() or 1
            # workers of a local instance import what the driver imports (test helpers, scripts' modules)
            env_vars = dict(runtime_env.get("env_vars", {}))
            env_vars.setdefault("PYTHONPATH", driver_pythonpath())
            runtime_env["env_vars"] = env_vars
        if runtime_env:
            options["runtime_env"] = runtime_env
        options.update(self.init_options)
        try:
            ray.init(**options)
        except Exception as e:  # noqa: BLE001 - connection problems come in many types
            where = f"the Ray cluster at {self.address!r}" if self.address else "a local Ray instance"
            raise ExecutorError(f"executor 'ray': could not start or join {where}: {type(e).__name__}: {e}") from e
        self._owns_ray = True
        self.started_local_instance = not self.address

    @property
    def max_workers(self) -> int:
        if self._max_workers is not None:
            return self._max_workers
        if not self.address and not ray.is_initialized() and self.num_cpus is not None:
            return max(1, int(self.num_cpus / self.cpus_per_task))
        self._ensure()
        cpus = ray.cluster_resources().get("CPU", 1.0)
        return max(1, int(cpus / self.cpus_per_task))

    # ------------------------------------------------------------------ work
    def map(self, fn: Callable[[Any], Any], items: Iterable[Any], *, chunksize: int | None = None) -> list[Any]:
        items = list(items)
        if not items:
            chunk_bounds(0, 1, chunksize)
            return []
        check_picklable(self.name, fn)
        self._ensure()
        workers = self.max_workers
        bounds = chunk_bounds(len(items), workers, chunksize)
        remote = _remote_chunk.options(num_cpus=self.cpus_per_task, max_retries=0)
        fn_ref = ray.put(fn)
        refs: list[Any] = [None] * len(bounds)
        pending: dict[Any, int] = {}
        next_chunk = 0
        try:
            while next_chunk < len(bounds) or pending:
                while next_chunk < len(bounds) and len(pending) < workers:
                    a, b = bounds[next_chunk]
                    ref = remote.remote(fn_ref, a, items[a:b])
                    refs[next_chunk] = ref
                    pending[ref] = next_chunk
                    next_chunk += 1
                done, _ = ray.wait(list(pending), num_returns=1)
                for ref in done:
                    pending.pop(ref)
            outputs = []
            for (a, b), ref in zip(bounds, refs):
                try:
                    outputs.append(ray.get(ref))
                except ray.exceptions.RayError as e:
                    raise ExecutorError(f"executor 'ray': the chunk of items {a}..{b - 1} could not be run "
                                        f"({type(e).__name__}: {e})") from e
        except BaseException:
            for ref in pending:
                ray.cancel(ref, force=True)
            raise
        return assemble(self.name, len(items), outputs)

    def rate_limit(self, key: str, max_concurrent: int) -> "RayRateLimit":
        self._ensure()
        return RayRateLimit(max_concurrent, key=key)

    def close(self) -> None:
        if self._owns_ray and ray.is_initialized():
            ray.shutdown()
        self._owns_ray = False

    def __repr__(self) -> str:
        return (f"RayExecutor(address={self.address!r}, num_cpus={self.num_cpus!r}, "
                f"max_workers={self._max_workers!r})")


# ---------------------------------------------------------------------- cluster-wide concurrency limit
@ray.remote(num_cpus=0, max_concurrency=10_000)
class _SemaphoreActor:
    """Holds one asyncio semaphore; every acquire/release of a :class:`RayRateLimit` goes through it."""

    def __init__(self, max_concurrent: int) -> None:
        self.capacity = max_concurrent
        self._sem = asyncio.Semaphore(max_concurrent)

    async def get_capacity(self) -> int:
        return self.capacity

    async def acquire(self, timeout: float | None) -> bool:
        try:
            await asyncio.wait_for(self._sem.acquire(), timeout)
        except asyncio.TimeoutError:
            return False
        return True

    async def release(self) -> None:
        self._sem.release()


class RayRateLimit(ConcurrencyLimit):
    """At most ``max_concurrent`` holders of ``key`` at once across a whole Ray cluster.

    Backed by a named actor (``gift-ratelimit-<key>``, 0 CPUs) created where the limit is first built
    (do that in the driver, e.g. through :meth:`RayExecutor.rate_limit`, so the actor lives as long as
    the driver). Pickles to its key; workers find the actor by name. A slot held by a worker that
    crashes is not given back.
    """

    def __init__(self, max_concurrent: int, *, key: str = "default") -> None:
        if not isinstance(max_concurrent, int) or isinstance(max_concurrent, bool) or max_concurrent < 1:
            raise ValidationError(f"RayRateLimit: max_concurrent must be a positive integer, got {max_concurrent!r}")
        if not isinstance(key, str) or not key:
            raise ValidationError(f"RayRateLimit: key must be a non-empty string, got {key!r}")
        self.max_concurrent, self.key = max_concurrent, key
        if not ray.is_initialized():
            raise ExecutorError("RayRateLimit needs a running Ray connection (build it through RayExecutor.rate_limit)")
        actor = self._actor()
        capacity = ray.get(actor.get_capacity.remote())
        if capacity != max_concurrent:
            raise ValidationError(f"RayRateLimit {key!r}: already exists on this cluster with max_concurrent="
                                  f"{capacity}, asked for {max_concurrent}; use another key")

    @property
    def actor_name(self) -> str:
        return f"gift-ratelimit-{self.key}"

    def _actor(self):
        handle = self.__dict__.get("_handle")
        if handle is None:
            handle = _SemaphoreActor.options(name=self.actor_name, get_if_exists=True).remote(self.max_concurrent)
            self.__dict__["_handle"] = handle
        return handle

    def __getstate__(self) -> dict:
        state = super().__getstate__()
        state.pop("_handle", None)
        return state

    def acquire(self, timeout: float | None = None) -> bool:
        if not ray.get(self._actor().acquire.remote(timeout)):
            raise TimeoutError(f"RayRateLimit {self.key!r}: no free slot of {self.max_concurrent} within {timeout} s")
        return True

    def release(self, token: Any) -> None:
        ray.get(self._actor().release.remote())

    def __repr__(self) -> str:
        return f"RayRateLimit(max_concurrent={self.max_concurrent}, key={self.key!r})"
