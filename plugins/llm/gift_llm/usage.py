"""Usage accounting of a run: calls, tokens, latency and cost, through a metering wrapper."""

from __future__ import annotations

import threading
from collections.abc import Mapping, Sequence
from typing import Any

import attrs

from gift.core.data import Completion, Message
from gift.core.interfaces import LMBackend


@attrs.define
class UsageStats:
    """Running totals of one wrapper. ``calls`` reached the model; ``hits`` were answered by the cache.

    ``requests = hits + misses`` when a cache is active; with the cache bypassed every request is a call.
    ``latency_s`` sums wall-clock seconds spent in the model; ``cost_usd`` sums provider prices (None when
    no call had a price).
    """

    requests: int = 0
    hits: int = 0
    misses: int = 0
    calls: int = 0
    choice_calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    latency_s: float = 0.0
    cost_usd: float | None = None
    #: Answers per build of the model runtime that made them (``{build: count}``; :class:`gift_llm.cache.CachedLM`
    #: counts fresh answers under the loaded build and cached ones under the build stored with them, ``"unrecorded"``
    #: for answers cached before builds were recorded). Empty for backends without a build (hosted models).
    made_by: dict[str, int] = attrs.field(factory=dict)
    _lock: threading.Lock = attrs.field(factory=threading.Lock, repr=False, eq=False)

    @property
    def tokens(self) -> int:
        return self.prompt_tokens + self.completion_tokens

    def add_call(self, completion: Completion | None = None, *, latency_s: float = 0.0) -> None:
        with self._lock:
            self.calls += 1
            if completion is None:
                self.choice_calls += 1
                self.latency_s += latency_s
                return
            u = completion.usage
            self.prompt_tokens += u.prompt_tokens
            self.completion_tokens += u.completion_tokens
            self.latency_s += u.latency_s
            if u.cost_usd is not None:
                self.cost_usd = (self.cost_usd or 0.0) + u.cost_usd

    def add_request(self, *, hit: bool | None) -> None:
        with self._lock:
            self.requests += 1
            if hit is True:
                self.hits += 1
            elif hit is False:
                self.misses += 1

    def add_made_by(self, build: str) -> None:
        with self._lock:
            self.made_by[build] = self.made_by.get(build, 0) + 1

    def as_dict(self) -> dict[str, Any]:
        d = {f.name: getattr(self, f.name) for f in attrs.fields(type(self)) if not f.name.startswith("_")}
        d["made_by"] = dict(self.made_by)
        d["tokens"] = self.tokens
        return d

    def reset(self) -> None:
        with self._lock:
            for f in attrs.fields(type(self)):
                if not f.name.startswith("_"):
                    d = f.default
                    setattr(self, f.name, d.factory() if isinstance(d, attrs.Factory) else d)


class LMWrapper(LMBackend):
    """Base of wrappers around another backend; unknown attributes are looked up on the wrapped one."""

    name = "wrapper"

    def __init__(self, inner: LMBackend):
        if not isinstance(inner, LMBackend):
            raise TypeError(f"expected an LMBackend to wrap, got {type(inner).__name__}")
        self.inner = inner
        self.model = inner.model
        self.supports_choice_probabilities = inner.supports_choice_probabilities  # type: ignore[misc]

    def identity(self) -> str:
        return self.inner.identity()

    def provenance(self) -> dict[str, Any]:
        return self.inner.provenance()

    def __getattr__(self, item: str) -> Any:
        if item == "inner":  # not yet set (during unpickling): avoid infinite recursion
            raise AttributeError(item)
        return getattr(self.inner, item)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.inner!r})"

    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        return self.inner.complete(messages, temperature=temperature, seed=seed, max_tokens=max_tokens, stop=stop,
                                   json_schema=json_schema)

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        return self.inner.choice_probabilities(messages, choices)


class MeteredLM(LMWrapper):
    """Counts calls, tokens, latency and cost of the wrapped backend in :attr:`stats`."""

    def __init__(self, inner: LMBackend):
        super().__init__(inner)
        self.stats = UsageStats()

    def _call_complete(self, messages, **kw) -> Completion:
        out = self.inner.complete(messages, **kw)
        self.stats.add_call(out)
        return out

    def _call_choices(self, messages, choices) -> dict[str, float]:
        import time

        t0 = time.perf_counter()
        out = self.inner.choice_probabilities(messages, choices)
        self.stats.add_call(None, latency_s=time.perf_counter() - t0)
        return out

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self.stats.add_request(hit=None)
        return self._call_complete(messages, temperature=temperature, seed=seed, max_tokens=max_tokens, stop=stop,
                                   json_schema=json_schema)

    def choice_probabilities(self, messages, choices):
        self.stats.add_request(hit=None)
        return self._call_choices(messages, choices)
