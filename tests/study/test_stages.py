"""Stage caches and results files: keyed by every input, atomic, corrupt files recovered, nothing lost."""

from __future__ import annotations

import json
import logging

import pytest

from gift.core.serialization import write_json
from gift.study.stages import StageCache
from gift_experiments.report import save_results


def test_a_stage_is_computed_once_per_inputs_and_again_when_any_input_changes(tmp_path):
    cache = StageCache(tmp_path)
    calls = []

    def compute(tag):
        def fn():
            calls.append(tag)
            return {"value": tag}
        return fn

    inputs = {"lm": {"identity": "llamacpp:m.gguf", "model_sha256": "abc"}, "kernel": "gift-prob", "suite": {"x": 1}}
    assert cache.get_or_compute("art", "align-gift-prob", inputs, compute(1)) == {"value": 1}
    assert cache.get_or_compute("art", "align-gift-prob", inputs, compute(2)) == {"value": 1}  # from the file
    assert calls == [1]
    other_lm = {**inputs, "lm": {"identity": "litellm:openai/gpt-4o-mini"}}
    other_suite = {**inputs, "suite": {"x": 2}}
    other_hash = {**inputs, "lm": {"identity": "llamacpp:m.gguf", "model_sha256": "def"}}
    for i, changed in enumerate((other_lm, other_suite, other_hash)):
        assert cache.get_or_compute("art", "align-gift-prob", changed, compute(10 + i)) == {"value": 10 + i}
    assert calls == [1, 10, 11, 12]
    files = sorted(p.name for p in (tmp_path / "stages" / "art").iterdir())
    assert len(files) == 4 and all(f.startswith("align-gift-prob-") and f.endswith(".json") for f in files)
    doc = json.loads((tmp_path / "stages" / "art" / files[0]).read_text())
    assert set(doc) == {"stage", "inputs", "code", "value"}  # a human can see what a stage was keyed on


def test_a_corrupt_stage_file_is_moved_aside_named_in_a_warning_and_recomputed(tmp_path, caplog):
    cache = StageCache(tmp_path)
    inputs = {"kernel": "language"}
    cache.get_or_compute("art", "align-language", inputs, lambda: [1, 2, 3])
    path = cache.path("art", "align-language", inputs)
    path.write_text(path.read_text()[:10])  # truncated, as by a crash of an older, non-atomic writer
    with caplog.at_level(logging.WARNING, logger="gift.study.stages"):
        assert cache.get_or_compute("art", "align-language", inputs, lambda: [4, 5]) == [4, 5]
    assert str(path) in caplog.text and "recomputing" in caplog.text
    assert cache.recovered == [str(path)]
    assert len(list(path.parent.glob("*.corrupt"))) == 1
    assert json.loads(path.read_text())["value"] == [4, 5]  # and the good value is stored again


def test_no_cache_when_there_is_no_output_directory():
    cache = StageCache(None)
    calls = []
    for _ in range(2):
        cache.get_or_compute("a", "s", {}, lambda: calls.append(1))
    assert len(calls) == 2


def test_atomic_strict_json_writes_leave_no_temporary_file_and_write_nan_as_null(tmp_path):
    import numpy as np

    path = tmp_path / "x.json"
    write_json(path, {"auc": float("nan"), "arr": np.array([1.0, np.nan]), "inf": float("inf")})
    text = path.read_text()
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"auc": None, "arr": [1.0, None], "inf": None}
    assert [p.name for p in tmp_path.iterdir()] == ["x.json"]


def test_results_are_never_replaced_by_less_complete_ones_silently(tmp_path, caplog):
    full = {"rq1": {"art": {"language": {"mean": 0.7}, "gift-prob": {"mean": 0.8}}},
            "rq2": {"art": {"language": {}, "gift-prob": {}}}}
    save_results(full, tmp_path)
    partial = {"rq1": {"art": {"language": {"mean": 0.7}}}, "rq2": {"art": {"language": {}}}}
    with caplog.at_level(logging.WARNING, logger="gift.report"):
        save_results(partial, tmp_path)
    assert "rq1/art/gift-prob" in caplog.text and "results.prev.json" in caplog.text
    assert json.loads((tmp_path / "results.prev.json").read_text()) == full
    assert json.loads((tmp_path / "results.json").read_text()) == partial
    caplog.clear()
    save_results(partial, tmp_path)  # as complete as before: replaced without a word
    assert not caplog.text


@pytest.mark.parametrize("bad", ["{", "not json", "[1, 2]"])
def test_an_unreadable_old_results_file_does_not_stop_a_run(tmp_path, bad):
    (tmp_path / "results.json").write_text(bad)
    save_results({"rq1": {}}, tmp_path)
    assert json.loads((tmp_path / "results.json").read_text()) == {"rq1": {}}
