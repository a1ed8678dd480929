"""Where batch work runs: one process, a local process pool, or (through a plugin) a Ray cluster.

An :class:`Executor` maps a picklable function over a list of items and returns the results in input
order::

    from gift.core.executor import get_executor, item_seeds

    items = [(scene_id, int(s)) for scene_id, s in zip(scene_ids, item_seeds(seed, len(scene_ids)))]
    with get_executor("local", max_workers=2) as ex:       # or "serial", or "ray" (gift-executor-ray)
        results = ex.map(generate_one, items)               # results[i] == generate_one(items[i])

Built-in executors (registered by :mod:`gift.executors`, kind ``"executor"``):

- ``serial``: a plain loop in the calling process; the reference and the debugging choice.
- ``local`` (the default): a ``concurrent.futures.ProcessPoolExecutor`` with the ``spawn`` start method,
  ``max_workers`` defaulting to ``os.cpu_count()``. The pool is started on the first ``map`` and reused.

Determinism contract (every executor, built-in or plugin, must keep it):

1. ``map(fn, items)[i] == fn(items[i])`` for every ``i``, in input order, whatever the chunking.
2. Randomness comes from the items only. An item carries its own seed (use :func:`item_seeds` to derive
   one per item from a study seed); ``fn`` must never seed from the worker's identity, pid, host, the
   clock, or the order in which items happen to finish.
3. ``fn`` and the items must be picklable (module-level functions, ``functools.partial`` of them, attrs
   data classes, numpy arrays). Work is never shared between items through global state.

With those three rules the results of ``serial``, ``local`` and ``ray`` are identical bit for bit
(``tests/executor`` checks it).

Failures: when ``fn`` raises for some items, every other item still runs; ``map`` then raises
:class:`ExecutionError` naming the first failing item (index and value) with the worker's traceback,
and keeps every completed result in ``error.completed`` so nothing already computed is lost.

LM concurrency: :class:`RateLimit` caps how many calls to one LM backend run at once across all
processes of a machine (a set of ``flock``-ed slot files; a slot held by a process that dies is freed
by the kernel). :meth:`Executor.rate_limit` returns the right limiter for an executor (the Ray plugin
returns a cluster-wide one); ``gift_llm.wrappers.RateLimitedLM`` wraps any LM backend with one.

CLI commands that run sweeps call :func:`add_executor_argument` on their parser and
:func:`executor_from_args` in ``run``; Python functions that take an ``executor=`` argument (an instance,
a registered name, or None) resolve it with :func:`using_executor`.
"""

from __future__ import annotations

import abc
import argparse
import contextlib
import errno
import hashlib
import math
import os
import pickle
import sys
import tempfile
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any, ClassVar

import attrs
import numpy as np

from gift.core.errors import GiftError, ValidationError

DEFAULT_EXECUTOR = "local"


class ExecutorError(GiftError):
    """An executor was misconfigured or could not run work (bad option, unpicklable function, dead pool)."""


@attrs.frozen
class ItemFailure:
    """What went wrong for one item: its index in the input, a short repr, and the worker's traceback."""

    index: int
    item: str
    error_type: str
    message: str
    traceback: str


class ExecutionError(GiftError):
    """``fn`` raised for one or more items.

    ``failures``: every :class:`ItemFailure`, by index. ``completed``: ``{index: result}`` of the items
    that succeeded. ``__cause__`` is the first failing item's original exception when it could be
    sent back from the worker.
    """

    def __init__(self, executor: str, failures: Sequence[ItemFailure], completed: Mapping[int, Any], total: int):
        self.failures = tuple(sorted(failures, key=lambda f: f.index))
        self.completed = dict(completed)
        first = self.failures[0]
        self.index, self.item = first.index, first.item
        more = f" (and {len(self.failures) - 1} more failed items)" if len(self.failures) > 1 else ""
        super().__init__(
            f"executor {executor!r}: item {first.index} of {total} ({first.item}) raised "
            f"{first.error_type}: {first.message}{more}; {len(self.completed)} completed results are kept in "
            f".completed\n--- worker traceback ---\n{first.traceback.rstrip()}")


