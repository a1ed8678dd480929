"""Drake motions of its own for ``pack_backpack_low``: every object can be packed with the usual high carry
or with a low one, so the simulator's ``preferred`` generator can show what this family's human wants.

Registered as ``drake/pack_backpack_low`` through the ``gift_register_motions`` hook (see :mod:`.plugin`);
needs gift-sim-drake, imported only when the Drake simulator stages this family.
"""

from __future__ import annotations

import numpy as np

from gift.core.data import Scene
from gift_sim_drake.families import ActionSet
from gift_sim_drake.plant import CONTAINERS
from gift_sim_drake.tabletop import ContainerFamily

#: The low carry: lift (m above the object's centre, at least ``LOW_MIN``) and cross the table at that
#: height, then clear the backpack's walls by ``LOW_CLEARANCE`` m (the usual carry: 15 cm up, at least
#: 25 cm, across at the height over the backpack, which it clears by 8 cm).
LOW_LIFT, LOW_MIN, LOW_CLEARANCE = 0.05, 0.08, 0.04


class PackBackpackLowMotion(ContainerFamily):
    """The scenes of ``pack_backpack`` (same layout, same backpack); per object two actions: the usual
    pick-and-place (actions ``0..n-1``) and one that carries the object low (``n..2n-1``)."""

    def __init__(self) -> None:
        super().__init__("pack_backpack_low", "backpack")

    def actions(self, scene: Scene) -> ActionSet:
        usual = super().actions(scene)  # keyframes: pre-grasp, grasp, lift, transit, above, place
        low = usual.targets.copy()
        z = np.asarray(scene.positions)[:, 2]
        low[:, 2, 2] = np.maximum(z + LOW_LIFT, LOW_MIN)  # lift just off the table
        above = CONTAINERS[self.landmark]["height"] + LOW_CLEARANCE
        low[:, 3, 2] = low[:, 2, 2]  # across the table at that height
        low[:, 4, 2] = above  # rise only at the backpack, just over its walls
        return ActionSet(np.concatenate([usual.targets, low]), usual.times, np.concatenate([usual.carried] * 2),
                         usual.attach, usual.detach, usual.push,
                         usual.labels + tuple(f"{label}, carried low" for label in usual.labels),
                         usual.nominal)  # the intent-blind controller carries high, as in pack_backpack
