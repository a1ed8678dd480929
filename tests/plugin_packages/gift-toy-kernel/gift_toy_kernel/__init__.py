"""A toy third-party kernel: Jaccard similarity of character trigrams of object names."""

import numpy as np

import gift
from gift.core.interfaces import SimilarityKernel


def _trigrams(text: str) -> set[str]:
    t = f"  {text.lower()} "
    return {t[i:i + 3] for i in range(len(t) - 2)}


class TrigramKernel(SimilarityKernel):
    """Jaccard similarity of the character trigrams of two object names."""

    name = "toy-trigram"

    def similarity(self, test, train, intent=None):
        a = [_trigrams(o.name) for o in test]
        b = [_trigrams(o.name) for o in train]
        return np.array([[len(x & y) / len(x | y) for y in b] for x in a], dtype=float).reshape(len(a), len(b))


@gift.hookimpl
def gift_register_kernels(register):
    register("toy-trigram", TrigramKernel)
