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
