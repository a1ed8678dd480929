"""Single-flight in the LM cache: concurrent identical misses make one model call, on SQLite and on Redis.

The slow test double sleeps 1 s per call and leaves one marker file per real call, so the number of
calls is counted across processes by the file system, not by the code under test.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import subprocess
import sys
import textwrap
import threading
import time
import uuid
import warnings
from pathlib import Path

import pytest

from gift.core.data import Completion, Usage, as_messages
from gift.core.interfaces import LMBackend
from gift_llm.cache import CachedLM, open_store

N_PROCESSES = 4
QUESTION = [{"role": "user", "content": "Is a paintbrush an art supply?"}]


class SlowLM(LMBackend):
    """Test double: sleeps ``delay_s``, writes a marker file into ``markers`` per call, answers deterministically."""

    name = "slow-double"
    model = "sleepy"
    supports_choice_probabilities = True

    def __init__(self, markers: str, delay_s: float = 1.0):
        self.markers, self.delay_s = Path(markers), delay_s

    def _call(self, what: str) -> None:
        time.sleep(self.delay_s)
        (self.markers / f"{what}-{os.getpid()}-{uuid.uuid4().hex}.call").write_text(str(os.getpid()))

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self._call("complete")
        return Completion(f"yes ({as_messages(messages)[-1].content}, pid {os.getpid()})",
                          Usage(prompt_tokens=7, completion_tokens=1, latency_s=self.delay_s), model=self.identity())

    def choice_probabilities(self, messages, choices):
        self._call("choices")
        return {c: 1.0 / len(choices) for c in choices}


@pytest.fixture(autouse=True)
def _no_cache_settings(monkeypatch):
    for var in ("GIFT_LM_CACHE_URL", "GIFT_LM_CACHE", "GIFT_LOCK_DIR"):
        monkeypatch.delenv(var, raising=False)


@pytest.fixture(params=["sqlite", "redis"])
def store_args(request, tmp_path):
    if request.param == "redis":
        return {"url": request.getfixturevalue("redis_url")}
    return {"path": str(tmp_path / "cache" / "lm.sqlite")}


def _ask_at_once(store_args, markers, barrier, queue):
    """Worker: build the cached slow LM, wait for every other worker, then ask the same question."""
    lm = CachedLM(SlowLM(markers), **store_args)
    barrier.wait(timeout=120)
    out = lm.complete(QUESTION)
    p = lm.choice_probabilities(QUESTION, ["yes", "no"])
    queue.put((out.text, out.usage.cached, p, lm.stats.calls, lm.stats.hits, lm.stats.misses))


def test_processes_asking_the_same_question_at_once_make_one_model_call(store_args, tmp_path):
    markers = tmp_path / "markers"
    markers.mkdir()
    ctx = mp.get_context("spawn")
    barrier, queue = ctx.Barrier(N_PROCESSES), ctx.Queue()
    procs = [ctx.Process(target=_ask_at_once, args=(store_args, str(markers), barrier, queue))
             for _ in range(N_PROCESSES)]
    for p in procs:
        p.start()
    results = [queue.get(timeout=180) for _ in procs]
    for p in procs:
        p.join(timeout=60)
        assert p.exitcode == 0
    calls = sorted(f.name.split("-")[0] for f in markers.iterdir())
    assert calls == ["choices", "complete"]  # one real call per question, whatever the number of processes
    assert len({r[0] for r in results}) == 1 and {str(r[2]) for r in results} == {str({"yes": 0.5, "no": 0.5})}
    assert sorted(r[1] for r in results) == [False] + [True] * (N_PROCESSES - 1)
    assert sum(r[3] for r in results) == 2 and sum(r[4] for r in results) == 2 * N_PROCESSES - 2
    assert sum(r[5] for r in results) == 2
    assert open_store(**store_args).count() == 2


def test_threads_asking_the_same_question_at_once_make_one_model_call(store_args, tmp_path):
    lm = CachedLM(SlowLM(str(tmp_path), delay_s=0.5), **store_args)
    barrier, texts = threading.Barrier(3), []

    def ask():
        barrier.wait(timeout=30)
        texts.append(lm.complete(QUESTION).text)

    threads = [threading.Thread(target=ask) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert len(list(tmp_path.glob("complete-*.call"))) == 1 and len(set(texts)) == 1 and len(texts) == 3
    assert (lm.stats.calls, lm.stats.hits, lm.stats.misses) == (1, 2, 1)


def test_different_questions_do_not_wait_for_each_other(store_args, tmp_path):
    lm = CachedLM(SlowLM(str(tmp_path), delay_s=1.0), **store_args)
    barrier = threading.Barrier(3)

    def ask(i):
        barrier.wait(timeout=30)
        lm.complete([{"role": "user", "content": f"question {i}"}])

    threads = [threading.Thread(target=ask, args=(i,)) for i in range(3)]
    t0 = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert len(list(tmp_path.glob("complete-*.call"))) == 3
    assert time.monotonic() - t0 < 2.5  # in parallel: about 1 s, not 3 s


_HOLD_LOCK_AND_DIE = textwrap.dedent("""
    import os, sys
    from gift_llm.cache import open_store
    store = open_store(**{store_args!r})
    store.lock_timeout_s = {ttl!r}  # the expiry of the Redis lock
    with store.lock("0" * 64):
        print("locked", flush=True)
        sys.stdin.readline()
        os.kill(os.getpid(), 9)
