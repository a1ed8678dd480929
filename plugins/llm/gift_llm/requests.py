"""Canonical form of an LM request: what the cache and the recorder key on (never an API key)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from typing import Any

from gift.core.data import Message, as_messages


def _message_key(m: Message) -> dict[str, Any]:
    """A message as requests key it: role and content, and the ``cut`` hint when there is one (a backend
    may split the prompt there, which can change its numbers slightly)."""
    return {**m.to_dict(), "cut": m.cut} if m.cut else m.to_dict()


def complete_request(messages, *, temperature: float, seed: int | None, max_tokens: int,
                     stop: Sequence[str] | None, json_schema: Mapping[str, Any] | None) -> dict[str, Any]:
    return {"kind": "complete", "messages": [_message_key(m) for m in as_messages(messages)],
            "temperature": float(temperature), "seed": None if seed is None else int(seed),
            "max_tokens": int(max_tokens), "stop": list(stop) if stop else None,
            "json_schema": json_schema if json_schema is None else json.loads(json.dumps(json_schema))}


def choices_request(messages, choices: Sequence[str]) -> dict[str, Any]:
    return {"kind": "choices", "messages": [_message_key(m) for m in as_messages(messages)], "choices": list(choices)}


def request_key(identity: str | None, request: Mapping[str, Any]) -> str:
    """SHA-256 of the canonical JSON of ``request`` (and the backend identity when given)."""
    blob = json.dumps({"identity": identity, "request": request}, sort_keys=True, ensure_ascii=False,
                      separators=(",", ":"))
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()
