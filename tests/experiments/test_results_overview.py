"""``scripts/results_overview.py``: the results-at-a-glance page is computed from the committed result files."""

from __future__ import annotations

import json

import pytest
import script_module  # this directory: scripts/ files as modules
import yaml

from gift.core.errors import GiftError
from gift.core.provenance import file_sha256
from gift.testing import TINY_SUITE


@pytest.fixture(scope="module")
def mod():
    return script_module.load_script("results_overview")


def test_the_committed_page_is_what_the_result_files_give(mod, tmp_path):
    # every number of docs/results/overview.md comes from the files RUNS names; an edit by hand or a new run
    # without regenerating the page fails here
    assert mod.main(["--check"]) == 0, "run: python scripts/results_overview.py"
    other = tmp_path / "overview.md"
    other.write_text("stale\n", encoding="utf-8")
    assert mod.main(["--check", "--out", str(other)]) == 1


def test_every_default_option_is_parsed_from_the_kernel_itself(mod):
    default = mod.default_configuration()
    assert default["ask_text"] == "'both'" and default["check"] == "'fit'"
    assert "language_kernel" not in default
    assert mod.parse_configuration("GiftProbKernel(a=1, b='x', language_kernel=LanguageKernel(n=2, m=3))") == {
        "a": "1", "b": "'x'"}


def _result(suite_path, source: str, f1s: dict[str, dict[str, tuple[int, int, int]]], configuration=None) -> dict:
    """A result file's shape as ``gift evaluate-alignment --out`` writes it, scored on the suite file
    ``suite_path`` (its hash as now); ``f1s``: kernel -> intent -> (tp, fp, fn)."""
    def rec(tp, fp, fn):
        m = {"tp": tp, "fp": fp, "tn": 0, "fn": fn, "f1": 2 * tp / (2 * tp + fp + fn), "auc": 0.9}
        return {"metrics": {c: {"all": dict(m)} for c in ("train-calibrated", "oracle")}}
    kernels = {k: {"intents": {i: rec(*c) for i, c in v.items()}} for k, v in f1s.items()}
    if configuration:
        kernels["gift-prob"]["configuration"] = configuration
    suite = {"name": "tiny", "path": str(suite_path), "sha256": file_sha256(suite_path)}
    return {"suite": "tiny", "suite_path": str(suite_path), "intent_source": source, "kernels": kernels,
            "manifest": {"git": {"commit": "c" * 40}, "runs": [{"started": "2026-12-06T01:00:00"}], "suite": suite,
                         "lm": {"llama_cpp": "0.3.36; CPU : AVX512 = 1", "model_sha256": "d" * 64}}}


def test_a_row_pools_counts_replaces_a_rerun_intent_and_names_what_differs(mod, tmp_path, monkeypatch):
    monkeypatch.setattr(mod, "DATA", tmp_path)
    suite = tmp_path / "tiny.yaml"
    suite.write_text(yaml.safe_dump(TINY_SUITE, sort_keys=False), encoding="utf-8")
    main = _result(suite, "inferred", {"gift-prob": {"a": (4, 0, 0), "b": (1, 3, 3)},
                                     "language": {"a": (2, 2, 2), "b": (2, 2, 2)},
                                     "vision": {"a": (1, 3, 3), "b": (4, 0, 0)}},
                   configuration="GiftProbKernel(check='fit', ask_text='name', language_kernel=x)")
    rerun = _result(suite, "inferred", {"gift-prob": {"b": (4, 0, 0)}})
    (tmp_path / "main.json").write_text(json.dumps(main))
    (tmp_path / "rerun.json").write_text(json.dumps(rerun))
    default = {"check": "'fit'", "ask_text": "'both'", "rungs": "'both'"}
    r = mod.row(mod.Run("tiny", "inferred", "main.json", replace={"b": "rerun.json"}), default)
    assert r["f1"] == pytest.approx(1.0)  # a and the rerun b: 8 tp, nothing wrong
    assert r["baselines"]["language"] == pytest.approx(0.5)  # 4 tp, 4 fp, 4 fn
    assert r["baselines"]["vision"] == pytest.approx(10 / 16)  # 5 tp, 3 fp, 3 fn
    assert (r["above"], r["level"]) == (1, 1)  # a: 1.0 against 0.5; b: 1.0 against vision's 1.0
    assert r["differs"] == "ask_text='name', no rungs yet"
    assert r["build"] == "AVX-512" and r["commit"] == "ccccccc" and r["model_sha256"] == "d" * 12
    assert r["suite_sha256"] == file_sha256(suite)[:12]
    with pytest.raises(SystemExit, match="holds tiny / inferred, not tiny / ground-truth"):
        mod.row(mod.Run("tiny", "ground-truth", "main.json"), default)
    with pytest.raises(SystemExit, match="missing"):
        mod.row(mod.Run("tiny", "inferred", "nowhere.json"), default)
    # a suite edited after the run: its labels are no longer the ones the run was scored on
    suite.write_text(suite.read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")
    with pytest.raises(GiftError, match="has changed since the run"):
        mod.row(mod.Run("tiny", "inferred", "main.json"), default)


def test_every_query_row_names_the_commit_of_the_curves_run_that_listed_its_suite(mod):
    # a curves run over several suites (``--suites gift-dev25,gift-dev26``) made the rows of each of them
    rows = mod.query_rows()
    assert rows and all(r["commit"] != "not recorded" for r in rows), [r["suite"] for r in rows
                                                                      if r["commit"] == "not recorded"]
    by_suite = {(r["suite"], r["source"]): r["commit"] for r in rows}
    assert by_suite[("gift-dev25", "inferred")] == by_suite[("gift-dev26", "ground-truth")]
