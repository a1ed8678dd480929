"""MaxEnt IRL learning: the linear model recovers θ, the neural model matches or beats it."""

from __future__ import annotations

import numpy as np
import pytest
from reward_data import boltzmann_demonstrations, random_specs, random_traces

import gift
from gift.core.metrics import cosine, mean_se, pairwise_win_rate, sample_pairs
from gift_rewards import LinearMaxEntReward, NeuralMaxEntReward, aggregate, aggregate_names, maxent_objective

N_STEPS = 21


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_linear_maxent_recovers_known_theta(seed):
    rng = np.random.default_rng(seed)
    specs = random_specs(4)
    theta = rng.normal(0.0, 1.0, 2 * len(specs))
    theta *= 6.0 / np.linalg.norm(theta)
    pool = random_traces(specs, 3000, N_STEPS, rng)
    demos = boltzmann_demonstrations(pool, lambda fb: aggregate(fb.values) @ theta, 400, rng)
    alternatives = random_traces(specs, 2000, N_STEPS, rng)

    model = LinearMaxEntReward().fit(demos, alternatives)

    assert model.fit_info["converged"], model.fit_info
    assert float(cosine(model.theta[None], theta[None])[0, 0]) >= 0.95
    # weights come back named by φ component
    names = aggregate_names([s.name for s in specs])
    assert list(model.weights) == list(names)
    assert model.weights["final:obj0_proximity_to_box"] == model.theta[len(specs)]


def test_linear_objective_gradient_is_exact():
    rng = np.random.default_rng(5)
    phi_demo, phi_all = rng.normal(size=(7, 6)), rng.normal(size=(30, 6))
    theta = rng.normal(size=6)
    value, grad = maxent_objective(theta, phi_demo, phi_all, -np.log(30), 0.1)
    eps = 1e-6
    numeric = [(maxent_objective(theta + eps * e, phi_demo, phi_all, -np.log(30), 0.1)[0]
                - maxent_objective(theta - eps * e, phi_demo, phi_all, -np.log(30), 0.1)[0]) / (2 * eps)
               for e in np.eye(6)]
    np.testing.assert_allclose(grad, numeric, rtol=1e-5, atol=1e-7)


def _linear_truth(fb):
    return aggregate(fb.values) @ (2.0 * np.array([1.0, -1.0, 0.5, 0.0, 3.0, -2.0, 1.0, -0.5]))


def _nonlinear_truth(fb):
    # the first object should end half-way, the other two at the same closeness: not linear in φ
    final = fb.values[:, -1, :]
    return -12.0 * np.abs(final[:, 0] - 0.5) - 6.0 * np.abs(final[:, 1] - final[:, 2])


def _win_rates(truth, seeds=(0, 1, 2)):
    specs = random_specs(3)
    linear, neural = [], []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        pool = random_traces(specs, 3000, N_STEPS, rng)
        demos = boltzmann_demonstrations(pool, truth, 300, rng)
        alternatives = random_traces(specs, 1500, N_STEPS, rng)
        test = random_traces(specs, 400, N_STEPS, rng)
        pairs = sample_pairs(len(test), 3000, rng)
        lin = gift.get_reward_model("maxent-linear").fit(demos, alternatives)
        net = gift.get_reward_model("maxent-neural", seed=seed).fit(demos, alternatives)
        assert isinstance(net, NeuralMaxEntReward) and net.fit_info["best_epoch"] >= 1
        linear.append(pairwise_win_rate(lin.score(test), truth(test), pairs))
        neural.append(pairwise_win_rate(net.score(test), truth(test), pairs))
    return mean_se(linear), mean_se(neural)


@pytest.mark.slow
def test_neural_matches_linear_on_linear_ground_truth():
    (lin, lin_se), (net, net_se) = _win_rates(_linear_truth)
    print(f"linear truth: linear {lin:.3f}±{lin_se:.3f}, neural {net:.3f}±{net_se:.3f}")
    assert lin >= 0.9
    assert abs(net - lin) <= 0.03


@pytest.mark.slow
def test_neural_beats_linear_on_nonlinear_ground_truth():
    (lin, lin_se), (net, net_se) = _win_rates(_nonlinear_truth)
    print(f"nonlinear truth: linear {lin:.3f}±{lin_se:.3f}, neural {net:.3f}±{net_se:.3f}")
    assert net >= 0.8
    assert net - lin >= 0.2
    assert net - lin > 3 * (lin_se + net_se)


def test_neural_training_is_seeded():
    rng = np.random.default_rng(3)
    specs = random_specs(2)
    demos, alternatives = random_traces(specs, 40, 11, rng), random_traces(specs, 200, 11, rng)
    test = random_traces(specs, 50, 11, rng)
    a = NeuralMaxEntReward(seed=7, max_epochs=60).fit(demos, alternatives).score(test)
    b = NeuralMaxEntReward(seed=7, max_epochs=60).fit(demos, alternatives).score(test)
    np.testing.assert_array_equal(a, b)


def test_neural_scores_in_numpy_match_torch_forward():
    torch = pytest.importorskip("torch")
    rng = np.random.default_rng(4)
    specs = random_specs(2)
    model = NeuralMaxEntReward(max_epochs=30).fit(random_traces(specs, 30, 9, rng), random_traces(specs, 90, 9, rng))
    test = random_traces(specs, 5000, 9, rng)  # more than one scoring block
    x = torch.from_numpy((test.values - model.mean) / model.std)
    h = x
    for w, b in model.layers[:-1]:
        h = torch.tanh(h @ torch.from_numpy(w).T + torch.from_numpy(b))
    w, b = model.layers[-1]
    out = (h @ torch.from_numpy(w).T + torch.from_numpy(b)).numpy()
    np.testing.assert_allclose(model.score(test), out[..., 0].mean(axis=1) + out[:, -1, 1], rtol=1e-10, atol=1e-10)
