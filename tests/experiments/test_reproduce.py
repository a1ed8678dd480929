"""A reduced `gift reproduce` end to end on the real components (Drake, MaxEnt IRL, MiniLM, EfficientNet
on renders, the embedded LM), its report and figures, and the resume of a finished run from its caches."""

from __future__ import annotations

import json
import os
import subprocess

import attrs
import numpy as np
import pytest

from gift.study.chain import ORACLE, StudyConfig
from gift.study.progress import Progress
from gift.study.sweeps import run_study
from gift_experiments.report import headline_table, write_report
from mini_suite import N_TEST, mini_suite

pytestmark = [pytest.mark.slow, pytest.mark.lm, pytest.mark.drake]

KERNELS = ("vision", "language", "lm-no-intent", "gift", "gift-prob")


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    """The reduced run, every LM call recorded (``GIFT_LM_RECORD``) for the replay test below."""
    from gift.study import components

    out = tmp_path_factory.mktemp("reproduce")
    suite = mini_suite(out / "mini-suite.yaml")
    record = out / "lm-calls.jsonl"
    components._WORKER.clear()  # a fresh LM, resolved while the recording is on
    os.environ["GIFT_LM_RECORD"] = str(record)
    cfg = StudyConfig(suite=str(suite), kernels=KERNELS, seeds=2, pairs=60, samples=1, train_scenes=2,
                          demos_per_scene=4, alternatives_per_scene=12, trajectories_per_generator=6,
                          sanity_reps=1, thresholds=("train-calibrated", "oracle"), rq3=True)
    try:
        results = run_study(cfg, out, Progress(False))
    finally:
        del os.environ["GIFT_LM_RECORD"]
        components._WORKER.clear()
    return cfg, out, results


def test_every_stage_produces_numbers_for_every_kernel(reduced):
    cfg, out, results = reduced
    rq1 = results["rq1"]["valuables"]
    assert set(rq1) == set(KERNELS) | {ORACLE}
    for k, v in rq1.items():
        assert 0.0 <= v["mean"] <= 1.0 and len(v["per_seed"]) == cfg.seeds, k
    # the alignment from the labels is a working reward: it ranks most pairs right
    assert rq1[ORACLE]["mean"] > 0.6
    rq2 = results["rq2"]["valuables"]
    for k in KERNELS:
        m = rq2[k]["train-calibrated"]["all"]
        assert m["n"] == N_TEST and m["tp"] + m["fp"] + m["tn"] + m["fn"] == N_TEST
        assert rq2[k]["oracle"]["all"]["f1"] >= m["f1"] - 1e-9  # the oracle cut is an upper bound
    sanity = results["sanity"]["valuables"]
    assert len(sanity["texts"]) == 1 and all(isinstance(t, str) and t for t in sanity["texts"])
    assert -1.0 <= sanity["inferred"][0] <= 1.0
    intent = results["intents"]["valuables"]
    assert intent["source"] == "inferred" and intent["motivations"]
    rq3 = results["rq3"]["valuables"]
    for k, v in rq3.items():
        assert len(v["objects"]) == 4 and np.isclose(sum(v["mean"]), 1.0), k
    scatter = results["scatter"]["valuables"]["points"]
    assert len(scatter) == N_TEST and all(0.0 <= p["language"] <= 1.0 and 0.0 <= p["vision"] <= 1.0 for p in scatter)
    manifest = results["manifest"]
    assert manifest["lm"]["usage"]["requests"] > 0  # the LM was asked (answered by the model or the cache)
    # provenance: the model file actually loaded, the commit of this checkout, the suite file's hash
    from gift_llm.embedded import EXPECTED_SHA256

    assert manifest["lm"]["model_sha256"] == EXPECTED_SHA256 and manifest["lm"]["identity"].startswith("llamacpp:")
    import llama_cpp  # the build that computed the answers: its version and the CPU kernels it was compiled with

    assert manifest["lm"]["llama_cpp"].startswith(f"{llama_cpp.__version__}; CPU : "), manifest["lm"]
    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    assert manifest["git"]["commit"] == head and manifest["suite"]["sha256"] and manifest["code_version"]
    # in inferred mode the relevant training objects come from the demonstrations, not the suite
    assert results["relevant"]["valuables"]["source"] == "demonstrations"


