"""``gift.study.sweeps.recorded_suite``: the suite a saved result was scored on, checked by its recorded sha256
(every script that reads labels for a saved result goes through it)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gift.core.errors import GiftError
from gift.core.provenance import file_sha256
from gift.study.sweeps import recorded_suite

ROOT = Path(__file__).resolve().parents[2]
RESULT = ROOT / "docs" / "results" / "data" / "front_half" / "gift-dev5-inferred.json"


def _result() -> dict:
    return json.loads(RESULT.read_text(encoding="utf-8"))


def test_a_result_made_in_another_checkout_finds_its_suite_by_name_and_hash():
    res = _result()
    res["suite_path"] = res["manifest"]["suite"]["path"] = "/nowhere/gift/suites/gift-dev5.yaml"
    suite = recorded_suite(res, "r.json")
    assert suite.name == "gift-dev5" and file_sha256(suite.path) == res["manifest"]["suite"]["sha256"]


def test_an_edited_copy_at_the_recorded_path_is_passed_over_for_the_file_that_matches(tmp_path):
    res = _result()
    original = recorded_suite(res)
    copy = tmp_path / "gift-dev5.yaml"
    copy.write_text(Path(original.path).read_text(encoding="utf-8") + "\n# edited after the run\n", encoding="utf-8")
    res["suite_path"] = str(copy)
    assert recorded_suite(res).path == original.path


def test_a_suite_changed_since_the_run_is_refused_naming_the_file():
    res = _result()
    res["manifest"]["suite"]["sha256"] = "0" * 64
    with pytest.raises(GiftError, match=r"changed\.json: suite 'gift-dev5' has changed since the run"):
        recorded_suite(res, "changed.json")
    with pytest.raises(GiftError, match="records no suite"):
        recorded_suite({"kernels": {}}, "bare.json")
