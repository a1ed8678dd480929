"""The persistent SQLite LM cache: keys, statistics, bypass, persistence across processes, concurrency."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
import textwrap

import pytest

from gift_llm.cache import CachedLM, CacheStore

from llm_scripted import ScriptedLM

MSG = [{"role": "user", "content": "hello"}]


def test_hits_misses_and_usage_accounting(tmp_path):
    inner = ScriptedLM()
    lm = CachedLM(inner, path=tmp_path / "c.sqlite")
    a = lm.complete(MSG, max_tokens=20)
    b = lm.complete(MSG, max_tokens=20)
    assert a.text == b.text and not a.usage.cached and b.usage.cached
    assert inner.calls == 1
    s = lm.stats
    assert (s.requests, s.hits, s.misses, s.calls) == (2, 1, 1, 1)
    assert (s.prompt_tokens, s.completion_tokens, s.tokens) == (10, 5, 15)
    assert s.cost_usd == pytest.approx(0.002)
    assert lm.identity() == inner.identity() and lm.model == inner.model


def test_every_sampling_parameter_is_part_of_the_key(tmp_path):
    inner = ScriptedLM()
    lm = CachedLM(inner, path=tmp_path / "c.sqlite")
    variants = [dict(), dict(seed=1), dict(seed=2), dict(temperature=0.7, seed=1), dict(max_tokens=7),
                dict(stop=["\n"]), dict(json_schema={"type": "object"})]
    texts = [lm.complete(MSG, **kw).text for kw in variants]
    assert inner.calls == len(variants) and lm.stats.misses == len(variants)
    assert texts[1] != texts[2]  # seeded samples are distinct entries
    for kw in variants:  # all cached now
        lm.complete(MSG, **kw)
    assert inner.calls == len(variants) and lm.stats.hits == len(variants)
    other = CachedLM(ScriptedLM(model="another-model"), path=tmp_path / "c.sqlite")
    other.complete(MSG)
    assert other.stats.misses == 1  # the model is part of the key


def test_choice_probabilities_are_cached(tmp_path):
    inner = ScriptedLM()
    lm = CachedLM(inner, path=tmp_path / "c.sqlite")
    assert lm.supports_choice_probabilities
    p1 = lm.choice_probabilities(MSG, ["yes", "no"])
    p2 = lm.choice_probabilities(MSG, ["yes", "no"])
    assert p1 == p2 == {"yes": 0.5, "no": 0.5} and inner.calls == 1 and lm.stats.hits == 1
    lm.choice_probabilities(MSG, ["no", "yes"])
    assert inner.calls == 2


@pytest.mark.parametrize("how", ["argument", "environment"])
def test_bypass_still_counts_calls(tmp_path, monkeypatch, how):
    if how == "environment":
        monkeypatch.setenv("GIFT_LM_CACHE", "off")
    inner = ScriptedLM()
    lm = CachedLM(inner, path=tmp_path / "c.sqlite", enabled=how != "argument")
    lm.complete(MSG)
    lm.complete(MSG)
    assert inner.calls == 2 and lm.stats.calls == 2 and lm.stats.hits == 0
    assert not (tmp_path / "c.sqlite").exists()


def test_default_location_follows_gift_cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("GIFT_CACHE_DIR", str(tmp_path / "root"))
    lm = CachedLM(ScriptedLM())
    lm.complete(MSG)
    assert lm.store.path == tmp_path / "root" / "lm" / "lm-cache.sqlite" and lm.store.path.exists()


_WRITER = textwrap.dedent("""
    import sys
    sys.path.insert(0, {tests!r})
    from llm_scripted import ScriptedLM
    from gift_llm.cache import CachedLM
    lm = CachedLM(ScriptedLM(), path={db!r})
    worker = int(sys.argv[1])
    for i in range(40):
        lm.complete([{{"role": "user", "content": f"w{{worker}} q{{i}}"}}])
        lm.complete([{{"role": "user", "content": f"shared q{{i}}"}}])
    print(lm.stats.hits, lm.stats.misses)
