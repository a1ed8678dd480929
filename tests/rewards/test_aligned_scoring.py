"""Scoring: columns by name, aligned scoring on the real pack_backpack family, the Boltzmann choice."""

from __future__ import annotations

import numpy as np
import pytest
from reward_data import pack_traces, random_specs, random_traces

import gift
from gift.core.alignment import align_state
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch
from gift.core.metrics import boltzmann, pairwise_win_rate
from gift_rewards import LinearMaxEntReward, NeuralMaxEntReward, aggregate

TRAIN = ("paintbrush", "sketchbook", "banana", "coffee mug")
RELEVANT = ("paintbrush", "sketchbook")  # intent: pack the art supplies
TEST = ("molding clay", "toothbrush")
N_STEPS = 61


@pytest.fixture(scope="module")
def pack():
    return gift.get_task("pack_backpack")


@pytest.fixture(scope="module")
def pack_training(pack):
    """Preferred trajectories pack exactly the relevant objects; alternatives pack random subsets."""
    rng = np.random.default_rng(0)
    relevant = np.array([o in RELEVANT for o in TRAIN])
    demos = pack_traces(pack, TRAIN, np.tile(relevant, (60, 1)), N_STEPS, rng)
    alternatives = pack_traces(pack, TRAIN, rng.random((600, len(TRAIN))) < 0.5, N_STEPS, rng)
    # the demonstrations really are what the ground truth prefers
    assert pack.ground_truth_reward(demos, RELEVANT).min() > pack.ground_truth_reward(alternatives, RELEVANT).mean()
    return demos, alternatives


@pytest.fixture(scope="module", params=["maxent-linear", "maxent-neural"])
def pack_reward(request, pack_training):
    return gift.get_reward_model(request.param).fit(*pack_training)


def test_pack_relevant_test_object_outranks_distractor(pack, pack_reward):
    rng = np.random.default_rng(1)
    # rows: pack only the clay, only the toothbrush, both, neither
    packed = np.array([[1, 0], [0, 1], [1, 1], [0, 0]], dtype=bool)
    test = pack_traces(pack, TEST, np.repeat(packed, 25, axis=0), N_STEPS, rng)
    alignment = Alignment({"molding clay": "paintbrush", "toothbrush": DISTRACTOR}, kernel="hand-built")

    scores = pack_reward.score_aligned(test, alignment)

    assert scores.shape == (100,)
    clay_only, brush_only, both, neither = scores.reshape(4, 25)
    assert clay_only.min() > brush_only.max()  # the relevant test object outranks the distractor
    assert both.min() > neither.max()
    # the human's true reward for this scene (clay relevant) orders these pairs the same way
    truth = pack.ground_truth_reward(test, ["molding clay"]).reshape(4, 25)
    pairs = np.stack(np.meshgrid(np.arange(25), np.arange(25, 50)), axis=-1).reshape(-1, 2)
    assert truth[0].min() > truth[1].max()
    assert pairwise_win_rate(scores, truth.ravel(), pairs) == 1.0
    # the paper's real-robot evaluation: a Boltzmann choice over a small candidate set
    candidates = test[[0, 25, 75]]  # clay, toothbrush, nothing packed
    p = boltzmann(pack_reward.score_aligned(candidates, alignment))
    assert p.argmax() == 0 and p[0] > 0.5


def test_pack_alignment_decides_the_ranking(pack, pack_reward):
    """The same trajectories rank the other way when the kernel maps the toothbrush to the art supply."""
    rng = np.random.default_rng(2)
    test = pack_traces(pack, TEST, np.array([[1, 0], [0, 1]], dtype=bool), N_STEPS, rng)
    swapped = Alignment({"molding clay": DISTRACTOR, "toothbrush": "sketchbook"})
    clay, brush = pack_reward.score_aligned(test, swapped)
    assert brush > clay
    # mapping a test object to an irrelevant training object makes packing it undesirable
    to_banana = Alignment({"molding clay": "banana", "toothbrush": DISTRACTOR})
    clay, brush = pack_reward.score_aligned(test, to_banana)
    assert clay < brush


