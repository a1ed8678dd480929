"""Recording a run of the real model and replaying it with no model at all."""

from __future__ import annotations

import json

import pytest

from gift.core.errors import LMError
from gift_llm.replay import RecordingLM, ReplayLM
from gift_llm.resolve import resolve_lm

QUESTIONS = ["What colour is the sky on a clear day? One word.", "Name a fruit that is yellow. One word."]


def _run(lm):
    out = [lm.complete([{"role": "user", "content": q}], max_tokens=6).text for q in QUESTIONS]
    out.append(lm.complete([{"role": "user", "content": QUESTIONS[0]}], max_tokens=6, temperature=0.8, seed=3).text)
    out.append(lm.choice_probabilities([{"role": "user", "content": "Is ice cold? Answer yes or no."}],
                                       ["yes", "no"]))
    return out


@pytest.mark.slow
@pytest.mark.lm
def test_recorded_run_replays_to_identical_outputs(embedded_lm, tmp_path, monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", "sk-recording-must-not-hold-this")
    rec = tmp_path / "run.jsonl"
    original = _run(RecordingLM(embedded_lm, rec))
    lines = [json.loads(x) for x in rec.read_text().splitlines()]
    assert len(lines) == 4 and all(x["identity"] == embedded_lm.identity() for x in lines)
    assert "sk-recording" not in rec.read_text()

    replay = resolve_lm(f"replay:{rec}")  # goes through the plugin registry; no model is loaded
    assert _run(replay) == original
    assert replay.stats.calls == 4 and replay.inner.recorded_identities == [embedded_lm.identity()]


def test_call_not_in_the_recording_is_a_clear_error(tmp_path):
    rec = tmp_path / "run.jsonl"
    rec.write_text("")
    lm = ReplayLM(rec)
    with pytest.raises(LMError, match="not in the recording"):
        lm.complete([{"role": "user", "content": "never recorded"}])
    with pytest.raises(LMError, match="does not exist"):
        ReplayLM(tmp_path / "missing.jsonl")
    rec.write_text("not json\n")
    with pytest.raises(LMError, match="line 1"):
        ReplayLM(rec)


def test_recording_says_whether_the_cache_answered(tmp_path):
    """Control flow of the record's ``cached`` flag (scripted LM behind a real SQLite cache)."""
    from gift_llm.cache import CachedLM
    from llm_scripted import ScriptedLM

    rec = tmp_path / "run.jsonl"
    lm = RecordingLM(CachedLM(ScriptedLM(["ok"]), path=tmp_path / "cache.sqlite"), rec)
    msgs = [{"role": "user", "content": "Is ice cold?"}]
    for _ in range(2):
        lm.complete(msgs, max_tokens=4)
        lm.choice_probabilities(msgs, ["yes", "no"])
    lines = [json.loads(x) for x in rec.read_text().splitlines()]
    assert [x["cached"] for x in lines] == [False, False, True, True]
    assert [x["request"]["kind"] for x in lines] == ["complete", "choices"] * 2
    assert all(x["seconds"] >= 0 for x in lines)
    assert ReplayLM(rec).complete(msgs, max_tokens=4).text == "ok"  # the extra fields do not disturb a replay
    bare = tmp_path / "bare.jsonl"  # no cache in between: unknown, not a miss
    RecordingLM(ScriptedLM(["ok"]), bare).complete(msgs)
    assert json.loads(bare.read_text())["cached"] is None
