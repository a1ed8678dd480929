"""The hooks of gift-example-robot (named by the ``[project.entry-points.gift]`` line of its pyproject)."""

import gift


@gift.hookimpl
def gift_register_robots(register):
    from gift_example_robot.robot import UR5E

    register(UR5E)  # registered under UR5E.name