@pytest.mark.parametrize("model_cls", [LinearMaxEntReward, NeuralMaxEntReward])
@pytest.mark.parametrize("mapping", [
    {"molding clay": "paintbrush", "toothbrush": DISTRACTOR, "stapler": "banana"},
    {"molding clay": "paintbrush", "toothbrush": "paintbrush", "stapler": "coffee mug"},  # two share a slot
], ids=["one-to-one", "many-to-one"])
def test_vectorized_alignment_equals_state_by_state(pack, pack_training, model_cls, mapping):
    reward = model_cls(**({"max_epochs": 40} if model_cls is NeuralMaxEntReward else {})).fit(*pack_training)
    rng = np.random.default_rng(3)
    objects = ("molding clay", "toothbrush", "stapler")
    test = pack_traces(pack, objects, rng.random((12, 3)) < 0.5, N_STEPS, rng)
    alignment = Alignment(mapping)
    naive = np.array([[align_state(state, test.specs, alignment, reward.feature_specs) for state in trace]
                      for trace in test.values])
    expected = reward.score(FeatureBatch(reward.feature_specs, naive))
    np.testing.assert_allclose(reward.score_aligned(test, alignment), expected, rtol=0, atol=1e-12)


def test_score_matches_columns_by_name():
    rng = np.random.default_rng(4)
    specs = random_specs(3)
    reward = LinearMaxEntReward().fit(random_traces(specs, 50, 11, rng), random_traces(specs, 200, 11, rng))
    test = random_traces(specs, 20, 11, rng)
    # R_θ(ξ) = θ · φ(ξ) with the φ the model was fitted on
    np.testing.assert_allclose(reward.score(test), aggregate(test.values) @ reward.theta, rtol=1e-12)
    order = [3, 1, 0, 2]
    permuted = FeatureBatch([specs[i] for i in order], test.values[..., order])
    np.testing.assert_allclose(reward.score(permuted), reward.score(test), rtol=0, atol=1e-12)
    # a missing object column means the object is absent: the same as its proximity being 0 throughout
    without = FeatureBatch(specs[1:], test.values[..., 1:])
    zeroed = test.values.copy()
    zeroed[..., 0] = 0.0
    np.testing.assert_allclose(reward.score(without), reward.score(FeatureBatch(specs, zeroed)), atol=1e-12)


def test_linear_model_needs_no_torch(tmp_path):
    """maxent-linear imports, fits, scores and saves with torch unimportable."""
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import importlib.abc, sys\n"
        "class NoTorch(importlib.abc.MetaPathFinder):\n"
        "    def find_spec(self, name, path, target=None):\n"
        "        if name.split('.')[0] == 'torch':\n"
        "            raise ImportError('torch is blocked in this test')\n"
        "sys.meta_path.insert(0, NoTorch())\n"
        "import numpy as np, gift\n"
        "from reward_data import random_specs, random_traces\n"
        "rng = np.random.default_rng(0); specs = random_specs(2)\n"
        "m = gift.get_reward_model('maxent-linear').fit(random_traces(specs, 20, 5, rng),"
        " random_traces(specs, 60, 5, rng))\n"
        "print(m.score(random_traces(specs, 3, 5, rng)).shape, 'torch' in sys.modules)\n"
        "try:\n"
        "    gift.get_reward_model('maxent-neural').fit(random_traces(specs, 20, 5, rng),"
        " random_traces(specs, 60, 5, rng))\n"
        "except Exception as e:\n"
        "    print(type(e).__name__, e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         cwd=Path(__file__).parent)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert lines[0] == "(3,) False"
    assert lines[1].startswith("GiftError") and "needs torch" in lines[1]
