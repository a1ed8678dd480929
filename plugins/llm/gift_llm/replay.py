"""Record every LM call of a run as JSONL, and replay it later with no model at all.

A recording line is ``{"key", "identity", "request", "response", "cached", "seconds"}`` where ``request``
is the canonical request of :mod:`gift_llm.requests` (messages and sampling parameters, never credentials),
``response`` is the completion (text, usage, model) or the choice probabilities, ``cached`` whether the
cache answered it (None when no cache was in between) and ``seconds`` the wall-clock time of the call.
:class:`ReplayLM` answers each request with the recorded responses in the recorded order (the last one
repeats if a request comes more often than recorded); a request that is not in the recording is an
:class:`LMError`.
"""

from __future__ import annotations

import json
import os
import threading
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

from gift.core.data import Completion, Message
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.cache import completion_from_json, completion_to_json
from gift_llm.requests import choices_request, complete_request, request_key
from gift_llm.usage import LMWrapper


class RecordingLM(LMWrapper):
    """Appends every call (hits of an inner cache included) to the JSONL file ``path``."""

    name = "recording"

    def __init__(self, inner: LMBackend, path: str | Path):
        super().__init__(inner)
        self.path = Path(path).expanduser()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = threading.Lock()

    def _hit(self) -> bool | None:
        last_hit = getattr(self.inner, "last_hit", None)
        return last_hit() if callable(last_hit) else None

    def _write(self, request: Mapping[str, Any], response: Any, cached: bool | None, seconds: float) -> None:
        line = json.dumps({"key": request_key(None, request), "identity": self.identity(), "request": request,
                           "response": response, "cached": cached, "seconds": round(seconds, 4)},
                          ensure_ascii=False)
        data = (line + "\n").encode("utf-8")
        # one write(2) per line on an O_APPEND descriptor: worker processes recording into the same file
        # (GIFT_LM_RECORD is inherited) cannot interleave their lines, whatever their length
        with self._lock:
            fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            try:
                view = memoryview(data)
                while view:
                    view = view[os.write(fd, view):]
                os.fsync(fd)
            finally:
                os.close(fd)

    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        kw = dict(temperature=temperature, seed=seed, max_tokens=max_tokens, stop=stop, json_schema=json_schema)
        t0 = time.perf_counter()
        out = self.inner.complete(messages, **kw)
        cached = True if out.usage.cached else self._hit()
        self._write(complete_request(messages, **kw), completion_to_json(out), cached, time.perf_counter() - t0)
        return out

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        t0 = time.perf_counter()
        out = self.inner.choice_probabilities(messages, choices)
        self._write(choices_request(messages, choices), out, self._hit(), time.perf_counter() - t0)
        return out


class ReplayLM(LMBackend):
    """Answers from a recording made with :class:`RecordingLM` (``model`` is the JSONL path)."""

    name: ClassVar[str] = "replay"
    supports_choice_probabilities: ClassVar[bool] = True

    def __init__(self, model: str | Path | None = None, *, path: str | Path | None = None,
                 identity: str | None = None, **_ignored: Any):
        src = path or model
        if not src:
            raise LMError("replay: give the recording, e.g. --lm replay:/path/run.jsonl")
        self.path = Path(src).expanduser()
        if not self.path.is_file():
            raise LMError(f"replay: recording {self.path} does not exist")
        self.only_identity = identity
        self._answers: dict[str, list[Any]] = {}
        self._served: dict[str, int] = {}
        self._lock = threading.Lock()
        identities = set()
        with open(self.path, encoding="utf-8") as f:
            for lineno, line in enumerate(f, 1):
                if not line.strip():
                    continue
                try:
                    rec = json.loads(line)
                    key, response, ident = rec["key"], rec["response"], rec.get("identity", "")
                except (ValueError, KeyError, TypeError) as e:
                    raise LMError(f"replay: {self.path} line {lineno} is not a recording entry: {e}") from None
                if identity is not None and ident != identity:
                    continue
                identities.add(ident)
                self._answers.setdefault(key, []).append(response)
        self.recorded_identities = sorted(identities)
        self.model = ",".join(self.recorded_identities) or str(self.path)

    def identity(self) -> str:
        return f"replay:{self.model}"

    def _next(self, request: Mapping[str, Any]) -> Any:
        key = request_key(None, request)
        with self._lock:
            answers = self._answers.get(key)
            if not answers:
                text = json.dumps(request.get("messages"), ensure_ascii=False)
                raise LMError(f"replay: this {request['kind']} call is not in the recording {self.path} "
                              f"(the run differs from the recorded one). Request messages: "
                              f"{text[:600]}{'...' if len(text) > 600 else ''}; parameters: "
                              f"{ {k: v for k, v in request.items() if k not in ('messages', 'kind')} }")
            i = self._served.get(key, 0)
            self._served[key] = i + 1
            return answers[min(i, len(answers) - 1)]

    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        req = complete_request(messages, temperature=temperature, seed=seed, max_tokens=max_tokens, stop=stop,
                               json_schema=json_schema)
        return completion_from_json(self._next(req))

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        got = self._next(choices_request(messages, choices))
        return {c: float(got[c]) for c in choices}
