"""The llamacpp evaluation schedule: an answer is a function of the prompt alone, whatever the KV cache held
before (fresh after ``llama.reset()``, after an unrelated prompt, after a prompt sharing a prefix)."""

from __future__ import annotations

import numpy as np
import pytest

from gift_llm.backends import llamacpp
from gift_llm.backends.llamacpp import ChatPrompt, reusable_prefix

SYSTEM = {"role": "system", "content": "You answer questions about everyday objects with a single word: yes or no."}
OTHER_SYSTEM = {"role": "system", "content": "You are a careful assistant who writes short poems about the sea."}


def ask(question: str, system=SYSTEM) -> list[dict[str, str]]:
    return [system, {"role": "user", "content": question}]


QUESTION = ask("Is a paintbrush (a tool for applying paint) one of the art supplies? Answer yes or no.")
SIBLING = ask("Is a stapler one of the art supplies? Answer yes or no.")  # shares the system message and more
UNRELATED = ask("Write one line about waves.", OTHER_SYSTEM)

FEW_SHOT = [SYSTEM, {"role": "user", "content": "Is a banana a fruit?"}, {"role": "assistant", "content": "yes"},
            {"role": "user", "content": "Is a hammer a fruit?"}, {"role": "assistant", "content": "no"}]


# ----------------------------------------------------------------------------- without the model

def test_reuse_stops_at_the_last_message_start_both_schedules_share():
    # cached pieces ended at 20 and 50; this prompt's messages start at 20, 50, 70
    assert reusable_prefix((20, 50), (20, 50, 70), common=80) == 50
    assert reusable_prefix((20, 50), (20, 50, 70), common=49) == 20  # tokens differ before 50
    assert reusable_prefix((20, 50), (20, 40, 50), common=80) == 20  # the cached piece [20, 50) spans a start
    assert reusable_prefix((20, 60), (20, 40), common=60) == 20
    assert reusable_prefix((25, 50), (20, 50), common=80) == 0
    assert reusable_prefix((), (20,), common=80) == 0 and reusable_prefix((20,), (), common=80) == 0


def test_chat_prompt_checks_its_message_starts():
    assert ChatPrompt([5, 6, 7, 8], [1, 3]).ends == (1, 3, 4)
    for bad in ([0], [4], [2, 2], [3, 1]):
        with pytest.raises(ValueError, match="must increase strictly"):
            ChatPrompt([5, 6, 7, 8], bad)


def test_identity_names_the_schedule(tmp_path):
    lm = llamacpp.LlamaCppLM(tmp_path / "m.gguf")  # not loaded
    assert lm.identity() == f"llamacpp:m.gguf+{llamacpp.SCHEDULE}"


# ----------------------------------------------------------------------------- with the model

def _situations(lm, before: dict[str, list | None], run):
    """``run()`` after each state of the KV cache; returns {situation: (result, reused tokens)}."""
    out = {}
    for name, previous in before.items():
        with lm._lock:
            lm.llama.reset()
            if previous is not None:
                lm.next_token_logits(lm.chat_prompt(previous))
            out[name] = (run(), lm.last_reused_tokens)
    return out


@pytest.mark.slow
@pytest.mark.lm
def test_logits_and_choice_probabilities_do_not_depend_on_the_previous_call(embedded_lm):
    prompt = embedded_lm.chat_prompt(QUESTION)
    assert len(prompt.starts) == 1  # the question starts after the system message
    before = {"fresh": None, "unrelated": UNRELATED, "shared prefix": SIBLING, "same prompt": QUESTION}
    logits = _situations(embedded_lm, before, lambda: embedded_lm.next_token_logits(prompt))
    assert {k: r for k, (_, r) in logits.items()} == {"fresh": 0, "unrelated": 0, "shared prefix": prompt.starts[0],
                                                      "same prompt": prompt.starts[0]}
    for name, (got, _) in logits.items():
        np.testing.assert_array_equal(got, logits["fresh"][0], err_msg=name)
    probs = _situations(embedded_lm, before,
                        lambda: embedded_lm.choice_probabilities(QUESTION, ["yes", "no"]))
    assert all(p == probs["fresh"][0] for p, _ in probs.values()), probs
    # bare token ids are one piece: evaluated whole, the same numbers whatever came before
    whole = _situations(embedded_lm, {"fresh": None, "shared prefix": SIBLING},
                        lambda: embedded_lm.next_token_logits(list(prompt.tokens)))
    assert whole["shared prefix"][1] == 0
    np.testing.assert_array_equal(whole["shared prefix"][0], whole["fresh"][0])


@pytest.mark.slow
@pytest.mark.lm
def test_few_shot_prompts_reuse_all_but_the_last_message_and_stay_exact(embedded_lm):
    """Pieces: the system message, the examples, the question. A prompt that shares everything but the
    question reuses the examples too; one whose last piece ended inside the examples only the system."""
    target = FEW_SHOT + [{"role": "user", "content": "Is a pear a fruit?"}]
    prompt = embedded_lm.chat_prompt(target)
    assert len(prompt.starts) == 2 and embedded_lm.chat_prompt(target[:1]).starts == ()
    before = {"fresh": None,
              "sibling": FEW_SHOT + [{"role": "user", "content": "Is a cup a fruit?"}],  # all but the last message
              "shorter": FEW_SHOT[:2],  # its last piece ends inside the examples: reuse stops before it
              "unrelated": UNRELATED}
    got = _situations(embedded_lm, before, lambda: embedded_lm.next_token_logits(prompt))
    assert {k: r for k, (_, r) in got.items()} == {"fresh": 0, "sibling": prompt.starts[-1],
                                                   "shorter": prompt.starts[0], "unrelated": 0}
    for name, (logits, _) in got.items():
        np.testing.assert_array_equal(logits, got["fresh"][0], err_msg=name)


