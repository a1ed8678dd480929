"""``gift reproduce`` / ``gift demo`` take --robot, --reward and --kernels from the plugin registry: a plugin's
robot, reward model or kernel is a valid choice without any change to the CLI, unknown names are clear errors."""

from __future__ import annotations

import types

import numpy as np
import pytest

import gift
from gift.cli import build_parser
from gift.core.interfaces import SimilarityKernel
from gift_experiments.plugin import _config_from_args
from gift_sim_drake.robots import ROBOTS


class OnesKernel(SimilarityKernel):
    """Every pair is similar."""

    name = "ones"

    def similarity(self, test, train, intent=None):
        return np.ones((len(test), len(train)))


@gift.hookimpl
def gift_register_robots(register):
    import attrs

    register("franka-left", attrs.evolve(ROBOTS["franka"], name="franka-left", mount=(0, 0.1, 0, 0, 0, 0)))


@gift.hookimpl
def gift_register_kernels(register):
    register("ones", OnesKernel)


@gift.hookimpl
def gift_register_reward_models(register):
    register("copy-of-linear", gift.get_manager().get("reward_model", "maxent-linear").factory)


@pytest.fixture
def third_party(fresh_plugins):
    gift.get_manager().register_plugin(types.SimpleNamespace(
        gift_register_robots=gift_register_robots, gift_register_kernels=gift_register_kernels,
        gift_register_reward_models=gift_register_reward_models), name="third_party", distribution="third-party")
    return gift.get_manager()


def test_choices_come_from_the_registry(third_party):
    parser = build_parser()
    args = parser.parse_args(["reproduce", "--robot", "franka-left", "--reward", "copy-of-linear",
                              "--kernels", "language, ones"])
    cfg = _config_from_args(args)
    assert (cfg.robot, cfg.reward, cfg.kernels) == ("franka-left", "copy-of-linear", ("language", "ones"))
    assert third_party.simulators_for_robot("franka-left") == ["drake-franka-left"]  # built by gift-sim-drake
    assert gift.robot_simulator("franka-left") == "drake-franka-left"
    demo = parser.parse_args(["demo", "--robot", "franka-left", "--kernels", "ones"])
    assert (demo.robot, demo.kernels) == ("franka-left", ("ones",))
    assert parser.parse_args(["demo"]).robot == "jaco"


@pytest.mark.parametrize("argv,message", [
    (["reproduce", "--kernels", "language,nope"],
     "argument --kernels: unknown kernel(s) 'nope'; registered kernels: gift, gift-prob, language"),
    (["demo", "--kernels", ","], "argument --kernels: give at least one kernel"),
    (["demo", "--robot", "r2d2"], "argument --robot: invalid choice: 'r2d2' (choose from 'franka', 'jaco'"),
    (["reproduce", "--reward", "best"], "argument --reward: invalid choice: 'best' (choose from 'maxent-linear'"),
])
def test_unknown_names_are_clear_errors(fresh_plugins, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args(argv)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
