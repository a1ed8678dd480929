"""Throughput of sweeps on 1 vs 2 workers: serial (the naive baseline), local process pool, Ray.

Two workloads from ``tests/executor/executor_sweeps.py``, 24 seeded items per round:

- ``rollouts``: trajectory generation (512 synthetic rollouts x 61 steps x 8 features per item; the
  feature batches travel back to the caller);
- ``evaluation``: an evaluation sweep that scores fresh rollouts with a fitted ``maxent-linear`` reward
  (shipped once per chunk) and the ground truth; only the scores travel back.

Pools are started and warmed before timing (steady-state throughput); ``extra_info`` records items/s.
Nothing here asserts anything about time; each benchmark checks its results equal the serial ones.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_executor_benchmark.py --benchmark-only``.
"""

from __future__ import annotations

import functools
import sys
from pathlib import Path

import pytest

from gift.core.executor import LocalExecutor, SerialExecutor, get_executor, item_seeds

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "executor"))
import executor_sweeps as sweeps  # noqa: E402

N_ITEMS = 24
ROLLOUT_ITEMS = [("place_mug", sweeps.OBJECTS, int(s), 512, 61) for s in item_seeds(100, N_ITEMS)]
EVAL_ITEMS = [("place_mug", sweeps.OBJECTS[:4], int(s), 512, 61) for s in item_seeds(200, N_ITEMS)]

CONFIGS = ["serial", "local-1", "local-2", "ray-1", "ray-2"]


@pytest.fixture(scope="module")
def executors():
    made: dict[str, object] = {"serial": SerialExecutor(), "local-1": LocalExecutor(max_workers=1),
                               "local-2": LocalExecutor(max_workers=2)}
    ray_base = None
    try:
        import gift_executor_ray  # noqa: F401

        ray_base = get_executor("ray", num_cpus=2)           # starts (and owns) a local Ray instance
        made["ray-1"] = get_executor("ray", max_workers=1)  # same instance, one task in flight
        made["ray-2"] = get_executor("ray", max_workers=2)
        ray_base.map(abs, [0])                              # start the instance now
    except ImportError:
        pass
    yield made
    for ex in made.values():
        ex.close()
    if ray_base is not None:
        ray_base.close()


@pytest.fixture(scope="module")
def reward():
    return sweeps.fit_reward()


def _run(benchmark, executors, config, fn, items, reference):
    ex = executors.get(config)
    if ex is None:
        pytest.skip(f"{config}: gift-executor-ray is not installed")
    ex.map(fn, items)  # warm the workers (process start, imports) outside the timing
    result = benchmark.pedantic(ex.map, args=(fn, items), rounds=3, iterations=1)
    benchmark.extra_info.update(executor=config, items=len(items),
                                items_per_s=round(len(items) / benchmark.stats.stats.mean, 2))
    assert reference(result)


@pytest.mark.slow
@pytest.mark.parametrize("config", CONFIGS)
def test_rollout_throughput(benchmark, executors, config):
    expected = [b.values.tobytes() for b in map(sweeps.synthetic_rollouts, ROLLOUT_ITEMS[:2])]
    _run(benchmark, executors, config, sweeps.synthetic_rollouts, ROLLOUT_ITEMS,
         lambda res: [b.values.tobytes() for b in res[:2]] == expected and len(res) == N_ITEMS)


@pytest.mark.slow
@pytest.mark.parametrize("config", CONFIGS)
def test_evaluation_sweep_throughput(benchmark, executors, reward, config):
    fn = functools.partial(sweeps.score_batch, reward)
    expected = [s.tobytes() for s, _ in map(fn, EVAL_ITEMS[:2])]
    _run(benchmark, executors, config, fn, EVAL_ITEMS,
         lambda res: [s.tobytes() for s, _ in res[:2]] == expected and len(res) == N_ITEMS)
