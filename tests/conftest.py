"""Fixtures shared by the whole test suite (plugin authors can import these helpers too)."""

from __future__ import annotations

import pytest

from gift.plugins.manager import reset_manager


@pytest.fixture
def fresh_plugins():
    """Forget loaded plugins before and after the test (for tests that change GIFT_PLUGINS etc.)."""
    reset_manager()
    yield
    reset_manager()