""")


def test_concurrent_processes_share_one_database(tmp_path):
    db = tmp_path / "c.sqlite"
    script = tmp_path / "writer.py"
    script.write_text(_WRITER.format(tests=os.path.dirname(__file__), db=str(db)))
    procs = [subprocess.Popen([sys.executable, str(script), str(w)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for w in range(4)]
    outs = [p.communicate(timeout=120) for p in procs]
    for p, (out, err) in zip(procs, outs):
        assert p.returncode == 0, err
    store = CacheStore(db)
    assert store.count() == 4 * 40 + 40  # every private entry plus one entry per shared prompt
    total_hits = sum(int(o.split()[0]) for o, _ in outs)
    assert total_hits <= 3 * 40  # a shared prompt is a hit only after another process stored it


def test_entries_survive_a_killed_process(tmp_path):
    """Every entry is committed at once: a process killed right after a call leaves it in the cache."""
    db = tmp_path / "c.sqlite"
    code = textwrap.dedent(f"""
        import os, sys
        sys.path.insert(0, {os.path.dirname(__file__)!r})
        from llm_scripted import ScriptedLM
        from gift_llm.cache import CachedLM
        lm = CachedLM(ScriptedLM(["kept"]), path={str(db)!r})
        lm.complete([{{"role": "user", "content": "hello"}}])
        os.kill(os.getpid(), 9)
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == -9
    inner = ScriptedLM(["different"])
    out = CachedLM(inner, path=db).complete(MSG)
    assert out.text == "kept" and out.usage.cached and inner.calls == 0


def test_no_secret_is_stored(tmp_path, monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", "sk-test-secret-value-123456")
    lm = CachedLM(ScriptedLM(), path=tmp_path / "c.sqlite")
    lm.complete(MSG)
    rows = sqlite3.connect(tmp_path / "c.sqlite").execute("SELECT * FROM entries").fetchall()
    assert rows and "sk-test-secret" not in json.dumps(rows)


def test_a_cut_hint_is_part_of_the_request_key_and_no_hint_keys_as_before():
    from gift.core.data import Message
    from gift_llm.requests import choices_request, request_key

    plain = [Message("system", "s"), Message("user", "Is a kettle one of the tools?")]
    hinted = [plain[0], Message("user", plain[1].content, cut=23)]
    as_dicts = [m.to_dict() for m in plain]
    assert request_key("lm", choices_request(plain, ["yes", "no"])) == request_key("lm", choices_request(as_dicts, ["yes", "no"]))
    assert request_key("lm", choices_request(hinted, ["yes", "no"])) != request_key("lm", choices_request(plain, ["yes", "no"]))
    assert choices_request(hinted, ["yes", "no"])["messages"][1]["cut"] == 23


class BuiltLM(ScriptedLM):
    """A scripted backend that reports the build of its runtime, as the llama.cpp backend does."""

    def __init__(self, build, **kw):
        super().__init__(**kw)
        self._runtime = build

    def build(self):
        return self._runtime


def test_each_answer_is_counted_under_the_build_that_made_it(tmp_path, caplog):
    """Fresh answers are stored with the loaded build; answers read back are counted under the build stored with
    them (``unrecorded`` for entries from before builds were stored), with one warning when that is not the loaded
    build; a backend without a build counts nothing."""
    path = tmp_path / "c.sqlite"
    plain = CachedLM(ScriptedLM(), path=path)
    plain.complete([{"role": "user", "content": "old"}])  # an entry stored without a build
    assert plain.stats.made_by == {} and plain.stats.as_dict()["made_by"] == {}
    a = CachedLM(BuiltLM("0.3.36; CPU : AVX2 = 1"), path=path)
    a.complete(MSG)
    a.choice_probabilities(MSG, ["yes", "no"])
    assert a.stats.made_by == {"0.3.36; CPU : AVX2 = 1": 2}
    with sqlite3.connect(path) as db:
        stored = [json.loads(r) for (r,) in db.execute("select response from entries order by created")]
    assert [s.get("_made_by") for s in stored] == [None, "0.3.36; CPU : AVX2 = 1", "0.3.36; CPU : AVX2 = 1"]
    b = CachedLM(BuiltLM("0.3.36; CPU : AVX512 = 1"), path=path)
    with caplog.at_level("WARNING", logger="gift_llm.cache"):
        assert b.complete(MSG).text == a.complete(MSG).text
        assert b.choice_probabilities(MSG, ["yes", "no"]) == {"yes": 0.5, "no": 0.5}  # the build is not a choice
        b.complete([{"role": "user", "content": "old"}])
        b.complete([{"role": "user", "content": "new"}])
    assert b.stats.made_by == {"0.3.36; CPU : AVX2 = 1": 2, "unrecorded": 1, "0.3.36; CPU : AVX512 = 1": 1}
    assert (b.stats.hits, b.stats.misses) == (3, 1)
    warned = [r for r in caplog.records if "another build" in r.getMessage()]
    assert len(warned) == 1 and "AVX512" in warned[0].getMessage()
    b.stats.reset()
    assert b.stats.made_by == {}
