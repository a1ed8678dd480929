"""The real embedded model (Qwen2.5-Coder-1.5B-Instruct Q4_K_M) through llama-cpp-python."""

from __future__ import annotations

import pytest

from gift.core.errors import LMError
from gift_llm import get_default_lm
from gift_llm.backends import llamacpp
from gift_llm.parsing import extract_dict
from gift_llm.structured import ask_dict

pytestmark = [pytest.mark.slow, pytest.mark.lm]

YES_NO = "Answer with yes or no only."


def test_complete_answers_a_trivial_question(embedded_lm):
    c = embedded_lm.complete([{"role": "user", "content": "What is 2 + 2? Reply with the number only."}],
                             max_tokens=5)
    assert "4" in c.text
    assert c.usage.prompt_tokens > 5 and 1 <= c.usage.completion_tokens <= 5 and c.usage.latency_s > 0
    assert c.model == f"llamacpp:qwen2.5-coder-1.5b-instruct-q4_k_m.gguf+{llamacpp.SCHEDULE}"


def test_choice_probabilities_separate_true_from_false(embedded_lm):
    def p_yes(statement):
        p = embedded_lm.choice_probabilities(
            [{"role": "system", "content": YES_NO}, {"role": "user", "content": statement}], ["yes", "no"])
        assert set(p) == {"yes", "no"} and abs(sum(p.values()) - 1.0) < 1e-9
        return p["yes"]

    true_ = p_yes("Is a banana a fruit?")
    false_ = p_yes("Is a hammer a fruit?")
    assert true_ > 0.5 > false_, (true_, false_)


def test_grammar_constrained_answers_parse_as_dicts(embedded_lm):
    generic = embedded_lm.complete([{"role": "user", "content": "Give the colour of an apple and of a banana."}],
                                   max_tokens=40, json_schema={"type": "object"})
    assert isinstance(extract_dict(generic.text), dict)
    schema = {"type": "object", "properties": {"animal": {"type": "string"}, "legs": {"type": "integer"}},
              "required": ["animal", "legs"]}
    typed = extract_dict(embedded_lm.complete([{"role": "user", "content": "Describe a dog as JSON."}],
                                              max_tokens=30, json_schema=schema).text)
    assert set(typed) == {"animal", "legs"} and isinstance(typed["legs"], int)


def test_prompt_prefix_is_reused_across_calls(embedded_lm):
    system = {"role": "system", "content": "You judge objects for a household robot. " * 8 + YES_NO}
    embedded_lm.choice_probabilities([system, {"role": "user", "content": "Is a mug fragile?"}], ["yes", "no"])
    embedded_lm.choice_probabilities([system, {"role": "user", "content": "Is a pillow fragile?"}], ["yes", "no"])
    n_system = len(embedded_lm.llama.tokenize(system["content"].encode(), add_bos=False))
    assert embedded_lm.last_reused_tokens >= n_system


def test_default_lm_is_shared_and_loaded_once(embedded_lm, cache_root):
    loads = llamacpp.LOAD_COUNT
    a, b = get_default_lm(), get_default_lm()
    assert a is b and a.inner.llama is embedded_lm.llama and llamacpp.LOAD_COUNT == loads
    assert a.store.path == cache_root / "lm" / "lm-cache.sqlite"


def test_repeated_run_with_the_cache_makes_no_model_call(embedded_lm, cache_root):
    from gift_llm.cache import CachedLM

    def run(lm):
        d = ask_dict(lm, "Map each object to 'food' or 'tool': bread, saw. Reply with a dictionary.",
                     allowed_values=["food", "tool"], max_tokens=30, json_schema={"type": "object"})
        p = lm.choice_probabilities([{"role": "user", "content": "Is bread edible? " + YES_NO}], ["yes", "no"])
        c = lm.complete("Say hello in one word.", max_tokens=4, temperature=0.9, seed=11)
        return d, p, c.text

    first = CachedLM(embedded_lm)
    out1 = run(first)
    assert first.stats.calls >= 3 and first.stats.hits == 0
    second = CachedLM(embedded_lm)  # a new run on the same cache file
    out2 = run(second)
    assert out2 == out1 and second.stats.calls == 0 and second.stats.hits == first.stats.misses
    # every answer is counted under the llama.cpp build (version and CPU kernels) that made it, stored with it
    build = llamacpp.llama_build()
    assert "CPU" in build
    assert first.stats.made_by == {build: first.stats.misses} and second.stats.made_by == {build: second.stats.hits}


def test_errors_are_clear(tmp_path, embedded_lm):
    with pytest.raises(LMError, match="does not exist"):
        llamacpp.LlamaCppLM(tmp_path / "nope.gguf").llama
    bad = tmp_path / "bad.gguf"
    bad.write_bytes(b"not a gguf at all")
    with pytest.raises(LMError, match="cannot load"):
        llamacpp.LlamaCppLM(bad).llama
    with pytest.raises(LMError, match="start with the same token"):
        embedded_lm.choice_probabilities([{"role": "user", "content": "?"}], ["yes", "Yes"])
