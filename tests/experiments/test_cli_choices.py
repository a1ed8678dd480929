"""``gift reproduce`` / ``gift demo`` take --robot, --reward and --kernels from the plugin registry: a plugin's
robot, reward model or kernel is a valid choice without any change to the CLI, unknown names are clear errors
(argparse choices for --robot and --reward, a check of every kernel spec for --kernels)."""

from __future__ import annotations

import types

import numpy as np
import pytest

import gift
from gift.cli import build_parser, main
from gift.core.interfaces import SimilarityKernel
from gift.study.chain import simulator_name
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

    register(attrs.evolve(ROBOTS["franka"], name="franka-left", mount=(0, 0.1, 0, 0, 0, 0)))


@gift.hookimpl
def gift_register_kernels(register):
    register("ones", OnesKernel)


@gift.hookimpl
def gift_register_reward_models(register):
    maxent = gift.get_manager().get("reward_model", "maxent-linear").factory

    def copy_of_linear(**options):
        """maxent-linear under another name."""
        model = maxent(**options)
        model.name = "copy-of-linear"
        return model

    register("copy-of-linear", copy_of_linear)


@pytest.fixture
def third_party(fresh_plugins):
    gift.get_manager().register_plugin(types.SimpleNamespace(
        gift_register_robots=gift_register_robots, gift_register_kernels=gift_register_kernels,
        gift_register_reward_models=gift_register_reward_models), name="third_party", distribution="third-party")
    return gift.get_manager()


def test_choices_come_from_the_registry(third_party):
    parser = build_parser()
    args = parser.parse_args(["reproduce", "--robot", "franka-left", "--reward", "copy-of-linear",
                              "--kernels", "language, ones,language:use_descriptions=true"])
    cfg = _config_from_args(args)
    assert (cfg.robot, cfg.reward) == ("franka-left", "copy-of-linear")
    assert cfg.kernels == ("language", "ones", "language:use_descriptions=true")
    assert third_party.simulators_for_robot("franka-left") == ["drake-franka-left"]  # built by gift-sim-drake
    assert gift.robot_simulator("franka-left") == simulator_name("franka-left") == "drake-franka-left"
    assert parser.parse_args(["demo", "--robot", "franka-left"]).robot == "franka-left"
    assert parser.parse_args(["demo"]).robot == "jaco"
    assert "franka-left" in parser.parse_args(["evaluate-alignment", "--suite", "s", "--kernels", "ones",
                                               "--robot", "franka-left"]).robot


@pytest.mark.parametrize("argv,message", [
    (["demo", "--robot", "r2d2"], "argument --robot: invalid choice: 'r2d2' (choose from 'franka', 'jaco'"),
    (["reproduce", "--robot", "drake-jaco"], "argument --robot: invalid choice: 'drake-jaco'"),
    (["reproduce", "--reward", "best"], "argument --reward: invalid choice: 'best' (choose from 'maxent-linear'"),
])
def test_unknown_robots_and_rewards_are_argparse_errors(fresh_plugins, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args(argv)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("command", ["reproduce", "demo"])
def test_unknown_kernels_are_clear_errors_before_anything_runs(fresh_plugins, capsys, tmp_path, command):
    assert main([command, "--kernels", "language,nope", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert f"gift {command}: error: unknown kernel(s) ['nope']; registered kernels: gift, gift-prob, language" in err
    assert not any(tmp_path.iterdir())  # nothing ran
