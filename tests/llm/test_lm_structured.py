"""ask_dict: validation and the repair loop (scripted LM: control flow only), then on the real model."""

from __future__ import annotations

import pytest

from gift.core.errors import LMAnswerError
from gift_llm.structured import ask_dict, check_dict
from llm_scripted import ScriptedLM


def test_valid_first_answer_needs_no_repair():
    lm = ScriptedLM(["Sure: {'apple': 'banana', 'mug': 'distractor'}"])
    d = ask_dict(lm, "map them", required_keys=["apple", "mug"], allowed_values=["banana", "distractor"])
    assert d == {"apple": "banana", "mug": "distractor"} and lm.calls == 1


def test_repair_request_shows_the_answer_and_the_problem():
    lm = ScriptedLM(["I think apple goes with banana.", "{'apple': 'pear'}", "{'apple': 'Banana'}"])
    d = ask_dict(lm, "map them", required_keys=["apple"], allowed_values=["banana", "distractor"], max_repairs=2)
    assert d == {"apple": "banana"} and lm.calls == 3  # 'Banana' canonicalised to the allowed spelling
    second = lm.prompts[1]
    assert second[-2].role == "assistant" and second[-2].content == "I think apple goes with banana."
    assert "no Python dictionary" in second[-1].content
    third = lm.prompts[2]
    assert "'pear'" in third[-1].content and "not one of the allowed values" in third[-1].content


def test_validate_callback_message_goes_into_the_repair_and_can_replace_the_dict():
    def validate(d):
        if d.get("n", 0) < 3:
            raise ValueError("n must be at least 3")
        return {**d, "checked": True}

    lm = ScriptedLM(["{'n': 1}", "{'n': 5}"])
    assert ask_dict(lm, "give n", validate=validate) == {"n": 5, "checked": True}
    assert "n must be at least 3" in lm.prompts[1][-1].content


def test_exhausted_repairs_raise_with_the_raw_answer():
    lm = ScriptedLM(["nothing useful", "still nothing", "nope"])
    with pytest.raises(LMAnswerError) as e:
        ask_dict(lm, "give a dict", max_repairs=2)
    assert lm.calls == 3 and e.value.raw == "nope"
    assert "after 2 repair request(s)" in str(e.value) and "attempt 3" in str(e.value)


def test_missing_keys_and_per_key_allowed_values():
    with pytest.raises(ValueError, match="'b' is missing"):
        check_dict({"a": 1}, required_keys=["a", "b"])
    d = check_dict({" A ": ["X", "y"]}, required_keys=["a"], allowed_values={"a": ["x", "y"]})
    assert d == {"a": ["x", "y"]}
    with pytest.raises(ValueError, match="'z'"):
        check_dict({"a": ["x", "z"]}, allowed_values={"a": ["x", "y"]})


@pytest.mark.slow
@pytest.mark.lm
def test_real_model_answers_a_validated_dict(embedded_lm):
    d = ask_dict(embedded_lm, [{"role": "system", "content": "Reply with a Python dictionary only."},
                               {"role": "user", "content": "Map each object to 'fruit' or 'tool': apple, hammer."}],
                 required_keys=["apple", "hammer"], allowed_values=["fruit", "tool"], max_tokens=40,
                 json_schema={"type": "object"})
    assert d == {"apple": "fruit", "hammer": "tool"}