# ------------------------------------------------------------------ helpers shared by every executor
def item_seeds(seed: int, n: int) -> np.ndarray:
    """``n`` independent 63-bit seeds derived from one study seed (``numpy.random.SeedSequence.spawn``).

    Give item ``i`` the seed ``item_seeds(seed, n)[i]``: results then depend on the item, never on which
    worker ran it. Returns ``[n]`` int64.
    """
    if n < 0:
        raise ValidationError(f"item_seeds: n must be >= 0, got {n}")
    children = np.random.SeedSequence(int(seed)).spawn(n)
    return np.array([int(c.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1)) for c in children], dtype=np.int64)


def _short_repr(item: Any, limit: int = 200) -> str:
    try:
        text = repr(item)
    except Exception as e:  # noqa: BLE001 - a broken __repr__ must not hide the real failure
        text = f"<{type(item).__name__} with failing repr: {e}>"
    return text if len(text) <= limit else text[:limit] + "...]"


def run_chunk(fn: Callable[[Any], Any], start: int, items: Sequence[Any]) -> list[tuple]:
    """Run ``fn`` over one chunk (in a worker). Returns ``[("ok", result) | ("err", ItemFailure, exc|None)]``.

    Exceptions are caught per item so the rest of the chunk still runs; the exception object travels
    back only when it can be pickled (its text and traceback always do).
    """
    out: list[tuple] = []
    for offset, item in enumerate(items):
        try:
            out.append(("ok", fn(item)))
        except Exception as e:  # noqa: BLE001 - reported to the caller with the item
            failure = ItemFailure(start + offset, _short_repr(item), type(e).__name__, str(e), traceback.format_exc())
            try:
                pickle.dumps(e)
                exc: BaseException | None = e
            except Exception:  # noqa: BLE001
                exc = None
            out.append(("err", failure, exc))
    return out


def chunk_bounds(n: int, workers: int, chunksize: int | None) -> list[tuple[int, int]]:
    """``[(start, stop)]`` covering ``range(n)``; default chunk size ``ceil(n / (4 * workers))``."""
    if chunksize is None:
        chunksize = max(1, math.ceil(n / (4 * max(1, workers))))
    elif int(chunksize) < 1:
        raise ExecutorError(f"chunksize must be >= 1, got {chunksize!r}")
    chunksize = int(chunksize)
    return [(i, min(n, i + chunksize)) for i in range(0, n, chunksize)]


def assemble(executor: str, n: int, chunk_outputs: Iterable[list[tuple]]) -> list[Any]:
    """Put chunk outputs (in chunk order) back into one result list; raise :class:`ExecutionError` on failures."""
    results: list[Any] = []
    failures: list[ItemFailure] = []
    causes: dict[int, BaseException | None] = {}
    for chunk in chunk_outputs:
        for entry in chunk:
            if entry[0] == "ok":
                results.append(entry[1])
            else:
                failures.append(entry[1])
                causes[entry[1].index] = entry[2]
                results.append(_MISSING)
    if len(results) != n:
        raise ExecutorError(f"executor {executor!r} returned {len(results)} results for {n} items")
    if failures:
        completed = {i: r for i, r in enumerate(results) if r is not _MISSING}
        err = ExecutionError(executor, failures, completed, n)
        raise err from causes.get(err.index)
    return results


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


_MISSING = _Missing()


def check_picklable(executor: str, fn: Callable[[Any], Any]) -> None:
    """Fail early, and clearly, when ``fn`` cannot be sent to another process."""
    try:
        pickle.dumps(fn)
    except Exception as e:  # noqa: BLE001
        raise ExecutorError(
            f"executor {executor!r}: the function {getattr(fn, '__qualname__', fn)!r} cannot be sent to worker "
            f"processes ({type(e).__name__}: {e}); define it at module level (lambdas and closures do not "
            f"pickle) or use the 'serial' executor") from e


