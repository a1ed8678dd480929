"""Checks of suite data shared by the shipped-suite tests: look-alike and name-alike rules, sizes."""

from __future__ import annotations

import re
from difflib import SequenceMatcher

import numpy as np

#: Largest extent (m) of an object on the table.
MAX_EXTENT_M = 0.45


def labels(intent) -> dict[str, bool]:
    """Object name -> relevant, over the intent's training and test objects."""
    out = {o: o in intent.relevant_train for o in intent.train_objects}
    out.update({t.object: t.relevant for t in intent.test})
    return out


def extent(app) -> float:
    """Largest dimension of an appearance in metres."""
    if app.shape == "box":
        return max(app.size)
    if app.shape == "cylinder":
        return max(2 * app.size[0], app.size[1])
    return 2 * app.size[0]


def looks_alike(a, b) -> bool:
    """Same primitive, overall size within 2x, proportions within 2x, colour within 0.2 (RGB distance)."""
    if a.shape != b.shape:
        return False
    sa, sb = np.array(a.size), np.array(b.size)
    if a.shape == "box":  # orientation does not matter
        sa, sb = np.sort(sa)[::-1], np.sort(sb)[::-1]
    ea, eb = extent(a), extent(b)
    if max(ea, eb) / min(ea, eb) > 2.0:
        return False
    ratio = (sa / ea) / (sb / eb)
    if np.any(ratio > 2.0) or np.any(ratio < 0.5):
        return False
    return float(np.linalg.norm(np.subtract(a.color, b.color))) <= 0.2


def names_alike(a: str, b: str) -> bool:
    """Share a word, or a common run of at least four letters (toothbrush ~ paintbrush)."""
    wa, wb = set(re.findall(r"[a-z0-9]+", a.lower())), set(re.findall(r"[a-z0-9]+", b.lower()))
    if wa & wb:
        return True
    m = SequenceMatcher(None, a.lower(), b.lower()).find_longest_match(0, len(a), 0, len(b))
    return m.size >= 4
