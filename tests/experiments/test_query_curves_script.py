"""scripts/query_curves.py --from-json: one page from runs made in separate processes keeps every run's
commit and code version (the page's provenance line names each part)."""

from __future__ import annotations

from pathlib import Path

import pytest
import script_module  # this directory: scripts/ files as modules


@pytest.fixture(scope="module")
def script():
    return script_module.load_script("query_curves")


def _run(commit: str, version: str, suite: str, seconds: float) -> dict:
    return {"kernel": "gift-prob", "rescore": False, "random_seeds": 3, "lm": {"model_sha256": "abc"},
            "command": f"python scripts/query_curves.py --suites {suite}", "git": {"commit": commit, "dirty": False},
            "code_version": version, "seconds": seconds, "suites": {suite: {"sha256": "0" * 64}},
            "runs": {f"{suite} | inferred": {}}, "failures": []}


def test_a_merged_page_names_the_commit_and_code_version_of_each_part(script):
    merged = script.merge([_run("a" * 40, "1" * 16, "s1", 600.0), _run("b" * 40, "2" * 16, "s2", 40.0)])
    assert set(merged["runs"]) == {"s1 | inferred", "s2 | inferred"} and merged["seconds"] == 640.0
    line = script.provenance(merged)
    assert line.startswith("Merged from runs at commit `aaaaaaaaaa`, code version `111111111111` (600 s)")
    assert "commit `bbbbbbbbbb`, code version `222222222222` (40 s)" in line
    # one run: its own commit, as before
    assert script.provenance(_run("c" * 40, "3" * 16, "s3", 1.0)) == "Commit `cccccccccc`, code version `333333333333`"
    # merging a merged page again keeps each of its parts
    again = script.merge([merged, _run("e" * 40, "5" * 16, "s5", 5.0)])
    assert [p["git"]["commit"][0] for p in again["parts"]] == ["a", "b", "e"] and again["seconds"] == 645.0
    assert set(again["runs"]) == {"s1 | inferred", "s2 | inferred", "s5 | inferred"}
    assert "commit `bbbbbbbbbb`" in script.provenance(again) and "commit `eeeeeeeeee`" in script.provenance(again)
    other = _run("d" * 40, "4" * 16, "s4", 1.0)
    other["lm"] = {"model_sha256": "other"}
    with pytest.raises(SystemExit, match="different LM model files"):
        script.merge([_run("a" * 40, "1" * 16, "s1", 1.0), other])


def test_regenerating_a_page_keeps_what_was_written_by_hand_after_the_marker(script, tmp_path):
    import json

    saved = Path(__file__).resolve().parents[2] / "docs" / "results" / "queries" / "curves.json"
    result = json.loads(saved.read_text(encoding="utf-8"))
    md = tmp_path / "queries.md"
    script.write(result, md)
    generated = md.read_text(encoding="utf-8")
    assert script.KEEP not in generated and "## In short" in generated
    md.write_text(generated + "\n" + script.KEEP + "\n\n## A decision\n\nWritten by hand.\n", encoding="utf-8")
    script.write(result, md)
    again = md.read_text(encoding="utf-8")
    assert again.startswith(generated) and again.endswith(script.KEEP + "\n\n## A decision\n\nWritten by hand.\n")
    assert again.count("## In short") == 1


def test_a_page_says_on_how_many_intents_answers_re_scored_when_not_on_all(script, tmp_path):
    import json

    saved = Path(__file__).resolve().parents[2] / "docs" / "results" / "queries-evidence" / "curves.json"
    result = json.loads(saved.read_text(encoding="utf-8"))
    assert result["rescore"] is True
    label = "gift-paper | inferred"
    intents = list(result["runs"][label]["intents"])
    md = tmp_path / "queries.md"
    result["runs"][label]["rescored_intents"] = intents  # every intent re-scored: nothing to say
    script.write(result, md)
    assert "Re-scored with the answers on" not in md.read_text(encoding="utf-8")
    result["runs"][label]["rescored_intents"] = intents[:2]
    script.write(result, md)
    text = md.read_text(encoding="utf-8")
    assert f"Re-scored with the answers on 2 of {len(intents)} intents" in text and text.count("Re-scored with") == 1
