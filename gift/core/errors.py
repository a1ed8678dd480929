"""Exception types shared across gift. Every error says what went wrong and where."""

from __future__ import annotations


class GiftError(Exception):
    """Base class of every error gift raises on purpose."""


class ValidationError(GiftError, ValueError):
    """A data-model value is out of its allowed range or of the wrong type."""


class SuiteError(GiftError):
    """A suite file is malformed. The message names the file, the intent id and the field."""

    def __init__(self, message: str, *, path: str | None = None, intent: str | None = None,
                 field: str | None = None):
        where = []
        if path:
            where.append(f"file {path}")
        if intent:
            where.append(f"intent {intent!r}")
        if field:
            where.append(f"field {field!r}")
        self.path, self.intent, self.field = path, intent, field
        super().__init__(f"{', '.join(where)}: {message}" if where else message)


class PlacementError(GiftError):
    """A simulator cannot lay out the requested objects in a scene (too many or too large for the table)."""


class PluginError(GiftError):
    """A plugin problem: duplicate component names, an unknown component, a bad registration."""


class ComponentOptionError(PluginError, TypeError):
    """Options a component's factory does not take (or a required one missing); the message lists the valid ones."""


class UnknownComponentError(PluginError, KeyError):
    """No component of that kind has that name."""

    def __str__(self) -> str:  # KeyError quotes its message; keep it readable
        return str(self.args[0]) if self.args else ""


class LMError(GiftError):
    """An LM backend failed (dead server, missing model, exhausted retries)."""


class LMAnswerError(LMError):
    """An LM answer could not be parsed or validated. ``raw`` holds the answer text."""

    def __init__(self, message: str, raw: str = ""):
        self.raw = raw
        shown = raw if len(raw) <= 2000 else raw[:2000] + "...[truncated]"
        super().__init__(f"{message}\n--- raw answer ---\n{shown}" if raw else message)
