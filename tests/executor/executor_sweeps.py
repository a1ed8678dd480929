"""Seeded sweep workloads shared by the executor tests and benchmarks (importable by worker processes).

Every function takes one item that carries its own seed, so its result cannot depend on the worker.

- :func:`synthetic_rollouts`: numpy trajectory generation for a task family of :mod:`gift.tasks`
  (smooth random end-effector paths towards a goal, objects on a table), features computed with the
  family's own columns and :func:`gift.tasks.proximity`. Stands in for the Drake simulator where that
  plugin is not installed.
- :func:`drake_rollouts`: the same item through a registered simulator (``drake-jaco``):
  ``make_scene`` + ``generate`` + ``features``.
- :func:`score_batch`: one evaluation-sweep item: roll out a batch, score it with a fitted reward model
  (shipped once per chunk inside a ``functools.partial``) and with the family's ground truth.
- :func:`limited_call`: holds a concurrency limit while "calling an LM", writing enter/exit timestamps.
- :func:`llama_threads`: the thread budget an embedded llama.cpp model would get in this worker.
"""

from __future__ import annotations

import functools
import os
import time
from typing import Any

import numpy as np

import gift
from gift.core.data import FeatureBatch, ObjectSpec
from gift.tasks import EE_HEIGHT_SCALE, EE_SPEED_SCALE, TASKS, proximity

OBJECTS = ("laptop", "notebook", "banana", "phone", "keys", "water bottle")
#: The task families by name, without a plugin lookup (workers then skip plugin discovery).
TASK_FAMILIES = {cls.name: cls for cls in TASKS}


def synthetic_rollouts(item: tuple[str, tuple[str, ...], int, int, int]) -> FeatureBatch:
    """``item = (task, objects, seed, n, n_steps)`` -> features ``[n, n_steps, F]`` of ``task``'s columns."""
    task_name, objects, seed, n, n_steps = item
    task = TASK_FAMILIES[task_name]()
    rng = np.random.default_rng(seed)
    k = len(objects)
    objs = np.concatenate([rng.uniform(-0.4, 0.4, (n, k, 2)), np.zeros((n, k, 1))], axis=2)    # [n, k, 3]
    start, goal = rng.uniform(-0.5, 0.5, (n, 1, 3)), rng.uniform(-0.5, 0.5, (n, 1, 3))
    start[..., 2], goal[..., 2] = 0.05, 0.05
    s = np.linspace(0.0, 1.0, n_steps)[None, :, None]                                          # [1, T, 1]
    noise = np.cumsum(rng.normal(0.0, 0.02, (n, n_steps, 3)), axis=1)
    noise -= s * noise[:, -1:, :]                                                               # pin the goal
    lift = rng.uniform(0.0, 0.4, (n, 1, 1)) * np.sin(np.pi * s) * np.array([0.0, 0.0, 1.0])
    ee = start + s * (goal - start) + noise + lift                                              # [n, T, 3]
    dist = np.linalg.norm(ee[:, :, None, :] - objs[:, None, :, :], axis=-1)                     # [n, T, k]
    prox = proximity(dist)
    height = np.clip(ee[..., 2] / EE_HEIGHT_SCALE, 0.0, 1.0)
    speed = np.linalg.norm(np.diff(ee, axis=1, prepend=ee[:, :1]), axis=-1)
    speed = np.clip(speed / EE_SPEED_SCALE, 0.0, 1.0)
    values = np.concatenate([prox, height[..., None], speed[..., None]], axis=2)
    return FeatureBatch(task.feature_specs(objects), values, {"seed": int(seed)})


@functools.lru_cache(maxsize=4)
def _simulator(name: str):
    return gift.get_simulator(name)


