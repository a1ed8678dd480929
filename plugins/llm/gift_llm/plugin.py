"""Entry point of gift_llm: registers the LM backends and the ``gift lm`` command."""

from __future__ import annotations

from typing import Any

from gift.plugins.hookspecs import hookimpl


def llamacpp(**options: Any):
    from gift_llm.backends.llamacpp import LlamaCppLM

    return LlamaCppLM(**options)


def litellm(**options: Any):
    from gift_llm.backends.litellm_backend import LiteLLM

    return LiteLLM(**options)


def transformers(**options: Any):
    from gift_llm.backends.transformers_backend import TransformersLM

    return TransformersLM(**options)


def replay(**options: Any):
    from gift_llm.replay import ReplayLM

    return ReplayLM(**options)


@hookimpl
def gift_register_lm_backends(register):
    register("llamacpp", llamacpp, description="in-process GGUF via llama-cpp-python (default: embedded "
                                                "Qwen2.5-Coder-1.5B Q4_K_M); grammar JSON, log-probabilities")
    register("litellm", litellm, description="hosted or OpenAI-compatible models via litellm "
                                              "(openai/..., anthropic/..., ollama/..., api_base=...)")
    register("transformers", transformers, description="local Hugging Face causal LM directory; "
                                                        "log-probabilities")
    register("replay", replay, description="replays a run recorded as JSONL, no model needed")


@hookimpl
def gift_register_doctor_checks(register):
    from gift_llm import doctor

    register("embedded model", doctor.check_embedded_model, description="the embedded GGUF: size and sha256")
    register("llama.cpp backend", doctor.check_llamacpp, description="llama-cpp-python imports")
    register("llama.cpp decodes", doctor.check_llamacpp_decodes,
             description="llama.cpp loads the embedded model and decodes 3 tokens (a child process; not --quick)")
    register("optional LM backends", doctor.check_optional_backends,
             description="litellm, llama.cpp's HTTP server, the Redis client")


@hookimpl
def gift_resolve_lm(spec, options):
    from gift_llm.resolve import resolve_lm

    return resolve_lm(spec, **options)


@hookimpl
def gift_register_commands(register):
    from gift_llm.cli import configure, run

    register("lm", run, help="ask the LM, install the embedded model, inspect the LM cache", configure=configure)
