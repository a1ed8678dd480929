"""``litellm``: any provider litellm knows (``openai/gpt-4o``, ``anthropic/...``, ``ollama/...``,
``hosted_vllm/...``) or any OpenAI-compatible server through ``api_base``.

API keys come only from the environment (litellm reads ``OPENAI_API_KEY``, ``ANTHROPIC_API_KEY``, ...;
``api_key_env`` names another variable). They never enter cache keys, recordings, logs or error messages,
and neither do credentials inside ``api_base`` (``http://user:PASSWORD@host/v1``, ``?api_key=...``): the
identity, messages and cache keys use :func:`gift.core.redaction.redact_url` of it.

Timeout: a request, its retries included, gives up after ``timeout_s`` seconds (default ``$GIFT_LM_TIMEOUT``,
else 120; ``--lm-timeout`` on the command line). Rate limits, timeouts, connection errors and 5xx answers are
retried with exponential backoff within that time and at most ``max_retries`` times, each retry logged as a
warning; then an :class:`LMError` names the model, the URL, the attempts and what happened.
"""

from __future__ import annotations

import logging
import math
import os
import random
import time
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

from gift.core.data import Completion, Message, Usage
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend, lm_timeout_s
from gift.core.redaction import redact_text, redact_url, url_secrets
from gift_llm.backends.common import choice_variants, message_dicts, renormalise

log = logging.getLogger(__name__)

#: Providers whose chat API returns token log-probabilities (``logprobs``/``top_logprobs``).
LOGPROB_PROVIDERS = ("openai", "hosted_vllm", "together_ai", "fireworks_ai", "deepseek")


#: How a JSON schema reaches the provider: ``json_schema`` (OpenAI structured outputs:
#: ``{"type": "json_schema", "json_schema": {"name", "schema", "strict"}}``), ``json_object_schema``
#: (llama.cpp server: ``{"type": "json_object", "schema": ...}``), ``json_object`` (JSON mode, no schema),
#: ``none`` (no ``response_format``; the prompt and gift's validators only); ``None``: chosen per model.
JSON_STYLES = (None, "json_schema", "json_object_schema", "json_object", "none")
#: Keywords left out of schemas sent as ``json_schema``: providers' strict modes reject length bounds
#: (gift's validators check what the schema no longer says).
UNPORTABLE_KEYWORDS = frozenset({"minLength", "maxLength", "minItems", "maxItems"})


def _map_subschemas(schema: Mapping[str, Any], f: Any) -> dict[str, Any]:
    """``schema`` with ``f`` applied to each direct subschema (properties, items, combinators)."""
    out: dict[str, Any] = {}
    for k, v in schema.items():
        if k == "properties" and isinstance(v, Mapping):
            out[k] = {name: f(sub) for name, sub in v.items()}
        elif k in ("items", "additionalProperties", "not") and isinstance(v, Mapping):
            out[k] = f(v)
        elif k in ("anyOf", "oneOf", "allOf", "prefixItems") and isinstance(v, list):
            out[k] = [f(sub) for sub in v]
        else:
            out[k] = v
    return out


def portable_schema(schema: Mapping[str, Any]) -> dict[str, Any]:
    """A copy of ``schema`` without :data:`UNPORTABLE_KEYWORDS` in any (sub)schema."""
    return _map_subschemas({k: v for k, v in schema.items() if k not in UNPORTABLE_KEYWORDS}, portable_schema)


def strict_compatible(schema: Mapping[str, Any]) -> bool:
    """Whether every object in ``schema`` requires all its properties and forbids others, as OpenAI's
    strict structured outputs demand."""
    if schema.get("type") == "object" or "properties" in schema:
        props = schema.get("properties") or {}
        if schema.get("additionalProperties") is not False or set(schema.get("required") or ()) != set(props):
            return False
    ok = [True]

    def visit(sub: Mapping[str, Any]) -> Mapping[str, Any]:
        ok[0] = ok[0] and strict_compatible(sub)
        return sub

    _map_subschemas(schema, visit)
    return ok[0]


def _litellm() -> Any:
    os.environ.setdefault("LITELLM_LOCAL_MODEL_COST_MAP", "True")
    try:
        import litellm
    except ImportError as e:
        raise LMError("litellm backend: the litellm package is not installed: pip install 'gift-llm[litellm]' "
                      "(from a clone: bash scripts/setup.sh)") from e
    litellm.suppress_debug_info = True
    return litellm


