"""Plain JSON values from the numpy/attrs-free containers that results and metadata are built of."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

#: What :func:`to_jsonable` does with NaN and ±inf: keep the float (``json`` writes ``NaN``/``Infinity``,
#: which Python reads back), write it as a string (``"nan"``, ``"inf"``), write ``null`` for NaN only
#: (``null-nan``), or ``null`` for every non-finite value, array elements included (``null``: strict JSON).
NONFINITE = ("keep", "string", "null-nan", "null")


def to_jsonable(value: Any, nonfinite: str = "keep") -> Any:
    """``value`` with mappings as ``{str: ...}``, tuples as lists, numpy arrays and scalars as Python values."""
    if nonfinite not in NONFINITE:
        raise ValueError(f"to_jsonable: nonfinite must be one of {NONFINITE}, got {nonfinite!r}")
    return _convert(value, nonfinite)


def _convert(value: Any, nonfinite: str) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _convert(v, nonfinite) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_convert(v, nonfinite) for v in value]
    if isinstance(value, np.ndarray):  # element values as they are (arrays hold data, not metadata)
        if nonfinite == "null" and value.dtype.kind == "f" and not np.all(np.isfinite(value)):
            return _convert(value.tolist(), nonfinite)
        return value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        if nonfinite == "string":
            return str(value)
        if nonfinite == "null-nan" and math.isnan(value):
            return None
        if nonfinite == "null":
            return None
    return value
