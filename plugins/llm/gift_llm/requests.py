"""Canonical form of an LM request: what the cache and the recorder key on (never an API key)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from typing import Any

from gift.core.data import as_messages


def complete_request(messages, *, temperature: float, seed: int | None, max_tokens: int,
                     stop: Sequence[str] | None, json_schema: Mapping[str, Any] | None) -> dict[str, Any]:
    return {"kind": "complete", "messages": [m.to_dict() for m in as_messages(messages)],
            "temperature": float(temperature), "seed": None if seed is None else int(seed),
            "max_tokens": int(max_tokens), "stop": list(stop) if stop else None,
            "json_schema": json_schema if json_schema is None else json.loads(json.dumps(json_schema))}


def choices_request(messages, choices: Sequence[str]) -> dict[str, Any]:
    return {"kind": "choices", "messages": [m.to_dict() for m in as_messages(messages)], "choices": list(choices)}


def request_key(identity: str | None, request: Mapping[str, Any]) -> str:
    """SHA-256 of the canonical JSON of ``request`` (and the backend identity when given)."""
    blob = json.dumps({"identity": identity, "request": request}, sort_keys=True, ensure_ascii=False,
                      separators=(",", ":"))
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()
