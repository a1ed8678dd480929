"""Persistent LM cache (an SQLite file, or a Redis server), as a wrapper around any backend.

Key: SHA-256 of the backend identity (name and model), the messages and every sampling parameter
(temperature, seed, max_tokens, stop, json_schema) — seeded samples are distinct entries. Both
:meth:`complete` and :meth:`choice_probabilities` are cached.

Where entries live is decided by :func:`open_store`: by default the SQLite file
``$GIFT_CACHE_DIR/lm/lm-cache.sqlite`` (default root: the user cache directory), which uses WAL journaling
and a busy timeout so several processes can share it, and commits every entry at once so a killed run
keeps what it computed; with ``GIFT_LM_CACHE_URL=redis://host:port/db`` (or ``url=``) a Redis server
(:class:`gift_llm.redis_store.RedisStore`). ``GIFT_LM_CACHE=off`` (or ``enabled=False``) bypasses the
cache; statistics are still kept.

Single-flight: when several threads or processes miss the same key at once, one calls the model and the
others wait for its answer (a per-key ``flock`` next to the SQLite file, a ``SET NX PX`` lock in Redis).

A damaged SQLite file (``file is not a database``, ``database disk image is malformed``) does not stop a
run: the file (with its ``-wal``/``-shm`` companions) is moved aside to ``<file>.corrupt-<time>``, a warning
names both paths, and an empty cache takes its place; the old file is kept for inspection. ``gift lm
cache-stats --repair`` runs SQLite's full integrity check and does the same when it fails.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import logging
import os
import sqlite3
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import attrs

from gift.core.data import Completion, Message, Usage
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift.core.redaction import redact_text
from gift_llm.paths import lm_cache_path, lm_cache_url
from gift_llm.requests import choices_request, complete_request, request_key
from gift_llm.usage import MeteredLM

if TYPE_CHECKING:
    from gift_llm.redis_store import RedisStore

log = logging.getLogger(__name__)
_OFF = {"0", "off", "false", "no", "disabled"}
_SCHEMA = """
CREATE TABLE IF NOT EXISTS entries (
    key TEXT PRIMARY KEY,
    kind TEXT NOT NULL,
    identity TEXT NOT NULL,
    request TEXT NOT NULL,
    response TEXT NOT NULL,
    created REAL NOT NULL
)
"""


def cache_enabled_by_env() -> bool:
    return os.environ.get("GIFT_LM_CACHE", "on").strip().lower() not in _OFF


def store_spec(path: str | Path | None = None, url: str | None = None) -> tuple[str, str]:
    """Which store :func:`open_store` opens: ``("redis", url)`` or ``("sqlite", path)``.

    Order: ``url``, then ``path``, then ``$GIFT_LM_CACHE_URL``, then the default SQLite file.
    """
    if url:
        return "redis", str(url)
    if path:
        return "sqlite", str(Path(path).expanduser())
    env_url = lm_cache_url()
    return ("redis", env_url) if env_url else ("sqlite", str(lm_cache_path()))


def open_store(path: str | Path | None = None, url: str | None = None) -> SQLiteStore | RedisStore:
    """The LM cache store: Redis when a URL is given or configured (:func:`store_spec`), else SQLite."""
    kind, where = store_spec(path, url)
    if kind == "redis":
        from gift_llm.redis_store import RedisStore

        return RedisStore(where)
    return SQLiteStore(where)


class SQLiteStore:
    """The SQLite file: one connection per thread and process, safe to share between processes.

    Single-flight locks are files ``<key>.lock`` locked with ``flock`` in ``lock_dir`` (default: the
    directory ``<file>.locks`` next to the database, or a subdirectory of ``$GIFT_LOCK_DIR`` when set);
    the kernel frees the lock of a process that dies. A waiter that did not get the lock within
    ``lock_timeout_s`` calls the model itself.
    """

    kind = "sqlite"

    def __init__(self, path: str | Path | None = None, timeout_s: float = 60.0, *,
                 lock_dir: str | Path | None = None, lock_timeout_s: float = 600.0):
        self.path = Path(path).expanduser() if path else lm_cache_path()
        self.location = str(self.path)
        self.timeout_s = timeout_s
        self.lock_timeout_s = float(lock_timeout_s)
        self.lock_dir = Path(lock_dir) if lock_dir else _default_lock_dir(self.path)
        self._local = threading.local()
        self._generation = 0
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise LMError(f"LM cache: cannot create the directory {self.path.parent}: {e}") from e

    def _conn(self) -> sqlite3.Connection:
        conn = getattr(self._local, "conn", None)
        if (conn is None or getattr(self._local, "pid", None) != os.getpid()
                or getattr(self._local, "generation", None) != self._generation):
            conn = self._open()
            self._local.conn, self._local.pid, self._local.generation = conn, os.getpid(), self._generation
        return conn

    def _open(self) -> sqlite3.Connection:
        # Switching a new file to WAL can fail with "database is locked" without waiting for the busy
        # timeout when several connections open it at the same moment: retry until ``timeout_s``.
        deadline, delay, recovered = time.monotonic() + self.timeout_s, 0.005, False
        while True:
            conn = None
            try:
                conn = sqlite3.connect(self.path, timeout=self.timeout_s, isolation_level=None)
                conn.execute("PRAGMA journal_mode=WAL")
                conn.execute("PRAGMA synchronous=NORMAL")
                conn.execute(_SCHEMA)
                return conn
            except sqlite3.Error as e:
                if conn is not None:
                    conn.close()
                if _is_damaged(e) and not recovered:
                    self._recover(e)
                    recovered = True
                    continue
                if not (isinstance(e, sqlite3.OperationalError) and "locked" in str(e)
                        and time.monotonic() < deadline):
                    raise LMError(f"LM cache: cannot open {self.path}: {e}{self._advice(e)}") from e
            time.sleep(delay)
            delay = min(delay * 2, 0.1)

    def _execute(self, what: str, fn: Callable[[sqlite3.Connection], Any]) -> Any:
        """``fn(connection)``; a damaged file is moved aside once (:meth:`_recover`) and ``fn`` retried."""
        for attempt in (0, 1):
            try:
                return fn(self._conn())
            except sqlite3.Error as e:
                if attempt == 0 and _is_damaged(e):
                    self._recover(e)
                    continue
                raise LMError(f"LM cache: {what} {self.path} failed: {e}{self._advice(e)}") from e

    def _advice(self, error: sqlite3.Error) -> str:
        if not _is_damaged(error):
            return ""
        return (f". The file is damaged: move it aside (mv {self.path} {self.path}.bad) or run `gift lm cache-stats "
                f"--repair`; gift then starts an empty cache")

    # ------------------------------------------------------------------ damaged files
    def integrity_problem(self, full: bool = True) -> str | None:
        """What SQLite's ``integrity_check`` (``quick_check`` unless ``full``) finds wrong with the file, or None."""
        if not self.path.exists():
            return None
        conn = None
        try:
            conn = sqlite3.connect(self.path, timeout=self.timeout_s, isolation_level=None)
            rows = conn.execute(f"PRAGMA {'integrity_check' if full else 'quick_check'}(5)").fetchall()
            return "; ".join(r[0] for r in rows if r[0] != "ok") or None
        except sqlite3.Error as e:
            return str(e)
        finally:
            if conn is not None:
                conn.close()

    def move_aside(self, reason: str = "") -> Path:
        """Rename the file (and its ``-wal``/``-shm``) to ``<file>.corrupt-<time>``; the next use starts empty."""
        stamp = time.strftime("%Y%m%d-%H%M%S")
        aside = self.path.with_name(f"{self.path.name}.corrupt-{stamp}")
        k = 1
        while aside.exists():
            aside = self.path.with_name(f"{self.path.name}.corrupt-{stamp}-{k}")
            k += 1
        try:
            for suffix in ("", "-wal", "-shm"):
                src = Path(str(self.path) + suffix)
                if src.exists():
                    os.replace(src, Path(str(aside) + suffix))
        except OSError as e:
            raise LMError(f"LM cache: {self.path} is damaged ({reason or 'integrity check failed'}) and cannot be "
                          f"moved aside ({e}): move it away by hand (mv {self.path} {aside}) or point "
                          f"GIFT_CACHE_DIR elsewhere; gift then starts an empty cache") from e
        self._generation += 1  # every thread of this process reconnects to the new file
        warnings.warn(f"LM cache: {self.path} is damaged ({reason or 'integrity check failed'}); moved it to {aside} "
                      f"and started an empty cache there. The old file is kept: delete it when you do not need it",
                      RuntimeWarning, stacklevel=3)
        return aside

    def repair(self) -> dict[str, Any]:
        """Full integrity check; a damaged file is moved aside (:meth:`move_aside`). ``{"problem", "moved_to"}``."""
        with self._repair_lock():
            problem = self.integrity_problem(full=True)
            moved = self.move_aside(problem) if problem else None
        return {"problem": problem, "moved_to": str(moved) if moved else None}

    def _recover(self, error: sqlite3.Error) -> None:
        """The file failed with ``error``: move it aside unless another thread or process already did."""
        conn, self._local.conn = getattr(self._local, "conn", None), None
        if conn is not None:
            with contextlib.suppress(sqlite3.Error):
                conn.close()
        with self._repair_lock():
            problem = self.integrity_problem(full=False)
            if problem is None:
                return  # already replaced by a healthy (or no) file
            self.move_aside(problem)

    @contextlib.contextmanager
    def _repair_lock(self) -> Iterator[None]:
        path = self.lock_dir / "repair.lock"
        fd = _flock(path, self.timeout_s)
        try:
            yield
        finally:
            if fd is not None:
                _unflock(path, fd)

    # ------------------------------------------------------------------ entries
    def get(self, key: str) -> Any | None:
        row = self._execute("read from", lambda c: c.execute("SELECT response FROM entries WHERE key = ?",
                                                             (key,)).fetchone())
        return None if row is None else json.loads(row[0])

    def put(self, key: str, kind: str, identity: str, request: Mapping[str, Any], response: Any) -> None:
        row = (key, kind, identity, json.dumps(request, ensure_ascii=False), json.dumps(response), time.time())
        self._execute("write to", lambda c: c.execute(
            "INSERT OR REPLACE INTO entries (key, kind, identity, request, response, created) "
            "VALUES (?, ?, ?, ?, ?, ?)", row))

    def count(self) -> int:
        return int(self._execute("read from", lambda c: c.execute("SELECT COUNT(*) FROM entries").fetchone()[0]))

    def summary(self) -> dict[str, Any]:
        rows = self._execute("read from", lambda c: c.execute(
            "SELECT identity, kind, COUNT(*) FROM entries GROUP BY identity, kind").fetchall())
        size = self.path.stat().st_size if self.path.exists() else 0
        return {"path": str(self.path), "store": self.kind, "entries": sum(r[2] for r in rows), "bytes": size,
                "by_model": [{"identity": redact_text(r[0]), "kind": r[1], "entries": r[2]} for r in sorted(rows)]}

    def clear(self, identity: str | None = None) -> int:
        return self._execute("delete from", lambda c: (
            c.execute("DELETE FROM entries WHERE identity = ?", (identity,)) if identity
            else c.execute("DELETE FROM entries")).rowcount)

    @contextlib.contextmanager
    def lock(self, key: str) -> Iterator[bool]:
        """Single-flight for ``key``: an exclusive ``flock``; yields False if not taken in time."""
        name = key if key.isalnum() and len(key) <= 128 else hashlib.sha256(key.encode()).hexdigest()
        path = self.lock_dir / f"{name}.lock"
        fd = _flock(path, self.lock_timeout_s)
        if fd is None:
            warnings.warn(f"LM cache: waited {self.lock_timeout_s:g} s for another process to answer {key[:16]}… "
                          f"(lock file {path}); calling the model without the lock", RuntimeWarning, stacklevel=3)
        try:
            yield fd is not None
        finally:
            if fd is not None:
                _unflock(path, fd)

    def __repr__(self) -> str:
        return f"SQLiteStore({self.location!r})"


