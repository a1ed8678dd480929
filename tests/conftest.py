"""Fixtures and set-up shared by the whole test suite (plugin authors: see ``gift.testing``).

Every test session gets a fresh, empty gift cache directory (``GIFT_CACHE_DIR``) and no Redis LM cache
(``GIFT_LM_CACHE_URL`` is removed), so no test is served by answers, embeddings or renders that an earlier
run left behind; only the assembled embedded model (``models/``) is linked in from the user's cache
instead of being copied again.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from gift.plugins.manager import reset_manager

_SESSION_CACHE: Path | None = None


def _user_cache_root() -> Path:
    env = os.environ.get("GIFT_CACHE_DIR", "").strip()
    if env:
        return Path(env).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("gift", appauthor=False))


def pytest_configure(config):
    global _SESSION_CACHE
    if os.environ.get("GIFT_TEST_KEEP_CACHE") == "1":  # opt-out for local iteration
        return
    models = _user_cache_root() / "models"
    _SESSION_CACHE = Path(tempfile.mkdtemp(prefix="gift-test-cache-"))
    if models.is_dir():
        (_SESSION_CACHE / "models").symlink_to(models, target_is_directory=True)
    os.environ["GIFT_CACHE_DIR"] = str(_SESSION_CACHE)
    os.environ.pop("GIFT_LM_CACHE_URL", None)  # nor by a Redis LM cache configured for real runs


def pytest_unconfigure(config):
    if _SESSION_CACHE is not None:
        shutil.rmtree(_SESSION_CACHE, ignore_errors=True)


@pytest.fixture(scope="session")
def drake_franka():
    """The ``drake-franka`` simulator, built once per test session (skips when gift-sim-drake is not installed)."""
    import gift
    from gift.core.errors import GiftError

    try:
        return gift.get_simulator("drake-franka")
    except GiftError as e:  # pragma: no cover - the plugin is part of the install
        pytest.skip(f"drake-franka unavailable: {e}")


@pytest.fixture
def fresh_plugins():
    """Forget loaded plugins before and after the test (for tests that change GIFT_PLUGINS etc.)."""
    reset_manager()
    yield
    reset_manager()
