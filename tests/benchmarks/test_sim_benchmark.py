"""Speed of the Drake simulator plugin: vectorized generation and features vs a per-trajectory loop.

- generation, 4-object ``pack_backpack`` scene, 200 ``random`` trajectories (Franka): one batched call
  (keyframes refined together, batched forward kinematics) vs 200 calls of one trajectory each; both with
  the scene's Drake IK keyframes already cached, plus a cold run that includes solving them;
- features of 1,000 trajectories: one vectorized call vs one call per trajectory.

``extra_info`` records trajectories per second. Nothing here asserts anything about time; each
benchmark checks that its results match the vectorized ones.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_sim_benchmark.py --benchmark-only``.
"""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.data import Appearance, FeatureBatch, ObjectSpec

pytestmark = pytest.mark.drake

OBJECTS = (
    ObjectSpec("paintbrush", appearance=Appearance("cylinder", (0.015, 0.18), (0.8, 0.55, 0.2))),
    ObjectSpec("banana", appearance=Appearance("box", (0.18, 0.04, 0.04), (0.95, 0.85, 0.2))),
    ObjectSpec("sketchbook", appearance=Appearance("box", (0.2, 0.15, 0.02), (0.9, 0.9, 0.85))),
    ObjectSpec("coffee mug", appearance=Appearance("cylinder", (0.04, 0.1), (0.2, 0.2, 0.25))),
)
N_GEN = 200
N_FEAT = 1000


@pytest.fixture(scope="module")
def sim(drake_franka):
    return drake_franka


@pytest.fixture(scope="module")
def scene(sim):
    s = sim.make_scene("pack_backpack", OBJECTS, ["paintbrush", "sketchbook"], seed=0)
    sim.planner.prepare(s)  # Drake IK at the keyframes, cached
    return s


@pytest.fixture(scope="module")
def big_batch(sim, scene):
    return sim.generate(scene, "random", N_FEAT, seed=0)


def test_generate_vectorized(benchmark, sim, scene):
    batch = benchmark(sim.generate, scene, "random", N_GEN, 1)
    assert len(batch) == N_GEN and batch.n_steps == 61
    benchmark.extra_info["trajectories_per_s"] = N_GEN / benchmark.stats.stats.mean


def test_generate_loop_baseline(benchmark, sim, scene):
    def loop():
        return [sim.generate(scene, "random", 1, seed) for seed in range(N_GEN)]

    batches = benchmark.pedantic(loop, rounds=3, iterations=1)
    assert len(batches) == N_GEN and all(len(b) == 1 for b in batches)
    benchmark.extra_info["trajectories_per_s"] = N_GEN / benchmark.stats.stats.mean


def test_generate_cold_including_drake_ik(benchmark, sim):
    seeds = iter(range(1000, 2000))

    def fresh_scene():
        s = sim.make_scene("pack_backpack", OBJECTS, ["paintbrush", "sketchbook"], seed=next(seeds))
        return (s,), {}

    batch = benchmark.pedantic(lambda s: sim.generate(s, "random", N_GEN, 1), setup=fresh_scene, rounds=3)
    assert len(batch) == N_GEN
    benchmark.extra_info["trajectories_per_s"] = N_GEN / benchmark.stats.stats.mean


def test_features_vectorized(benchmark, sim, big_batch):
    feats = benchmark(sim.features, big_batch, "pack_backpack")
    assert feats.values.shape == (N_FEAT, 61, 6)
    benchmark.extra_info["trajectories_per_s"] = N_FEAT / benchmark.stats.stats.mean


def test_features_loop_baseline(benchmark, sim, big_batch):
    def loop():
        return FeatureBatch.concat([sim.features(big_batch[i], "pack_backpack") for i in range(N_FEAT)])

    feats = benchmark.pedantic(loop, rounds=3, iterations=1)
    np.testing.assert_allclose(feats.values, sim.features(big_batch, "pack_backpack").values)
    benchmark.extra_info["trajectories_per_s"] = N_FEAT / benchmark.stats.stats.mean
