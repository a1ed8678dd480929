"""Abstract interfaces of gift: one class per concept of the paper.

=========================================  ============================================
Paper                                      Code
=========================================  ============================================
ω̂ = J(D_H, D_¬H)                           :meth:`IntentEstimator.estimate`
K(s, s' | ω) ∈ [0, 1]                      :meth:`SimilarityKernel.similarity` -> [n_test, n_train]
per-object relevance under ω              :meth:`RelevanceKernel.score` -> RelevanceScores
f_ω(s') = argmax_s K(s, s' | ω)            :meth:`AlignmentOperator.align`
f_ω(ξ') (semantic components only)         :func:`gift.core.alignment.align_features`
R_θ(ξ)                                     :meth:`RewardModel.score`
R̃_θ(ξ' | ω) = R_θ(f_ω(ξ'))                 :meth:`RewardModel.score_aligned`
ask the human instead of guessing          :meth:`QueryPolicy.choose` (:mod:`gift.core.queries`)
=========================================  ============================================

Every method is batch-first: it takes many trajectories (or objects) per call.
"""

from __future__ import annotations

import abc
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from gift.core.data import (
    Alignment,
    Completion,
    DemonstrationPair,
    FeatureBatch,
    FeatureSpec,
    Intent,
    Message,
    ObjectSpec,
    RelevanceScores,
    Scene,
    TrajectoryBatch,
)
from gift.core.errors import GiftError

if TYPE_CHECKING:
    from gift.core.queries import QueryState


class Task(abc.ABC):
    """A task family: its landmarks, its features, and its ground-truth reward.

    A family is simulator-independent and works for any object names and relevance labels.
    """

    name: ClassVar[str]
    description: ClassVar[str] = ""
    #: Landmarks of the family (e.g. ``("backpack",)``), present in every scene.
    landmarks: ClassVar[tuple[str, ...]] = ()

    @abc.abstractmethod
    def feature_specs(self, objects: Sequence[str]) -> tuple[FeatureSpec, ...]:
        """The feature columns of a scene holding ``objects`` (semantic ones first)."""

    @abc.abstractmethod
    def ground_truth_reward(self, features: FeatureBatch, relevant: Sequence[str]) -> np.ndarray:
        """The human's true reward of N trajectories: ``[N]``, given the relevant object names."""

    def context(self) -> str:
        """One sentence about the task for the LM prompts (what the robot does)."""
        return self.description


class Simulator(abc.ABC):
    """Builds scenes, generates trajectories, computes features and renders objects."""

    name: ClassVar[str]
    #: Degrees of freedom of the robot.
    dof: ClassVar[int] = 7
    #: Number of states per trajectory.
    n_steps: ClassVar[int] = 61

    @abc.abstractmethod
    def make_scene(self, task: str, objects: Sequence[ObjectSpec], relevant: Sequence[str],
                   seed: int) -> Scene:
        """A randomised scene of family ``task`` (start, goal and placements from ``seed``).

        Raises :class:`~gift.core.errors.PlacementError` when the objects do not fit on the table."""

    @abc.abstractmethod
    def generate(self, scene: Scene, generator: str, n: int, seed: int) -> TrajectoryBatch:
        """``n`` trajectories in ``scene``; ``generator`` is ``"preferred"`` or ``"default"``."""

    @abc.abstractmethod
    def features(self, trajectories: TrajectoryBatch, task: str) -> FeatureBatch:
        """Per-time-step features ``[N, T, F]`` of the family ``task``."""

    def render_object(self, obj: ObjectSpec, size: int = 224) -> np.ndarray:
        """Images of one object from three viewpoints: ``[3, size, size, 3]`` uint8 RGB."""
        raise NotImplementedError(f"simulator {self.name!r} cannot render")


