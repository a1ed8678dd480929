"""Progress bars for long stages: tqdm on a terminal, nothing when stderr is not one (logs, CI, pipes)."""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import Any


class Progress:
    """``progress(iterable, desc, total)`` wraps ``iterable`` in a tqdm bar when enabled.

    ``enabled=None`` (the default): only when stderr is a terminal. ``True`` forces bars (tests, logs that
    want them), ``False`` silences them.
    """

    def __init__(self, enabled: bool | None = None) -> None:
        self.enabled = sys.stderr.isatty() if enabled is None else bool(enabled)

    def __call__(self, iterable: Iterable[Any], desc: str, total: int | None = None) -> Iterable[Any]:
        if not self.enabled:
            return iterable
        try:
            from tqdm.auto import tqdm
        except ImportError:  # tqdm is optional: no bar
            return iterable
        return tqdm(iterable, desc=desc, total=total, leave=False, file=sys.stderr)
