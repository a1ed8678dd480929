"""litellm over real HTTP against llama-cpp-python's OpenAI-compatible server on 127.0.0.1."""

from __future__ import annotations

import sqlite3
import socket

import pytest

from gift.core.errors import LMError
from gift_llm.backends.litellm_backend import LiteLLM
from gift_llm.cache import CachedLM
from gift_llm.parsing import extract_dict
from gift_llm.resolve import resolve_lm

pytestmark = [pytest.mark.slow, pytest.mark.lm]
SECRET = "sk-test-never-store-me-0123456789"


@pytest.fixture
def server_lm(llama_server, monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", SECRET)  # sent as a bearer token to the local server, stored nowhere
    return LiteLLM("openai/local", api_base=llama_server, max_retries=2, backoff_s=0.2)


def test_complete_and_json_over_http(server_lm, tmp_path):
    lm = CachedLM(server_lm, path=tmp_path / "c.sqlite")
    c = lm.complete([{"role": "user", "content": "What is 2 + 2? Reply with the number only."}], max_tokens=5)
    assert "4" in c.text and c.usage.prompt_tokens > 5 and c.usage.completion_tokens >= 1
    again = lm.complete([{"role": "user", "content": "What is 2 + 2? Reply with the number only."}], max_tokens=5)
    assert again.text == c.text and again.usage.cached and lm.stats.calls == 1
    schema = {"type": "object", "properties": {"animal": {"type": "string"}, "legs": {"type": "integer"}},
              "required": ["animal", "legs"]}
    d = extract_dict(lm.complete("Describe a cat as JSON.", max_tokens=30, json_schema=schema).text)
    assert set(d) == {"animal", "legs"}
    dump = "".join(map(str, sqlite3.connect(tmp_path / "c.sqlite").execute("SELECT * FROM entries").fetchall()))
    assert SECRET not in dump and "litellm:openai/local@" in dump


def test_choice_probabilities_from_top_logprobs(server_lm):
    assert server_lm.supports_choice_probabilities  # openai/ provider: logprobs available
    ask = "Answer with yes or no only. "
    p_true = server_lm.choice_probabilities([{"role": "user", "content": ask + "Is a banana a fruit?"}],
                                            ["yes", "no"])
    p_false = server_lm.choice_probabilities([{"role": "user", "content": ask + "Is a hammer a fruit?"}],
                                             ["yes", "no"])
    assert p_true["yes"] > 0.5 > p_false["yes"], (p_true, p_false)


def test_resolve_lm_builds_litellm_from_a_model_string(llama_server, tmp_path):
    lm = resolve_lm("litellm:openai/local", api_base=llama_server, cache_path=tmp_path / "c.sqlite")
    assert lm.identity() == f"litellm:openai/local@{llama_server}" and lm.inner.name == "litellm"
    assert lm.complete("Reply with the word ok.", max_tokens=3).text.strip()


def test_dead_server_is_a_clear_error_without_secrets(monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", SECRET)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # closed again: nothing listens there
    url = f"http://127.0.0.1:{port}/v1"
    lm = LiteLLM("openai/local", api_base=url, max_retries=1, backoff_s=0.05, timeout_s=5)
    with pytest.raises(LMError) as e:
        lm.complete("hello", max_tokens=2)
    msg = str(e.value)
    assert url in msg and "after 2 attempts" in msg and SECRET not in msg


# ----------------------------------------------------------------------------- structured output


def _call3(lm):
    """One schema-constrained Call 3 (the ``gift`` kernel, one sample) through ``lm``; its stats and votes."""
    from gift.core.data import Intent
    from gift_kernels.lm_kernels import MappingKernel

    k = MappingKernel(lm=lm, samples=1, temperature=0.0)
    votes = k.votes(["crayons", "apple"], ["paintbrush", "banana"], Intent("pack art supplies"))
    return k, votes


def _as_llama_cpp_server_format(body):
    """OpenAI structured output -> the ``json_object`` + ``schema`` form, the only one llama_cpp.server reads."""
    fmt = body.get("response_format") or {}
    if fmt.get("type") == "json_schema":
        body = {**body, "response_format": {"type": "json_object", "schema": fmt["json_schema"]["schema"]}}
    return body


@pytest.mark.parametrize("style", [None, "json_schema", "none"])
def test_call3_schema_goes_over_http_as_each_style_and_the_answer_validates(llama_server, monkeypatch, style):
    import json

    import jsonschema
    from gift_kernels import schemas
    from recording_proxy import recording_proxy

    monkeypatch.setenv("OPENAI_API_KEY", SECRET)
    with recording_proxy(llama_server, rewrite=_as_llama_cpp_server_format) as (url, exchanges):
        lm = LiteLLM("openai/local", api_base=url, json_style=style, max_retries=1)
        k, votes = _call3(lm)
    body = exchanges[0]["request"]
    prompt = body["messages"][1]["content"]
    order = [json.loads(next(ln for ln in prompt.splitlines() if ln.startswith(key)).split(":", 1)[1])
             for key in ("New objects", "Training objects")]
    schema = schemas.mapping_schema(*order)
    assert votes.counts.sum() == 2  # both objects placed
    if style == "none":  # nothing but the prompt (and gift's validator)
        assert "response_format" not in body
        return
    if style is None:  # an OpenAI-compatible server at api_base: llama.cpp's form, the full schema
        assert lm.structured_output_style() == "json_object_schema"
        assert body["response_format"] == {"type": "json_object", "schema": schema}
    else:  # what providers with structured outputs get: strict, the portable subset
        fmt = body["response_format"]
        assert fmt["type"] == "json_schema" and fmt["json_schema"]["strict"] is True
        assert fmt["json_schema"]["schema"] == schema  # Call 3's schema has no length bounds to drop
        assert fmt["json_schema"]["schema"]["properties"]["crayons"]["enum"] == [*order[1], "distractor"]
    assert len(exchanges) == 1 and k.stats.repairs == 0 and not k.fallbacks  # no repair needed
    answer = json.loads(exchanges[0]["response"]["choices"][0]["message"]["content"])
    jsonschema.validate(answer, schema)
