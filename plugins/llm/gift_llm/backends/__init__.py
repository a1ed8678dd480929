"""LM backends: ``llamacpp`` (in-process GGUF), ``litellm`` (hosted or any OpenAI-compatible server),
``transformers`` (local Hugging Face directory) and ``replay`` (a recorded run, no model)."""
