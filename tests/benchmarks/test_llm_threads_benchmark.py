"""llama.cpp threads on a shared machine: the thread governor against a fixed thread count, in one run.

Another process keeps one core busy for the duration of the module (a bounded busy loop, as on a
machine that also runs a test suite, a render or another model). ``fixed`` runs every call on all the
cores of the budget (the behaviour before the governor); ``governed`` lets
:class:`gift_llm.backends.llamacpp.ThreadGovernor` take the cores the other process leaves free. Both
answer the same yes/no questions of the demo's kind; the probabilities must be identical to the last bit
(the thread count does not change the logits). Nothing here asserts anything about time.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_llm_threads_benchmark.py``.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.lm]

SYSTEM = "You answer questions about everyday objects with a single word: yes or no."
QUESTIONS = [f"Is a {o} one of the art supplies? Answer yes or no."
             for o in ("paintbrush (a tool for applying paint)", "stapler (it joins sheets of paper)")]


@pytest.fixture(scope="module")
def busy_core():
    """One other process spinning on a core (stops by itself after 10 minutes at most)."""
    hog = subprocess.Popen([sys.executable, "-c", "import time\nend = time.time() + 600\nwhile time.time() < end: pass"])
    yield hog
    hog.kill()
    hog.wait()


@pytest.fixture(scope="module")
def backends(busy_core):
    from gift_llm import get_default_lm
    from gift_llm.backends.llamacpp import LlamaCppLM, default_threads

    shared = get_default_lm(cache=False).inner
    shared.llama  # noqa: B018 - load before timing
    opts = dict(n_ctx=shared.n_ctx, reuse_prefix=False)  # every call evaluates its whole prompt: equal work
    return {"fixed": LlamaCppLM(shared.path, adapt_threads=False, **opts),  # same loaded Llama
            "governed": LlamaCppLM(shared.path, **opts), "budget": default_threads()}


def _ask_all(lm):
    return [lm.choice_probabilities([{"role": "system", "content": SYSTEM}, {"role": "user", "content": q}],
                                    ["yes", "no"]) for q in QUESTIONS]


@pytest.fixture(scope="module")
def expected(backends):
    return _ask_all(backends["governed"])  # the cheaper variant; equality is symmetric


@pytest.mark.benchmark(group="llm-threads")
@pytest.mark.parametrize("variant", ["fixed", "governed"])
def test_threads_with_one_core_busy(benchmark, backends, expected, variant):
    lm = backends[variant]
    out = benchmark.pedantic(_ask_all, args=(lm,), rounds=1, iterations=1, warmup_rounds=0)
    assert out == expected  # bit for bit: threads never change the answers
    benchmark.extra_info["threads_last_call"] = lm.last_threads
    benchmark.extra_info["budget"] = backends["budget"]
    if variant == "governed" and (os.cpu_count() or 1) > 1 and backends["budget"] > 1:
        assert lm.last_threads < backends["budget"]  # it saw the busy core
