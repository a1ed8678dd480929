"""The hooks of gift-example-task (named by the ``[project.entry-points.gift]`` line of its pyproject)."""

import gift


@gift.hookimpl
def gift_register_tasks(register):
    from gift_example_task.family import PackBackpackLow

    register(PackBackpackLow.name, PackBackpackLow, description="pack objects into the backpack, carrying them low")


def drake_motion():
    """The Drake scenes and actions of pack_backpack_low (imports gift-sim-drake only when used)."""
    from gift_example_task.motions import PackBackpackLowMotion

    return PackBackpackLowMotion()


@gift.hookimpl
def gift_register_motions(register):
    register("drake/pack_backpack_low", drake_motion, description="pack_backpack scenes with high and low carries")
