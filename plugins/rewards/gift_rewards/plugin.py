"""Entry point of gift_rewards: registers its reward models with gift."""

from gift.plugins.hookspecs import hookimpl
from gift_rewards.linear_maxent import LinearMaxEntReward
from gift_rewards.neural_maxent import NeuralMaxEntReward


@hookimpl
def gift_register_reward_models(register):
    register(LinearMaxEntReward.name, LinearMaxEntReward,
             description="linear MaxEnt IRL on time-aggregated features (mean and final step), numpy/scipy")
    register(NeuralMaxEntReward.name, NeuralMaxEntReward,
             description="MLP per-step reward summed over time, MaxEnt IRL in torch (CPU), early stopping")