class LMBackend(abc.ABC):
    """A language model. Every LM call of gift goes through :meth:`complete`."""

    name: ClassVar[str]
    #: True when :meth:`choice_probabilities` is available (needs token log-probabilities).
    supports_choice_probabilities: ClassVar[bool] = False
    #: The model identifier (a path, a hub name, a provider/model string).
    model: str = ""

    @abc.abstractmethod
    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        """Answer a chat. ``json_schema`` asks backends that can constrain decoding to emit such JSON."""

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        """P(answer = c) for each short answer ``c``, renormalised over ``choices``."""
        raise NotImplementedError(f"LM backend {self.name!r} has no log-probabilities; "
                                  f"use a backend with supports_choice_probabilities=True (llamacpp, transformers)")

    def identity(self) -> str:
        """Stable identity for caches: backend name and model."""
        return f"{self.name}:{self.model}"

    def provenance(self) -> dict[str, Any]:
        """What a result made with this LM records about it: ``identity`` and, for a model loaded from a
        file, ``model_path`` and ``model_sha256`` of the file actually loaded."""
        return {"identity": self.identity()}


#: Environment variable holding the request timeout of LM backends in seconds (``--lm-timeout`` sets it).
LM_TIMEOUT_ENV = "GIFT_LM_TIMEOUT"
#: Request timeout of backends that call a server, when neither an option nor the environment sets one.
DEFAULT_LM_TIMEOUT_S = 120.0


def lm_timeout_s(default: float | None = DEFAULT_LM_TIMEOUT_S) -> float | None:
    """The request timeout of LM backends in seconds: ``$GIFT_LM_TIMEOUT`` when set, else ``default``.

    A backend that calls a server gives up on a request (retries included) after this long. In-process
    backends (a model in this process) have nothing that can stall and are bounded by ``max_tokens``.
    """
    import os

    raw = os.environ.get(LM_TIMEOUT_ENV, "").strip()
    if not raw:
        return default
    try:
        value = float(raw)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        from gift.core.errors import ValidationError

        raise ValidationError(f"{LM_TIMEOUT_ENV}={raw!r}: the LM request timeout must be a positive number of "
                              f"seconds")
    return value


class IntentEstimator(abc.ABC):
    """J(D_H, D_¬H): infers the intent behind preferred-vs-default demonstrations."""

    name: ClassVar[str]

    @abc.abstractmethod
    def estimate(self, demonstrations: Sequence[DemonstrationPair], *, task_context: str = "",
                 objects: Sequence[str] = ()) -> Intent:
        """The inferred intent (with motivations and semantic axes over ``objects``)."""


class SimilarityKernel(abc.ABC):
    """K(s, s' | ω) on the semantic components of states: object-to-object similarity."""

    name: ClassVar[str]
    #: True when the kernel reads the intent (GIFT); False for surface kernels (vision, language).
    uses_intent: ClassVar[bool] = False

    @abc.abstractmethod
    def similarity(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                   intent: Intent | None = None) -> np.ndarray:
        """K as a matrix ``[n_test, n_train]`` with values in [0, 1]."""


class RelevanceKernel(SimilarityKernel):
    """A kernel that scores each object once per scene: how much it is one of the things the intent is about.

    The alignment contract (:func:`gift.core.alignment.score_alignment`) calls :meth:`score` exactly once
    per test scene; there is no hidden state between calls. K follows from the scores
    (:attr:`RelevanceScores.K`): the relevance of a test object in the columns of the relevant training
    objects, 0 elsewhere, so the paper's argmax rule gives the same decisions.
    """

    @abc.abstractmethod
    def score(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None = None,
              relevant_train: Sequence[str] = ()) -> RelevanceScores:
        """Relevance ``[n_test]``, leave-one-out training relevance ``[n_train]`` and the relevant mask.

        ``relevant_train``: the training objects the demonstrations treat as part of the goal (inferred
        from them, or given); empty: the kernel guesses them itself.
        """

    def score_with_answers(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None,
                           relevant_train: Sequence[str], answers: Mapping[str, bool]) -> RelevanceScores | None:
        """The scene scored again with the human's ``answers`` (test object name -> part of the goal?) as
        evidence next to the demonstrations, or None (the default) when the kernel cannot use answers: the
        query loop then only re-thresholds the first scores (:mod:`gift.core.queries`, rule 5).

        Called with one or more answers, each time the set of answers grows; the answered objects' own
        decisions are fixed by the query loop whatever this returns.
        """
        return None

    def similarity(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                   intent: Intent | None = None) -> np.ndarray:
        """``[n_test, n_train]`` from one :meth:`score` pass (no relevant training objects given)."""
        if not len(test) or not len(train):
            return np.zeros((len(test), len(train)))
        return self.score(test, train, intent).K


