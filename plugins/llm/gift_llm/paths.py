"""Where gift keeps its caches: ``$GIFT_CACHE_DIR`` or the user cache directory (``~/.cache/gift``)."""

from __future__ import annotations

import os
from pathlib import Path

from gift.core.paths import cache_root

__all__ = ["cache_root", "lm_cache_path", "lm_cache_url", "models_dir"]


def models_dir() -> Path:
    """Directory of assembled model files (the embedded GGUF)."""
    return cache_root() / "models"


def lm_cache_path() -> Path:
    """SQLite file of the persistent LM cache."""
    return cache_root() / "lm" / "lm-cache.sqlite"


def lm_cache_url() -> str | None:
    """``$GIFT_LM_CACHE_URL`` (e.g. ``redis://host:6379/0``): a cache server instead of the SQLite file."""
    return os.environ.get("GIFT_LM_CACHE_URL", "").strip() or None
