"""Robots as plugins, without any simulator: RobotSpec validation, the gift_register_robots hook, and the
per-robot simulator hook (called for robots registered before or after the simulator plugin)."""

from __future__ import annotations

import types
from pathlib import Path

import attrs
import pytest

import gift
from gift.core.errors import PluginError, UnknownComponentError, ValidationError
from gift.core.robots import RobotSpec
from gift.plugins.manager import GiftPluginManager, PluginWarning

URDF = "<robot name='arm'/>"


@pytest.fixture
def urdf(tmp_path) -> Path:
    path = tmp_path / "arm.urdf"
    path.write_text(URDF)
    return path


def spec(name: str, urdf: Path, **kw) -> RobotSpec:
    return RobotSpec(name, str(urdf), "base", "tcp", rest=(0.0, 0.5), description=f"the {name} arm", **kw)


def robot_plugin(*specs: RobotSpec, register_as: str | None = None) -> types.SimpleNamespace:
    @gift.hookimpl
    def gift_register_robots(register):
        for s in specs:
            register(register_as or s.name, s)

    return types.SimpleNamespace(gift_register_robots=gift_register_robots)


def simulator_plugin(calls: list) -> types.SimpleNamespace:
    """Registers ``toy-<robot>`` for every robot, like gift-sim-drake registers ``drake-<robot>``."""

    @gift.hookimpl
    def gift_register_robot_simulators(register, robot):
        calls.append(robot.name)
        register(f"toy-{robot.name}", lambda robot=robot, **kw: ("toy simulator", robot.name, kw))

    return types.SimpleNamespace(gift_register_robot_simulators=gift_register_robot_simulators)


def manager(*plugins: tuple[str, object]) -> GiftPluginManager:
    m = GiftPluginManager()
    for name, plugin in plugins:
        m.register_plugin(plugin, name=name, distribution=f"dist-{name}")
    return m.load([])


def test_robot_spec_holds_plain_data_with_clear_errors(urdf, tmp_path):
    s = spec("arm-2", urdf, mount=(0, 0, 0.1, 0, 0, 3.14))
    assert s.dof == 2 and s.urdf_path == urdf and s.mount[2] == 0.1 and s.rest == (0.0, 0.5)
    assert attrs.evolve(s) == s and hash(attrs.evolve(s)) == hash(s)  # frozen, hashable
    with pytest.raises(ValidationError, match=r"RobotSpec.name must be lower-case letters.*got 'My Arm'"):
        spec("My Arm", urdf)
    with pytest.raises(ValidationError, match=r"rest must be a non-empty sequence of finite joint angles"):
        RobotSpec("arm", str(urdf), "base", "tcp", rest=(0.0, float("nan")))
    with pytest.raises(ValidationError, match=r"expected a sequence of numbers, got the string '0 1'"):
        RobotSpec("arm", str(urdf), "base", "tcp", rest="0 1")
    with pytest.raises(ValidationError, match=r"mount must be 6 finite numbers"):
        spec("arm", urdf, mount=(0, 0, 0))
    with pytest.raises(ValidationError, match=r"ee_link must be a non-empty string"):
        RobotSpec("arm", str(urdf), "base", "", rest=(0.0,))
    with pytest.raises(ValidationError, match=r"urdf 'arm.urdf' is a relative path without a package"):
        RobotSpec("arm", "arm.urdf", "base", "tcp", rest=(0.0,))
    with pytest.raises(ValidationError, match=r"URDF file 'robots/nope.urdf' in package 'gift' not found"):
        RobotSpec("arm", "robots/nope.urdf", "base", "tcp", rest=(0.0,), package="gift").urdf_path
    with pytest.raises(ValidationError, match=r"its URDF lives in package 'no_such_pkg', which is not importable"):
        RobotSpec("arm", "a.urdf", "base", "tcp", rest=(0.0,), package="no_such_pkg").urdf_path
    shipped = RobotSpec("arm", "suites/gift-paper.yaml", "base", "tcp", rest=(0.0,), package="gift")
    assert shipped.urdf_path.is_file()  # a package resource resolves to a file on disk


def test_robots_register_by_name_and_are_looked_up_as_specs(urdf):
    a, b = spec("arm-a", urdf), spec("arm-b", urdf)
    m = manager(("robots", robot_plugin(a, b)))
    assert m.names("robot") == ["arm-a", "arm-b"]
    assert m.create("robot", "arm-a") is a
    comp = m.get("robot", "arm-b")
    assert (comp.distribution, comp.description) == ("dist-robots", "the arm-b arm")
    with pytest.raises(PluginError, match=r"robot 'arm-a' is a RobotSpec and takes no options, got \['speed'\]"):
        m.create("robot", "arm-a", speed=2)
    with pytest.raises(UnknownComponentError, match=r"no robot named 'arm-c'; registered: arm-a, arm-b"):
        m.simulators_for_robot("arm-c")
    assert m.simulators_for_robot("arm-a") == []  # no simulator plugin


