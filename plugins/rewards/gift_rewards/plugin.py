"""Entry point of gift_rewards: registers its components with gift."""

from gift.plugins.hookspecs import hookimpl  # noqa: F401  (hooks are added as components land)
