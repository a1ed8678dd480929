"""gift_llm: the LM backends of gift and everything around them.

Public entry points (other parts of gift call these)::

    from gift_llm import get_default_lm, resolve_lm
    lm = get_default_lm()                         # embedded Qwen2.5-Coder-1.5B on llamacpp, cached
    lm = resolve_lm("litellm:openai/gpt-4o")      # any backend:model string, cached
    from gift_llm.structured import ask_dict      # dictionary answers with validation and repairs
    from gift_llm.parsing import extract_dict     # a dict anywhere in free text, never eval
    lm.stats.as_dict()                            # calls, hits, misses, tokens, latency, cost
"""

from __future__ import annotations

from typing import Any

__all__ = ["get_default_lm", "resolve_lm", "CachedLM", "ask_dict", "extract_dict", "extract_dicts"]


def __getattr__(name: str) -> Any:  # lazy: importing gift_llm stays cheap (no llama.cpp, no litellm)
    if name in ("get_default_lm", "resolve_lm"):
        from gift_llm import resolve

        return getattr(resolve, name)
    if name == "CachedLM":
        from gift_llm.cache import CachedLM

        return CachedLM
    if name == "ask_dict":
        from gift_llm.structured import ask_dict

        return ask_dict
    if name in ("extract_dict", "extract_dicts"):
        from gift_llm import parsing

        return getattr(parsing, name)
    raise AttributeError(f"module 'gift_llm' has no attribute {name!r}")
