"""``llamacpp``: an in-process GGUF through llama-cpp-python.

* Chat through ``create_chat_completion`` with the chat template stored in the GGUF.
* ``json_schema`` constrains decoding with a :class:`llama_cpp.LlamaGrammar` (built from the schema, which
  fixes the order of an object's properties as listed; a schema without ``properties`` gets the generic
  JSON-object grammar).
* :meth:`LlamaCppLM.choice_probabilities` evaluates the chat prompt with the assistant turn opened and
  reads the next-token distribution (variants such as ``yes``/``Yes``/`` yes`` are summed).
* Evaluation schedule (:data:`SCHEDULE`): every result is a function of the prompt alone. llama.cpp's
  numbers for a token depend on how the prompt was split into decode batches, so a prompt is always
  evaluated in the same pieces, cut at message starts (found by formatting the leading messages with the
  chat template): the first message, the messages between, and the last message with the opened
  assistant turn, each piece from its own start (in batches of ``n_batch``). The KV cache of the previous
  call is reused up to the last cut at which the cached pieces and this prompt's agree; the last piece is
  always evaluated afresh. Both :meth:`LlamaCppLM.choice_probabilities` and :meth:`LlamaCppLM.complete`
  follow it (``complete`` evaluates up to the last cut itself and lets llama-cpp-python's prefix match
  evaluate the rest in one piece). ``identity()`` names the schedule, so cached answers of another
  schedule are never mixed in.

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
import logging
import math
import os
import threading
import time
import weakref
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

import attrs
import numpy as np

from gift.core.data import Completion, Message, Usage, as_messages
from gift.core.errors import LMError
from gift.core.interfaces import LMBackend
from gift_llm.backends.common import first_token_ids, message_dicts, probabilities_from_logits

log = logging.getLogger(__name__)

#: How prompts are split into decode batches and which KV-cache entries are reused (see the module
#: docstring). Part of :meth:`LlamaCppLM.identity`, so caches keyed by it never mix answers computed under
#: different schedules; change it whenever the split changes. ``msg1``: pieces cut at the second and at
#: the last message's start, KV reuse only up to a cut; and, where the last message carries a ``cut`` hint
#: (:class:`gift.core.data.Message`), also there (such prompts are other requests: the hint is part of the
#: cache key, so answers computed without it are never mixed in). (Not one piece per message: every decode call
#: costs about 0.19 CPU-s on top of its tokens, so a 10-message few-shot prompt evaluated fresh took 7.2
#: CPU-s in 10 pieces against 6.2 in 3 and 5.5 in one, while gift's calls reuse nothing between the
#: first and the last message; docs/performance.md.)
SCHEDULE = "msg1"

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


def llama_build() -> str:
    """``"<llama-cpp-python version>; <ggml's CPU features>"``, e.g. ``"0.3.36; CPU : SSE3 = 1 | AVX2 = 1 | ..."``:
    the build that computes the answers (``-march=native`` and portable builds use different kernels)."""
    import llama_cpp

    info = llama_cpp.llama_print_system_info()
    info = info.decode("utf-8", "replace") if isinstance(info, bytes) else str(info)
    return f"{llama_cpp.__version__}; {' '.join(info.split()).strip(' |')}"


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


def _is_increasing(instance: Any, attribute: Any, starts: tuple[int, ...]) -> None:
    n = len(instance.tokens)
    if any(not 0 < a < n for a in starts) or list(starts) != sorted(set(starts)):
        raise ValueError(f"ChatPrompt: cuts {starts} must increase strictly within (0, {n})")


@attrs.frozen
class ChatPrompt:
    """A chat prompt as tokens, with the token indices where its evaluation pieces start (message starts).

    ``tokens``: the formatted prompt (assistant turn opened), ``[n]``. ``starts``: strictly increasing
    indices in ``(0, n)``; the prompt is evaluated in the pieces ``[0, s1), [s1, s2), ..., [s_last, n)``
    (empty ``starts``: one piece, never reused).
    """

    tokens: tuple[int, ...] = attrs.field(converter=tuple)
    starts: tuple[int, ...] = attrs.field(converter=tuple, default=(), validator=_is_increasing)

    @property
    def ends(self) -> tuple[int, ...]:
        """End index of every piece (the cuts and the prompt's length)."""
        return (*self.starts, len(self.tokens))


#: Per shared ``Llama``: the end index of every piece evaluated into its KV cache by this module, in order.
#: Valid only up to the tokens the context still holds (``llama.n_tokens``); read and written under the
#: model's lock. Every evaluation on a shared ``Llama`` goes through :class:`LlamaCppLM`.
_PIECES: weakref.WeakKeyDictionary[Any, tuple[int, ...]] = weakref.WeakKeyDictionary()


def _common_prefix(cached: np.ndarray, tokens: Sequence[int]) -> int:
    """Length of the longest common prefix of the cached token ids and ``tokens``."""
    n = min(len(cached), len(tokens))
    differ = np.flatnonzero(np.asarray(cached[:n]) != np.asarray(tokens[:n], dtype=cached.dtype))
    return int(differ[0]) if differ.size else n


def reusable_prefix(cached_ends: Sequence[int], starts: Sequence[int], common: int) -> int:
    """Tokens of the KV cache a prompt may keep: its largest cut ``s`` such that the cached pieces ended
    exactly at this prompt's cuts up to ``s`` and the first ``common >= s`` tokens agree (0 when none). The KV entries before ``s`` are then what evaluating the prompt afresh would compute."""
    keep = 0
    for cached, start in zip(cached_ends, starts):
        if cached != start or start > common:
            break
        keep = start
    return keep


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
        #: Reuse the KV cache of the previous call up to a shared cut (False: evaluate every prompt
        #: from its first token; the same pieces, so the same numbers).
        self.reuse_prefix = bool(reuse_prefix)
        #: Prompt tokens taken from the KV cache in the last call (:meth:`complete` or :meth:`next_token_logits`).
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
        """``llamacpp:<model file name>+<schedule>``: the schedule changes the numbers, so it keys caches too."""
        return f"{self.name}:{self.model}+{SCHEDULE}"

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
        """Identity, path and SHA-256 of the GGUF file this backend loads (hashed once per file version), and the
        llama.cpp build that runs it (:func:`llama_build`: kernels built for other instruction sets may answer
        differently)."""
        from gift.core.provenance import file_sha256

        return {"identity": self.identity(), "model_path": str(self.path), "model_sha256": file_sha256(self.path),
                "llama_cpp": self.build()}

    def build(self) -> str:
        """The llama.cpp build that computes this backend's answers (:func:`llama_build`); the LM cache stores it
        with each answer (:meth:`gift_llm.cache.CachedLM.build`)."""
        return llama_build()

    def _grammar(self, schema: Mapping[str, Any]) -> Any:
        from llama_cpp import LlamaGrammar
        from llama_cpp.llama_grammar import JSON_GBNF

        key = json.dumps(schema)  # not sort_keys: the grammar writes an object's properties in the schema's order
        if key not in self._grammars:
            try:
                if schema.get("properties") or schema.get("items") or schema.get("enum"):
                    self._grammars[key] = LlamaGrammar.from_json_schema(key, verbose=False)
                else:
                    self._grammars[key] = LlamaGrammar.from_string(JSON_GBNF, verbose=False)
            except Exception as e:  # noqa: BLE001
                raise LMError(f"llamacpp: cannot build a grammar from the JSON schema {key[:200]}: {e}") from e
        return self._grammars[key]

    # ------------------------------------------------------------------ evaluation schedule
    def _formatters(self) -> tuple[Any, Any] | None:
        """Chat formatters of the GGUF's template (assistant turn opened, and not), None without a template."""
        if self._formatter is None:
            llama = self.llama
            template = llama.metadata.get("tokenizer.chat_template")
            if not template:
                return None
            from llama_cpp.llama_chat_format import Jinja2ChatFormatter

            eos, bos = llama.token_eos(), llama.token_bos()
            text_of = llama._model.token_get_text  # noqa: SLF001 - same helper Llama uses for its templates
            opts = dict(template=template, eos_token=text_of(eos) if eos != -1 else "",
                        bos_token=text_of(bos) if bos != -1 else "", stop_token_ids=[eos] if eos != -1 else None)
            self._formatter = (Jinja2ChatFormatter(add_generation_prompt=True, **opts),
                               Jinja2ChatFormatter(add_generation_prompt=False, **opts))
        return self._formatter

    def _format(self, formatter: Any, messages: list[dict[str, str]]) -> tuple[list[int], Any]:
        res = formatter(messages=messages)
        return self.llama.tokenize(res.prompt.encode("utf-8"), add_bos=not res.added_special, special=True), res

    def chat_prompt(self, messages: Sequence[Message]) -> ChatPrompt:
        """The chat-formatted prompt (assistant turn opened) as tokens, cut where the second and the last
        message start.

        A message starts where the template's formatting of the messages before it (without a generation
        prompt) ends, provided those tokens are a prefix of the prompt's; if that fails, the prompt is one
        piece (evaluated whole every time).
        """
        formatters = self._formatters()
        if formatters is None:
            raise LMError(f"llamacpp {self.model}: the GGUF has no chat template; choice_probabilities needs one")
        messages = as_messages(messages)
        dicts = message_dicts(messages)
        tokens, _ = self._format(formatters[0], dicts)
        starts = self._cuts(formatters[1], dicts, tokens)
        last = messages[-1]
        if starts and 0 < last.cut < len(last.content):
            # the last message's cut hint: where its first `cut` characters, formatted as if the message ended
            # there, stop agreeing with the prompt's tokens (a function of the prompt and the hint alone)
            partial, _ = self._format(formatters[1], dicts[:-1] + [{**dicts[-1], "content": last.content[:last.cut]}])
            n = _common_prefix(np.asarray(partial), tokens)
            if starts[-1] < n < len(tokens):
                starts = (*starts, n)
        return ChatPrompt(tokens, starts)

    def _cuts(self, formatter: Any, dicts: list[dict[str, str]], tokens: list[int]) -> tuple[int, ...]:
        llama = self.llama
        if getattr(llama, "_is_recurrent", False) or getattr(llama, "_is_hybrid", False):
            return ()  # a recurrent state cannot be cut back to a message start
        starts: list[int] = []
        for k in (k for k in sorted({1, len(dicts) - 1}) if 0 < k < len(dicts)):  # the second, the last message
            prefix, _ = self._format(formatter, dicts[:k])
            n = len(prefix)
            if not (starts[-1] if starts else 0) < n < len(tokens) or prefix != tokens[:n]:
                log.debug("llamacpp %s: message %d does not start at a token boundary of the prompt; "
                          "evaluating the prompt whole", self.model, k)
                return ()
            starts.append(n)
        return tuple(starts)

    def _check_fits(self, prompt: ChatPrompt) -> None:
        if len(prompt.tokens) >= self.n_ctx:
            raise LMError(f"llamacpp {self.model}: prompt of {len(prompt.tokens)} tokens does not fit "
                          f"n_ctx={self.n_ctx} (raise it with n_ctx=...)")

    def _evaluate(self, prompt: ChatPrompt, *, upto: int) -> int:
        """Bring the KV cache to ``prompt.tokens[:upto]`` (``upto``: a piece end) following the schedule;
        returns the tokens kept from the cache. The caller holds the lock."""
        llama = self.llama
        keep = 0
        if self.reuse_prefix:
            cached = llama.input_ids[: llama.n_tokens]
            keep = reusable_prefix(_PIECES.get(llama, ()), prompt.starts, _common_prefix(cached, prompt.tokens))
        if keep == 0:
            llama.reset()
        llama.n_tokens = keep  # eval() drops the KV entries from n_tokens on
        done = [e for e in prompt.ends if e <= keep]
        _PIECES[llama] = tuple(done)
        for end in prompt.ends:
            if keep < end <= upto:
                llama.eval(list(prompt.tokens[llama.n_tokens:end]))
                done.append(end)
                _PIECES[llama] = tuple(done)
        self.last_reused_tokens = keep
        return keep

    # ------------------------------------------------------------------ complete
    def complete(self, messages: Sequence[Message], *, temperature: float = 0.0, seed: int | None = None,
                 max_tokens: int = 512, stop: Sequence[str] | None = None,
                 json_schema: Mapping[str, Any] | None = None) -> Completion:
        llama = self.llama
        kwargs: dict[str, Any] = dict(temperature=float(temperature), max_tokens=int(max_tokens),
                                      top_p=0.95, top_k=40, min_p=0.05, typical_p=1.0, repeat_penalty=1.0)
        if seed is not None:
            kwargs["seed"] = int(seed)
        if json_schema is not None:
            kwargs["grammar"] = self._grammar(json_schema)
        assert self._lock is not None
        t0 = time.perf_counter()
        with self._lock:
            self._set_threads(llama)
            formatters = self._formatters()
            try:
                if formatters is None:  # llama-cpp-python's fallback format; no reuse, so still order-free
                    llama.reset()
                    _PIECES.pop(llama, None)
                    self.last_reused_tokens = 0
                    out = llama.create_chat_completion(messages=message_dicts(messages),
                                                       stop=list(stop) if stop else None, **kwargs)
                    text = out["choices"][0]["message"].get("content") or ""
                else:
                    dicts = message_dicts(messages)
                    tokens, res = self._format(formatters[0], dicts)
                    prompt = ChatPrompt(tokens, self._cuts(formatters[1], dicts, tokens))
                    self._check_fits(prompt)
                    # Evaluate up to the last cut here; generate() then finds exactly these tokens
                    # in the context (its longest prefix match stops there) and evaluates the last piece in
                    # one call, then one token per step.
                    self._evaluate(prompt, upto=prompt.starts[-1] if prompt.starts else 0)
                    out = llama.create_completion(prompt=list(prompt.tokens), stop=list(stop or []) + list(res.stop),
                                                  stopping_criteria=res.stopping_criteria, **kwargs)
                    _PIECES[llama] = prompt.ends
                    text = out["choices"][0].get("text") or ""
            except ValueError as e:  # e.g. prompt longer than the context window
                raise LMError(f"llamacpp {self.model}: {e} (n_ctx={self.n_ctx}; raise it with n_ctx=...)") from e
        latency = time.perf_counter() - t0
        usage = out.get("usage") or {}
        return Completion(text, Usage(prompt_tokens=int(usage.get("prompt_tokens", 0)),
                                      completion_tokens=int(usage.get("completion_tokens", 0)),
                                      latency_s=latency, cost_usd=0.0), model=self.identity())

    # ------------------------------------------------------------------ log-probabilities
    def _prompt_tokens(self, messages: Sequence[Message]) -> list[int]:
        """Chat-formatted prompt with the assistant turn opened, as tokens."""
        return list(self.chat_prompt(messages).tokens)

    def next_token_logits(self, prompt: ChatPrompt | Sequence[int]) -> np.ndarray:
        """Logits ``[vocab]`` of the token after ``prompt``, evaluated by the schedule: KV entries up to a
        shared cut are reused, the last piece is evaluated afresh. Bare token ids are one piece."""
        if not isinstance(prompt, ChatPrompt):
            prompt = ChatPrompt(prompt)
        if not prompt.tokens:
            raise LMError(f"llamacpp {self.model}: empty prompt")
        self._check_fits(prompt)
        llama = self.llama
        assert self._lock is not None
        with self._lock:
            self._set_threads(llama)
            self._evaluate(prompt, upto=len(prompt.tokens))
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
            logits = self.next_token_logits(self.chat_prompt(messages))
        return probabilities_from_logits(logits, ids)
