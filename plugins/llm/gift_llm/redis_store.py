"""The LM cache on a Redis server, for studies whose workers run on several machines.

Chosen by ``GIFT_LM_CACHE_URL=redis://host:port/db`` or ``CachedLM(inner, url=...)`` (see
:func:`gift_llm.cache.open_store`). Same keys and JSON values as the SQLite file: entry ``<key>`` is the
hash ``gift:lm:entry:<key>`` with the fields ``kind``, ``identity``, ``request``, ``response`` (JSON) and
``created``. Single-flight locks are ``gift:lm:lock:<key>``, taken with ``SET NX PX``: they expire after
``lock_timeout_s``, so a worker that dies while holding one blocks the others at most that long.
Needs the ``redis`` package (``pip install 'gift-llm[redis]'``).
"""

from __future__ import annotations

import contextlib
import json
import os
import time
import uuid
import warnings
from collections.abc import Iterator, Mapping
from typing import Any
from urllib.parse import urlsplit

from gift.core.errors import LMError
from gift.core.redaction import redact_url

_SCHEMES = ("redis", "rediss", "unix")
# Delete the lock only if it is still ours (it may have expired and been taken by another worker).
_RELEASE = "if redis.call('get', KEYS[1]) == ARGV[1] then return redis.call('del', KEYS[1]) else return 0 end"
_BATCH = 500


class RedisStore:
    """LM cache entries in Redis; thread-safe, shared by every process that uses the same URL.

    ``namespace`` prefixes every key (several caches can share one database). ``lock_timeout_s`` is the
    expiry of a single-flight lock and the longest a worker waits for another one's answer (then it calls
    the model itself). The server is pinged on construction, so a wrong URL fails at once.
    """

    kind = "redis"

    def __init__(self, url: str, *, namespace: str = "gift:lm", lock_timeout_s: float = 600.0,
                 connect_timeout_s: float = 5.0):
        self.url = str(url)
        self.location = redact_url(self.url)
        if urlsplit(self.url).scheme not in _SCHEMES:
            raise LMError(f"LM cache: unsupported cache URL {self.location!r}: expected redis://host:port/db "
                          f"(or rediss://, unix://)")
        try:
            import redis
        except ImportError as e:
            raise LMError(f"LM cache: the cache URL {self.location} needs the Python package 'redis': "
                          f"pip install 'gift-llm[redis]' (or pip install redis)") from e
        self._errors = redis.exceptions.RedisError
        self.namespace = namespace
        self.lock_timeout_s = float(lock_timeout_s)
        try:
            self._r = redis.Redis.from_url(self.url, decode_responses=True, socket_connect_timeout=connect_timeout_s,
                                           socket_timeout=max(30.0, connect_timeout_s))
        except ValueError as e:
            raise LMError(f"LM cache: bad cache URL {self.location!r}: {e}") from e
        self._release = self._r.register_script(_RELEASE)
        with self._failing("connect (PING)"):
            self._r.ping()

    @contextlib.contextmanager
    def _failing(self, what: str) -> Iterator[None]:
        try:
            yield
        except self._errors as e:
            raise LMError(f"LM cache: Redis at {self.location}: {what} failed: {e} (is the server running, and is "
                          f"the URL in GIFT_LM_CACHE_URL or url= right? Without a URL the SQLite file is used)") from e

    def _entry(self, key: str) -> str:
        return f"{self.namespace}:entry:{key}"

    def get(self, key: str) -> Any | None:
        with self._failing("read"):
            raw = self._r.hget(self._entry(key), "response")
        return None if raw is None else json.loads(raw)

    def put(self, key: str, kind: str, identity: str, request: Mapping[str, Any], response: Any) -> None:
        fields = {"kind": kind, "identity": identity, "request": json.dumps(request, ensure_ascii=False),
                  "response": json.dumps(response), "created": repr(time.time())}
        with self._failing("write"):
            self._r.hset(self._entry(key), mapping=fields)

    def _batches(self) -> Iterator[list[str]]:
        batch: list[str] = []
        for name in self._r.scan_iter(match=self._entry("*"), count=1000):
            batch.append(name)
            if len(batch) >= _BATCH:
                yield batch
                batch = []
        if batch:
            yield batch

    def count(self) -> int:
        with self._failing("count"):
            return sum(len(b) for b in self._batches())

    def summary(self) -> dict[str, Any]:
        groups: dict[tuple[str, str], int] = {}
        size = 0
        with self._failing("summary"):
            for batch in self._batches():
                pipe = self._r.pipeline(transaction=False)
                for name in batch:
                    pipe.hmget(name, "identity", "kind")
                    pipe.memory_usage(name)
                out = pipe.execute()
                for (identity, kind), nbytes in zip(out[0::2], out[1::2]):
                    if identity is not None:  # deleted between SCAN and HMGET
                        groups[identity, kind] = groups.get((identity, kind), 0) + 1
                        size += int(nbytes or 0)
        return {"path": self.location, "store": self.kind, "entries": sum(groups.values()), "bytes": size,
                "by_model": [{"identity": i, "kind": k, "entries": n} for (i, k), n in sorted(groups.items())]}

    def clear(self, identity: str | None = None) -> int:
        removed = 0
        with self._failing("clear"):
            for batch in self._batches():
                if identity:
                    pipe = self._r.pipeline(transaction=False)
                    for name in batch:
                        pipe.hget(name, "identity")
                    batch = [n for n, i in zip(batch, pipe.execute()) if i == identity]
                if batch:
                    removed += int(self._r.delete(*batch))
        return removed

    @contextlib.contextmanager
    def lock(self, key: str) -> Iterator[bool]:
        """Single-flight for ``key``: ``SET <lock> <token> NX PX``; yields False if not taken in time."""
        name, token = f"{self.namespace}:lock:{key}", f"{os.getpid()}:{uuid.uuid4().hex}"
        held = self._acquire(name, token)
        if not held:
            warnings.warn(f"LM cache: waited {self.lock_timeout_s:g} s for another worker to answer {key[:16]}… "
                          f"(lock {name} at {self.location}); calling the model without the lock",
                          RuntimeWarning, stacklevel=3)
        try:
            yield held
        finally:
            if held:
                with self._failing("unlock"):
                    self._release(keys=[name], args=[token])

    def _acquire(self, name: str, token: str) -> bool:
        ttl_ms = max(1, int(self.lock_timeout_s * 1000))
        deadline, delay = time.monotonic() + self.lock_timeout_s, 0.005
        with self._failing("lock"):
            while not self._r.set(name, token, nx=True, px=ttl_ms):
                if time.monotonic() >= deadline:
                    return False
                time.sleep(delay)
                delay = min(delay * 1.5, 0.1)
        return True

    def __repr__(self) -> str:
        return f"RedisStore({self.location!r}, namespace={self.namespace!r})"
