"""extract_dict / extract_dicts / extract_named_dicts on realistic and adversarial LM answers."""

from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gift.core.errors import LMAnswerError
from gift_llm.parsing import extract_dict, extract_dicts, extract_named_dicts

FENCED = """Here is the mapping you asked for.

```python
mapping = {
    'apple': 'banana',   # both are fruit
    "laptop": 'distractor',
}
```
Let me know if you need anything else."""

PAPER_CALL1 = """1) The goal is packing.
motivations = {
    'The human keeps food away from sharp tools.': ['banana_proximity_to_scalpel', 'peach_proximity_to_suture',],
    'The human packs items used together.': ['banana_proximity_to_backpack'],
}

semantic_similarities = {
    'is it edible?': ['banana_proximity_to_scalpel'],
}
"""


@pytest.mark.parametrize("text, expected", [
    ('{"a": 1, "b": [1, 2]}', {"a": 1, "b": [1, 2]}),
    ("{'a': True, 'b': None}", {"a": True, "b": None}),
    ('{"a": true, "b": null, "c": false,}', {"a": True, "b": None, "c": False}),
    (FENCED, {"apple": "banana", "laptop": "distractor"}),
    ("Answer: {mug: cup, knife: distractor} done", {"mug": "cup", "knife": "distractor"}),
    ("x = {'k': 'it\\'s'}", {"k": "it's"}),
    ('{"k": "a } brace and a { brace"}', {"k": "a } brace and a { brace"}),
    ("{\u201capple\u201d: \u201cred\u201d}", {"apple": "red"}),
    ("{'t': (1, 2), 'n': -3.5e2, 'nested': {'x': [{'y': 1}]}}",
     {"t": (1, 2), "n": -350.0, "nested": {"x": [{"y": 1}]}}),
    ("{'a': 'first' 'second'}", {"a": "firstsecond"}),
    ('{"a": 1 // a comment\n, /* block */ "b": 2}', {"a": 1, "b": 2}),
    ("{'a': '''multi\nline'''}", {"a": "multi\nline"}),
])
def test_extract_dict_accepts_common_answer_shapes(text, expected):
    assert extract_dict(text) == expected


def test_last_complete_dict_wins_and_all_are_listed():
    text = "Example: {'a': 1}. My answer: {'a': 2} and a broken one {'a': "
    assert extract_dict(text) == {"a": 2}
    assert extract_dicts(text) == [{"a": 1}, {"a": 2}]


def test_named_dicts_of_the_paper_intent_answer():
    named = extract_named_dicts(PAPER_CALL1)
    assert set(named) == {"motivations", "semantic_similarities"}
    assert named["motivations"]["The human packs items used together."] == ["banana_proximity_to_backpack"]
    assert named["semantic_similarities"] == {"is it edible?": ["banana_proximity_to_scalpel"]}
    assert extract_dict(PAPER_CALL1) == named["semantic_similarities"]


@pytest.mark.parametrize("text", ["", "no dictionary here", "{{{{", "{'a': }", "{'a' 'b'}", "[1, 2, 3]",
                                  "{1, 2, 3}", "{'a': [1, 2}", "__import__('os').system('echo hi')",
                                  "{'a': __import__('os')}"])
def test_no_dict_is_a_clear_error_with_the_raw_answer(text):
    with pytest.raises(LMAnswerError) as e:
        extract_dict(text)
    assert e.value.raw == text
    assert "no dictionary" in str(e.value)


def test_code_is_never_executed(tmp_path):
    marker = tmp_path / "pwned"
    text = f"{{'a': open({str(marker)!r}, 'w').write('x')}}"
    with pytest.raises(LMAnswerError):
        extract_dict(text)
    assert not marker.exists()


def test_deep_nesting_never_overflows_the_stack():
    """Nesting beyond MAX_DEPTH is not parsed as one dict; an inner dict within the limit is returned."""
    from gift_llm.parsing import MAX_DEPTH

    deep = "{'a': " * 5000 + "1" + "}" * 5000
    out = extract_dict(deep)
    depth = 0
    while isinstance(out, dict):
        out, depth = out["a"], depth + 1
    assert out == 1 and depth <= MAX_DEPTH + 1
    with pytest.raises(LMAnswerError):
        extract_dict("[" * 5000 + "]" * 5000)


def test_non_text_answer_is_an_answer_error():
    with pytest.raises(LMAnswerError):
        extract_dict(None)  # type: ignore[arg-type]


def test_surrogate_pair_escapes_become_one_character_in_a_python_literal_too():
    """Found by the fuzz test below: a JSON dict followed by a comment is read as a Python literal, and Python,
    unlike JSON, keeps a surrogate-pair escape as two code points; the parser joins them either way."""
    assert extract_dict('{"\\ud800\\udc00": []}\n#') == {"\U00010000": []}
    assert extract_dict("{'smile': ['\\ud83d\\ude00', {'\\ud83d\\ude00': 1}]}  # a comment") == \
        {"smile": ["\U0001f600", {"\U0001f600": 1}]}
    assert extract_dict('{"lone": "\\ud800"}') == {"lone": "\ud800"}  # a lone surrogate stays as written


# ---------------------------------------------------------------- fuzzing
_keys = st.text(min_size=1, max_size=12)
_leaves = st.none() | st.booleans() | st.integers(-10**6, 10**6) | st.text(max_size=20)
_values = st.recursive(_leaves, lambda c: st.lists(c, max_size=4) | st.dictionaries(_keys, c, max_size=3),
                       max_leaves=10)
_dicts = st.dictionaries(_keys, _values, min_size=1, max_size=5)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(d=_dicts, before=st.text(max_size=40).filter(lambda s: "{" not in s),
       after=st.text(max_size=40).filter(lambda s: "{" not in s), style=st.sampled_from(["json", "repr"]))
def test_fuzz_roundtrip_of_a_dict_embedded_in_prose(d, before, after, style):
    body = json.dumps(d) if style == "json" else repr(d)
    assert extract_dict(f"{before}\n{body}\n{after}") == d


_junk_alphabet = st.sampled_from(list("{}[]()'\"\\:,#/*\n =abc01-.TrueNoneull\u201c\u201d`"))


@settings(max_examples=1500, deadline=None)
@given(text=st.text(alphabet=_junk_alphabet, max_size=120))
def test_fuzz_malformed_answers_give_a_dict_or_a_clear_error(text):
    try:
        out = extract_dict(text)
    except LMAnswerError as e:
        assert e.raw == text
    else:
        assert isinstance(out, dict)


@settings(max_examples=300, deadline=None)
@given(d=_dicts, cut=st.integers(0, 10_000), noise=st.text(max_size=30))
def test_fuzz_truncated_or_corrupted_dicts(d, cut, noise):
    body = repr(d)
    text = body[: cut % (len(body) + 1)] + noise
    try:
        out = extract_dict(text)
    except LMAnswerError:
        return
    assert isinstance(out, dict)


@settings(max_examples=200, deadline=None)
@given(text=st.text(max_size=300))
def test_fuzz_arbitrary_unicode(text):
    try:
        assert isinstance(extract_dict(text), dict)
    except LMAnswerError:
        pass
