"""Executors: serial == local == ray bit for bit, order, failures, cross-process LM concurrency limits."""

from __future__ import annotations

import argparse
import functools
import os
import pickle
import threading
import time

import numpy as np
import pytest

import gift
from gift.core.data import Completion, Usage
from gift.core.errors import GiftError, UnknownComponentError
from gift.core.executor import (
    ExecutionError,
    ExecutorError,
    LocalExecutor,
    RateLimit,
    SerialExecutor,
    add_executor_argument,
    chunk_bounds,
    executor_from_args,
    get_executor,
    item_seeds,
)
from gift.core.interfaces import LMBackend
from gift_llm.wrappers import RateLimitedLM

import executor_sweeps as sweeps

def rollout_items(seed: int = 7, n_items: int = 10) -> list[tuple]:
    objects = sweeps.OBJECTS[:4]
    tasks = ("place_mug", "sweep_spill", "pack_backpack", "store_drawer")
    return [(tasks[i % 4], objects, int(s), 16, 25) for i, s in enumerate(item_seeds(seed, n_items))]


def as_bytes(batches) -> list[tuple]:
    return [(b.names, b.values.dtype.str, b.values.shape, b.values.tobytes()) for b in batches]


# ------------------------------------------------------------------ registry and options
def test_builtin_executors_are_registered_and_local_is_default():
    names = {c["name"] for c in gift.list_components("executor")["executor"]}
    assert {"serial", "local"} <= names
    ex = get_executor()
    assert isinstance(ex, LocalExecutor) and ex.max_workers == (os.cpu_count() or 1)
    assert get_executor(ex) is ex
    with pytest.raises(ExecutorError, match="options"):
        get_executor(ex, max_workers=2)
    with pytest.raises(UnknownComponentError, match="no executor named 'nope'; registered: .*local"):
        get_executor("nope")


def test_bad_options_say_what_is_wrong():
    with pytest.raises(ExecutorError, match="max_workers must be a positive integer, got 0"):
        LocalExecutor(max_workers=0)
    with pytest.raises(ExecutorError, match="serial.*max_workers=4"):
        SerialExecutor(max_workers=4)
    with pytest.raises(ExecutorError, match="chunksize must be >= 1"):
        SerialExecutor().map(abs, [1, 2], chunksize=0)
    with pytest.raises(GiftError, match="max_concurrent must be a positive integer"):
        RateLimit(0)


def test_chunks_cover_every_item_once():
    for n in range(0, 40, 3):
        for workers in (1, 2, 5):
            for cs in (None, 1, 4):
                bounds = chunk_bounds(n, workers, cs)
                assert [i for a, b in bounds for i in range(a, b)] == list(range(n))


def test_item_seeds_are_reproducible_and_distinct():
    a, b = item_seeds(3, 100), item_seeds(3, 100)
    assert a.dtype == np.int64 and np.array_equal(a, b) and len(set(a.tolist())) == 100
    assert not np.array_equal(a, item_seeds(4, 100))
    assert np.array_equal(item_seeds(3, 10), a[:10])  # a prefix does not depend on the sweep length


def test_cli_helper_builds_the_chosen_executor():
    parser = add_executor_argument(argparse.ArgumentParser())
    ex = executor_from_args(parser.parse_args(["--executor", "local", "--workers", "3"]))
    assert isinstance(ex, LocalExecutor) and ex.max_workers == 3
    assert isinstance(executor_from_args(parser.parse_args([])), LocalExecutor)
    assert isinstance(executor_from_args(parser.parse_args(["--executor", "serial", "--workers", "2"])),
                      SerialExecutor)
    with pytest.raises(ExecutorError, match="--ray-address .* needs --executor ray"):
        executor_from_args(parser.parse_args(["--ray-address", "auto"]))


# ------------------------------------------------------------------ same results everywhere
def test_serial_and_local_give_identical_bits(local_executor):
    items = rollout_items()
    ref = SerialExecutor().map(sweeps.synthetic_rollouts, items)
    assert as_bytes(local_executor.map(sweeps.synthetic_rollouts, items)) == as_bytes(ref)
    assert as_bytes(local_executor.map(sweeps.synthetic_rollouts, items, chunksize=1)) == as_bytes(ref)
    # the items, not the workers, carry the randomness: different seeds give different data
    assert ref[0].values.tobytes() != sweeps.synthetic_rollouts(rollout_items(seed=8)[0]).values.tobytes()


