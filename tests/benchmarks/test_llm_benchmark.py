"""LM plugin speed: prompt-prefix reuse in llama.cpp, and the SQLite cache, each against its naive baseline.

- ``prefix``: yes/no ``choice_probabilities`` of the embedded model for questions that share a long system
  prompt (237-token prompts, 224 tokens shared) — KV-cache reuse of the shared prefix (``reuse_prefix=True``, the default) vs
  re-evaluating the whole prompt every call (``reuse_prefix=False``).
- ``cache``: the same questions answered from the persistent cache vs by the model.

Nothing here asserts anything about time; each benchmark checks its answers against the baseline's.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_llm_benchmark.py``.
"""

from __future__ import annotations

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.lm]

SYSTEM = ("You help a household robot decide which objects matter for a task. The human prefers keeping "
          "fragile or water-sensitive items away from liquids, and keeping sharp tools away from food. ") * 6 \
    + "Answer with yes or no only."
QUESTIONS = [f"Should the robot keep the {o} away from the open water bottle?"
             for o in ("laptop", "phone", "apple", "sponge")]


@pytest.fixture(scope="module")
def backends():
    from gift_llm import get_default_lm
    from gift_llm.backends.llamacpp import LlamaCppLM

    shared = get_default_lm(cache=False).inner
    naive = LlamaCppLM(shared.path, n_ctx=shared.n_ctx, reuse_prefix=False)  # same loaded Llama
    return {"reuse": shared, "naive": naive}


@pytest.fixture(scope="module")
def expected(backends):
    """Answers of the naive baseline, computed once."""
    return _ask_all(backends["naive"])


def _ask_all(lm):
    return [lm.choice_probabilities([{"role": "system", "content": SYSTEM}, {"role": "user", "content": q}],
                                    ["yes", "no"]) for q in QUESTIONS]


@pytest.mark.benchmark(group="llm-prefix")
@pytest.mark.parametrize("variant", ["naive", "reuse"])
def test_prefix_reuse(benchmark, backends, expected, variant):
    lm = backends[variant]
    out = benchmark.pedantic(_ask_all, args=(lm,), rounds=2, iterations=1, warmup_rounds=0)
    for got, ref in zip(out, expected):
        assert got["yes"] == pytest.approx(ref["yes"], abs=0.02)
    benchmark.extra_info["questions_per_round"] = len(QUESTIONS)
    benchmark.extra_info["reused_prompt_tokens_last_call"] = lm.last_reused_tokens


@pytest.mark.benchmark(group="llm-cache")
@pytest.mark.parametrize("variant", ["model", "cache"])
def test_cache_vs_model(benchmark, backends, variant, tmp_path):
    from gift_llm.cache import CachedLM

    lm = CachedLM(backends["reuse"], path=tmp_path / "c.sqlite", enabled=variant == "cache")
    filled = _ask_all(lm)  # fills the cache in the cached variant
    out = benchmark.pedantic(_ask_all, args=(lm,), rounds=2, iterations=1, warmup_rounds=0)
    assert out == filled or variant == "model"
    if variant == "cache":
        assert lm.stats.calls == len(QUESTIONS)  # only the filling round reached the model
