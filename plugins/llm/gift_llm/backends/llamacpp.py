"""``llamacpp``: an in-process GGUF through llama-cpp-python.

* Chat through ``create_chat_completion`` with the chat template stored in the GGUF.
* ``json_schema`` constrains decoding with a :class:`llama_cpp.LlamaGrammar` (built from the schema; a
  schema without ``properties`` gets the generic JSON-object grammar).
* :meth:`LlamaCppLM.choice_probabilities` evaluates the chat prompt with the assistant turn opened and
  reads the next-token distribution (variants such as ``yes``/``Yes``/`` yes`` are summed).
* Prompt-prefix reuse: both paths keep the evaluated tokens in the KV cache, and the next call only
  evaluates the suffix after the longest shared token prefix.

One :class:`llama_cpp.Llama` is loaded per (model path, n_ctx) per process and shared by every backend
instance on that file; calls to it are serialised by a lock.

Threads: unless ``n_threads`` is given, a model uses the process's thread budget
(:func:`default_threads`: ``$OMP_NUM_THREADS``, which the ``local`` executor sets for each worker and Ray
sets for its tasks, else all cores), for generation and prompt evaluation alike, so the workers of a pool
do not oversubscribe the cores. Within that budget, each call runs on the cores that other processes leave
free (:class:`ThreadGovernor`): llama.cpp's threads meet at a barrier after every operation, so one
thread that shares its core with another busy process stalls the others. On 2 cores with other work
running, 2 threads generated 0.34 tokens/s against 5.3 for 1 thread (docs/performance.md). The thread
count does not change a single bit of the logits (tests/llm/test_lm_llamacpp.py).
"""

from __future__ import annotations

import atexit
import json
import math
import os
import threading
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from gift.core.data import Completion, Message, Usage
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.backends.common import first_token_ids, message_dicts, probabilities_from_logits

_MODELS: dict[tuple[str, int], tuple[Any, threading.RLock]] = {}
_MODELS_LOCK = threading.Lock()
#: Number of GGUF loads in this process (tests check the default model is loaded once).
LOAD_COUNT = 0


def default_threads() -> int:
    """CPU threads for a model of this process: ``$OMP_NUM_THREADS`` when it is a positive integer (the
    ``local`` executor sets it to ``cpu_count // workers`` in each worker, Ray to a task's CPUs), else
    ``os.cpu_count()``."""
    try:
        budget = int(os.environ.get("OMP_NUM_THREADS", "").strip())
    except ValueError:
        budget = 0
    return budget if budget > 0 else (os.cpu_count() or 1)


def _cpu_ticks() -> tuple[int, int, int] | None:
    """``(all CPUs' ticks, busy ticks of all CPUs, this process's ticks)`` from ``/proc`` (None elsewhere)."""
    try:
        with open("/proc/stat", "rb") as f:
            fields = [int(x) for x in f.readline().split()[1:]]
        with open("/proc/self/stat", "rb") as f:
            own = f.read().rsplit(b")", 1)[1].split()
    except (OSError, ValueError, IndexError):
        return None
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)  # idle + iowait
    total = sum(fields[:8])  # user nice system idle iowait irq softirq steal (guest time is inside user)
    return total, total - idle, int(own[11]) + int(own[12])  # utime + stime


class ThreadGovernor:
    """Threads for the next llama.cpp call: the ``budget``, less the cores other processes kept busy since
    the previous call (measured from ``/proc/stat`` minus this process's own CPU time).

    ``others >= k - 1/2`` busy cores take ``k`` threads off; at least one thread is always used. Decisions
    are reused for calls less than ``min_interval_s`` apart (too short a window to measure); the first
    call, when it comes sooner than that after construction, estimates ``others`` from the 1-minute load
    average instead. Without ``/proc`` the budget is used. ``sample`` returns ``(total, busy, own)`` ticks
    (tests pass their own).
    """

    def __init__(self, budget: int, *, min_interval_s: float = 0.25, sample=_cpu_ticks,
                 cpus: int | None = None) -> None:
        self.budget = max(1, int(budget))
        self.cpus = int(cpus or os.cpu_count() or 1)
        self.min_interval_s = float(min_interval_s)
        self._sample = sample
        self._last = sample()
        self._last_t = time.monotonic()
        self.others = 0.0  #: cores other processes kept busy in the last window
        self.threads = self.budget
        self._decided = False

    def _decide(self, others: float) -> int:
        self.others = max(0.0, others)
        self.threads = max(1, min(self.budget, self.cpus - math.floor(self.others + 0.5)))
        self._decided = True
        return self.threads

    def next_threads(self) -> int:
        now = time.monotonic()
        if now - self._last_t < self.min_interval_s:
            if not self._decided and self._last is not None:
                return self._decide(os.getloadavg()[0])
            return self.threads
        cur = self._sample()
        if cur is None or self._last is None:
            self._last, self._last_t = cur, now
            return self.threads
        d_total, d_busy, d_own = (c - p for c, p in zip(cur, self._last))
        self._last, self._last_t = cur, now
        if d_total <= 0:
            return self.threads
        return self._decide((d_busy - d_own) / (d_total / self.cpus))  # busy CPUs not ours, in CPUs


