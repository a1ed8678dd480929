"""gift-example-task: a new task family for gift (see docs/tutorials/task-plugin.md)."""

from gift_example_task.family import LIFT_PENALTY, PackBackpackLow
from gift_example_task.demos import sample_demonstrations

__all__ = ["LIFT_PENALTY", "PackBackpackLow", "sample_demonstrations"]
