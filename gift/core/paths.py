"""Where gift keeps its caches: ``$GIFT_CACHE_DIR`` or the user cache directory (``~/.cache/gift`` on Linux).

Every cache of every plugin lives under :func:`cache_root`: ``lm/`` (LM answers), ``models/`` (the
assembled embedded GGUF), ``embeddings/``, ``renders/``, ``datasets/`` (trajectories).
"""

from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """Root of every gift cache; ``GIFT_CACHE_DIR`` overrides the platform's user cache directory."""
    env = os.environ.get("GIFT_CACHE_DIR", "").strip()
    if env:
        return Path(env).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("gift", appauthor=False))