class AlignmentOperator(abc.ABC):
    """f_ω(s') = argmax_s K(s, s' | ω), or DISTRACTOR when nothing is similar enough."""

    name: ClassVar[str]

    @abc.abstractmethod
    def align(self, kernel: SimilarityKernel, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
              intent: Intent | None = None, *, relevant_train: Sequence[str] = ()) -> Alignment:
        """Map every test object to a training object or DISTRACTOR."""


class QueryPolicy(abc.ABC):
    """Chooses which test object to ask the human about next ("is it part of the goal?").

    A policy sees a :class:`~gift.core.queries.QueryState`: the scene's alignment scores (of every intent
    candidate, when there are several), the current cut, the answers so far and, where the scene's test
    trajectories are known, their error bounds. :func:`gift.core.queries.asking` asks the object
    :meth:`choose` returns, re-scores the scene with the answer and asks again.
    """

    name: ClassVar[str]

    @abc.abstractmethod
    def priority(self, state: QueryState, rng: np.random.Generator) -> np.ndarray:
        """``[n_test]``: how much an answer about each test object is worth now (higher is asked first).
        Values of objects already asked are ignored. ``rng``: the session's generator (random policies)."""

    def choose(self, state: QueryState, rng: np.random.Generator) -> str | None:
        """The object to ask about next, or None when every object was asked.

        The highest :meth:`priority` among the objects not yet asked; ties go to the object whose decision
        score is nearest the cut, then to the first in the scene's order (both compared at 12 decimals).
        """
        askable = np.flatnonzero(~state.asked)
        if askable.size == 0:
            return None
        pr = np.asarray(self.priority(state, rng), dtype=float).reshape(-1)
        if pr.shape != (len(state.test),) or not np.all(np.isfinite(pr[askable])):
            raise GiftError(f"query policy {self.name!r} returned {pr.shape} priorities (finite values needed for "
                            f"the {askable.size} objects not yet asked) for {len(state.test)} test objects")
        dist = np.round(np.abs(state.scores.decision - state.cut), 12)
        order = np.lexsort((askable, dist[askable], -np.round(pr[askable], 12)))
        return state.test[int(askable[order[0]])]


class RewardModel(abc.ABC):
    """R_θ(ξ), learned once from demonstrations; scores batches of trajectories."""

    name: ClassVar[str]

    @property
    @abc.abstractmethod
    def feature_specs(self) -> tuple[FeatureSpec, ...]:
        """The training feature columns the reward reads."""

    @abc.abstractmethod
    def fit(self, demonstrations: FeatureBatch, alternatives: FeatureBatch) -> "RewardModel":
        """Learn θ so that ``demonstrations`` are likely against ``alternatives`` (MaxEnt IRL)."""

    @abc.abstractmethod
    def score(self, features: FeatureBatch) -> np.ndarray:
        """R_θ(ξ) for N trajectories: ``[N]``. Columns are matched by feature name."""

    def score_aligned(self, features: FeatureBatch, alignment: Alignment) -> np.ndarray:
        """R̃_θ(ξ' | ω) = R_θ(f_ω(ξ')) for N test trajectories: ``[N]``."""
        from gift.core.alignment import align_features

        return self.score(align_features(features, alignment, self.feature_specs))

    @abc.abstractmethod
    def save(self, path: str | Path) -> None:
        """Write weights, feature names and metadata."""

    @classmethod
    @abc.abstractmethod
    def load(cls, path: str | Path) -> "RewardModel":
        """Read what :meth:`save` wrote."""
