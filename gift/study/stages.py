"""Stage caches: a finished stage of a study is read back instead of recomputed, never mistaken for another.

A stage file ``<root>/stages/<intent>/<stage>-<key>.json`` holds ``{"stage", "inputs", "value"}``. The key
is a hash of *everything the value depends on* (:meth:`StageCache.key`): the stage's own inputs as the
study passes them (the intent's suite entry and object catalog, sizes and seeds, the component specs
and options, the resolved LM identity and its model file's hash), plus :func:`gift.core.provenance.code_version`.
Change any of them and the stage is recomputed; the old file stays.

Writes are strict JSON and atomic (:func:`gift.core.serialization.write_json`); the value a stage returns
is the one read back, so a fresh run and a resumed one see the same thing (NaN as None). A stage file that
cannot be read (truncated, not JSON, not a stage) is moved aside as ``*.corrupt`` with a warning naming
it, and the stage is recomputed.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from gift.core.provenance import code_version
from gift.core.serialization import to_jsonable, write_json

log = logging.getLogger(__name__)


def digest(value: Any, n: int = 16) -> str:
    """A stable hash of a JSON-able value (keys sorted)."""
    text = json.dumps(to_jsonable(value, nonfinite="string"), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:n]


class StageCache:
    """JSON values of finished stages under ``root/stages``; ``root=None`` caches nothing."""

    def __init__(self, root: str | os.PathLike | None) -> None:
        self.root = None if root is None else Path(root) / "stages"
        #: stage files recomputed because they could not be read (for the run's failure report)
        self.recovered: list[str] = []

    @staticmethod
    def key(inputs: Mapping[str, Any]) -> str:
        return digest({"inputs": inputs, "code": code_version()})

    def path(self, group: str, stage: str, inputs: Mapping[str, Any]) -> Path | None:
        if self.root is None:
            return None
        return self.root / _safe(group) / f"{_safe(stage)}-{self.key(inputs)}.json"

    def get_or_compute(self, group: str, stage: str, inputs: Mapping[str, Any], fn: Callable[[], Any]) -> Any:
        """The stored value of ``stage`` for these ``inputs``, else ``fn()`` (then stored)."""
        path = self.path(group, stage, inputs)
        if path is not None and path.exists():
            value = self._read(path, stage)
            if value is not _MISSING:
                return value
        value = fn()
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_json(path, {"stage": stage, "inputs": inputs, "code": code_version(), "value": value}, indent=None)
            value = json.loads(path.read_text(encoding="utf-8"))["value"]  # a fresh run sees what a resume reads
        return value

    def _read(self, path: Path, stage: str) -> Any:
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
            if not isinstance(doc, dict) or doc.get("stage") != stage or "value" not in doc:
                raise ValueError("not a stage file of this stage")
            return doc["value"]
        except (OSError, ValueError) as e:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
            aside = path.with_name(f"{path.name}.{time.strftime('%Y%m%d-%H%M%S')}.corrupt")
            try:
                path.replace(aside)
                where = f"moved aside to {aside.name}"
            except OSError:
                where = "left in place"
            log.warning("stage file %s could not be read (%s: %s); %s, recomputing the stage",
                        path, type(e).__name__, e, where)
            self.recovered.append(str(path))
            return _MISSING


_MISSING = object()


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_.+=" else "_" for c in str(name))[:120]