def test_bad_robot_registrations_name_the_plugin(urdf):
    with pytest.raises(PluginError, match=r"plugin 'typo' registered robot 'arm-b' with a RobotSpec named 'arm-a'; "
                                          r"the two names must agree"):
        manager(("typo", robot_plugin(spec("arm-a", urdf), register_as="arm-b")))

    @gift.hookimpl
    def gift_register_robots(register):
        register("arm", {"urdf": "arm.urdf"})

    with pytest.raises(PluginError, match=r"plugin 'dicts' registered robot 'arm' as a dict; register a "
                                          r"gift.core.robots.RobotSpec"):
        manager(("dicts", types.SimpleNamespace(gift_register_robots=gift_register_robots)))
    with pytest.raises(PluginError, match=r"two plugins register the robot 'arm-a': 'first'"):
        manager(("first", robot_plugin(spec("arm-a", urdf))), ("second", robot_plugin(spec("arm-a", urdf))))


def test_a_simulator_plugin_builds_one_simulator_per_robot_of_any_plugin(urdf):
    calls: list[str] = []
    m = manager(("sims", simulator_plugin(calls)), ("robots", robot_plugin(spec("arm-a", urdf), spec("arm-b", urdf))))
    assert sorted(calls) == ["arm-a", "arm-b"]  # once per robot, after every robot is collected
    assert m.simulators_for_robot("arm-a") == ["toy-arm-a"]
    comp = m.get("simulator", "toy-arm-b")
    assert comp.extra["robot"] == "arm-b" and comp.plugin == "sims" and comp.distribution == "dist-sims"
    assert m.create("simulator", "toy-arm-a", size=3) == ("toy simulator", "arm-a", {"size": 3})
    # a robot plugin registered later gets its simulators too, and only its own are added
    m.register_plugin(robot_plugin(spec("arm-c", urdf)), name="late-robot")
    assert calls.count("arm-c") == 1 and calls.count("arm-a") == 1
    assert m.simulators_for_robot("arm-c") == ["toy-arm-c"]
    # a simulator plugin registered later builds for the robots already known
    late: list[str] = []

    @gift.hookimpl
    def gift_register_robot_simulators(register, robot):
        late.append(robot.name)
        register(f"other-{robot.name}", object)

    m.register_plugin(types.SimpleNamespace(gift_register_robot_simulators=gift_register_robot_simulators),
                      name="late-sims")
    assert sorted(late) == ["arm-a", "arm-b", "arm-c"] and calls.count("arm-a") == 1
    assert m.simulators_for_robot("arm-a") == ["other-arm-a", "toy-arm-a"]


def test_a_failing_robot_simulator_hook_is_skipped_with_a_warning(urdf):
    @gift.hookimpl
    def gift_register_robot_simulators(register, robot):
        raise RuntimeError("no such arm model")

    with pytest.warns(PluginWarning, match=r"hook gift_register_robot_simulators raised RuntimeError: no such arm "
                                           r"model for robot 'arm-a'"):
        m = manager(("broken", types.SimpleNamespace(gift_register_robot_simulators=gift_register_robot_simulators)),
                    ("robots", robot_plugin(spec("arm-a", urdf))))
    assert m.names("robot") == ["arm-a"] and m.simulators_for_robot("arm-a") == []
    assert "gift_register_robot_simulators(arm-a)" in m.failed["broken"]


def test_gift_get_robot_and_robot_simulator(urdf, monkeypatch):
    calls: list[str] = []
    m = manager(("robots", robot_plugin(spec("arm-a", urdf))))
    monkeypatch.setattr(gift, "get_manager", lambda: m)
    assert gift.get_robot("arm-a").name == "arm-a"
    with pytest.raises(UnknownComponentError, match=r"robot 'arm-a' is registered but no simulator is built for it"):
        gift.robot_simulator("arm-a")
    m.register_plugin(simulator_plugin(calls), name="sims")
    assert gift.robot_simulator("arm-a") == "toy-arm-a"
    with pytest.raises(UnknownComponentError, match=r"no robot named 'arm-z'; registered: arm-a"):
        gift.robot_simulator("arm-z")
