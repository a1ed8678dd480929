"""Wrappers around any LM backend, all in gift_llm: :class:`~gift_llm.cache.CachedLM` (persistent answer
cache), :class:`~gift_llm.replay.RecordingLM` (records calls for :class:`~gift_llm.replay.ReplayLM`) and
:class:`RateLimitedLM` (caps concurrent calls with an executor's concurrency limit).

:func:`gift.resolve_lm` builds the usual stack (cache, optional recording); wrap by hand for anything else::

    from gift.core.executor import get_executor
    from gift_llm.wrappers import RateLimitedLM
    limit = get_executor("local").rate_limit("openai", max_concurrent=4)
    lm = RateLimitedLM(gift.resolve_lm("litellm:openai/gpt-4o", cache=False), limit)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

from gift.core.data import Completion, Message
from gift.core.errors import ValidationError
from gift.core.executor import ConcurrencyLimit
from gift.core.interfaces import LMBackend


class RateLimitedLM(LMBackend):
    """Any LM backend with its calls capped by a :class:`ConcurrencyLimit`.

    ``identity()`` is the wrapped backend's, so caches keyed by it are shared with the unwrapped backend.
    Put the limit *inside* a cache when you can (only misses need a slot); wrapping a cached backend
    is correct but holds a slot during hits too.
    """

    name: ClassVar[str] = "rate-limited"

    def __init__(self, backend: LMBackend, limit: ConcurrencyLimit) -> None:
        if not isinstance(backend, LMBackend):
            raise ValidationError(f"RateLimitedLM: backend must be an LMBackend, got {type(backend).__name__}")
        self.backend, self.limit = backend, limit
        self.model = backend.model
        self.supports_choice_probabilities = backend.supports_choice_probabilities

    def complete(self, messages: Sequence[Message], **kwargs: Any) -> Completion:
        with self.limit:
            return self.backend.complete(messages, **kwargs)

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        with self.limit:
            return self.backend.choice_probabilities(messages, choices)

    def identity(self) -> str:
        return self.backend.identity()

    def provenance(self) -> dict[str, Any]:
        return self.backend.provenance()
