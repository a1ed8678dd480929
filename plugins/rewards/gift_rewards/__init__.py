"""gift_rewards: MaxEnt IRL reward models for gift and their batched (aligned) scoring.

- ``maxent-linear`` (:class:`LinearMaxEntReward`): R_θ(ξ) = θ · φ(ξ), numpy/scipy.
- ``maxent-neural`` (:class:`NeuralMaxEntReward`): per-step MLP reward summed over time, torch on the CPU.

Both score ``[N, T, F]`` batches in one vectorized call (:meth:`score`), and test scenes through the
core's column-remap alignment (:meth:`score_aligned`). :func:`load_reward` reads any saved reward.
"""

from __future__ import annotations

from pathlib import Path

from gift_rewards.linear_maxent import LinearMaxEntReward, maxent_objective
from gift_rewards.maxent_irl import MaxEntReward, NotFittedError, read_reward_file
from gift_rewards.neural_maxent import NeuralMaxEntReward
from gift_rewards.trajectory_features import aggregate, aggregate_names

REWARD_CLASSES: dict[str, type[MaxEntReward]] = {cls.name: cls for cls in (LinearMaxEntReward, NeuralMaxEntReward)}


def load_reward(path: str | Path) -> MaxEntReward:
    """Load a reward saved by :meth:`MaxEntReward.save`, whatever its kind."""
    from gift.core.errors import ValidationError

    kind = read_reward_file(path)["model"]
    if kind not in REWARD_CLASSES:
        raise ValidationError(f"{path}: unknown reward kind {kind!r}; known: {sorted(REWARD_CLASSES)}")
    return REWARD_CLASSES[kind].load(path)


__all__ = ["LinearMaxEntReward", "NeuralMaxEntReward", "MaxEntReward", "NotFittedError", "REWARD_CLASSES",
           "aggregate", "aggregate_names", "load_reward", "maxent_objective", "read_reward_file"]
