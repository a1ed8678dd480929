"""The cost of constrained decoding: one Call-3 sample of the ``gift`` kernel with its JSON-schema grammar
vs free text (the baseline), on the embedded model, uncached.

Grammar sampling checks candidate tokens against the grammar at every step (with enums of every object
name); free text needs no check but writes more (prose, code fences) and may need repair requests. Both
variants map the same objects with the same seed and temperature (0.7, the kernel's default for its N
samples). Size: ``GIFT_BENCH_CALL3_OBJECTS`` test objects (default 8; the measurement in
``docs/results/alignment.md`` used 25) against the 6 training objects of the pack family of gift-paper.

Nothing here asserts anything about time; each round checks that every object was placed, and records
the answers read, repair requests, fallbacks and completion tokens.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_schema_benchmark.py``.
"""

from __future__ import annotations

import os

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.lm]

N_TEST = int(os.environ.get("GIFT_BENCH_CALL3_OBJECTS", "8"))


@pytest.fixture(scope="module")
def scene():
    from gift.core.data import Intent
    from gift.core.suite import load_suite

    suite = load_suite("gift-paper")
    art, reading = suite.intent("art_supplies"), suite.intent("reading_material")
    test = list(dict.fromkeys([*art.test_objects, *reading.test_objects]))[:N_TEST]
    assert len(test) == N_TEST, f"gift-paper's pack family has only {len(test)} test objects"
    return test, list(art.train_objects), Intent(text=art.text, source="ground-truth")


@pytest.fixture(scope="module")
def raw_lm():
    from gift_llm import get_default_lm
    from gift_llm.usage import MeteredLM

    return MeteredLM(get_default_lm(cache=False).inner)  # the model itself, no cache


@pytest.mark.benchmark(group="call3-grammar")
@pytest.mark.parametrize("variant", ["free", "grammar"])
def test_call3_with_and_without_grammar(benchmark, raw_lm, scene, variant):
    from gift_kernels.lm_kernels import MappingKernel

    test, train, intent = scene
    kernels = []

    def one_sample():
        k = MappingKernel(lm=raw_lm, samples=1, temperature=0.7, seed=0, constrained=variant == "grammar")
        kernels.append(k)
        return k.votes(test, train, intent)

    before = raw_lm.stats.completion_tokens, raw_lm.stats.calls
    votes = benchmark.pedantic(one_sample, rounds=2, iterations=1, warmup_rounds=0)
    assert votes.counts.sum(axis=1).tolist() == [1] * len(test)  # every object placed (mapped or defaulted)
    tokens, calls = raw_lm.stats.completion_tokens - before[0], raw_lm.stats.calls - before[1]
    benchmark.extra_info.update(
        objects=len(test), training_objects=len(train), answers_per_round=calls / len(kernels),
        repairs_per_round=sum(k.stats.repairs for k in kernels) / len(kernels),
        fallbacks_per_round=sum(len(k.fallbacks) for k in kernels) / len(kernels),
        completion_tokens_per_round=tokens / len(kernels))
    if variant == "grammar":  # the grammar leaves nothing to repair
        assert all(k.stats.repairs == 0 and not k.fallbacks for k in kernels)
