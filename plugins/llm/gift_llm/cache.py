"""Persistent LM cache in SQLite, as a wrapper around any backend.

Key: SHA-256 of the backend identity (name and model), the messages and every sampling parameter
(temperature, seed, max_tokens, stop, json_schema) — seeded samples are distinct entries. Both
:meth:`complete` and :meth:`choice_probabilities` are cached. The database lives at
``$GIFT_CACHE_DIR/lm/lm-cache.sqlite`` (default root: the user cache directory), uses WAL journaling and a
busy timeout so several processes can share it, and commits every entry at once so a killed run keeps
what it computed. ``GIFT_LM_CACHE=off`` (or ``enabled=False``) bypasses it; statistics are still kept.
"""

from __future__ import annotations

import json
import os
import sqlite3
import threading
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import attrs

from gift.core.data import Completion, Message, Usage
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.paths import lm_cache_path
from gift_llm.requests import choices_request, complete_request, request_key
from gift_llm.usage import MeteredLM

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


class CacheStore:
    """The SQLite file: one connection per thread and process, safe to share between processes."""

    def __init__(self, path: str | Path | None = None, timeout_s: float = 60.0):
        self.path = Path(path).expanduser() if path else lm_cache_path()
        self.timeout_s = timeout_s
        self._local = threading.local()
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise LMError(f"LM cache: cannot create the directory {self.path.parent}: {e}") from e

    def _conn(self) -> sqlite3.Connection:
        conn = getattr(self._local, "conn", None)
        if conn is None or getattr(self._local, "pid", None) != os.getpid():
            try:
                conn = sqlite3.connect(self.path, timeout=self.timeout_s, isolation_level=None)
                conn.execute("PRAGMA journal_mode=WAL")
                conn.execute("PRAGMA synchronous=NORMAL")
                conn.execute(_SCHEMA)
            except sqlite3.Error as e:
                raise LMError(f"LM cache: cannot open {self.path}: {e}") from e
            self._local.conn, self._local.pid = conn, os.getpid()
        return conn

    def get(self, key: str) -> Any | None:
        try:
            row = self._conn().execute("SELECT response FROM entries WHERE key = ?", (key,)).fetchone()
        except sqlite3.Error as e:
            raise LMError(f"LM cache: read from {self.path} failed: {e}") from e
        return None if row is None else json.loads(row[0])

    def put(self, key: str, kind: str, identity: str, request: Mapping[str, Any], response: Any) -> None:
        try:
            self._conn().execute(
                "INSERT OR REPLACE INTO entries (key, kind, identity, request, response, created) "
                "VALUES (?, ?, ?, ?, ?, ?)",
                (key, kind, identity, json.dumps(request, ensure_ascii=False), json.dumps(response), time.time()))
        except sqlite3.Error as e:
            raise LMError(f"LM cache: write to {self.path} failed: {e}") from e

    def count(self) -> int:
        return int(self._conn().execute("SELECT COUNT(*) FROM entries").fetchone()[0])

    def summary(self) -> dict[str, Any]:
        rows = self._conn().execute("SELECT identity, kind, COUNT(*) FROM entries GROUP BY identity, kind").fetchall()
        size = self.path.stat().st_size if self.path.exists() else 0
        return {"path": str(self.path), "entries": sum(r[2] for r in rows), "bytes": size,
                "by_model": [{"identity": r[0], "kind": r[1], "entries": r[2]} for r in rows]}

    def clear(self, identity: str | None = None) -> int:
        conn = self._conn()
        cur = (conn.execute("DELETE FROM entries WHERE identity = ?", (identity,)) if identity
               else conn.execute("DELETE FROM entries"))
        return cur.rowcount


class CachedLM(MeteredLM):
    """An :class:`LMBackend` that answers repeated requests from the persistent cache.

    ``.stats`` (:class:`gift_llm.usage.UsageStats`) counts hits, misses, model calls, tokens, latency, cost.
    """

    name = "cached"

    def __init__(self, inner: LMBackend, path: str | Path | None = None, enabled: bool = True):
        super().__init__(inner)
        self.enabled = bool(enabled) and cache_enabled_by_env()
        self.store = CacheStore(path) if self.enabled else None

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
        hit = self.store.get(key)
        if hit is not None:
            self.stats.add_request(hit=True)
            c = completion_from_json(hit, cached=True)
            return attrs.evolve(c, usage=attrs.evolve(c.usage, latency_s=time.perf_counter() - t0, cost_usd=0.0))
        self.stats.add_request(hit=False)
        out = self._call_complete(messages, **kw)
        self.store.put(key, "complete", identity, req, completion_to_json(out))
        return out

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        if self.store is None:
            return super().choice_probabilities(messages, choices)
        identity = self.identity()
        req = choices_request(messages, choices)
        key = request_key(identity, req)
        hit = self.store.get(key)
        if hit is not None:
            self.stats.add_request(hit=True)
            return {c: float(hit[c]) for c in choices}
        self.stats.add_request(hit=False)
        out = self._call_choices(messages, choices)
        self.store.put(key, "choices", identity, req, out)
        return out


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
