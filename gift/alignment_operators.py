"""Built-in alignment operators (a built-in plugin): ``argmax-threshold`` from :mod:`gift.core.alignment`."""

from __future__ import annotations

from gift.core.alignment import ArgmaxThresholdAlignment
from gift.plugins.hookspecs import hookimpl


@hookimpl
def gift_register_alignment_operators(register):
    register(ArgmaxThresholdAlignment, description="argmax over training objects, distractor below a threshold "
                                                   "(oracle | non-oracle | train-calibrated | float)")
