"""Plain JSON values from the numpy/attrs-free containers that results and metadata are built of, and the
one strict JSON writer of gift's result files.

Every result file and every ``--json`` output of gift is strict JSON (RFC 8259): parsers in other languages
(``jq``, JavaScript's ``JSON.parse``, Go, Rust) read it. JSON has no NaN or infinity, so a value that is not
a finite number, such as the AUC of a subset with only one class, is written as ``null``, meaning "not
defined here"; readers that average such values skip the nulls. :func:`dumps` and :func:`write_json` refuse
to write a bare ``NaN``/``Infinity`` (``allow_nan=False``), so one cannot slip through.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

#: What :func:`to_jsonable` does with NaN and ±inf: write ``null`` (``"null"``, the rule for result files),
#: write it as a string (``"nan"``, ``"inf"``, ``"-inf"``; for files that must round-trip the value),
#: write ``null`` for NaN only (``"null-nan"``; ±inf stay floats), or keep the float (``"keep"``: Python's
#: ``json`` then writes the non-standard ``NaN``/``Infinity``, which strict parsers reject).
NONFINITE = ("null", "string", "null-nan", "keep")


def to_jsonable(value: Any, nonfinite: str = "keep") -> Any:
    """``value`` with mappings as ``{str: ...}``, tuples as lists, numpy arrays and scalars as Python values.

    Non-finite floats (also inside numpy arrays) follow ``nonfinite`` (see :data:`NONFINITE`).
    """
    if nonfinite not in NONFINITE:
        raise ValueError(f"to_jsonable: nonfinite must be one of {NONFINITE}, got {nonfinite!r}")
    return _convert(value, nonfinite)


def _convert(value: Any, nonfinite: str) -> Any:
    if isinstance(value, Mapping):
        return {str(k): _convert(v, nonfinite) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_convert(v, nonfinite) for v in value]
    if isinstance(value, np.ndarray):
        if nonfinite != "keep" and value.dtype.kind in "fc" and not np.isfinite(value).all():
            return _convert(value.tolist(), nonfinite)  # only arrays that hold a NaN/inf pay for the walk
        return value.tolist()
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        if nonfinite == "null":
            return None
        if nonfinite == "string":
            return str(value)
        if nonfinite == "null-nan" and math.isnan(value):
            return None
    return value


def dumps(value: Any, *, nonfinite: str = "null", **kwargs: Any) -> str:
    """Strict JSON text of ``value`` (after :func:`to_jsonable`); ``kwargs`` go to :func:`json.dumps`.

    ``nonfinite`` must map every NaN/±inf to something JSON has (``"null"`` or ``"string"``); a value that
    is still not finite raises ``ValueError`` naming where it is.
    """
    data = to_jsonable(value, nonfinite)
    try:
        return json.dumps(data, allow_nan=False, **kwargs)
    except ValueError as e:
        where = _first_nonfinite(data)
        raise ValueError(f"not strict JSON: the non-finite number at {where or '?'} ({e}); "
                         f"use nonfinite='null' or 'string'") from None


def write_json(path: str | os.PathLike, value: Any, *, nonfinite: str = "null", indent: int | None = 2,
               **kwargs: Any) -> Path:
    """Write ``value`` as strict JSON (:func:`dumps`) to ``path`` atomically (a temporary file renamed over it),
    so a reader never sees half a file and a failed write leaves the previous file as it was."""
    path = Path(path)
    text = dumps(value, nonfinite=nonfinite, indent=indent, **kwargs)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text + "\n")
            f.flush()
            os.fsync(f.fileno())  # on disk before the rename makes it the file
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def finite_values(values: Iterable[Any]) -> list[float]:
    """The values that are finite numbers (``null``/None, NaN and ±inf are missing): what means average over."""
    out = []
    for v in values:
        if isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and math.isfinite(v):
            out.append(float(v))
    return out


def _first_nonfinite(value: Any, path: str = "$") -> str | None:
    if isinstance(value, float) and not math.isfinite(value):
        return path
    if isinstance(value, dict):
        for k, v in value.items():
            found = _first_nonfinite(v, f"{path}.{k}")
            if found:
                return found
    elif isinstance(value, list):
        for i, v in enumerate(value):
            found = _first_nonfinite(v, f"{path}[{i}]")
            if found:
                return found
    return None