# ------------------------------------------------------------------ executors
class Executor(abc.ABC):
    """Runs ``fn`` over many items. Batch-first: one :meth:`map` call per sweep.

    Executors are context managers; :meth:`close` releases their workers (idempotent). Factories
    registered under kind ``"executor"`` should accept ``max_workers=`` (``--workers`` passes it).
    """

    name: ClassVar[str]
    #: True when ``fn`` runs in the calling process (callers may then pass it unpicklable callbacks).
    in_process: ClassVar[bool] = False
    #: True when what ``fn`` prints to stderr reaches the caller's stderr at once and reliably (a worker
    #: may then print its own progress lines); False when it is forwarded late or may be lost (Ray).
    live_stderr: ClassVar[bool] = False

    @property
    @abc.abstractmethod
    def max_workers(self) -> int:
        """How many items may run at the same time."""

    @abc.abstractmethod
    def map(self, fn: Callable[[Any], Any], items: Iterable[Any], *, chunksize: int | None = None) -> list[Any]:
        """``[fn(x) for x in items]``, in input order. ``chunksize``: items sent to a worker at once
        (default ``ceil(len(items) / (4 * max_workers))``). Raises :class:`ExecutionError` if any item fails."""

    def rate_limit(self, key: str, max_concurrent: int) -> "ConcurrencyLimit":
        """A limiter that lets at most ``max_concurrent`` holders of ``key`` run at once across this
        executor's workers. Default: a :class:`RateLimit` (one machine)."""
        return RateLimit(max_concurrent, key=key)

    def close(self) -> None:
        """Release the workers. Safe to call twice."""

    def __enter__(self) -> "Executor":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"{type(self).__name__}(max_workers={self.max_workers})"


class SerialExecutor(Executor):
    """Runs every item in the calling process, one after the other (the reference executor)."""

    name: ClassVar[str] = "serial"
    in_process: ClassVar[bool] = True
    live_stderr: ClassVar[bool] = True

    def __init__(self, max_workers: int | None = None) -> None:
        if max_workers not in (None, 1):
            raise ExecutorError(f"executor 'serial' runs one item at a time; max_workers={max_workers!r} "
                                f"is not allowed (use 'local' for a process pool)")

    @property
    def max_workers(self) -> int:
        return 1

    def map(self, fn: Callable[[Any], Any], items: Iterable[Any], *, chunksize: int | None = None) -> list[Any]:
        items = list(items)
        chunk_bounds(len(items), 1, chunksize)  # validates chunksize like the others
        return assemble(self.name, len(items), [run_chunk(fn, 0, items)])


def _limit_worker_threads(threads: int | None) -> None:
    """Pool initializer: cap BLAS/OpenMP threads per worker so workers do not oversubscribe the cores."""
    if threads is None:
        return
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(threads)
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # optional; environment variables still apply to libraries loaded later
        return
    threadpool_limits(threads)


#: Seconds between two checks of the watcher thread that ends an orphaned worker.
PARENT_POLL_S = 0.2
#: Exit status of a worker that ended because the process that started it died.
ORPHAN_EXIT_STATUS = 75
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


def _exit_if_orphaned(expected_parent: int) -> None:
    if os.getppid() != expected_parent:  # re-parented (to init or a subreaper): the parent is gone
        os._exit(ORPHAN_EXIT_STATUS)


