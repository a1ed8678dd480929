"""The plugin system: hook specifications and the manager that discovers plugins by entry point."""

from gift.plugins.hookspecs import hookimpl, hookspec
from gift.plugins.manager import Component, GiftPluginManager, PluginWarning, get_manager, reset_manager

__all__ = ["hookimpl", "hookspec", "Component", "GiftPluginManager", "PluginWarning", "get_manager",
           "reset_manager"]
