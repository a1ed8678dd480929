"""The LM cache on a real Redis server (``redis-server`` started per test by the ``redis_url`` fixture).

Same keys and JSON values as the SQLite file, the same store API, the ``gift lm cache-stats`` command on it,
sharing between processes, and clear errors for a dead server or a missing client package.
"""

from __future__ import annotations

import json
import multiprocessing as mp
import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from gift.core.data import Completion, Usage, as_messages
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.cache import CachedLM, SQLiteStore, open_store, store_spec
from gift_llm.redis_store import RedisStore
from gift_llm.requests import complete_request, request_key

from redis_server import free_port, running_redis

MSG = [{"role": "user", "content": "hello"}]
GIFT = str(Path(sys.executable).with_name("gift"))


class CountingLM(LMBackend):
    """Test double: answers ``"<last message> -> pid <pid>"`` and counts its calls."""

    name = "counting"
    supports_choice_probabilities = True

    def __init__(self, model: str = "double"):
        self.model = model
        self.calls = 0

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self.calls += 1
        text = f"{as_messages(messages)[-1].content} -> pid {os.getpid()}"
        return Completion(text, Usage(prompt_tokens=3, completion_tokens=2, latency_s=0.01, cost_usd=0.001),
                          model=self.identity())

    def choice_probabilities(self, messages, choices):
        self.calls += 1
        return {c: (i + 1) / sum(range(1, len(choices) + 1)) for i, c in enumerate(choices)}


@pytest.fixture(autouse=True)
def _no_cache_settings(monkeypatch):
    for var in ("GIFT_LM_CACHE_URL", "GIFT_LM_CACHE", "GIFT_LOCK_DIR"):
        monkeypatch.delenv(var, raising=False)


def _dead_url() -> str:
    return f"redis://127.0.0.1:{free_port()}/0"  # nobody listens there


def _entries():
    """(key, kind, identity, request, response) for two backends and both kinds of request."""
    out = []
    for identity in ("counting:a", "counting:b"):
        for i in range(3):
            req = complete_request([{"role": "user", "content": f"q{i} ✓"}], temperature=0.0, seed=i,
                                   max_tokens=8, stop=None, json_schema=None)
            resp = {"text": f"answer {i} é", "model": identity,
                    "usage": {"prompt_tokens": 1, "completion_tokens": 2, "latency_s": 0.5, "cost_usd": None}}
            out.append((request_key(identity, req), "complete", identity, req, resp))
        req = {"kind": "choices", "messages": [{"role": "user", "content": "y/n?"}], "choices": ["y", "n"]}
        out.append((request_key(identity, req), "choices", identity, req, {"y": 0.25, "n": 0.75}))
    return out


def test_put_get_count_summary_clear_match_the_sqlite_store(redis_url, tmp_path):
    redis_store, sqlite_store = RedisStore(redis_url), SQLiteStore(tmp_path / "c.sqlite")
    entries = _entries()
    for store in (redis_store, sqlite_store):
        assert store.count() == 0 and store.get(entries[0][0]) is None
        for e in entries:
            store.put(*e)
        store.put(*entries[0])  # replacing an entry does not add one
    assert redis_store.count() == sqlite_store.count() == len(entries)
    for key, _, _, _, response in entries:
        assert redis_store.get(key) == sqlite_store.get(key) == response

    # the same JSON text in both stores, field for field
    import redis

    raw = redis.Redis.from_url(redis_url, decode_responses=True)
    rows = sqlite3.connect(tmp_path / "c.sqlite").execute("SELECT key, kind, identity, request, response FROM entries")
    for key, kind, identity, request, response in rows:
        h = raw.hgetall(f"gift:lm:entry:{key}")
        assert (h["kind"], h["identity"], h["request"], h["response"]) == (kind, identity, request, response)

    r_sum, s_sum = redis_store.summary(), sqlite_store.summary()
    assert r_sum["by_model"] == s_sum["by_model"] and r_sum["entries"] == s_sum["entries"] == len(entries)
    assert (r_sum["store"], r_sum["path"], s_sum["store"]) == ("redis", redis_url, "sqlite")
    assert r_sum["bytes"] > 0

    assert redis_store.clear("counting:a") == sqlite_store.clear("counting:a") == 4
    assert redis_store.count() == sqlite_store.count() == 4
    assert redis_store.get(entries[0][0]) is None and redis_store.get(entries[-1][0]) == {"y": 0.25, "n": 0.75}
    assert redis_store.clear() == sqlite_store.clear() == 4
    assert redis_store.count() == sqlite_store.count() == 0


def test_cached_lm_answers_the_second_call_from_redis(redis_url, tmp_path):
    inner = CountingLM()
    lm = CachedLM(inner, url=redis_url)
    assert isinstance(lm.store, RedisStore)
    a = lm.complete(MSG, max_tokens=20)
    b = lm.complete(MSG, max_tokens=20)
    assert a.text == b.text and not a.usage.cached and b.usage.cached and inner.calls == 1
    p1 = lm.choice_probabilities(MSG, ["yes", "no"])
    p2 = lm.choice_probabilities(MSG, ["yes", "no"])
    assert p1 == p2 and inner.calls == 2
    s = lm.stats
    assert (s.requests, s.hits, s.misses, s.calls) == (4, 2, 2, 2)

    fresh = CountingLM()  # a new run on the same server: no model call at all
    again = CachedLM(fresh, url=redis_url)
    assert again.complete(MSG, max_tokens=20).text == a.text and fresh.calls == 0
    assert not (tmp_path / "c.sqlite").exists()


