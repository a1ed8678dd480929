"""Helpers shared by the backends: message conversion and first-token choice scoring."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np

from gift.core.data import as_messages
from gift.core.errors import LMError


def message_dicts(messages) -> list[dict[str, str]]:
    """``[{"role", "content"}]`` from anything :func:`gift.core.data.as_messages` accepts."""
    return [m.to_dict() for m in as_messages(messages)]


def choice_variants(choice: str) -> list[str]:
    """Surface forms that count as answering ``choice``: case variants, with and without a leading space."""
    c = choice.strip()
    if not c:
        raise LMError("choice_probabilities: an empty choice string cannot be scored")
    base = {c, c.lower(), c.upper(), c[:1].upper() + c[1:], c[:1].lower() + c[1:]}
    return sorted(base | {" " + v for v in base})


def first_token_ids(choices: Sequence[str], tokenize: Callable[[str], list[int]]) -> dict[str, set[int]]:
    """For each choice, the distinct first-token ids of its variants. Overlaps between choices are an error."""
    ids: dict[str, set[int]] = {}
    for c in choices:
        ids[c] = {toks[0] for v in choice_variants(c) if (toks := tokenize(v))}
        if not ids[c]:
            raise LMError(f"choice_probabilities: choice {c!r} tokenizes to nothing")
    owner: dict[int, str] = {}
    for c, s in ids.items():
        for t in s:
            if t in owner and owner[t] != c:
                raise LMError(f"choice_probabilities: choices {owner[t]!r} and {c!r} start with the same token "
                              f"(id {t}); use choices that differ in their first word")
            owner[t] = c
    return ids


def probabilities_from_logits(logits: np.ndarray, ids: dict[str, Iterable[int]]) -> dict[str, float]:
    """Sum softmax probabilities of each choice's token ids (``logits`` is ``[vocab]``), renormalised."""
    z = np.asarray(logits, dtype=np.float64)
    z = z - z.max()
    p = np.exp(z)
    p /= p.sum()
    mass = {c: float(sum(p[t] for t in s)) for c, s in ids.items()}
    return renormalise(mass)


def renormalise(mass: dict[str, float]) -> dict[str, float]:
    total = sum(mass.values())
    if not np.isfinite(total) or total <= 0.0:
        return {c: 1.0 / len(mass) for c in mass}
    return {c: m / total for c, m in mass.items()}
