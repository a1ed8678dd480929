"""The example kernel inside gift's scoring loop, benchmarked with pytest-benchmark.

One round scores a batch of test trajectories in every test scene: K -> f_ω (argmax-threshold) ->
R̃_θ(ξ'|ω) = R_θ(f_ω(ξ')). The vectorised kernel is compared with a naive per-pair Python kernel that
computes the same numbers, in the same run (``--benchmark-group-by=group``).

Run:  pytest benchmarks --benchmark-only     (in CI: --benchmark-disable runs each once, as a test)
"""

import numpy as np
import pytest

import gift
from gift.core.interfaces import SimilarityKernel
from gift.testing import tiny_suite_object
from gift_example_kernel.kernel import KeywordOverlapKernel, intent_keywords

pytest.importorskip("gift_kernels")
pytest.importorskip("gift_rewards")

N_TRAJ, N_STEPS, N_SCENES = 128, 61, 16


class NaiveKeywordOverlap(SimilarityKernel):
    """The same K as KeywordOverlapKernel, one pair at a time with Python sets (the baseline)."""

    name = "keyword-overlap-naive"
    uses_intent = True

    def __init__(self, intent_weight: float = 2.0) -> None:
        self.inner = KeywordOverlapKernel(intent_weight)

    def similarity(self, test, train, intent=None):
        boost = intent_keywords(intent)
        weight = lambda words: sum(1.0 + (self.inner.intent_weight if w in boost else 0.0) for w in words)  # noqa
        out = np.zeros((len(test), len(train)))
        for i, s in enumerate(test):
            a = self.inner.object_keywords(s)
            for j, t in enumerate(train):
                b = self.inner.object_keywords(t)
                union = weight(a | b)
                out[i, j] = weight(a & b) / union if union else 0.0
        return out


@pytest.fixture(scope="module")
def scoring_problem():
    """A learned reward on the tiny suite's art_supplies intent and N_SCENES test scenes of N_TRAJ trajectories."""
    suite = tiny_suite_object()
    spec = suite.intent("art_supplies")
    task = gift.get_task(spec.task)
    train = suite.specs(spec.train_objects)
    train_specs = task.feature_specs(spec.train_objects)
    rng = np.random.default_rng(0)
    ramp = np.linspace(0, 1, N_STEPS)[None, :, None]
    relevant = np.array([s.subject in spec.relevant_train for s in train_specs])
    demo = np.where(relevant, ramp * rng.uniform(0.7, 1.0, (64, 1, len(train_specs))), 0.05)
    alt = ramp * rng.uniform(0.0, 1.0, (256, 1, len(train_specs)))
    reward = gift.get_reward_model("maxent-linear").fit(gift.FeatureBatch(train_specs, demo),
                                                        gift.FeatureBatch(train_specs, alt))
    names = list(suite.objects)
    scenes = []
    for _ in range(N_SCENES):
        objects = suite.specs(sorted(rng.choice(names, size=4, replace=False)))
        specs = task.feature_specs([o.name for o in objects])
        values = rng.uniform(0, 1, (N_TRAJ, N_STEPS, len(specs)))
        scenes.append((objects, gift.FeatureBatch(specs, values)))
    intent = gift.Intent(spec.text, source="ground-truth")
    return reward, train, scenes, intent, spec.relevant_train


def scoring_loop(kernel, problem) -> np.ndarray:
    """R̃_θ of every trajectory of every test scene: ``[N_SCENES, N_TRAJ]``."""
    reward, train, scenes, intent, relevant_train = problem
    align = gift.get_alignment_operator("argmax-threshold", threshold=0.2)
    out = []
    for objects, features in scenes:
        alignment = align.align(kernel, objects, train, intent, relevant_train=relevant_train)
        out.append(reward.score_aligned(features, alignment))
    return np.stack(out)


def test_naive_and_vectorised_kernels_agree(scoring_problem):
    np.testing.assert_allclose(scoring_loop(KeywordOverlapKernel(), scoring_problem),
                               scoring_loop(NaiveKeywordOverlap(), scoring_problem), atol=1e-9)


@pytest.mark.benchmark(group="scoring-loop")
def test_scoring_loop_keyword_overlap(benchmark, scoring_problem):
    scores = benchmark(scoring_loop, KeywordOverlapKernel(), scoring_problem)
    assert scores.shape == (N_SCENES, N_TRAJ) and np.all(np.isfinite(scores))


@pytest.mark.benchmark(group="scoring-loop")
def test_scoring_loop_naive_baseline(benchmark, scoring_problem):
    scores = benchmark(scoring_loop, NaiveKeywordOverlap(), scoring_problem)
    assert scores.shape == (N_SCENES, N_TRAJ) and np.all(np.isfinite(scores))


@pytest.mark.benchmark(group="kernel-only")
def test_kernel_keyword_overlap(benchmark, scoring_problem):
    _, train, scenes, intent, _ = scoring_problem
    tests = [o for objects, _ in scenes for o in objects]
    k = benchmark(KeywordOverlapKernel().similarity, tests, train, intent)
    assert k.shape == (len(tests), len(train))


@pytest.mark.benchmark(group="kernel-only")
def test_kernel_naive_baseline(benchmark, scoring_problem):
    _, train, scenes, intent, _ = scoring_problem
    tests = [o for objects, _ in scenes for o in objects]
    k = benchmark(NaiveKeywordOverlap().similarity, tests, train, intent)
    assert k.shape == (len(tests), len(train))