def load_llama(path: str | Path, *, n_ctx: int = 4096, n_threads: int | None = None, n_batch: int = 512,
               seed: int = 0, verbose: bool = False) -> tuple[Any, threading.RLock]:
    """The shared ``Llama`` for ``path`` (loaded on first use) and the lock guarding it.

    ``n_threads`` (generation and prompt evaluation; default :func:`default_threads`) only applies to the
    first load of a (path, n_ctx) in a process.
    """
    global LOAD_COUNT
    path = Path(path).expanduser().resolve()
    if not path.is_file():
        raise LMError(f"llamacpp: model file {path} does not exist")
    key = (str(path), int(n_ctx))
    with _MODELS_LOCK:
        if key in _MODELS:
            return _MODELS[key]
        try:
            from llama_cpp import Llama
        except ImportError as e:
            raise LMError("llamacpp: llama-cpp-python is not installed: pip install 'gift-llm[llamacpp]' "
                          "(from a clone: bash scripts/setup.sh)") from e
        threads = int(n_threads) if n_threads is not None else default_threads()
        if threads < 1:
            raise LMError(f"llamacpp: n_threads must be >= 1, got {n_threads!r}")
        try:
            llama = Llama(model_path=str(path), n_ctx=int(n_ctx), n_threads=threads, n_threads_batch=threads,
                          n_batch=int(n_batch), seed=int(seed), logits_all=False, verbose=verbose)
        except Exception as e:  # noqa: BLE001 - llama.cpp raises ValueError/RuntimeError on bad files
            raise LMError(f"llamacpp: cannot load {path}: {type(e).__name__}: {e}") from e
        LOAD_COUNT += 1
        _MODELS[key] = (llama, threading.RLock())
        return _MODELS[key]


@atexit.register
def _close_all() -> None:
    """Free the shared models before interpreter shutdown (avoids noise from ``Llama.__del__`` at exit)."""
    with _MODELS_LOCK:
        for llama, _ in _MODELS.values():
            try:
                llama.close()
            except Exception:  # noqa: BLE001 - best effort at exit
                pass
        _MODELS.clear()


