"""``keyword-overlap``: weighted Jaccard similarity of the keywords of two objects' names and descriptions.

K(s, s' | ω) = Σ_{w ∈ A ∩ B} c(w) / Σ_{w ∈ A ∪ B} c(w), with A and B the keyword sets of the two objects
and c(w) = 1 + ``intent_weight`` when the keyword also occurs in the intent (its text, motivations and
semantic-axis questions), else 1. Without an intent every keyword counts 1 (plain Jaccard).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from gift.core.data import Intent, ObjectSpec
from gift.core.errors import ValidationError
from gift.core.interfaces import SimilarityKernel

#: Words that carry no role information.
STOPWORDS = frozenset("""a an and are as at be by for from has have in is it its of on or that the this to
    with used use you your can made small large big""".split())


def keywords(text: str) -> frozenset[str]:
    """Lower-case word stems of ``text`` (a trailing plural ``s`` dropped), without stopwords."""
    words = re.findall(r"[a-z]+", text.lower())
    return frozenset(w[:-1] if len(w) > 3 and w.endswith("s") and not w.endswith("ss") else w
                     for w in words if w not in STOPWORDS and len(w) > 1)


def intent_keywords(intent: Intent | None) -> frozenset[str]:
    """Keywords of the intent's text, motivations and semantic-axis questions (empty without an intent)."""
    if intent is None:
        return frozenset()
    parts = [intent.text, *(m.text for m in intent.motivations), *(a.question for a in intent.axes)]
    return keywords(" ".join(parts))


class KeywordOverlapKernel(SimilarityKernel):
    """Weighted Jaccard of name + description keywords; keywords shared with the intent weigh more.

    ``intent_weight`` >= 0: extra weight of a keyword that the intent mentions;
    ``use_descriptions``: include the catalog descriptions (else names only).
    """

    name: ClassVar[str] = "keyword-overlap"
    uses_intent: ClassVar[bool] = True

    def __init__(self, intent_weight: float = 2.0, use_descriptions: bool = True) -> None:
        if not (np.isfinite(intent_weight) and intent_weight >= 0):
            raise ValidationError(f"keyword-overlap: intent_weight must be a finite number >= 0, got {intent_weight!r}")
        self.intent_weight = float(intent_weight)
        self.use_descriptions = bool(use_descriptions)

    def object_keywords(self, obj: ObjectSpec) -> frozenset[str]:
        return keywords(f"{obj.name} {obj.description}" if self.use_descriptions else obj.name)

    def similarity(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                   intent: Intent | None = None) -> np.ndarray:
        """K ``[n_test, n_train]`` in [0, 1]; 0 where neither object has any keyword."""
        test_kw = [self.object_keywords(o) for o in test]
        train_kw = [self.object_keywords(o) for o in train]
        vocab = sorted(set().union(*test_kw, *train_kw))
        index = {w: i for i, w in enumerate(vocab)}
        a = _incidence(test_kw, index)  # [n_test, V]
        b = _incidence(train_kw, index)  # [n_train, V]
        boost = intent_keywords(intent)
        c = np.array([1.0 + (self.intent_weight if w in boost else 0.0) for w in vocab])  # [V]
        inter = (a * c) @ b.T  # [n_test, n_train]
        union = (a @ c)[:, None] + (b @ c)[None, :] - inter
        with np.errstate(invalid="ignore", divide="ignore"):
            k = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)
        return np.clip(k, 0.0, 1.0)


def _incidence(sets: Sequence[frozenset[str]], index: dict[str, int]) -> np.ndarray:
    """Binary ``[len(sets), len(index)]`` matrix: row i has 1 at the columns of the words of set i."""
    out = np.zeros((len(sets), len(index)))
    for i, words in enumerate(sets):
        out[i, [index[w] for w in words]] = 1.0
    return out