def _set_parent_death_signal(signum: int) -> bool:
    """Linux: ask the kernel to send ``signum`` to this process when its parent dies (``prctl``)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def die_with_parent(poll_s: float = PARENT_POLL_S) -> None:
    """Make this process end when its parent process dies, even by ``SIGKILL`` (call it in a child).

    Two mechanisms, both checking that the parent *process* is gone (the process was re-parented), so the
    end of one thread of the parent does not count:

    - Linux: ``prctl(PR_SET_PDEATHSIG, SIGHUP)`` with a handler that exits at once (an idle worker blocked
      on its task queue wakes up immediately);
    - everywhere: a daemon thread that checks ``os.getppid()`` every ``poll_s`` seconds.

    An orphaned process exits with :data:`ORPHAN_EXIT_STATUS` without running cleanup (its results have
    nobody to go to).
    """
    import signal

    parent = os.getppid()
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGHUP, lambda signum, frame: _exit_if_orphaned(parent))
        _set_parent_death_signal(signal.SIGHUP)

    def watch() -> None:
        while True:
            time.sleep(poll_s)
            _exit_if_orphaned(parent)

    threading.Thread(target=watch, name="gift-parent-watch", daemon=True).start()
    _exit_if_orphaned(parent)  # the parent may have died before the watch started


def _init_worker(threads: int | None) -> None:
    """Pool initializer: end with the parent process (:func:`die_with_parent`), cap BLAS/OpenMP threads."""
    die_with_parent()
    _limit_worker_threads(threads)


class LocalExecutor(Executor):
    """A process pool on this machine (``spawn`` start method, so it is safe with threads and Drake).

    ``max_workers``: processes (default ``os.cpu_count()``). ``threads_per_worker``: BLAS/OpenMP
    threads in each worker (default ``max(1, cpu_count // max_workers)``; ``0`` leaves them alone).
    The pool starts on the first :meth:`map` and is reused until :meth:`close`.

    Workers die with the process that started them (:func:`die_with_parent`): killing a sweep, even with
    ``kill -9``, leaves no worker running on (and calling the LM) in the background.
    """

    name: ClassVar[str] = "local"
    live_stderr: ClassVar[bool] = True  # spawned workers inherit the caller's stderr

    def __init__(self, max_workers: int | None = None, *, threads_per_worker: int | None = None,
                 start_method: str = "spawn") -> None:
        cpus = os.cpu_count() or 1
        if max_workers is None:
            max_workers = cpus
        if not isinstance(max_workers, int) or isinstance(max_workers, bool) or max_workers < 1:
            raise ExecutorError(f"executor 'local': max_workers must be a positive integer, got {max_workers!r}")
        if threads_per_worker is None:
            threads_per_worker = max(1, cpus // max_workers)
        if threads_per_worker < 0:
            raise ExecutorError(f"executor 'local': threads_per_worker must be >= 0, got {threads_per_worker!r}")
        if start_method not in ("spawn", "forkserver", "fork"):
            raise ExecutorError(f"executor 'local': start_method must be spawn, forkserver or fork, "
                                f"got {start_method!r}")
        self._max_workers = max_workers
        self.threads_per_worker = threads_per_worker or None
        self.start_method = start_method
        self._pool: ProcessPoolExecutor | None = None
        self._lock = threading.Lock()

    @property
    def max_workers(self) -> int:
        return self._max_workers

    def _get_pool(self) -> ProcessPoolExecutor:
        with self._lock:
            if self._pool is None:
                import multiprocessing

                self._pool = ProcessPoolExecutor(
                    max_workers=self._max_workers, mp_context=multiprocessing.get_context(self.start_method),
                    initializer=_init_worker, initargs=(self.threads_per_worker,))
            return self._pool

    def map(self, fn: Callable[[Any], Any], items: Iterable[Any], *, chunksize: int | None = None) -> list[Any]:
        items = list(items)
        bounds = chunk_bounds(len(items), self._max_workers, chunksize)
        if not items:
            return []
        check_picklable(self.name, fn)
        pool = self._get_pool()
        futures = [pool.submit(run_chunk, fn, a, items[a:b]) for a, b in bounds]
        outputs = []
        for (a, b), fut in zip(bounds, futures):
            try:
                outputs.append(fut.result())
            except Exception as e:  # a worker died or an item could not be pickled: whole chunk lost
                for f in futures:
                    f.cancel()
                self.close()
                raise ExecutorError(f"executor 'local': the chunk of items {a}..{b - 1} could not be run "
                                    f"({type(e).__name__}: {e}); the pool was shut down. Workers are spawned: a script that "
                                    f"uses the local executor must guard its top level with "
                                    f"`if __name__ == '__main__':`") from e
        return assemble(self.name, len(items), outputs)

    def close(self) -> None:
        with self._lock:
            pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)

    def __del__(self) -> None:  # best effort; call close() or use ``with``
        try:
            pool = self._pool
            if pool is not None:
                pool.shutdown(wait=False, cancel_futures=True)
        except Exception:  # noqa: BLE001
            pass


def get_executor(name_or_instance: str | Executor | None = None, **options: Any) -> Executor:
    """An executor by registered name (``serial``, ``local``, ``ray``, ...), default ``local``.

    An :class:`Executor` instance is returned as is (options are then not allowed).
    """
    if isinstance(name_or_instance, Executor):
        if options:
            raise ExecutorError(f"get_executor: options {sorted(options)} given together with an executor instance "
                                f"{name_or_instance!r}; configure the instance instead")
        return name_or_instance
    name = name_or_instance or DEFAULT_EXECUTOR
    if not isinstance(name, str):
        raise ExecutorError(f"get_executor: expected an executor name or instance, got {type(name).__name__}")
    from gift.plugins.manager import get_manager

    executor = get_manager().create("executor", name, **options)
    if not isinstance(executor, Executor):
        raise ExecutorError(f"executor {name!r} built a {type(executor).__name__}, not a gift Executor")
    return executor


@contextlib.contextmanager
def using_executor(executor: str | Executor | None, default: str = "serial") -> Iterator[Executor]:
    """``with using_executor(executor) as ex:`` for functions with an ``executor=`` argument.

    An :class:`Executor` instance is used as is and left open (its owner closes it); a registered name,
    or ``None`` for ``default``, is built here and closed when the block ends.
    """
    if isinstance(executor, Executor):
        yield executor
        return
    built = get_executor(executor or default)
    try:
        yield built
    finally:
        built.close()


# ------------------------------------------------------------------ CLI helpers
def add_executor_argument(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Add ``--executor``, ``--workers`` and ``--ray-address`` to a sweep command's parser."""
    group = parser.add_argument_group("execution")
    group.add_argument("--executor", default=DEFAULT_EXECUTOR, metavar="NAME",
                       help="where the sweep runs: serial, local (process pool, default), ray (gift-executor-ray) "
                            "or any executor a plugin registers")
    group.add_argument("--workers", type=int, default=None, metavar="N",
                       help="parallel workers (local: processes, default all cores; ray: CPUs of a local Ray "
                            "instance / tasks in flight)")
    group.add_argument("--ray-address", default=None, metavar="ADDR",
                       help="with --executor ray: the cluster to join ('auto', 'ray://head:10001', "
                            "'head:6379'); without it a local Ray instance is started")
    return parser


def executor_from_args(args: argparse.Namespace) -> Executor:
    """Build the executor chosen by :func:`add_executor_argument`'s options."""
    name = getattr(args, "executor", None) or DEFAULT_EXECUTOR
    options: dict[str, Any] = {}
    workers = getattr(args, "workers", None)
    if workers is not None:
        if workers < 1:
            raise ExecutorError(f"--workers must be >= 1, got {workers}")
        if name != "serial":
            options["max_workers"] = workers
    address = getattr(args, "ray_address", None)
    if address:
        if name != "ray":
            raise ExecutorError(f"--ray-address {address!r} needs --executor ray (got --executor {name})")
        options["address"] = address
    return get_executor(name, **options)


# ------------------------------------------------------------------ concurrency limits
class ConcurrencyLimit(abc.ABC):
    """At most ``max_concurrent`` holders at once. Use ``with limit: ...`` (do not nest the same limit)."""

    max_concurrent: int
    key: str

    @abc.abstractmethod
    def acquire(self, timeout: float | None = None) -> Any:
        """Block until a slot is free; return a token for :meth:`release`. Raises ``TimeoutError``."""

    @abc.abstractmethod
    def release(self, token: Any) -> None:
        """Give the slot back."""

    def _held(self) -> list:
        local = self.__dict__.get("_local")
        if local is None:
            local = self.__dict__["_local"] = threading.local()
        if not hasattr(local, "tokens"):
            local.tokens = []
        return local.tokens

    def __enter__(self) -> "ConcurrencyLimit":
        self._held().append(self.acquire())
        return self

    def __exit__(self, *exc: Any) -> None:
        self.release(self._held().pop())

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_local", None)
        return state


def default_lock_directory() -> str:
    """``$GIFT_LOCK_DIR``, else ``<tmp>/gift-locks-<uid>`` (one machine)."""
    user = os.getuid() if hasattr(os, "getuid") else os.environ.get("USERNAME", "user")
    return os.environ.get("GIFT_LOCK_DIR") or os.path.join(tempfile.gettempdir(), f"gift-locks-{user}")


class RateLimit(ConcurrencyLimit):
    """Cross-process concurrency limit: ``max_concurrent`` slot files locked with ``flock``.

    Every process (or thread) that uses the same ``key`` and ``directory`` shares the limit; pickling
    keeps only the configuration, so a limit can be sent to workers. ``directory`` on a shared file
    system that supports ``flock`` extends it across machines. A slot held by a process that dies is
    released by the kernel. ``poll``: seconds between attempts while every slot is busy.
    """

    def __init__(self, max_concurrent: int, *, key: str = "default", directory: str | None = None,
                 poll: float = 0.002) -> None:
        if not isinstance(max_concurrent, int) or isinstance(max_concurrent, bool) or max_concurrent < 1:
            raise ValidationError(f"RateLimit: max_concurrent must be a positive integer, got {max_concurrent!r}")
        if not isinstance(key, str) or not key:
            raise ValidationError(f"RateLimit: key must be a non-empty string, got {key!r}")
        self.max_concurrent, self.key, self.poll = max_concurrent, key, float(poll)
        self.directory = directory or default_lock_directory()

    def _slot_path(self, slot: int) -> str:
        digest = hashlib.sha1(self.key.encode()).hexdigest()[:16]
        return os.path.join(self.directory, f"{digest}.{slot}.lock")

    def acquire(self, timeout: float | None = None) -> int:
        import fcntl  # POSIX only; imported here so the core still imports elsewhere

        os.makedirs(self.directory, exist_ok=True)
        deadline = None if timeout is None else time.monotonic() + timeout
        first = os.getpid() % self.max_concurrent  # spread processes over slots (does not affect results)
        delay = self.poll
        while True:
            for k in range(self.max_concurrent):
                fd = os.open(self._slot_path((first + k) % self.max_concurrent), os.O_RDWR | os.O_CREAT, 0o666)
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    return fd
                except OSError as e:
                    os.close(fd)
                    if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                        raise
            if deadline is not None and time.monotonic() >= deadline:
                raise TimeoutError(f"RateLimit {self.key!r}: no free slot of {self.max_concurrent} "
                                   f"within {timeout} s (lock files in {self.directory})")
            time.sleep(delay)
            delay = min(delay * 1.5, 20 * self.poll)

    def release(self, token: int) -> None:
        import fcntl

        try:
            fcntl.flock(token, fcntl.LOCK_UN)
        finally:
            os.close(token)

    def __repr__(self) -> str:
        return f"RateLimit(max_concurrent={self.max_concurrent}, key={self.key!r}, directory={self.directory!r})"


@contextlib.contextmanager
def limited(limit: ConcurrencyLimit | None) -> Iterator[None]:
    """``with limited(limit_or_None):`` - hold a slot when a limit is given, do nothing otherwise."""
    if limit is None:
        yield
    else:
        with limit:
            yield


__all__ = [
    "DEFAULT_EXECUTOR", "ConcurrencyLimit", "ExecutionError", "Executor", "ExecutorError", "ItemFailure",
    "LocalExecutor", "RateLimit", "SerialExecutor", "add_executor_argument", "assemble",
    "check_picklable", "chunk_bounds", "default_lock_directory", "die_with_parent", "executor_from_args",
    "get_executor", "item_seeds", "limited", "run_chunk", "using_executor",
]
