"""gift-example-robot: a Universal Robots UR5e for gift (see docs/tutorials/robot-plugin.md)."""

from gift_example_robot.robot import UR5E

__all__ = ["UR5E"]
