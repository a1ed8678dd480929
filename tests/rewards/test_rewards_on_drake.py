"""The reward models on real Drake trajectories (drake-franka, pack_backpack): learn, then generalise."""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.data import DISTRACTOR, Alignment
from gift.core.metrics import pairwise_win_rate

pytestmark = [pytest.mark.drake, pytest.mark.slow]

TRAIN = ("paintbrush", "sketchbook", "banana", "coffee mug")
RELEVANT = ("paintbrush", "sketchbook")


@pytest.fixture(scope="module")
def sim(drake_franka):
    return drake_franka


@pytest.fixture(scope="module")
def train_data(sim):
    scene = sim.make_scene("pack_backpack", TRAIN, RELEVANT, seed=0)
    preferred = sim.features(sim.generate(scene, "preferred", 30, 0), "pack_backpack")
    alternatives = sim.features(sim.generate(scene, "random", 200, 1), "pack_backpack")
    held_out = sim.features(sim.generate(scene, "random", 100, 2), "pack_backpack")
    return preferred, alternatives, held_out


@pytest.mark.parametrize("name", ["maxent-linear", pytest.param("maxent-neural", marks=pytest.mark.xfail(
    strict=True, reason="known limitation: the MLP reward extrapolates badly to a state in which no training "
    "object is packed (a distractor is dropped, so its trajectories show none), which never occurs in training; "
    "measured: every toothbrush trajectory scores above every clay trajectory. The linear reward gives such "
    "states 0 and ranks them correctly."))])
def test_reward_learned_on_drake_generalises_through_alignment(sim, train_data, name):
    preferred, alternatives, held_out = train_data
    reward = gift.get_reward_model(name).fit(preferred, alternatives)

    # in the training scene: held-out trajectories that act on different kinds of object (true rewards
    # ~+1 for packing a relevant one, ~-1 for an irrelevant one) are ranked like the human's true reward
    truth = gift.get_task("pack_backpack").ground_truth_reward(held_out, RELEVANT)
    i, j = np.triu_indices(len(truth), k=1)
    distinct = np.abs(truth[i] - truth[j]) > 0.5
    assert distinct.sum() > 100
    assert pairwise_win_rate(reward.score(held_out), truth, np.stack([i, j], 1)[distinct]) >= 0.95

    # a new scene: the clay plays the paintbrush's role, the toothbrush is a distractor
    scene = sim.make_scene("pack_backpack", ("molding clay", "toothbrush"), ("molding clay",), seed=3)
    batch = sim.generate(scene, "random", 100, 2)
    acted_on = np.asarray(batch.meta["acted_on"])
    assert {"molding clay", "toothbrush"} <= set(acted_on)
    scores = reward.score_aligned(sim.features(batch, "pack_backpack"),
                                  Alignment({"molding clay": "paintbrush", "toothbrush": DISTRACTOR}))
    assert scores[acted_on == "molding clay"].min() > scores[acted_on == "toothbrush"].max()
