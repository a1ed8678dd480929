"""Ask an LM for a dictionary: parse it from free text, validate it, ask for repairs, then fail clearly.

With a ``json_schema``, backends that constrain decoding (``llamacpp``: a grammar) can only produce a
dictionary of that schema; the parsing, the validation and the repair requests stay for the backends
that cannot, and for what a schema cannot say.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from typing import Any

import attrs

from gift.core.data import Message, as_messages
from gift.core.errors import LMAnswerError
from gift.core.interfaces import LMBackend
from gift_llm.parsing import extract_dict

log = logging.getLogger(__name__)

REPAIR_PROMPT = ("Your previous answer could not be used: {problem}\n"
                 "Reply again with only the corrected Python dictionary, nothing else.")


def _norm(x: Any) -> Any:
    return " ".join(x.split()).casefold() if isinstance(x, str) else x


def _canonical(value: Any, allowed: Collection[Any], where: str) -> Any:
    """``value`` (or each element of a list value) mapped onto ``allowed``, ignoring case and spacing."""
    lookup = {_norm(a): a for a in allowed}
    if isinstance(value, (list, tuple)):
        return type(value)(_canonical(v, allowed, where) for v in value)
    try:
        return lookup[_norm(value)]
    except (KeyError, TypeError):
        shown = sorted(map(str, allowed))
        raise ValueError(f"{where} has the value {value!r}, which is not one of the allowed values "
                         f"{shown[:40]}{' ...' if len(shown) > 40 else ''}") from None


def check_dict(d: dict, *, required_keys: Iterable[Any] = (),
               allowed_values: Collection[Any] | Mapping[Any, Collection[Any]] | None = None) -> dict:
    """Validate ``d``: every required key present; every value (or list element) allowed.

    ``allowed_values`` is one collection for all values or a mapping key -> collection (keys not in the
    mapping are free). String matches ignore case and repeated spaces, and return the allowed spelling.
    Raises :class:`ValueError` describing every problem.
    """
    keys = {_norm(k): k for k in d}
    problems = [f"the key {k!r} is missing" for k in required_keys if _norm(k) not in keys]
    if problems:
        raise ValueError("; ".join(problems))
    # rename keys that differ only in case/spacing to the required spelling
    out = dict(d)
    for k in required_keys:
        if k not in out:
            out[k] = out.pop(keys[_norm(k)])
    if allowed_values is not None:
        for k, v in list(out.items()):
            allowed = (allowed_values.get(k) if isinstance(allowed_values, Mapping) else allowed_values)
            if allowed is None:
                continue
            try:
                out[k] = _canonical(v, allowed, f"the key {k!r}")
            except ValueError as e:
                problems.append(str(e))
    if problems:
        raise ValueError("; ".join(problems))
    return out


@attrs.define
class AskStats:
    """Running counts of the :func:`ask_dict` calls that share this object (one per kernel or estimator).

    ``asked``: dictionaries asked for; ``answers``: LM answers read (first answers and repairs);
    ``repairs``: repair requests sent; ``failed``: calls that ended in :class:`LMAnswerError`.
    """

    asked: int = 0
    answers: int = 0
    repairs: int = 0
    failed: int = 0

    def as_dict(self) -> dict[str, int]:
        return attrs.asdict(self)


def ask_dict(lm: LMBackend, messages: Sequence[Message] | str, *,
             validate: Callable[[dict], dict | None] | None = None, required_keys: Iterable[Any] = (),
             allowed_values: Collection[Any] | Mapping[Any, Collection[Any]] | None = None, max_repairs: int = 2,
             temperature: float = 0.0, seed: int | None = None, max_tokens: int = 512,
             json_schema: Mapping[str, Any] | None = None, stats: AskStats | None = None) -> dict:
    """Complete ``messages``, extract the last dictionary of the answer and validate it.

    ``validate(d)`` may raise :class:`ValueError` (its message goes into the repair request) or return a
    replacement dict. On a parse or validation failure the model is shown its answer and what was wrong,
    up to ``max_repairs`` times; then :class:`LMAnswerError` carries the last raw answer. ``json_schema``
    goes with every request (first answer and repairs); ``stats`` counts answers, repairs and failures.
    """
    if max_repairs < 0:
        raise ValueError(f"max_repairs must be >= 0, got {max_repairs}")
    required_keys = tuple(required_keys)
    chat = list(as_messages(messages))
    problems: list[str] = []
    raw = ""
    if stats is not None:
        stats.asked += 1
    for attempt in range(max_repairs + 1):
        if attempt and stats is not None:
            stats.repairs += 1
        raw = lm.complete(chat, temperature=temperature, seed=seed, max_tokens=max_tokens,
                          json_schema=json_schema).text
        if stats is not None:
            stats.answers += 1
        try:
            d = extract_dict(raw)
            d = check_dict(d, required_keys=required_keys, allowed_values=allowed_values)
            if validate is not None:
                replaced = validate(d)
                if replaced is not None:
                    d = replaced
            return d
        except LMAnswerError:
            problem = "it contains no Python dictionary (write it as {'key': value, ...})"
        except ValueError as e:
            problem = str(e)
        problems.append(f"attempt {attempt + 1}: {problem}")
        log.info("%s: answer %d invalid%s: %s", lm.identity(), attempt + 1,
                 " (with a JSON schema)" if json_schema is not None else "", problem[:300])
        chat += [Message("assistant", raw), Message("user", REPAIR_PROMPT.format(problem=problem))]
    if stats is not None:
        stats.failed += 1
    raise LMAnswerError(f"{lm.identity()} gave no valid dictionary after {max_repairs} repair request(s): "
                        + " | ".join(problems), raw)


def last_dict(error: LMAnswerError) -> dict | None:
    """The last dictionary in the raw answer of a failed :func:`ask_dict` (``None`` if it has none).

    For callers that can use the valid part of an answer that stayed invalid after the repairs.
    """
    try:
        return extract_dict(error.raw)
    except (LMAnswerError, ValueError):
        return None
