"""Choosing an LM: the embedded default, a registered backend name, or a ``backend:model`` string."""

from __future__ import annotations

import os
import threading
from pathlib import Path
from typing import Any

from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.cache import CachedLM, cache_enabled_by_env, store_spec
from gift_llm.replay import RecordingLM

_DEFAULTS: dict[tuple, CachedLM] = {}
_DEFAULTS_LOCK = threading.Lock()
_WRAPPER_KEYS = ("cache", "cache_path", "cache_url", "record")


def get_default_lm(**options: Any) -> LMBackend:
    """The embedded default (Qwen2.5-Coder-1.5B-Instruct Q4_K_M on ``llamacpp``) in the persistent cache.

    One shared instance per model path and options per process: the GGUF is loaded once. ``options``
    go to :class:`gift_llm.backends.llamacpp.LlamaCppLM` (``n_ctx``, ``n_threads``, ...); ``cache=False``
    bypasses the cache, ``cache_path`` moves it, ``cache_url=redis://...`` puts it on a Redis server,
    ``record=path.jsonl`` records every call.
    """
    from gift_llm.backends.llamacpp import LlamaCppLM
    from gift_llm.embedded import embedded_model_path

    wrap = {k: options.pop(k) for k in _WRAPPER_KEYS if k in options}
    path = Path(options.pop("model", None) or embedded_model_path()).resolve()
    enabled = bool(wrap.get("cache", True)) and cache_enabled_by_env()
    store = store_spec(wrap.get("cache_path"), wrap.get("cache_url")) if enabled else None
    key = (str(path), tuple(sorted(options.items())), store)
    with _DEFAULTS_LOCK:
        if key not in _DEFAULTS:
            kind, where = store or ("sqlite", None)
            _DEFAULTS[key] = CachedLM(LlamaCppLM(path, **options), path=where if kind == "sqlite" else None,
                                      url=where if kind == "redis" else None, enabled=enabled)
        lm: LMBackend = _DEFAULTS[key]
    return _record(lm, wrap.get("record"))


def _record(lm: LMBackend, record: str | Path | None) -> LMBackend:
    record = record or os.environ.get("GIFT_LM_RECORD") or None
    return RecordingLM(lm, record) if record else lm


def resolve_lm(name_or_backend: str | LMBackend | None = None, **options: Any) -> LMBackend:
    """An LM backend from a name, wrapped in the cache (unless ``cache=False``).

    * ``None``: ``$GIFT_LM`` if set, else the embedded default (:func:`get_default_lm`).
    * ``"default"`` / ``"embedded"``: the embedded default.
    * a registered backend name (``"llamacpp"``, ``"litellm"``, ...): built with ``options``.
    * ``"backend:model"``: ``"litellm:openai/gpt-4o"``, ``"llamacpp:/path/model.gguf"``,
      ``"replay:/path/run.jsonl"``, ``"transformers:/path/hf-dir"``.
    * an :class:`LMBackend` instance: wrapped as is.

    ``cache_path`` / ``cache_url`` choose the cache store (:func:`gift_llm.cache.open_store`);
    ``record=path.jsonl`` (or ``$GIFT_LM_RECORD``) records every call for :class:`gift_llm.replay.ReplayLM`.
    A replay is never cached (it needs no model) but still counts its calls.
    """
    if name_or_backend is None:
        name_or_backend = os.environ.get("GIFT_LM", "").strip() or None
    if name_or_backend is None or name_or_backend in ("default", "embedded"):
        return get_default_lm(**options)
    wrap = {k: options.pop(k) for k in _WRAPPER_KEYS if k in options}
    if isinstance(name_or_backend, LMBackend):
        backend = name_or_backend
    elif isinstance(name_or_backend, str):
        backend = _build(name_or_backend, options)
    else:
        raise LMError(f"resolve_lm: expected a backend name, a 'backend:model' string or an LMBackend, got "
                      f"{type(name_or_backend).__name__}")
    if isinstance(backend, CachedLM) or (isinstance(backend, RecordingLM)):
        return _record(backend, wrap.get("record"))
    enabled = bool(wrap.get("cache", True)) and backend.name != "replay"
    return _record(CachedLM(backend, path=wrap.get("cache_path"), url=wrap.get("cache_url"), enabled=enabled),
                   wrap.get("record"))


def _build(spec: str, options: dict[str, Any]) -> LMBackend:
    import gift

    manager = gift.get_manager()
    names = manager.names("lm_backend")
    name, _, model = spec.partition(":")
    if name not in names:
        raise LMError(f"unknown LM {spec!r}: the part before ':' must be a registered LM backend "
                      f"({', '.join(names) or 'none'}), e.g. 'litellm:openai/gpt-4o' or 'llamacpp:/path/m.gguf'")
    if model:
        options = {**options, "model": model}
    try:
        backend = manager.create("lm_backend", name, **options)
    except TypeError as e:
        raise LMError(f"LM backend {name!r}: bad options {sorted(options)}: {e}") from e
    if not isinstance(backend, LMBackend):
        raise LMError(f"LM backend {name!r} built a {type(backend).__name__}, not an LMBackend")
    return backend