def test_the_environment_selects_redis_and_an_explicit_choice_wins(redis_url, tmp_path, monkeypatch):
    monkeypatch.setenv("GIFT_CACHE_DIR", str(tmp_path / "root"))
    assert store_spec() == ("sqlite", str(tmp_path / "root" / "lm" / "lm-cache.sqlite"))
    monkeypatch.setenv("GIFT_LM_CACHE_URL", redis_url)
    assert isinstance(open_store(), RedisStore)
    assert isinstance(open_store(path=tmp_path / "x.sqlite"), SQLiteStore)  # an explicit path beats the env
    assert store_spec(path=tmp_path / "x.sqlite", url=redis_url) == ("redis", redis_url)

    from gift_llm.resolve import resolve_lm

    lm = resolve_lm(CountingLM())
    assert isinstance(lm.store, RedisStore) and lm.store.url == redis_url
    lm.complete(MSG)
    assert RedisStore(redis_url).count() == 1


def _ask_then_ask_the_other(store_args, mine, other, barrier, queue):
    """Worker: ask ``mine``, wait for the other worker to do the same, then ask ``other``."""
    lm = CachedLM(CountingLM(), **store_args)
    first = lm.complete([{"role": "user", "content": mine}]).text
    barrier.wait(timeout=60)
    second = lm.complete([{"role": "user", "content": other}])
    queue.put((mine, first, second.text, second.usage.cached, lm.inner.calls, os.getpid()))


@pytest.mark.parametrize("store", ["sqlite", "redis"])
def test_two_processes_get_each_others_answers(store, redis_url, tmp_path):
    store_args = {"url": redis_url} if store == "redis" else {"path": str(tmp_path / "c.sqlite")}
    ctx = mp.get_context("spawn")
    barrier, queue = ctx.Barrier(2), ctx.Queue()
    procs = [ctx.Process(target=_ask_then_ask_the_other, args=(store_args, q, o, barrier, queue))
             for q, o in (("question A", "question B"), ("question B", "question A"))]
    for p in procs:
        p.start()
    results = {r[0]: r for r in (queue.get(timeout=120) for _ in procs)}
    for p in procs:
        p.join(timeout=60)
        assert p.exitcode == 0
    (_, first_a, got_b, cached_b, calls_a, pid_a) = results["question A"]
    (_, first_b, got_a, cached_a, calls_b, pid_b) = results["question B"]
    assert pid_a != pid_b and calls_a == calls_b == 1  # each called the model for its own question only
    assert cached_a and cached_b
    assert got_a == first_a == f"question A -> pid {pid_a}"  # B read A's answer, made in A's process
    assert got_b == first_b == f"question B -> pid {pid_b}"
    assert open_store(**store_args).count() == 2


def test_gift_lm_cache_stats_on_redis(redis_url):
    lm = CachedLM(CountingLM(model="m1"), url=redis_url)
    lm.complete(MSG)
    lm.choice_probabilities(MSG, ["a", "b"])
    CachedLM(CountingLM(model="m2"), url=redis_url).complete(MSG)

    def gift(*args, **env):
        p = subprocess.run([GIFT, *args], capture_output=True, text=True, timeout=300,
                           env={**os.environ, **env})
        assert p.returncode == 0, p.stderr
        return p.stdout

    info = json.loads(gift("lm", "cache-stats", "--json", GIFT_LM_CACHE_URL=redis_url))
    assert info["store"] == "redis" and info["path"] == redis_url and info["entries"] == 3
    assert {(r["identity"], r["kind"], r["entries"]) for r in info["by_model"]} == {
        ("counting:m1", "complete", 1), ("counting:m1", "choices", 1), ("counting:m2", "complete", 1)}
    info = json.loads(gift("lm", "cache-stats", "--json", "--url", redis_url, "--clear", "--identity", "counting:m1"))
    assert info["removed"] == 2 and info["entries"] == 1
    assert "0 entries" in gift("lm", "cache-stats", "--clear", GIFT_LM_CACHE_URL=redis_url)


def test_an_unreachable_server_is_a_clear_error(monkeypatch):
    url = _dead_url()
    with pytest.raises(LMError, match=rf"Redis at {url}: connect \(PING\) failed.*Connection refused"):
        CachedLM(CountingLM(), url=url)
    monkeypatch.setenv("GIFT_LM_CACHE_URL", url)
    with pytest.raises(LMError, match=rf"Redis at {url}: connect"):
        CachedLM(CountingLM())
    with pytest.raises(LMError, match="unsupported cache URL 'http://127.0.0.1:1/'"):
        CachedLM(CountingLM(), url="http://127.0.0.1:1/")


def test_a_server_that_dies_during_a_run_is_a_clear_error(tmp_path):
    with running_redis(tmp_path) as (url, server):
        lm = CachedLM(CountingLM(), url=url)
        lm.complete(MSG)
        server.terminate()
        server.wait(timeout=10)
        with pytest.raises(LMError, match=rf"Redis at {url}: read failed"):
            lm.complete([{"role": "user", "content": "a new question"}])


def test_the_password_of_a_url_is_never_shown(monkeypatch):
    url = _dead_url().replace("redis://", "redis://user:s3cret-pw@")
    with pytest.raises(LMError) as err:
        CachedLM(CountingLM(), url=url)
    assert "s3cret-pw" not in str(err.value) and "user:***@127.0.0.1" in str(err.value)


def test_a_missing_redis_package_names_the_package(monkeypatch, redis_url):
    monkeypatch.setitem(sys.modules, "redis", None)  # what `import redis` sees when it is not installed
    with pytest.raises(LMError, match=r"needs the Python package 'redis': pip install 'gift-llm\[redis\]'"):
        CachedLM(CountingLM(), url=redis_url)