def test_evaluation_sweep_identical_on_serial_and_local(local_executor):
    reward = sweeps.fit_reward()
    items = [("place_mug", sweeps.OBJECTS[:4], int(s), 32, 30) for s in item_seeds(11, 8)]
    fn = functools.partial(sweeps.score_batch, reward)
    ref = SerialExecutor().map(fn, items)
    got = local_executor.map(fn, items)
    assert [(a.tobytes(), b.tobytes()) for a, b in got] == [(a.tobytes(), b.tobytes()) for a, b in ref]
    # the learned reward is a real one: it ranks the synthetic batches like the ground truth does
    scores, truth = (np.concatenate(x) for x in zip(*ref))
    assert np.corrcoef(scores, truth)[0, 1] > 0.5


@pytest.mark.slow
def test_serial_local_and_ray_give_identical_bits(local_executor, ray_executor):
    items = rollout_items(seed=21, n_items=12)
    ref = as_bytes(SerialExecutor().map(sweeps.synthetic_rollouts, items))
    assert as_bytes(local_executor.map(sweeps.synthetic_rollouts, items)) == ref
    assert as_bytes(ray_executor.map(sweeps.synthetic_rollouts, items)) == ref
    assert as_bytes(ray_executor.map(sweeps.synthetic_rollouts, items, chunksize=5)) == ref

    reward = sweeps.fit_reward()
    fn = functools.partial(sweeps.score_batch, reward)
    eval_items = [("place_mug", sweeps.OBJECTS[:4], int(s), 32, 30) for s in item_seeds(5, 6)]
    flat = lambda res: [(a.tobytes(), b.tobytes()) for a, b in res]  # noqa: E731
    assert flat(ray_executor.map(fn, eval_items)) == flat(SerialExecutor().map(fn, eval_items))


@pytest.mark.drake
@pytest.mark.slow
def test_drake_trajectory_generation_identical_on_serial_local_and_ray(local_executor, ray_executor):
    if "drake-jaco" not in gift.get_manager().names("simulator"):
        pytest.skip("the drake-jaco simulator (gift-sim-drake) is not registered")
    tasks = ("place_mug", "pack_backpack", "sweep_spill", "store_drawer")
    items = [("drake-jaco", tasks[i % 4], ("laptop", "banana", "phone"), ("laptop",), int(s), 3)
             for i, s in enumerate(item_seeds(1, 6))]
    ref = as_bytes(SerialExecutor().map(sweeps.drake_rollouts, items))
    assert len({r[3] for r in ref}) == len(ref)  # six different scenes
    assert as_bytes(local_executor.map(sweeps.drake_rollouts, items)) == ref
    assert as_bytes(ray_executor.map(sweeps.drake_rollouts, items)) == ref


# ------------------------------------------------------------------ order and failures
def test_order_is_preserved_when_later_items_finish_first(local_executor):
    items = [(i, 0.05 * (6 - i)) for i in range(6)]
    out = local_executor.map(sweeps.sleepy_identity, items, chunksize=1)
    assert [i for i, _ in out] == list(range(6))
    assert len({pid for _, pid in out}) == 2 and os.getpid() not in {pid for _, pid in out}


def check_failure(executor):
    with pytest.raises(ExecutionError) as info:
        executor.map(functools.partial(sweeps.failing_on, 3), list(range(8)), chunksize=3)
    err = info.value
    assert err.index == 3 and err.item == "3"
    assert f"executor {executor.name!r}: item 3 of 8 (3) raised ValueError: cannot handle item 3" in str(err)
    assert "executor_sweeps.py" in str(err) and "failing_on" in str(err)  # the worker's traceback
    assert err.completed == {i: i * i for i in range(8) if i != 3}       # nothing computed is lost
    assert isinstance(err.__cause__, ValueError)


def test_a_failing_item_surfaces_with_its_index_serial_and_local(local_executor):
    check_failure(SerialExecutor())
    check_failure(local_executor)
    assert local_executor.map(abs, [-1, -2]) == [1, 2]  # the pool survives an item failure


@pytest.mark.slow
def test_a_failing_item_surfaces_with_its_index_ray(ray_executor):
    check_failure(ray_executor)


def test_unpicklable_function_is_refused_before_any_work(local_executor):
    with pytest.raises(ExecutorError, match="cannot be sent to worker processes.*module level"):
        local_executor.map(lambda x: x, [1, 2])


