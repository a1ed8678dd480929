"""The hooks of gift-example-task (named by the ``[project.entry-points.gift]`` line of its pyproject)."""

import gift


@gift.hookimpl
def gift_register_tasks(register):
    from gift_example_task.family import PackBackpackLow

    register(PackBackpackLow.name, PackBackpackLow, description="pack objects into the backpack, carrying them low")