def test_report_figures_and_results_json(reduced):
    cfg, out, results = reduced
    report = write_report(results, out, command="gift reproduce --intents valuables ...")
    text = report.read_text()
    for k in KERNELS:
        assert f"| {k} " in text or f" {k} |" in text
    # every kernel as it was built, its defaults included, in results.json and the report
    built = {k: results["alignment"]["valuables"][k]["configuration"] for k in KERNELS}
    assert built["gift"].startswith("MappingKernel(samples=1,") and "use_intent=True" in built["gift"]
    assert "use_intent=False" in built["lm-no-intent"] and "embed_text='description'" in built["gift-prob"]
    assert f"- `gift-prob`: `{built['gift-prob']}`" in text
    pngs = {p.name for p in out.glob("*.png")}
    assert {"win_rate.png", "intent_cosine.png", "f1_train-calibrated.png", "confounds_train-calibrated.png",
            "scatter_valuables.png", "boltzmann_valuables.png"} <= pngs
    for name in pngs:
        assert f"({name})" in text
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    saved = json.loads((out / "results.json").read_text())
    assert saved["rq1"]["valuables"][ORACLE]["mean"] == pytest.approx(results["rq1"]["valuables"][ORACLE]["mean"])


def test_rerun_resumes_from_the_caches_without_model_calls(reduced):
    from gift.study.sweeps import previous_runs

    cfg, out, results = reduced
    again = run_study(cfg, out, Progress(False), previous=previous_runs(out / "results.json"))
    assert len(again["manifest"]["runs"]) == 2  # the resume adds its record to the first run's
    # NaN (an AUC of a one-class subset) must compare equal to NaN: assert_equal does that
    np.testing.assert_equal(again["rq1"], results["rq1"])
    np.testing.assert_equal(again["rq2"], results["rq2"])
    assert again["intents"] == results["intents"]
    # the resume's own run record: no model call (the manifest's top-level usage sums every run)
    usage = (again["manifest"]["runs"][-1].get("lm") or {}).get("usage") or {"misses": 0}
    assert usage["misses"] == 0


def test_headline_table_summarises_runs_per_robot(reduced):
    cfg, out, results = reduced
    table = headline_table({"jaco": results, "franka": results}, "train-calibrated")
    lines = table.splitlines()
    assert lines[0] == "| kernel | win rate (jaco) | F1 (jaco) | win rate (franka) | F1 (franka) |"
    rows = {line.split(" | ")[0].strip("| "): line for line in lines[2:]}
    assert set(rows) == set(KERNELS) | {ORACLE}
    wr = results["rq1"]["valuables"]["gift-prob"]["mean"]
    f1 = results["rq2"]["valuables"]["gift-prob"]["train-calibrated"]["all"]["f1"]
    assert rows["gift-prob"].count(f"{wr:.3f}") == 2 and rows["gift-prob"].count(f"{f1:.3f}") == 2
    assert rows[ORACLE].endswith("| – |")  # the label alignment has a win rate but no F1 row


def test_a_rerun_with_another_lm_recomputes_every_lm_stage_and_names_that_lm(reduced):
    """Stage keys cover the resolved LM: the same config with the run's recording as the LM (``replay:``)
    finds no finished LM stage, recomputes them all from the replay, and gets the same numbers."""
    cfg, out, results = reduced
    replay = attrs.evolve(cfg, lm=f"replay:{out / 'lm-calls.jsonl'}")
    again = run_study(replay, out, Progress(False))
    lm = again["manifest"]["lm"]
    assert lm["identity"].startswith("replay:") and lm["usage"]["requests"] > 0  # answered again, not read back
    np.testing.assert_equal(again["rq2"], results["rq2"])
    assert again["intents"] == results["intents"]
