"""Composing GIFT in Python: learn a reward, infer intent, align, score.

>>> pipe = GiftPipeline(kernel="language", alignment="argmax-threshold", reward_model="maxent-linear")
>>> pipe.learn_reward(demos, alternatives)          # R_θ from MaxEnt IRL
>>> intent = pipe.estimate_intent(pairs)            # ω̂ = J(D_H, D_¬H)   (needs an intent_estimator)
>>> alignment = pipe.align(test_objects, train_objects, intent)   # f_ω on objects
>>> pipe.score(test_features, alignment)            # R̃_θ(ξ'|ω) = R_θ(f_ω(ξ'))  -> [N]

Components are given as registered names (built with default options) or as instances.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from gift.core.data import Alignment, DemonstrationPair, FeatureBatch, Intent, ObjectSpec
from gift.core.errors import GiftError
from gift.core.interfaces import (
    AlignmentOperator,
    IntentEstimator,
    RewardModel,
    SimilarityKernel,
    Simulator,
)


def _resolve(kind: str, value: Any, base: type) -> Any:
    if value is None or isinstance(value, base):
        return value
    if isinstance(value, str):
        from gift.plugins.manager import get_manager

        return get_manager().create(kind, value)
    raise TypeError(f"{kind} must be a registered name or a {base.__name__} instance, got {type(value).__name__}")


class GiftPipeline:
    """The steps of GIFT with swappable components."""

    def __init__(self, *, simulator: Simulator | str | None = None,
                 intent_estimator: IntentEstimator | str | None = None,
                 kernel: SimilarityKernel | str | None = None,
                 alignment: AlignmentOperator | str | None = None,
                 reward_model: RewardModel | str | None = None) -> None:
        self.simulator = _resolve("simulator", simulator, Simulator)
        self.intent_estimator = _resolve("intent_estimator", intent_estimator, IntentEstimator)
        self.kernel = _resolve("kernel", kernel, SimilarityKernel)
        self.alignment = _resolve("alignment_operator", alignment, AlignmentOperator)
        self.reward_model = _resolve("reward_model", reward_model, RewardModel)

    def _need(self, attr: str) -> Any:
        value = getattr(self, attr)
        if value is None:
            raise GiftError(f"this pipeline has no {attr}; pass {attr}=... to GiftPipeline")
        return value

    def learn_reward(self, demonstrations: FeatureBatch, alternatives: FeatureBatch) -> RewardModel:
        """Fit R_θ by the reward model's learner (MaxEnt IRL for the built-in ones)."""
        return self._need("reward_model").fit(demonstrations, alternatives)

    def estimate_intent(self, pairs: Sequence[DemonstrationPair], *, task_context: str = "",
                        objects: Sequence[str] = ()) -> Intent:
        """ω̂ = J(D_H, D_¬H)."""
        return self._need("intent_estimator").estimate(pairs, task_context=task_context, objects=objects)

    def align(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None = None, *,
              relevant_train: Sequence[str] = ()) -> Alignment:
        """f_ω on the objects of a test scene."""
        return self._need("alignment").align(self._need("kernel"), test, train, intent,
                                             relevant_train=relevant_train)

    def score(self, features: FeatureBatch, alignment: Alignment) -> np.ndarray:
        """R̃_θ(ξ'|ω) for N test trajectories: ``[N]``."""
        return self._need("reward_model").score_aligned(features, alignment)