class LlamaCppLM(LMBackend):
    """In-process GGUF model through llama-cpp-python (grammar-constrained JSON, log-probabilities).

    ``n_threads``: CPU threads (default: the process's budget, :func:`default_threads`, of which each call
    takes the cores other processes leave free unless ``adapt_threads=False``; see :class:`ThreadGovernor`).
    """

    name: ClassVar[str] = "llamacpp"
    supports_choice_probabilities: ClassVar[bool] = True

    def __init__(self, model: str | Path | None = None, *, n_ctx: int = 4096, n_threads: int | None = None,
                 n_batch: int = 512, seed: int = 0, reuse_prefix: bool = True, adapt_threads: bool = True,
                 verbose: bool = False, **_ignored: Any):
        if model is None:
            from gift_llm.embedded import embedded_model_path

            model = embedded_model_path()
        self.path = Path(model).expanduser().resolve()
        self.model = self.path.name
        self.n_ctx = int(n_ctx)
        if self.n_ctx < 256:
            raise LMError(f"llamacpp: n_ctx={n_ctx} is too small (use at least 256)")
        #: Keep the KV cache of the previous call and evaluate only the new suffix (False: re-evaluate all).
        self.reuse_prefix = bool(reuse_prefix)
        #: Prompt tokens taken from the KV cache in the last :meth:`next_token_logits` call.
        self.last_reused_tokens = 0
        self._opts = dict(n_ctx=self.n_ctx, n_threads=n_threads, n_batch=n_batch, seed=seed, verbose=verbose)
        if n_threads is not None and int(n_threads) < 1:
            raise LMError(f"llamacpp: n_threads must be >= 1, got {n_threads!r}")
        #: Fixed thread count (``n_threads`` given or ``adapt_threads=False``), else None: a governor decides.
        self._fixed_threads = int(n_threads) if n_threads is not None else None
        self.adapt_threads = bool(adapt_threads)
        self._governor = (ThreadGovernor(default_threads()) if self._fixed_threads is None and self.adapt_threads
                          else None)
        #: Threads the last call ran on.
        self.last_threads = 0
        self._llama: Any = None
        self._lock: threading.RLock | None = None
        self._grammars: dict[str, Any] = {}
        self._formatter: Any = None

    # ------------------------------------------------------------------ model
    @property
    def llama(self) -> Any:
        """The shared ``llama_cpp.Llama`` (loaded on first access)."""
        if self._llama is None:
            self._llama, self._lock = load_llama(self.path, **self._opts)
        return self._llama

    def identity(self) -> str:
        return f"{self.name}:{self.model}"

    def _set_threads(self, llama: Any) -> int:
        """Set the shared context's threads for this call (caller holds the lock); returns the count."""
        if self._fixed_threads is not None:
            n = self._fixed_threads
        elif not self.adapt_threads:
            n = default_threads()
        else:
            assert self._governor is not None
            n = self._governor.next_threads()
        llama._ctx.set_n_threads(n, n)  # noqa: SLF001 - a plain llama_set_n_threads on the context
        self.last_threads = n
        return n

    def provenance(self) -> dict[str, Any]:
        """Identity, path and SHA-256 of the GGUF file this backend loads (hashed once per file version)."""
        from gift.core.provenance import file_sha256

        return {"identity": self.identity(), "model_path": str(self.path), "model_sha256": file_sha256(self.path)}

    def _grammar(self, schema: Mapping[str, Any]) -> Any:
        from llama_cpp import LlamaGrammar
        from llama_cpp.llama_grammar import JSON_GBNF

        key = json.dumps(schema, sort_keys=True)
        if key not in self._grammars:
            try:
                if schema.get("properties") or schema.get("items") or schema.get("enum"):
                    self._grammars[key] = LlamaGrammar.from_json_schema(key, verbose=False)
                else:
                    self._grammars[key] = LlamaGrammar.from_string(JSON_GBNF, verbose=False)
            except Exception as e:  # noqa: BLE001
                raise LMError(f"llamacpp: cannot build a grammar from the JSON schema {key[:200]}: {e}") from e
        return self._grammars[key]

    # ------------------------------------------------------------------ complete
    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        llama = self.llama
        kwargs: dict[str, Any] = dict(messages=message_dicts(messages), temperature=float(temperature),
                                      max_tokens=int(max_tokens), stop=list(stop) if stop else None)
        if seed is not None:
            kwargs["seed"] = int(seed)
        if json_schema is not None:
            kwargs["grammar"] = self._grammar(json_schema)
        assert self._lock is not None
        t0 = time.perf_counter()
        with self._lock:
            if not self.reuse_prefix:
                llama.reset()
            self._set_threads(llama)
            try:
                out = llama.create_chat_completion(**kwargs)
            except ValueError as e:  # e.g. prompt longer than the context window
                raise LMError(f"llamacpp {self.model}: {e} (n_ctx={self.n_ctx}; raise it with n_ctx=...)") from e
        latency = time.perf_counter() - t0
        usage = out.get("usage") or {}
        text = out["choices"][0]["message"].get("content") or ""
        return Completion(text, Usage(prompt_tokens=int(usage.get("prompt_tokens", 0)),
                                      completion_tokens=int(usage.get("completion_tokens", 0)),
                                      latency_s=latency, cost_usd=0.0), model=self.identity())

    # ------------------------------------------------------------------ log-probabilities
    def _prompt_tokens(self, messages: Sequence[Message]) -> list[int]:
        """Chat-formatted prompt with the assistant turn opened, as tokens."""
        llama = self.llama
        if self._formatter is None:
            from llama_cpp.llama_chat_format import Jinja2ChatFormatter

            template = llama.metadata.get("tokenizer.chat_template")
            if not template:
                raise LMError(f"llamacpp {self.model}: the GGUF has no chat template; choice_probabilities "
                              f"needs one")
            eos, bos = llama.token_eos(), llama.token_bos()
            text_of = llama._model.token_get_text  # noqa: SLF001 - same helper Llama uses for its templates
            self._formatter = Jinja2ChatFormatter(template=template, eos_token=text_of(eos) if eos != -1 else "",
                                                  bos_token=text_of(bos) if bos != -1 else "",
                                                  add_generation_prompt=True)
        res = self._formatter(messages=message_dicts(messages))
        return llama.tokenize(res.prompt.encode("utf-8"), add_bos=not res.added_special, special=True)

    def next_token_logits(self, tokens: Sequence[int]) -> np.ndarray:
        """Logits ``[vocab]`` of the token after ``tokens``, evaluating only the suffix not yet in the KV cache."""
        llama = self.llama
        tokens = list(tokens)
        if len(tokens) >= self.n_ctx:
            raise LMError(f"llamacpp {self.model}: prompt of {len(tokens)} tokens does not fit n_ctx={self.n_ctx}")
        prefix = 0
        if self.reuse_prefix:
            for a, b in zip(llama._input_ids.tolist(), tokens):  # noqa: SLF001
                if a != b:
                    break
                prefix += 1
        prefix = max(0, min(prefix, len(tokens) - 1))  # always decode at least one token to get fresh logits
        self._set_threads(llama)
        llama.n_tokens = prefix
        llama.eval(tokens[prefix:])  # eval drops KV entries past n_tokens first
        self.last_reused_tokens = prefix
        logits = np.ctypeslib.as_array(llama._ctx.get_logits(), shape=(llama.n_vocab(),))  # noqa: SLF001
        return np.array(logits, dtype=np.float64)

    def choice_probabilities(self, messages: Sequence[Message], choices: Sequence[str]) -> dict[str, float]:
        if not choices:
            raise LMError("choice_probabilities: no choices given")
        llama = self.llama
        assert self._lock is not None

        def tok(s: str) -> list[int]:
            return llama.tokenize(s.encode("utf-8"), add_bos=False, special=False)

        with self._lock:
            ids = first_token_ids(list(choices), tok)
            logits = self.next_token_logits(self._prompt_tokens(messages))
        return probabilities_from_logits(logits, ids)
