"""gift-prob's yes/no questions on the embedded model: asked object by object with the cut hint (the default)
against category by category without it (the order and the prompts before), in the same run.

One small inferred-intent scene (3 test and 4 training objects of the benchmark's own, the category ladder:
about 6 categories, each question in two forms). The category and ladder calls are made once, before timing;
each round then asks every yes/no question of the scene afresh (uncached model, the kernel's memo emptied).

- ``object-order``: :meth:`GiftProbKernel.score` collects the scene's questions, then asks them grouped by the
  object as shown; each question carries a cut hint before its category, so llama.cpp evaluates the object's
  text once and, per question, only the category and what follows (``gift_llm.backends.llamacpp``);
- ``category-order``: the questions asked as the scoring reaches them (category by category) and without the
  hint: each question's whole last message evaluated every time.

The two split the prompts differently into decode batches, so their log-odds are close, not equal; the
benchmark checks the scores agree (ranking and size). CPU seconds per round go in ``extra_info``.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_gift_prob_benchmark.py``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from gift.core.data import Intent, Message, ObjectSpec

pytestmark = [pytest.mark.slow, pytest.mark.lm]

TRAIN = [ObjectSpec("watering can", "a metal can with a long spout for pouring water on plants"),
         ObjectSpec("pair of secateurs", "spring-loaded clippers for cutting stems and twigs"),
         ObjectSpec("bar of soap", "a block of scented soap for washing hands"),
         ObjectSpec("desk calendar", "a small stand with a page for each month")]
RELEVANT = ("watering can", "pair of secateurs")
TEST = [ObjectSpec("hand trowel", "a short pointed scoop for digging small holes in a flower bed"),
        ObjectSpec("garden gnome", "a painted clay figure of a bearded man in a pointed hat"),
        ObjectSpec("tube of toothpaste", "a squeezable tube of mint paste for brushing teeth")]
INTENT = Intent(text="The person wanted to put the watering can in the drawer.", source="inferred")
_scores: dict[str, object] = {}


@pytest.fixture(scope="module")
def named():
    """A kernel on the uncached embedded model whose categories and ladders are already named."""
    from gift_llm import get_default_lm
    from gift_kernels.lm_kernels import GiftProbKernel

    k = GiftProbKernel(lm=get_default_lm(cache=False))
    k.score(TEST[:1], TRAIN, INTENT, RELEVANT)  # names the category and the ladders (kept in the kernel)
    return k


def _round(k, variant: str):
    k._memo.clear()
    if variant == "category-order":
        k._in_object_order = lambda run: None
        ask = type(k)._ask
        k._ask = lambda msgs: ask(k, tuple(Message(m.role, m.content) for m in msgs))  # without the hint
    try:
        return k.score(TEST, TRAIN, INTENT, RELEVANT), len(k._memo)
    finally:
        k.__dict__.pop("_in_object_order", None)
        k.__dict__.pop("_ask", None)


@pytest.mark.benchmark(group="gift-prob questions")
@pytest.mark.parametrize("variant", ["category-order", "object-order"])
def test_gift_prob_question_order(benchmark, named, variant):
    cpu: list[float] = []

    def timed():  # CPU seconds too: on a shared machine they vary less than wall time
        c0 = time.process_time()
        out = _round(named, variant)
        cpu.append(time.process_time() - c0)
        return out

    scores, questions = benchmark.pedantic(timed, rounds=1, iterations=1, warmup_rounds=0)
    _scores[variant] = scores
    benchmark.extra_info["cpu_s_per_round"] = [round(c, 2) for c in cpu]
    benchmark.extra_info["questions_per_round"] = questions
    assert questions > 2 * (len(TEST) + len(TRAIN))  # several categories per object, each asked
    if len(_scores) == 2:
        a, b = _scores["category-order"], _scores["object-order"]
        # decode-batch noise: 0.012 at most over a 19-object scene of gift-dev6 (docs/performance.md)
        assert np.abs(a.relevance - b.relevance).max() < 0.05 and np.abs(a.train_loo - b.train_loo).max() < 0.05
        assert int(np.argmax(a.relevance)) == int(np.argmax(b.relevance)) == 0  # the trowel first