def drake_rollouts(item: tuple[str, str, tuple[str, ...], tuple[str, ...], int, int]) -> FeatureBatch:
    """``item = (simulator, task, objects, relevant, seed, n)`` -> features of ``n`` preferred rollouts."""
    sim_name, task, objects, relevant, seed, n = item
    sim = _simulator(sim_name)
    scene = sim.make_scene(task, [ObjectSpec(o) for o in objects], relevant, seed=int(seed))
    return sim.features(sim.generate(scene, "preferred", n, seed=int(seed)), task)


def score_batch(reward: Any, item: tuple[str, tuple[str, ...], int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """One evaluation item: ``(learned scores [n], ground-truth rewards [n])`` of a fresh seeded batch."""
    features = synthetic_rollouts(item)
    truth = TASK_FAMILIES[item[0]]().ground_truth_reward(features, item[1][:2])
    return reward.score(features), truth


def fit_reward(task: str = "place_mug", objects: tuple[str, ...] = OBJECTS[:4], seed: int = 0):
    """``maxent-linear`` fitted on synthetic data: the top ground-truth tenth is the demonstration set."""
    feats = synthetic_rollouts((task, objects, seed, 400, 30))
    truth = TASK_FAMILIES[task]().ground_truth_reward(feats, objects[:2])
    order = np.argsort(-truth)
    reward = gift.get_reward_model("maxent-linear")
    return reward.fit(feats[order[:40]], feats[order[40:]])


def failing_on(bad: int, item: int) -> int:
    """``item ** 2``, but raises for ``item == bad`` (exception surfacing test)."""
    if item == bad:
        raise ValueError(f"cannot handle item {item}")
    return item * item


def sleepy_identity(item: tuple[int, float]) -> tuple[int, int]:
    """Sleep ``delay`` seconds, return ``(index, pid)`` (later items may finish first)."""
    index, delay = item
    time.sleep(delay)
    return index, os.getpid()


def limited_call(limit: Any, item: tuple[int, float]) -> tuple[int, int, float, float]:
    """Hold ``limit`` for ``hold`` seconds (a stand-in for the LM round trip); return
    ``(index, pid, entered, left)`` with ``time.time()`` stamps taken while holding the slot."""
    index, hold = item
    with limit:
        entered = time.time()
        time.sleep(hold)
        left = time.time()
    return index, os.getpid(), entered, left


def max_overlap(intervals: list[tuple[float, float]]) -> int:
    """Largest number of ``(start, end)`` intervals open at the same instant."""
    events = sorted([(s, 1) for s, _ in intervals] + [(e, -1) for _, e in intervals], key=lambda x: (x[0], x[1]))
    live = best = 0
    for _, step in events:
        live += step
        best = max(best, live)
    return best


# ------------------------------------------------------------------ LM calls through the shared cache
@functools.lru_cache(maxsize=4)
def _cached_lm(cache_path: str, limit: Any, n_ctx: int):
    """Per worker process: the embedded llama.cpp model behind the LM plugin's SQLite cache at
    ``cache_path``; model calls (cache misses only) hold ``limit``."""
    from gift_llm.cache import CachedLM
    from gift_llm.wrappers import RateLimitedLM

    inner = gift.resolve_lm("llamacpp", n_ctx=n_ctx, n_threads=1, cache=False)
    if limit is not None:
        inner = RateLimitedLM(inner, limit)
    return CachedLM(inner, path=cache_path)


def ask_lm(cache_path: str, limit: Any, item: tuple[str, int]) -> tuple[str, bool]:
    """``item = (question, seed)`` -> ``(answer text, answered from the cache?)`` (temperature 0, 6 tokens)."""
    question, seed = item
    lm = _cached_lm(cache_path, limit, 512)
    out = lm.complete([gift.Message("user", question)], temperature=0.0, seed=int(seed), max_tokens=6)
    return out.text, bool(out.usage.cached)


def llama_threads(_item: Any) -> tuple[int, str | None]:
    """``(threads a llamacpp model loaded here would use, $OMP_NUM_THREADS)`` in this worker process."""
    from gift_llm.backends.llamacpp import default_threads

    return default_threads(), os.environ.get("OMP_NUM_THREADS")
