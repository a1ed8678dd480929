"""A results file records the commit and code version the run started with, not the ones at its end."""

from __future__ import annotations

import types
from pathlib import Path

import numpy as np

import gift
from gift.core.interfaces import SimilarityKernel
from gift.study import sweeps

SUITE = str(Path(__file__).resolve().parents[1] / "kernels" / "data" / "mini_suite.yaml")


HEAD = {"commit": "a" * 40, "dirty": False}


class OnesKernel(SimilarityKernel):
    """Every pair is similar; someone commits while it scores."""

    name = "ones"

    def similarity(self, test, train, intent=None):
        HEAD["commit"] = "b" * 40
        return np.ones((len(test), len(train)))


def test_the_commit_is_taken_when_the_run_starts(fresh_plugins, monkeypatch):
    gift.get_manager().register_plugin(types.SimpleNamespace(
        gift_register_kernels=gift.hookimpl(lambda register: register("ones", OnesKernel))), name="ones")
    monkeypatch.setattr(sweeps, "git_commit", lambda: dict(HEAD))
    res = sweeps.evaluate_alignment(SUITE, ["ones"], thresholds=["oracle"], executor="serial")
    assert res["kernels"]["ones"]["intents"] and not res["kernels"]["ones"]["errors"]
    assert res["manifest"]["git"]["commit"] == "a" * 40
    assert res["manifest"]["runs"][-1]["git"]["commit"] == "a" * 40
