"""Composing GIFT in Python: learn a reward, infer intent, align, score, with the study layer's code.

>>> pipe = GiftPipeline(kernel="language", alignment="argmax-threshold", reward_model="maxent-linear")
>>> pipe.learn_reward(training.demonstrations, training.alternatives)   # R_θ from MaxEnt IRL
>>> relevant = pipe.relevant_objects(training)                         # from the demonstrations alone
>>> intent = pipe.estimate_intent(training.pairs())                    # ω̂ = J(D_H, D_¬H)  (needs an estimator)
>>> alignment = pipe.align(test_objects, train_objects, intent, relevant_train=relevant)   # f_ω on objects
>>> pipe.score(test_features, alignment)                               # R̃_θ(ξ'|ω) = R_θ(f_ω(ξ'))  -> [N]

Components are registered specs (``"name"`` or ``"name:key=value"``, built by
:func:`gift.study.components.build`, the builder every command uses, with ``lm`` for those that take one)
or instances. :mod:`gift.study.scenes` builds the scenes and training sets (``examples/pipeline.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from gift.core.data import Alignment, DemonstrationPair, FeatureBatch, Intent, ObjectSpec
from gift.core.errors import GiftError
from gift.core.interfaces import AlignmentOperator, IntentEstimator, RewardModel, SimilarityKernel, Simulator


def _resolve(kind: str, value: Any, base: type, lm: Any) -> Any:
    if value is None or isinstance(value, base):
        return value
    if isinstance(value, str):
        from gift.study.components import build

        return build(kind, value, lm=lm)
    raise TypeError(f"{kind} must be a registered spec or a {base.__name__} instance, got {type(value).__name__}")


class GiftPipeline:
    """The steps of GIFT with swappable components (``lm``: the LM spec or instance for components that take one)."""

    def __init__(self, *, simulator: Simulator | str | None = None,
                 intent_estimator: IntentEstimator | str | None = None,
                 kernel: SimilarityKernel | str | None = None,
                 alignment: AlignmentOperator | str | None = None,
                 reward_model: RewardModel | str | None = None, lm: Any = None) -> None:
        self.simulator = _resolve("simulator", simulator, Simulator, lm)
        self.intent_estimator = _resolve("intent_estimator", intent_estimator, IntentEstimator, lm)
        self.kernel = _resolve("kernel", kernel, SimilarityKernel, lm)
        self.alignment = _resolve("alignment_operator", alignment, AlignmentOperator, lm)
        self.reward_model = _resolve("reward_model", reward_model, RewardModel, lm)

    def _need(self, attr: str) -> Any:
        value = getattr(self, attr)
        if value is None:
            raise GiftError(f"this pipeline has no {attr}; pass {attr}=... to GiftPipeline")
        return value

    def learn_reward(self, demonstrations: FeatureBatch, alternatives: FeatureBatch) -> RewardModel:
        """Fit R_θ by the reward model's learner (MaxEnt IRL for the built-in ones)."""
        return self._need("reward_model").fit(demonstrations, alternatives)

    @staticmethod
    def relevant_objects(pairs: Sequence[DemonstrationPair] | Any, objects: Sequence[str] | None = None
                         ) -> tuple[str, ...]:
        """The training objects the demonstrations treat as part of the goal (no labels, no LM): what the
        study uses in inferred mode. ``pairs``: demonstration pairs or a :class:`~gift.study.scenes.TrainingSet`."""
        from gift.core.demonstrations import infer_relevant_objects

        if hasattr(pairs, "pairs"):
            objects = pairs.objects if objects is None else objects
            pairs = pairs.pairs()
        if objects is None:
            raise GiftError("relevant_objects: pass the training object names (or a TrainingSet)")
        return tuple(infer_relevant_objects(list(pairs), list(objects)).relevant)

    def estimate_intent(self, pairs: Sequence[DemonstrationPair], *, task_context: str = "",
                        objects: Sequence[str] = ()) -> Intent:
        """ω̂ = J(D_H, D_¬H)."""
        return self._need("intent_estimator").estimate(pairs, task_context=task_context, objects=objects)

    def align(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None = None, *,
              relevant_train: Sequence[str] = ()) -> Alignment:
        """f_ω on the objects of a test scene (one scoring pass, :func:`gift.core.alignment.score_alignment`)."""
        return self._need("alignment").align(self._need("kernel"), test, train, intent,
                                             relevant_train=relevant_train)

    def score(self, features: FeatureBatch, alignment: Alignment) -> np.ndarray:
        """R̃_θ(ξ'|ω) for N test trajectories: ``[N]``."""
        return self._need("reward_model").score_aligned(features, alignment)