""")


def test_a_lock_holder_that_dies_does_not_block_the_others(store_args, tmp_path):
    """flock is freed by the kernel at once; a Redis lock expires (here after 2 s)."""
    script = _HOLD_LOCK_AND_DIE.format(store_args=store_args, ttl=2.0)
    holder = subprocess.Popen([sys.executable, "-c", script], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "locked"
    store = open_store(**store_args)
    store.lock_timeout_s = 0.3
    with pytest.warns(RuntimeWarning, match="calling the model without the lock"), store.lock("0" * 64) as held:
        assert not held  # held by the live process
    holder.stdin.write("die\n")
    holder.stdin.flush()
    assert holder.wait(timeout=30) == -9
    store.lock_timeout_s = 30.0
    t0 = time.monotonic()
    with store.lock("0" * 64) as held:
        assert held
    assert time.monotonic() - t0 < 3.0
    if "path" in store_args:  # the dead holder's lock file was reused, and removed on release
        assert list(store.lock_dir.iterdir()) == []


def test_sqlite_lock_files_live_next_to_the_cache_or_under_gift_lock_dir(tmp_path, monkeypatch):
    store = open_store(path=tmp_path / "c.sqlite")
    assert store.lock_dir == tmp_path / "c.sqlite.locks"
    with store.lock("ab" * 32):
        assert [p.name for p in store.lock_dir.iterdir()] == ["ab" * 32 + ".lock"]
    assert list(store.lock_dir.iterdir()) == []  # removed on release
    monkeypatch.setenv("GIFT_LOCK_DIR", str(tmp_path / "locks"))
    other = open_store(path=tmp_path / "c.sqlite")
    assert other.lock_dir.parent == tmp_path / "locks" and other.lock_dir.name.startswith("lm-cache-")


class FailingOnceLM(SlowLM):
    """Test double: the first call raises, later calls answer (after ``delay_s``)."""

    failed = False

    def complete(self, messages, **kw):
        if not self.failed:
            self.failed = True
            raise RuntimeError("provider error")
        return super().complete(messages, **kw)


def test_a_failed_model_call_releases_the_lock(store_args, tmp_path):
    lm = CachedLM(FailingOnceLM(str(tmp_path), delay_s=0.0), **store_args)
    lm.store.lock_timeout_s = 1.0
    with pytest.raises(RuntimeError, match="provider error"):
        lm.complete(QUESTION)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # waiting for a lock that was never released would warn
        assert not lm.complete(QUESTION).usage.cached
    assert lm.complete(QUESTION).usage.cached and len(list(tmp_path.glob("complete-*.call"))) == 1