CacheStore = SQLiteStore  # the name before the Redis store existed


#: SQLite result codes of a damaged file: SQLITE_CORRUPT, SQLITE_NOTADB.
_DAMAGED_CODES = (11, 26)


def _is_damaged(error: BaseException) -> bool:
    """True for SQLite's "file is not a database" and "database disk image is malformed" errors."""
    if not isinstance(error, sqlite3.DatabaseError):
        return False
    code = getattr(error, "sqlite_errorcode", None)
    if code is not None:
        return (code & 0xFF) in _DAMAGED_CODES
    text = str(error)
    return "not a database" in text or "malformed" in text


def _default_lock_dir(db: Path) -> Path:
    env = os.environ.get("GIFT_LOCK_DIR", "").strip()
    if env:  # one subdirectory per cache file: unrelated caches never wait for each other
        return Path(env) / f"lm-cache-{hashlib.sha1(str(db.resolve()).encode()).hexdigest()[:12]}"
    return db.with_name(db.name + ".locks")


def _flock(path: Path, timeout_s: float) -> int | None:
    """Open and ``flock`` ``path``; the file descriptor, or None after ``timeout_s``.

    The holder deletes the file on release, so a lock counts only if ``path`` still names the locked file.
    """
    import fcntl

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise LMError(f"LM cache: cannot create the lock directory {path.parent}: {e}") from e
    deadline, delay = time.monotonic() + timeout_s, 0.002
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as e:
            raise LMError(f"LM cache: cannot open the lock file {path}: {e}") from e
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            os.close(fd)
            if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise LMError(f"LM cache: cannot lock {path}: {e}") from e
            if time.monotonic() >= deadline:
                return None
            time.sleep(delay)
            delay = min(delay * 1.5, 0.05)
            continue
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)  # the previous holder deleted it after we opened it: try the current file