class LiteLLM(LMBackend):
    """Hosted or OpenAI-compatible chat models through litellm (keys from the environment only)."""

    name: ClassVar[str] = "litellm"
    supports_choice_probabilities: ClassVar[bool] = False

    def __init__(self, model: str | None = None, *, api_base: str | None = None, api_key_env: str | None = None,
                 timeout_s: float | None = None, max_retries: int = 4, backoff_s: float = 1.0,
                 backoff_max_s: float = 30.0,
                 logprobs: bool | None = None, top_logprobs: int = 20, json_style: str | None = None,
                 **_ignored: Any):
        if not model:
            raise LMError("litellm backend: name a model, e.g. --lm litellm:openai/gpt-4o")
        self.model = str(model)
        self.api_base = api_base or None
        self.api_key_env = api_key_env
        if api_key_env and not os.environ.get(api_key_env):
            raise LMError(f"litellm {self.model}: the environment variable {api_key_env} is not set")
        self.timeout_s = lm_timeout_s() if timeout_s is None else float(timeout_s)
        if not self.timeout_s > 0:
            raise LMError(f"litellm {self.model}: timeout_s must be > 0 seconds, got {timeout_s!r}")
        self.max_retries = int(max_retries)
        self.backoff_s, self.backoff_max_s = float(backoff_s), float(backoff_max_s)
        provider = self.model.split("/", 1)[0] if "/" in self.model else "openai"
        self.supports_choice_probabilities = (provider in LOGPROB_PROVIDERS if logprobs is None  # type: ignore[misc]
                                              else bool(logprobs))
        self.top_logprobs = int(top_logprobs)
        if json_style not in JSON_STYLES:
            raise LMError(f"litellm {self.model}: json_style must be one of {[s for s in JSON_STYLES if s]}, "
                          f"got {json_style!r}")
        self.json_style = json_style

    def structured_output_style(self) -> str:
        """How a ``json_schema`` is sent (see :data:`JSON_STYLES`): ``json_style`` when given; else
        ``json_object_schema`` for an OpenAI-compatible server at ``api_base`` (llama.cpp's server turns the
        schema into a grammar; other servers fall back to JSON mode); ``json_schema`` when litellm's
        ``supports_response_schema`` says the provider enforces schemas; ``json_object`` (JSON mode) when
        the provider takes a ``response_format`` at all; else ``none``."""
        if self.json_style:
            return self.json_style
        if self.api_base and self.model.startswith("openai/"):
            return "json_object_schema"
        litellm = _litellm()
        try:
            if litellm.supports_response_schema(model=self.model):
                return "json_schema"
        except Exception:  # noqa: BLE001 - a model litellm does not know: no schema support claimed
            pass
        try:
            params = litellm.get_supported_openai_params(model=self.model) or []
        except Exception:  # noqa: BLE001
            params = []
        return "json_object" if "response_format" in params else "none"

    def _response_format(self, schema: Mapping[str, Any]) -> dict[str, Any] | None:
        """The ``response_format`` of a request with ``schema`` (``None``: send none)."""
        style = self.structured_output_style()
        if style == "none":
            return None
        if style == "json_object_schema":
            return {"type": "json_object", "schema": dict(schema)}
        if style == "json_object" or not schema.get("properties"):
            return {"type": "json_object"}
        portable = portable_schema(schema)
        return {"type": "json_schema", "json_schema": {"name": "answer", "schema": portable,
                                                       "strict": strict_compatible(portable)}}

    def identity(self) -> str:
        """``litellm:MODEL@URL`` with the URL's credentials redacted (it keys the cache and is shown)."""
        return f"{self.name}:{self.model}" + (f"@{redact_url(self.api_base)}" if self.api_base else "")

    @property
    def where(self) -> str:
        return redact_url(self.api_base) if self.api_base else "the provider's default endpoint"

    def _secrets(self) -> list[str]:
        names = [self.api_key_env] if self.api_key_env else []
        names += [k for k in os.environ if k.endswith(("_API_KEY", "_TOKEN", "_SECRET", "_KEY"))]
        return ([os.environ[k] for k in names if k and len(os.environ.get(k, "")) >= 6]
                + url_secrets(self.api_base or ""))

    def _scrub(self, text: str) -> str:
        return redact_text(text, self._secrets())

    def _call(self, **kwargs: Any) -> Any:
        litellm = _litellm()
        ex = litellm.exceptions
        retryable = (ex.RateLimitError, ex.Timeout, ex.APIConnectionError, ex.ServiceUnavailableError,
                     ex.InternalServerError, ex.BadGatewayError)
        # retries are this loop's alone: litellm's (num_retries) and its OpenAI client's (max_retries) are off,
        # so a request never outlives its timeout
        kwargs.update(model=self.model, drop_params=True, num_retries=0, max_retries=0)
        if self.api_base:
            kwargs["api_base"] = self.api_base
        if self.api_key_env:
            kwargs["api_key"] = os.environ[self.api_key_env]
        elif self.api_base and self.model.startswith(("openai/", "hosted_vllm/")) and not os.environ.get(
                "OPENAI_API_KEY"):
            kwargs["api_key"] = "no-key-needed"  # local OpenAI-compatible servers ignore it; the client wants one
        attempt, start = 0, time.monotonic()
        deadline = start + self.timeout_s
        while True:
            kwargs["timeout"] = max(deadline - time.monotonic(), 0.05)  # what is left of the request's time
            try:
                return litellm.completion(**kwargs)
            except retryable as e:
                attempt += 1
                left = deadline - time.monotonic()
                delay = min(self.backoff_max_s, self.backoff_s * 2 ** (attempt - 1)) * (0.5 + random.random() / 2)
                if attempt > self.max_retries or left <= delay + 0.1:
                    why = (f"after {attempt} attempts" if attempt > self.max_retries else
                           f"after {attempt} attempt{'s' if attempt > 1 else ''} in {time.monotonic() - start:.1f} s "
                           f"(the request timeout is {self.timeout_s:g} s: --lm-timeout or $GIFT_LM_TIMEOUT)")
                    raise LMError(f"litellm {self.model} at {self.where}: {type(e).__name__} {why}: "
                                  f"{self._scrub(str(e))[:500]}") from None
                log.warning("litellm %s at %s: %s on attempt %d of %d; retrying in %.1f s (%.0f s of the %g s "
                            "request timeout left)", self.model, self.where, type(e).__name__, attempt,
                            self.max_retries + 1, delay, left, self.timeout_s)
                time.sleep(delay)
            except Exception as e:  # noqa: BLE001 - auth, bad request, unknown model: not retryable
                raise LMError(f"litellm {self.model} at {self.where}: {type(e).__name__}: "
                              f"{self._scrub(str(e))[:500]}") from None

    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        kw: dict[str, Any] = dict(messages=message_dicts(messages), temperature=float(temperature),
                                  max_tokens=int(max_tokens))
        if seed is not None:
            kw["seed"] = int(seed)
        if stop:
            kw["stop"] = list(stop)
        if json_schema is not None and (fmt := self._response_format(json_schema)) is not None:
            kw["response_format"] = fmt
        t0 = time.perf_counter()
        resp = self._call(**kw)
        latency = time.perf_counter() - t0
        try:
            text = resp.choices[0].message.content or ""
        except (AttributeError, IndexError) as e:
            raise LMError(f"litellm {self.model} at {self.where}: malformed response: {e}") from None
        usage = getattr(resp, "usage", None)
        cost = None
        try:
            cost = float(_litellm().completion_cost(completion_response=resp))
        except Exception:  # noqa: BLE001 - no price known for this model
            cost = None
        return Completion(text, Usage(prompt_tokens=int(getattr(usage, "prompt_tokens", 0) or 0),
                                      completion_tokens=int(getattr(usage, "completion_tokens", 0) or 0),
                                      latency_s=latency, cost_usd=cost), model=self.identity())

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        """From the provider's ``top_logprobs`` of the first answer token; choices outside the top-k get 0."""
        if not self.supports_choice_probabilities:
            return super().choice_probabilities(messages, choices)
        if not choices:
            raise LMError("choice_probabilities: no choices given")
        resp = self._call(messages=message_dicts(messages), temperature=0.0, max_tokens=1, logprobs=True,
                          top_logprobs=self.top_logprobs)
        try:
            first = resp.choices[0].logprobs["content"][0] if isinstance(resp.choices[0].logprobs, dict) \
                else resp.choices[0].logprobs.content[0]
            tops = first["top_logprobs"] if isinstance(first, dict) else first.top_logprobs
            pairs = [((t["token"], t["logprob"]) if isinstance(t, dict) else (t.token, t.logprob)) for t in tops]
        except (AttributeError, IndexError, KeyError, TypeError) as e:
            raise LMError(f"litellm {self.model} at {self.where}: the response has no token log-probabilities "
                          f"({type(e).__name__}: {e}); this provider cannot do choice_probabilities") from None
        variants = {c: set(choice_variants(c)) for c in choices}
        mass = {c: 0.0 for c in choices}
        for token, logprob in pairs:
            for c, vs in variants.items():
                if token in vs or any(v.startswith(token) and token.strip() for v in vs):
                    mass[c] += math.exp(float(logprob))
                    break
        return renormalise(mass)
