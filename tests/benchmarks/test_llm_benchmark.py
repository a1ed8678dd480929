"""LM plugin speed: the llamacpp evaluation schedule with prompt-prefix reuse, and the SQLite cache, each
against its naive baseline in the same run.

- ``prefix``: ``choice_probabilities``-style next-token logits of the embedded model for yes/no questions
  that share a long system message (4 prompts of about 240 tokens) and two few-shot prompts of the
  category kind (system message, two answered examples, a question). Variants:

  * ``reuse`` (the default, :data:`gift_llm.backends.llamacpp.SCHEDULE`): the prompt cut into pieces at
    the second and the last message's start, the KV cache reused up to the last cut shared with the
    previous prompt;
  * ``pieces``: the same pieces, every prompt evaluated from its first token (``reuse_prefix=False``);
    must give the same logits to the last bit;
  * ``one-batch``: every prompt evaluated whole, in one piece (the no-reuse evaluation before the
    schedule); logits differ slightly (another split into decode batches);
  * ``token-prefix``: the schedule before ``msg1``: the KV cache reused up to the longest shared token
    prefix, whatever the split (results depend on the previous call).
- ``cache``: the same questions answered from the persistent cache vs by the model.

Nothing here asserts anything about time; each benchmark checks its answers against the baseline's.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_llm_benchmark.py``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

pytestmark = [pytest.mark.slow, pytest.mark.lm]

SYSTEM = ("You help a household robot decide which objects matter for a task. The human prefers keeping "
          "fragile or water-sensitive items away from liquids, and keeping sharp tools away from food. ") * 6 \
    + "Answer with yes or no only."
QUESTIONS = [f"Should the robot keep the {o} away from the open water bottle?"
             for o in ("laptop", "phone", "apple", "sponge")]
FEW_SHOT_SYSTEM = "You name the kind of objects a goal is about, in a few words."
EXAMPLES = [("Put the apples and pears in the bowl.", "fruit"), ("Keep the knives away from the baby.", "sharp tools")]
GOALS = ["Move the laptop away from the water.", "Stack the plates and the cups."]


def _conversations() -> list[list[dict[str, str]]]:
    yes_no = [[{"role": "system", "content": SYSTEM}, {"role": "user", "content": q}] for q in QUESTIONS]
    shots = [{"role": "system", "content": FEW_SHOT_SYSTEM}]
    for goal, answer in EXAMPLES:
        shots += [{"role": "user", "content": f"Goal: {goal}"}, {"role": "assistant", "content": answer}]
    return yes_no + [shots + [{"role": "user", "content": f"Goal: {g}"}] for g in GOALS]


def _token_prefix_logits(lm, tokens) -> np.ndarray:
    """The evaluation before the schedule: keep the longest shared token prefix, evaluate the rest at once."""
    llama = lm.llama
    keep = 0
    for a, b in zip(llama.input_ids[: llama.n_tokens].tolist(), tokens):
        if a != b:
            break
        keep += 1
    llama.n_tokens = min(keep, len(tokens) - 1)
    llama.eval(list(tokens[llama.n_tokens:]))
    return np.array(np.ctypeslib.as_array(llama._ctx.get_logits(), shape=(llama.n_vocab(),)), dtype=np.float64)


@pytest.fixture(scope="module")
def backends():
    from gift_llm import get_default_lm
    from gift_llm.backends.llamacpp import LlamaCppLM

    shared = get_default_lm(cache=False).inner
    # the same loaded model on one thread, so that CPU seconds compare the schedules, not thread counts
    reuse = LlamaCppLM(shared.path, n_ctx=shared.n_ctx, n_threads=1)
    pieces = LlamaCppLM(shared.path, n_ctx=shared.n_ctx, n_threads=1, reuse_prefix=False)
    assert reuse.llama is pieces.llama is shared.llama
    return {"reuse": reuse, "pieces": pieces}


@pytest.fixture(scope="module")
def prompts(backends):
    return [backends["reuse"].chat_prompt(c) for c in _conversations()]


def _evaluate_all(backends, prompts, variant) -> list[np.ndarray]:
    lm = backends["pieces" if variant == "pieces" else "reuse"]
    with lm._lock:  # one lock per loaded model: no other call between the prompts
        if variant == "one-batch":
            return [lm.next_token_logits(list(p.tokens)) for p in prompts]  # bare tokens: one piece, no reuse
        if variant == "token-prefix":
            return [_token_prefix_logits(lm, p.tokens) for p in prompts]
        return [lm.next_token_logits(p) for p in prompts]


_BASELINE: list[np.ndarray] = []


def expected(backends, prompts) -> list[np.ndarray]:
    """Logits of the ``pieces`` baseline: its benchmark round when that ran first (it is parametrized first),
    else computed here once."""
    if not _BASELINE:
        _BASELINE.extend(_evaluate_all(backends, prompts, "pieces"))
    return _BASELINE


@pytest.mark.benchmark(group="llm-prefix")
@pytest.mark.parametrize("variant", ["pieces", "one-batch", "token-prefix", "reuse"])
def test_prefix_reuse(benchmark, backends, prompts, variant):
    backends["reuse"].llama.reset()
    cpu: list[float] = []

    def timed():  # CPU seconds too: on a shared machine they vary less than wall time
        c0 = time.process_time()
        out = _evaluate_all(backends, prompts, variant)
        cpu.append(time.process_time() - c0)
        return out

    out = benchmark.pedantic(timed, rounds=1, iterations=1, warmup_rounds=0)
    if variant == "pieces" and not _BASELINE:
        _BASELINE.extend(out)  # this round is the baseline the other variants are checked against
        ref_logits: list[np.ndarray] = []  # nothing to compare it with
    else:
        ref_logits = expected(backends, prompts)
        assert len(out) == len(ref_logits) == len(prompts)
    for got, ref in zip(out, ref_logits):
        if variant in ("pieces", "reuse"):
            np.testing.assert_array_equal(got, ref)  # the schedule: the same numbers with or without reuse
        else:
            assert np.abs(got - ref).max() < 1.0  # another split into decode batches: close, not equal
            assert int(np.argmax(got)) == int(np.argmax(ref))
    benchmark.extra_info["cpu_s_per_round"] = [round(c, 2) for c in cpu]
    benchmark.extra_info["prompts_per_round"] = len(prompts)
    benchmark.extra_info["prompt_tokens_per_round"] = sum(len(p.tokens) for p in prompts)
    if variant == "reuse":
        benchmark.extra_info["reused_tokens_per_round"] = sum(p.starts[-1] for p in prompts[1:])


def _ask_all(lm):
    return [lm.choice_probabilities(c, ["yes", "no"]) for c in _conversations()[: len(QUESTIONS)]]


@pytest.mark.benchmark(group="llm-cache")
@pytest.mark.parametrize("variant", ["model", "cache"])
def test_cache_vs_model(benchmark, backends, variant, tmp_path):
    from gift_llm.cache import CachedLM

    lm = CachedLM(backends["reuse"], path=tmp_path / "c.sqlite", enabled=variant == "cache")
    filled = _ask_all(lm)  # fills the cache in the cached variant
    out = benchmark.pedantic(_ask_all, args=(lm,), rounds=2, iterations=1, warmup_rounds=0)
    assert out == filled  # the schedule makes the model's answers repeatable too
    if variant == "cache":
        assert lm.stats.calls == len(QUESTIONS)  # only the filling round reached the model
