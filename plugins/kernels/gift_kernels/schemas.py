"""JSON schemas of every structured LM call of gift_kernels, in one place.

Each builder returns the schema of one answer, with the names the answer may use as enums:

- Call 1 (:func:`intent_schema`): ``{"motivations": [{"text", "features": [feature, ...]}] * 3,
  "semantic_similarities": [{"question", "features": [feature, ...]}, ...]}``.
- Call 2 (:func:`axes_schema`): ``{"axes": [{"question", "objects": [object, ...]}, ...]}``.
- Call 3 (:func:`mapping_schema`): ``{"<test object>": "<training object>" | "distractor", ...}`` with one
  required key per test object, in the order given.
- The gift-prob category call (:func:`category_schema`): ``{"category": "<short noun phrase>"}``.

Only the JSON-schema subset that llama.cpp's schema-to-grammar converter turns into a grammar is used:
``type``, ``properties``, ``required`` (every property), ``additionalProperties: false``, ``enum``,
``items``, ``minItems``/``maxItems`` and ``minLength``/``maxLength``. On the ``llamacpp`` backend the
grammar then makes a malformed answer, an unknown name, an extra key or an unmapped object impossible.
Backends that cannot constrain decoding get the same schema as a request (litellm) or not at all; the
parsers of :mod:`gift_kernels.intent` and :mod:`gift_kernels.lm_kernels` still validate every answer and
ask for repairs.

Lengths are characters; list bounds keep a sampled answer from repeating one name until ``max_tokens``.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import Any

from gift.core.data import DISTRACTOR
from gift.core.errors import GiftError

#: Call 1: motivations asked for (the paper's three ranked motivations).
MOTIVATIONS = 3
#: Call 1: at most this many semantic similarities.
MAX_SIMILARITIES = 3
#: Call 2: at most this many semantic axes.
MAX_AXES = 6
#: Features named per motivation or similarity, at most.
MAX_FEATURES = 4
#: Characters of a motivation text (one or two sentences), of a yes/no question, of a category.
TEXT_MAX_CHARS = 240
QUESTION_MAX_CHARS = 120
CATEGORY_MAX_CHARS = 40

#: Characters a name may not hold: llama-cpp-python's schema-to-grammar converter writes enum values into
#: grammar literals without escaping a backslash, so ``"`` and ``\`` would break the grammar.
_UNSPELLABLE = re.compile(r'["\\\x00-\x1f\x7f]')


def names(values: Iterable[Any], what: str) -> list[str]:
    """``values`` as distinct non-empty strings in their first order; :class:`GiftError` when there are none."""
    values = list(values)
    out: list[str] = []
    for v in values:
        s = str(v)
        if not s.strip():
            raise GiftError(f"schemas: an empty {what} name in {values!r}")
        if _UNSPELLABLE.search(s):
            raise GiftError(f"schemas: the {what} name {s!r} holds a double quote, a backslash or a control "
                            f"character, which llama.cpp's schema grammar cannot spell; rename it")
        if s not in out:
            out.append(s)
    if not out:
        raise GiftError(f"schemas: no {what} names given; a schema needs at least one")
    return out


def text(max_chars: int) -> dict[str, Any]:
    """A non-empty string of at most ``max_chars`` characters."""
    return {"type": "string", "minLength": 1, "maxLength": int(max_chars)}


def name_list(allowed: list[str], max_items: int, min_items: int = 1) -> dict[str, Any]:
    """A list of ``min_items`` to ``max_items`` names, each one of ``allowed``."""
    return {"type": "array", "items": {"type": "string", "enum": list(allowed)},
            "minItems": int(min_items), "maxItems": int(max(min_items, min(max_items, len(allowed))))}


def closed_object(properties: Mapping[str, Any]) -> dict[str, Any]:
    """An object with exactly ``properties``, all required, in this order."""
    return {"type": "object", "properties": dict(properties), "required": list(properties),
            "additionalProperties": False}


def intent_schema(features: Iterable[str], motivations: int = MOTIVATIONS) -> dict[str, Any]:
    """Call 1: ``motivations`` ranked motivations and up to :data:`MAX_SIMILARITIES` semantic
    similarities, each naming 1 to :data:`MAX_FEATURES` of ``features``."""
    feats = names(features, "feature")
    if motivations < 1:
        raise GiftError(f"schemas: motivations must be >= 1, got {motivations}")
    mot = closed_object({"text": text(TEXT_MAX_CHARS), "features": name_list(feats, MAX_FEATURES)})
    sim = closed_object({"question": text(QUESTION_MAX_CHARS), "features": name_list(feats, MAX_FEATURES)})
    return closed_object({
        "motivations": {"type": "array", "items": mot, "minItems": motivations, "maxItems": motivations},
        "semantic_similarities": {"type": "array", "items": sim, "minItems": 0, "maxItems": MAX_SIMILARITIES}})


def axes_schema(objects: Iterable[str]) -> dict[str, Any]:
    """Call 2: 1 to :data:`MAX_AXES` yes/no questions, each with the ``objects`` (at least one) it says yes to."""
    objs = names(objects, "object")
    axis = closed_object({"question": text(QUESTION_MAX_CHARS), "objects": name_list(objs, len(objs))})
    return closed_object({"axes": {"type": "array", "items": axis, "minItems": 1, "maxItems": MAX_AXES}})


def mapping_schema(test: Iterable[str], train: Iterable[str]) -> dict[str, Any]:
    """Call 3: one required key per test object (in this order), each mapped to a training object or
    :data:`~gift.core.data.DISTRACTOR`."""
    targets = {"type": "string", "enum": names([*names(train, "training object"), DISTRACTOR], "target")}
    return closed_object({t: targets for t in names(test, "test object")})


def category_schema(max_chars: int = CATEGORY_MAX_CHARS) -> dict[str, Any]:
    """gift-prob's category call: ``{"category": <1 to max_chars characters>}``."""
    return closed_object({"category": text(max_chars)})


def ladder_schema(levels: Iterable[str], max_chars: int = CATEGORY_MAX_CHARS) -> dict[str, Any]:
    """gift-prob's category ladder: ``{<level>: <1 to max_chars characters>, ...}`` for each level."""
    return closed_object({lv: text(max_chars) for lv in levels})
