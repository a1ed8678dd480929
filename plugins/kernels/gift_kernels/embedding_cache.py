"""Embedding cache shared by the embedding kernels: in-process dict + one ``.npy`` per key on disk.

The disk cache lives under ``$GIFT_CACHE_DIR`` (default: the platform's user cache dir for ``gift``),
in ``embeddings/<model>/<sha1 of key>.npy``. Keys are texts (language) or object descriptions of what
was rendered (vision); the model name and version are part of the directory, so a new model never
reads another model's vectors.

Reproducible vectors: the float32 output of a torch model changes in its last bits with the number of
intra-op threads and, for padded text batches, with the other texts of the batch. The kernels therefore
compute every missing vector on its own, on :data:`EMBED_THREADS` thread (:func:`torch_threads`), so a
vector does not depend on which process computed it (the calling process, a pool or Ray worker with a
different thread budget) or on what else was missing from the cache at the time.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import threading
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np

from gift.core.paths import cache_root

#: torch intra-op threads while an embedding model computes vectors (fixed, so the bits are too).
EMBED_THREADS = 1
_threads_lock = threading.RLock()


@contextlib.contextmanager
def torch_threads(n: int = EMBED_THREADS) -> Iterator[None]:
    """Run the block with torch on exactly ``n`` intra-op CPU threads; the previous count is restored.

    Process-wide (torch has one setting); concurrent blocks in threads of one process are serialised.
    """
    import torch

    with _threads_lock:
        previous = torch.get_num_threads()
        torch.set_num_threads(int(n))
        try:
            yield
        finally:
            torch.set_num_threads(previous)


class EmbeddingCache:
    """Vectors ``[d]`` per string key, for one model. ``disk=False`` keeps them in memory only."""

    def __init__(self, model_id: str, *, disk: bool = True) -> None:
        self.model_id = model_id
        self.directory = cache_root() / "embeddings" / model_id if disk else None
        self._memory: dict[str, np.ndarray] = {}

    def _path(self, key: str) -> Path:
        return self.directory / f"{hashlib.sha1(key.encode('utf-8')).hexdigest()}.npy"

    def get(self, key: str) -> np.ndarray | None:
        vec = self._memory.get(key)
        if vec is None and self.directory is not None:
            p = self._path(key)
            if p.exists():
                try:
                    vec = np.load(p)
                except (OSError, ValueError):  # a torn write from a killed process: recompute
                    vec = None
                if vec is not None:
                    self._memory[key] = vec
        return vec

    def put(self, key: str, vec: np.ndarray) -> None:
        vec = np.asarray(vec, dtype=np.float32)
        self._memory[key] = vec
        if self.directory is not None:
            try:
                self.directory.mkdir(parents=True, exist_ok=True)
                tmp = self._path(key).with_suffix(f".{os.getpid()}.tmp.npy")
                np.save(tmp, vec)
                os.replace(tmp, self._path(key))
            except OSError:  # a read-only cache dir costs speed, not correctness
                pass

    def embed(self, keys: Sequence[str], compute: Callable[[list[str]], np.ndarray]) -> np.ndarray:
        """Vectors ``[len(keys), d]``; ``compute(missing_keys) -> [n_missing, d]`` runs once for the misses."""
        found = {k: self.get(k) for k in dict.fromkeys(keys)}
        missing = [k for k, v in found.items() if v is None]
        if missing:
            new = np.asarray(compute(missing), dtype=np.float32)
            for k, v in zip(missing, new):
                self.put(k, v)
                found[k] = v
        return np.stack([found[k] for k in keys]) if keys else np.zeros((0, 0), dtype=np.float32)
