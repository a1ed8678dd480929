"""The study layer: the one chain from a suite intent to alignment metrics and win rates.

- :mod:`gift.study.components`: building registered components from specs (one builder, one cache per process).
- :mod:`gift.study.scenes`: scenes, training sets (demonstrations) and test scenes.
- :mod:`gift.study.chain`: :class:`StudyConfig` and the chain of one intent (:func:`run_intent`).
- :mod:`gift.study.sweeps`: many intents on an executor (:func:`run_study`, :func:`evaluate_alignment`).
- :mod:`gift.study.stages`: stage caches keyed by everything a stage depends on.

``gift reproduce``, ``gift demo``, ``gift evaluate-alignment``, :class:`gift.GiftPipeline` and
``examples/pipeline.py`` all run this code.
"""

from gift.study.chain import ALL_KERNELS, ORACLE, IntentJob, StudyConfig, intent_seeds, run_intent
from gift.study.components import Components, build, components_for, parse_spec
from gift.study.progress import Progress
from gift.study.scenes import TrainingSet, load_training_set, save_training_set, training_set
from gift.study.sweeps import evaluate_alignment, run_study

__all__ = ["ALL_KERNELS", "ORACLE", "Components", "IntentJob", "Progress", "StudyConfig", "TrainingSet", "build",
           "components_for", "evaluate_alignment", "intent_seeds", "load_training_set", "parse_spec", "run_intent",
           "run_study", "save_training_set", "training_set"]
