"""gift.testing, the pytest plugin for plugin authors: its fixtures load through the ``pytest11`` entry
point, the project's own components pass its contracts, and broken components fail them loudly."""

from __future__ import annotations

import importlib.metadata

import numpy as np
import pytest

import gift
from gift.core.interfaces import SimilarityKernel
from gift.testing import TINY_SUITE, check_kernel_contract


def test_the_fixtures_come_from_the_pytest11_entry_point(request):
    eps = {ep.name: ep.value for ep in importlib.metadata.entry_points(group="pytest11")}
    assert eps.get("gift") == "gift.testing"
    assert request.config.pluginmanager.has_plugin("gift")


def test_tiny_suite_is_a_valid_suite_of_registered_task_families(tiny_suite, gift_plugin_manager):
    assert [i.id for i in tiny_suite.intents] == [i["id"] for i in TINY_SUITE["intents"]]
    assert {i.task for i in tiny_suite.intents} <= set(gift_plugin_manager.names("task"))
    for intent in tiny_suite.intents:
        assert set(intent.relevant_train) <= set(intent.train_objects)


def test_gift_plugin_manager_is_fresh_and_loaded(gift_plugin_manager):
    assert gift_plugin_manager is gift.get_manager()
    assert "pack_backpack" in gift_plugin_manager.names("task")


@pytest.mark.slow
def test_the_language_kernel_meets_the_kernel_contract(kernel_contract, tiny_objects):
    pytest.importorskip("gift_kernels")
    train, test, intent = tiny_objects
    k = kernel_contract(gift.get_kernel("language"), train, test, intent)
    assert k.shape == (len(test), len(train))


@pytest.mark.parametrize("name, options", [("maxent-linear", {}),
                                           pytest.param("maxent-neural", {"max_epochs": 150}, marks=pytest.mark.slow)])
def test_the_reward_models_meet_the_reward_contract(reward_contract, name, options):
    pytest.importorskip("gift_rewards")
    scores = reward_contract(gift.get_reward_model(name, **options))
    assert np.all(np.isfinite(scores))


class _Broken(SimilarityKernel):
    name = "broken"

    def __init__(self, mode: str) -> None:
        self.mode = mode
        self.calls = 0

    def similarity(self, test, train, intent=None):
        self.calls += 1
        k = np.full((len(test), len(train)), 0.5)
        if self.mode == "range":
            return k * 3
        if self.mode == "shape":
            return k.T
        if self.mode == "random":
            return k + 0.01 * self.calls
        if self.mode == "batch":
            return k / max(len(test), 1)
        if self.mode == "intent" and intent is not None:
            return k * 0.5
        return k


@pytest.mark.parametrize("mode, message", [("range", "in \\[0, 1\\]"), ("shape", "n_test, n_train"),
                                           ("random", "not deterministic"), ("batch", "depends on the batch"),
                                           ("intent", "uses_intent is False")])
def test_kernel_contract_rejects_broken_kernels_with_the_reason(mode, message):
    with pytest.raises(AssertionError, match=message):
        check_kernel_contract(_Broken(mode))