def hinted(category: str, obj: str = "paintbrush (a tool for applying paint)") -> list[dict]:
    """A yes/no question with the cut hint gift-prob gives it: before the category."""
    content = f"Is a {obj} one of the {category}? Answer yes or no."
    return [SYSTEM, {"role": "user", "content": content, "cut": content.index(category)}]


@pytest.mark.slow
@pytest.mark.lm
def test_a_cut_hint_is_one_more_piece_that_questions_about_the_same_object_reuse_exactly(embedded_lm):
    """A hint in the last message cuts it where the hinted text stops agreeing with the prompt's tokens: the
    same tokens as without it, one more piece. A question about the same object under another category
    reuses that piece; the numbers are the same whatever came before. Against the unhinted prompt (another
    split into decode batches) they are close, not equal."""
    prompt = embedded_lm.chat_prompt(hinted("art supplies"))
    plain = embedded_lm.chat_prompt(QUESTION)
    assert prompt.tokens == plain.tokens and prompt.starts[0] == plain.starts[0] and len(prompt.starts) == 2
    piece = embedded_lm.llama.detokenize(list(prompt.tokens[prompt.starts[0]:prompt.starts[1]])).decode()
    assert piece.endswith("Is a paintbrush (a tool for applying paint) one of the"), piece
    before = {"fresh": None, "same object": hinted("office things"), "other object": hinted("art supplies", "stapler"),
              "unrelated": UNRELATED}
    got = _situations(embedded_lm, before, lambda: embedded_lm.next_token_logits(prompt))
    assert {k: r for k, (_, r) in got.items()} == {"fresh": 0, "same object": prompt.starts[1],
                                                   "other object": prompt.starts[0], "unrelated": 0}
    for name, (logits, _) in got.items():
        np.testing.assert_array_equal(logits, got["fresh"][0], err_msg=name)
    unhinted = _situations(embedded_lm, {"fresh": None}, lambda: embedded_lm.next_token_logits(plain))["fresh"][0]
    assert np.abs(unhinted - got["fresh"][0]).max() < 1.0 and int(np.argmax(unhinted)) == int(np.argmax(got["fresh"][0]))


class EvalLog:
    """Records ``(first position, tokens)`` of every ``llama.eval`` call."""

    def __init__(self, llama):
        self.llama, self.inner, self.calls = llama, llama.eval, []

    def __call__(self, tokens):
        self.calls.append((self.llama.n_tokens, len(tokens)))
        return self.inner(tokens)


@pytest.mark.slow
@pytest.mark.lm
def test_complete_answers_do_not_depend_on_the_previous_call(embedded_lm):
    """Greedy, sampled with a seed, and grammar-constrained answers are the same fresh, after an unrelated
    prompt and after a prompt sharing a prefix; the prompt is evaluated in the same pieces every time (the
    last from the last message start in one call), then one token per step."""
    llama = embedded_lm.llama
    prompt = embedded_lm.chat_prompt(QUESTION)
    s, n = prompt.starts[0], len(prompt.tokens)
    requests = {"greedy": dict(max_tokens=6),
                "seeded": dict(max_tokens=6, temperature=0.9, seed=7),
                "json": dict(max_tokens=12, json_schema={"type": "object", "properties": {"answer": {"type": "string"}},
                                                         "required": ["answer"]})}
    for kind, kw in requests.items():
        log = llama.eval = EvalLog(llama)  # an instance attribute shadowing the method until deleted
        runs = {}
        try:
            for name, previous in {"fresh": None, "unrelated": UNRELATED, "shared prefix": SIBLING}.items():
                with embedded_lm._lock:
                    llama.reset()
                    if previous is not None:
                        embedded_lm.next_token_logits(embedded_lm.chat_prompt(previous))
                    log.calls.clear()
                    c = embedded_lm.complete(QUESTION, **kw)
                    runs[name] = (c.text, embedded_lm.last_reused_tokens, list(log.calls))
        finally:
            del llama.eval
        texts = {name: text for name, (text, _, _) in runs.items()}
        assert len(set(texts.values())) == 1, (kind, texts)
        assert [r for _, r, _ in runs.values()] == [0, 0, s], kind
        fresh_calls = runs["fresh"][2]
        assert fresh_calls[:2] == [(0, s), (s, n - s)] and all(k == 1 for _, k in fresh_calls[2:]), (kind, fresh_calls)
        assert runs["unrelated"][2] == fresh_calls and runs["shared prefix"][2] == fresh_calls[1:], kind
    assert texts and runs["fresh"][0]  # the json answer is not empty


@pytest.mark.slow
@pytest.mark.lm
def test_stop_sequences_still_cut_the_answer(embedded_lm):
    c = embedded_lm.complete([{"role": "user", "content": "Count from 1 to 9, separated by commas."}],
                             max_tokens=24, stop=["5"])
    assert "4" in c.text and "5" not in c.text and "6" not in c.text, c.text