def _unflock(path: Path, fd: int) -> None:
    import fcntl

    try:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)
        fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)


#: Key under which a cached answer stores the build that made it (:meth:`CachedLM.build`); not an answer field.
MADE_BY = "_made_by"
#: How :attr:`gift_llm.usage.UsageStats.made_by` counts cached answers stored before builds were recorded.
UNRECORDED = "unrecorded"
_UNSET = object()


class CachedLM(MeteredLM):
    """An :class:`LMBackend` that answers repeated requests from the persistent cache.

    ``path`` (SQLite file) or ``url`` (``redis://host:port/db``) choose the store (:func:`open_store`).
    A miss takes the store's per-key lock and checks again before calling the model, so concurrent
    identical requests make one model call. ``.stats`` (:class:`gift_llm.usage.UsageStats`) counts hits
    (answers read from the store, also after waiting for another worker), misses, model calls, tokens,
    latency, cost.
    """

    name = "cached"

    def __init__(self, inner: LMBackend, path: str | Path | None = None, enabled: bool = True, *,
                 url: str | None = None):
        super().__init__(inner)
        self.enabled = bool(enabled) and cache_enabled_by_env()
        self.store = open_store(path, url) if self.enabled else None
        self._last = threading.local()
        self._build: str | None | object = _UNSET
        self._warned_build = False

    def build(self) -> str | None:
        """The build of the model runtime that makes this backend's fresh answers (the wrapped backend's
        ``build()``: for ``llamacpp`` the llama.cpp version and its CPU kernels), stored with each answer it
        caches; None when the backend has no such build (hosted models)."""
        if self._build is _UNSET:
            made_by = getattr(self.inner, "build", None)  # wrappers pass the lookup on to what they wrap
            try:
                self._build = (made_by() or None) if callable(made_by) else None
            except Exception:  # noqa: BLE001 - a backend that cannot describe its build records none
                self._build = None
        return self._build  # type: ignore[return-value]

    def _count_build(self, stored: Mapping[str, Any] | None) -> None:
        """Count one answer under the build that made it (:attr:`UsageStats.made_by`): the loaded build for a
        fresh answer (``stored`` None), else the build stored with the cached answer, ``"unrecorded"`` when the
        answer predates builds being stored. Warns once when cached answers come from another build."""
        now = self.build()
        made = now if stored is None else stored.get(MADE_BY)
        if made is None and now is None:
            return
        self.stats.add_made_by(made or UNRECORDED)
        if stored is not None and made != now and not self._warned_build:
            self._warned_build = True
            log.warning("LM answers read from the cache were made by another build of the model runtime (%s) than "
                        "the one loaded (%s); the results' manifest counts answers per build (lm.usage.made_by)",
                        made or UNRECORDED, now or "none recorded")

    def last_hit(self) -> bool | None:
        """Whether this thread's last request was answered from the cache (None: none yet, or cache off)."""
        return getattr(self._last, "hit", None) if self.store is not None else None

    def _lookup(self, key: str, kind: str, identity: str, request: Mapping[str, Any], call: Callable[[], Any],
                encode: Callable[[Any], Any]) -> tuple[Any, Any]:
        """``(stored JSON, None)`` on a hit, ``(None, fresh answer)`` after this worker's model call."""
        hit = self.store.get(key)
        if hit is None:
            with self.store.lock(key):
                hit = self.store.get(key)  # another worker may have answered while this one waited
                if hit is None:
                    self.stats.add_request(hit=False)
                    self._last.hit = False
                    out = call()
                    payload = encode(out)
                    if self.build() is not None:
                        payload = {**payload, MADE_BY: self.build()}
                    self.store.put(key, kind, identity, request, payload)
                    self._count_build(None)
                    return None, out
        self.stats.add_request(hit=True)
        self._last.hit = True
        self._count_build(hit if isinstance(hit, Mapping) else {})
        return hit, None

    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        kw = dict(temperature=temperature, seed=seed, max_tokens=max_tokens, stop=stop, json_schema=json_schema)
        if self.store is None:
            return super().complete(messages, **kw)
        identity = self.identity()
        req = complete_request(messages, **kw)
        key = request_key(identity, req)
        t0 = time.perf_counter()
        hit, out = self._lookup(key, "complete", identity, req, lambda: self._call_complete(messages, **kw),
                                completion_to_json)
        if hit is None:
            return out
        c = completion_from_json(hit, cached=True)
        return attrs.evolve(c, usage=attrs.evolve(c.usage, latency_s=time.perf_counter() - t0, cost_usd=0.0))

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        if self.store is None:
            return super().choice_probabilities(messages, choices)
        identity = self.identity()
        req = choices_request(messages, choices)
        key = request_key(identity, req)
        hit, out = self._lookup(key, "choices", identity, req, lambda: self._call_choices(messages, choices), dict)
        return out if hit is None else {c: float(hit[c]) for c in choices}


def completion_to_json(c: Completion) -> dict[str, Any]:
    u = c.usage
    return {"text": c.text, "model": c.model,
            "usage": {"prompt_tokens": u.prompt_tokens, "completion_tokens": u.completion_tokens,
                      "latency_s": u.latency_s, "cost_usd": u.cost_usd}}


def completion_from_json(d: Mapping[str, Any], *, cached: bool = False) -> Completion:
    u = d.get("usage") or {}
    return Completion(d["text"], Usage(prompt_tokens=int(u.get("prompt_tokens", 0)),
                                       completion_tokens=int(u.get("completion_tokens", 0)),
                                       latency_s=float(u.get("latency_s", 0.0)), cost_usd=u.get("cost_usd"),
                                       cached=cached), model=d.get("model", ""))
