"""The objects and cases the Drake simulator tests use."""

from __future__ import annotations

from gift.core.data import Appearance, ObjectSpec

OBJECTS = (
    ObjectSpec("paintbrush", "a brush for painting", Appearance("cylinder", (0.015, 0.18), (0.8, 0.55, 0.2))),
    ObjectSpec("banana", "a ripe banana", Appearance("box", (0.18, 0.04, 0.04), (0.95, 0.85, 0.2))),
    ObjectSpec("sketchbook", "a book of drawing paper", Appearance("box", (0.2, 0.15, 0.02), (0.9, 0.9, 0.85))),
    ObjectSpec("coffee mug", "a ceramic mug", Appearance("cylinder", (0.04, 0.1), (0.2, 0.2, 0.25))),
)
RELEVANT = ("paintbrush", "sketchbook")
FAMILIES = ("pack_backpack", "store_drawer", "sweep_spill", "place_mug")
#: The built-in arms and the example package's 6-DoF UR5e (registered by the conftest).
ROBOTS = ("drake-franka", "drake-jaco", "drake-ur5e")
