"""``transformers``: a local Hugging Face causal LM directory (never downloads: ``local_files_only``).

Chat through the tokenizer's chat template (a plain ``role: content`` layout when it has none);
:meth:`TransformersLM.choice_probabilities` reads the next-token distribution after the opened assistant
turn, like the llamacpp backend. CPU by default; ``device`` and ``dtype`` are options.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

from gift.core.data import Completion, Message, Usage
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.backends.common import first_token_ids, message_dicts, probabilities_from_logits

_FALLBACK_TEMPLATE = ("{% for m in messages %}{{ m['role'] }}: {{ m['content'] }}\n{% endfor %}"
                      "{% if add_generation_prompt %}assistant:{% endif %}")
_LOADED: dict[tuple[str, str, str], tuple[Any, Any, threading.Lock]] = {}
_LOADED_LOCK = threading.Lock()


class TransformersLM(LMBackend):
    """A local Hugging Face causal LM directory (chat template, log-probabilities)."""

    name: ClassVar[str] = "transformers"
    supports_choice_probabilities: ClassVar[bool] = True

    def __init__(self, model: str | Path | None = None, *, device: str = "cpu", dtype: str = "float32",
                 **_ignored: Any):
        if not model:
            raise LMError("transformers backend: give a local model directory, e.g. --lm transformers:/path/dir")
        self.path = Path(model).expanduser().resolve()
        if not (self.path / "config.json").is_file():
            raise LMError(f"transformers backend: {self.path} is not a Hugging Face model directory "
                          f"(no config.json); models are never downloaded at run time")
        self.model = str(self.path)
        self.device, self.dtype = device, dtype
        self._tok: Any = None
        self._lm: Any = None
        self._lock: threading.Lock | None = None

    def _load(self) -> tuple[Any, Any, threading.Lock]:
        if self._lm is None:
            key = (str(self.path), self.device, self.dtype)
            with _LOADED_LOCK:
                if key not in _LOADED:
                    try:
                        import torch
                        from transformers import AutoModelForCausalLM, AutoTokenizer
                    except ImportError as e:
                        raise LMError("transformers backend: torch/transformers are not installed: "
                                      "pip install 'gift-llm[transformers]'") from e
                    try:
                        tok = AutoTokenizer.from_pretrained(self.path, local_files_only=True)
                        lm = AutoModelForCausalLM.from_pretrained(self.path, local_files_only=True,
                                                                  dtype=getattr(torch, self.dtype))
                    except Exception as e:  # noqa: BLE001
                        raise LMError(f"transformers backend: cannot load {self.path}: {type(e).__name__}: {e}") from e
                    lm.to(self.device).eval()
                    if not getattr(tok, "chat_template", None):
                        tok.chat_template = _FALLBACK_TEMPLATE
                    _LOADED[key] = (tok, lm, threading.Lock())
                self._tok, self._lm, self._lock = _LOADED[key]
        assert self._lock is not None
        return self._tok, self._lm, self._lock

    def _prompt_ids(self, messages: Sequence[Message]) -> Any:
        tok, _, _ = self._load()
        text = tok.apply_chat_template(message_dicts(messages), tokenize=False, add_generation_prompt=True)
        return tok(text, return_tensors="pt", add_special_tokens=False)["input_ids"].to(self.device)

    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        import torch

        tok, lm, lock = self._load()
        ids = self._prompt_ids(messages)
        gen: dict[str, Any] = dict(max_new_tokens=int(max_tokens), do_sample=temperature > 0,
                                   pad_token_id=tok.pad_token_id if tok.pad_token_id is not None else tok.eos_token_id)
        if temperature > 0:
            gen["temperature"] = float(temperature)
        t0 = time.perf_counter()
        with lock, torch.no_grad():
            if seed is not None:
                torch.manual_seed(int(seed))
            out = lm.generate(ids, attention_mask=torch.ones_like(ids), **gen)
        new = out[0, ids.shape[1]:]
        text = tok.decode(new, skip_special_tokens=True)
        for s in stop or ():
            if s and s in text:
                text = text[:text.index(s)]
        return Completion(text, Usage(prompt_tokens=int(ids.shape[1]), completion_tokens=int(new.shape[0]),
                                      latency_s=time.perf_counter() - t0, cost_usd=0.0), model=self.identity())

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        import torch

        if not choices:
            raise LMError("choice_probabilities: no choices given")
        tok, lm, lock = self._load()
        ids_of = first_token_ids(list(choices), lambda s: tok(s, add_special_tokens=False)["input_ids"])
        ids = self._prompt_ids(messages)
        with lock, torch.no_grad():
            logits = lm(ids).logits[0, -1].double().cpu().numpy()
        return probabilities_from_logits(logits, ids_of)
