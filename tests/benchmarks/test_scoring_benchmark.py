"""Speed of test-time scoring R̃_θ(ξ'|ω) = R_θ(f_ω(ξ')): the vectorized path vs the paper's per-state loop.

10,000 test trajectories × 61 steps of the real ``pack_backpack`` feature columns for four test objects,
aligned to a reward learned on four training objects:

- ``vectorized``: :meth:`RewardModel.score_aligned` — f_ω as one column remap of the ``[N, T, F]`` batch
  (for the linear reward folded into θ, so scoring is one matrix-vector product), then one batched R_θ;
- ``naive-per-state``: f_ω applied state by state (:func:`gift.core.alignment.align_state`), then R_θ of
  each aligned trajectory — the paper's formulation written as a loop.

Both run in the same session for ``maxent-linear``; its vectorized test records ``speedup_vs_naive``
(ratio of median times) in ``extra_info`` and prints it. ``maxent-neural`` is timed on the vectorized
path only (its per-trajectory loop would cost the same alignment work). Nothing asserts anything about
time; every path checks its scores against the other.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_scoring_benchmark.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.alignment import align_state
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch

N_TRAJ, N_STEPS = 10_000, 61
TRAIN = ("paintbrush", "sketchbook", "banana", "coffee mug")
RELEVANT = ("paintbrush", "sketchbook")
TEST = ("molding clay", "toothbrush", "stapler", "crayons")
ALIGNMENT = Alignment({"molding clay": "paintbrush", "crayons": "sketchbook", "toothbrush": DISTRACTOR,
                       "stapler": "banana"}, kernel="hand-built")
GROUP = f"aligned scoring, {N_TRAJ:,} x {N_STEPS} steps"
N_CHECK = 300  # trajectories the vectorized test re-scores with the naive loop to compare

_median_s: dict[str, float] = {}


def _traces(specs, n: int, rng: np.random.Generator, packed: np.ndarray | None = None) -> FeatureBatch:
    """Random feature traces in [0, 1]; objects marked in ``packed`` ``[n, n_objects]`` end near 1."""
    values = rng.random((n, N_STEPS, len(specs))) * 0.3
    if packed is not None:
        ramp = np.linspace(0.0, 1.0, N_STEPS)[None, :, None] ** 2
        k = packed.shape[1]
        values[..., :k] = np.where(packed[:, None, :], np.maximum(values[..., :k], ramp), values[..., :k])
    return FeatureBatch(specs, values)


@pytest.fixture(scope="module")
def pack():
    return gift.get_task("pack_backpack")


@pytest.fixture(scope="module")
def training(pack):
    rng = np.random.default_rng(0)
    specs = pack.feature_specs(TRAIN)
    relevant = np.array([o in RELEVANT for o in TRAIN])
    demos = _traces(specs, 100, rng, np.tile(relevant, (100, 1)))
    alternatives = _traces(specs, 500, rng, rng.random((500, len(TRAIN))) < 0.5)
    return demos, alternatives


@pytest.fixture(scope="module")
def test_features(pack):
    rng = np.random.default_rng(1)
    return _traces(pack.feature_specs(TEST), N_TRAJ, rng, rng.random((N_TRAJ, len(TEST))) < 0.5)


@pytest.fixture(scope="module")
def linear_reward(training):
    return gift.get_reward_model("maxent-linear").fit(*training)


@pytest.fixture(scope="module", params=["maxent-linear", "maxent-neural"])
def reward(request, training, linear_reward):
    return linear_reward if request.param == "maxent-linear" else gift.get_reward_model(request.param).fit(*training)


def naive_scores(reward, features: FeatureBatch, alignment: Alignment) -> np.ndarray:
    """R_θ(f_ω(ξ')) with f_ω applied to one state at a time and R_θ to one trajectory at a time: ``[N]``."""
    train = reward.feature_specs
    out = np.empty(len(features))
    for i, trace in enumerate(features.values):
        aligned = np.stack([align_state(state, features.specs, alignment, train) for state in trace])
        out[i] = reward.score(FeatureBatch(train, aligned[None]))[0]
    return out


def _record(benchmark, path: str) -> None:
    stats = getattr(benchmark, "stats", None)
    if stats is None:  # --benchmark-disable: nothing was timed
        return
    key = f"{benchmark.extra_info.get('model', '')}:{path}"
    _median_s[key] = stats.stats.median
    benchmark.extra_info["trajectories_per_s"] = N_TRAJ / stats.stats.median


def test_scoring_naive_per_state(benchmark, linear_reward, test_features):
    """The baseline: the linear reward scored through the per-state loop (one round: ~10^6 Python calls)."""
    reward = linear_reward
    benchmark.group = GROUP
    benchmark.extra_info["model"] = "maxent-linear"
    scores = benchmark.pedantic(naive_scores, args=(reward, test_features, ALIGNMENT), rounds=1, iterations=1)
    np.testing.assert_allclose(scores, reward.score_aligned(test_features, ALIGNMENT), rtol=0, atol=1e-9)
    _record(benchmark, "naive")


def test_scoring_vectorized(benchmark, reward, test_features, capsys):
    benchmark.group = GROUP
    benchmark.extra_info["model"] = reward.name
    scores = benchmark.pedantic(reward.score_aligned, args=(test_features, ALIGNMENT), rounds=10, iterations=1,
                                warmup_rounds=1)
    assert scores.shape == (N_TRAJ,)
    check = test_features[np.arange(N_CHECK)]
    np.testing.assert_allclose(scores[:N_CHECK], naive_scores(reward, check, ALIGNMENT), rtol=0, atol=1e-9)
    _record(benchmark, "vectorized")
    naive = _median_s.get(f"{reward.name}:naive")  # the baseline loop runs the linear reward
    mine = _median_s.get(f"{reward.name}:vectorized")
    if naive and mine:
        ratio = naive / mine
        benchmark.extra_info["naive_per_state_s"] = naive
        benchmark.extra_info["speedup_vs_naive"] = ratio
        with capsys.disabled():
            print(f"\n[{GROUP}] {reward.name}: vectorized {mine * 1e3:.1f} ms, naive per-state loop "
                  f"{naive:.2f} s -> speed-up {ratio:,.0f}x (target >= 100x)")