# ------------------------------------------------------------------ concurrency limits
def test_rate_limit_caps_concurrent_calls_across_processes(tmp_path):
    hold = 0.15
    items = [(i, hold) for i in range(12)]
    with LocalExecutor(max_workers=4) as ex:
        free = ex.map(functools.partial(sweeps.limited_call, RateLimit(100, key="free", directory=str(tmp_path))),
                      items, chunksize=1)
        limit = RateLimit(2, key="llamacpp:test", directory=str(tmp_path))
        capped = ex.map(functools.partial(sweeps.limited_call, limit), items, chunksize=1)
    assert sweeps.max_overlap([(a, b) for _, _, a, b in free]) >= 3   # the measurement sees parallelism ...
    assert len({pid for _, pid, _, _ in capped}) >= 3                   # ... from several processes
    assert sweeps.max_overlap([(a, b) for _, _, a, b in capped]) == 2   # ... and the limit holds it at 2
    assert pickle.loads(pickle.dumps(limit)).max_concurrent == 2


def test_rate_limit_times_out_with_a_clear_error(tmp_path):
    limit = RateLimit(1, key="busy", directory=str(tmp_path))
    other = RateLimit(1, key="busy", directory=str(tmp_path))
    with limit:
        with pytest.raises(TimeoutError, match="RateLimit 'busy': no free slot of 1 within 0.05 s"):
            other.acquire(timeout=0.05)
    other.release(other.acquire(timeout=0.05))


@pytest.mark.slow
def test_ray_rate_limit_caps_concurrent_calls(ray_executor):
    limit = ray_executor.rate_limit("lm-test", 1)
    out = ray_executor.map(functools.partial(sweeps.limited_call, limit), [(i, 0.1) for i in range(6)], chunksize=1)
    assert len({pid for _, pid, _, _ in out}) == 2
    assert sweeps.max_overlap([(a, b) for _, _, a, b in out]) == 1


class _ScriptedLM(LMBackend):
    """Control-flow stand-in: answers with the number of the call (never used to show LM quality)."""

    name = "scripted"
    model = "script-v1"

    def __init__(self):
        self.calls = 0

    def complete(self, messages, **kwargs):
        self.calls += 1
        return Completion(text=str(self.calls), model=self.model, usage=Usage())


def test_rate_limited_lm_keeps_the_backend_identity_and_holds_a_slot(tmp_path):
    inner = _ScriptedLM()
    limit = RateLimit(1, key=inner.identity(), directory=str(tmp_path))
    lm = RateLimitedLM(inner, limit)
    assert lm.identity() == "scripted:script-v1" and lm.model == "script-v1"
    assert lm.complete([gift.Message("user", "hi")]).text == "1"
    other = RateLimit(1, key=inner.identity(), directory=str(tmp_path))
    token = other.acquire()  # the only slot is held by someone else: the wrapped call must wait
    worker = threading.Thread(target=lm.complete, args=([gift.Message("user", "again")],))
    worker.start()
    time.sleep(0.2)
    assert inner.calls == 1 and worker.is_alive()
    other.release(token)
    worker.join(timeout=5)
    assert inner.calls == 2 and not worker.is_alive()


# ------------------------------------------------------------------ real LM behind the shared SQLite cache
@pytest.mark.slow
@pytest.mark.lm
def test_lm_cache_written_by_one_process_serves_local_and_ray_workers(tmp_path, local_executor, ray_executor):
    """The LM plugin's SQLite cache at a shared path: answers computed by the embedded llama.cpp model in
    this process are read, not recomputed, by local pool workers and by Ray workers."""
    pytest.importorskip("llama_cpp")
    from gift.core.errors import LMError
    from gift_llm.embedded import embedded_model_path

    try:
        embedded_model_path()
    except LMError as e:
        pytest.skip(f"embedded model not installed: {e}")
    cache = str(tmp_path / "shared-lm-cache.sqlite")
    questions = [("Name one fruit.", 0), ("Name one color.", 0), ("Name one fruit.", 1)]
    limit = RateLimit(1, key="llamacpp:embedded", directory=str(tmp_path))
    fn = functools.partial(sweeps.ask_lm, cache, limit)

    first = SerialExecutor().map(fn, questions)                    # the only model calls of this test
    assert [hit for _, hit in first] == [False, False, False]
    assert all(text.strip() for text, _ in first)
    items = questions * 3
    want = [(text, True) for text, _ in first] * 3
    assert local_executor.map(fn, items, chunksize=1) == want     # every answer a cache hit, same text
    assert ray_executor.map(fn, items, chunksize=1) == want
