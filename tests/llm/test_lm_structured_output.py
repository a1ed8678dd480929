"""Which ``response_format`` the litellm backend sends with a JSON schema, per litellm's support tables.

No request is sent here; ``test_lm_litellm.py`` sends the schemas over HTTP to a real server.
"""

from __future__ import annotations

import pytest

from gift.core.errors import LMError
from gift_kernels import schemas
from gift_llm.backends.litellm_backend import LiteLLM, portable_schema, strict_compatible


def test_the_style_follows_litellms_support_check_per_model():
    assert LiteLLM("openai/gpt-4o").structured_output_style() == "json_schema"
    assert LiteLLM("anthropic/claude-sonnet-4-20250514").structured_output_style() == "json_schema"
    assert LiteLLM("ollama/llama3").structured_output_style() == "json_object"  # JSON mode only
    assert LiteLLM("replicate/meta/llama-2-70b-chat").structured_output_style() == "none"
    assert LiteLLM("openai/local", api_base="http://127.0.0.1:1/v1").structured_output_style() == "json_object_schema"
    assert LiteLLM("openai/gpt-4o", json_style="none").structured_output_style() == "none"
    assert LiteLLM("ollama/llama3")._response_format(schemas.category_schema()) == {"type": "json_object"}
    assert LiteLLM("replicate/meta/llama-2-70b-chat")._response_format(schemas.category_schema()) is None
    with pytest.raises(LMError, match="json_style must be one of"):
        LiteLLM("openai/gpt-4o", json_style="grammar")


def test_providers_get_a_strict_portable_copy_of_the_schema():
    full = schemas.intent_schema(["a_proximity_to_b", "maxLength"])
    sent = LiteLLM("openai/gpt-4o")._response_format(full)
    assert sent["type"] == "json_schema" and sent["json_schema"]["name"] == "answer"
    assert sent["json_schema"]["strict"] is True
    schema = sent["json_schema"]["schema"]
    mots = schema["properties"]["motivations"]
    assert "minItems" not in mots and "maxLength" not in mots["items"]["properties"]["text"]
    assert mots["items"]["properties"]["features"]["items"]["enum"] == ["a_proximity_to_b", "maxLength"]
    assert mots["items"]["required"] == ["text", "features"] and mots["items"]["additionalProperties"] is False
    assert full["properties"]["motivations"]["minItems"] == 3  # the caller's schema is left alone
    mapping = schemas.mapping_schema(["maxLength", "apple"], ["paintbrush"])  # an object named like a keyword
    assert portable_schema(mapping) == mapping and strict_compatible(mapping)
    for s in (schemas.axes_schema(["x"]), schemas.category_schema(), full):
        assert strict_compatible(portable_schema(s))
    assert not strict_compatible({"type": "object", "properties": {"a": {"type": "string"}}, "required": []})
    assert not strict_compatible({"type": "array", "items": {"type": "object", "properties": {}}})
