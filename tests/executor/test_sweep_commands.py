"""The sweep commands on every executor: `gift evaluate-alignment` and `gift reproduce` write the same JSON,
bit for bit (apart from timing and the run manifest), with ``--executor serial``, ``local --workers 2`` and
``ray --workers 2``.

Each executor runs the real CLI in a subprocess with its own empty ``GIFT_CACHE_DIR``, so each one renders
the objects (Drake), computes its own MiniLM/EfficientNet vectors and Drake trajectories: nothing is shared
through a cache. The Ray run starts (and stops) a local Ray instance with 2 CPUs. No LM is loaded.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gift.core.errors import GiftError
from gift.core.executor import ExecutionError

import executor_sweeps as sweeps

pytestmark = [pytest.mark.slow, pytest.mark.drake]

SUITE = Path(__file__).parent / "data" / "sweep_suite.yaml"
INTENTS = ("art_supplies", "valuables")
#: two real kernels, one whose constructor fails in the worker, one the parent rejects before any work
KERNELS = ("language", "vision", "language:use_descriptions=maybe", "no-such-kernel")
REPRODUCE = ["--kernels", "language,vision", "--intent-source", "ground-truth", "--pairs", "30", "--seeds", "2",
             "--trajectories", "4", "--train-scenes", "2", "--sanity-reps", "0"]
EXECUTORS = {"serial": ["--executor", "serial"], "local": ["--executor", "local", "--workers", "2"],
             "ray": ["--executor", "ray", "--workers", "2"]}


def _ray_available() -> bool:
    try:
        import gift_executor_ray  # noqa: F401
        import ray  # noqa: F401
    except ImportError:
        return False
    return True


def gift_cli(args: list[str], cache: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "GIFT_CACHE_DIR": str(cache)}
    proc = subprocess.run([sys.executable, "-m", "gift.cli", *map(str, args)], env=env, capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, f"gift {args[0]} failed ({proc.returncode}):\n{proc.stderr[-4000:]}"
    return proc


def without(value, keys: set[str]):
    """``value`` with every dict entry named in ``keys`` removed, at any depth."""
    if isinstance(value, dict):
        return {k: without(v, keys) for k, v in value.items() if k not in keys}
    if isinstance(value, list):
        return [without(v, keys) for v in value]
    return value


def canonical(path: Path, drop: set[str]) -> str:
    """The JSON file without the ``drop`` fields, as text (key order kept; NaN compares equal to NaN)."""
    return json.dumps(without(json.loads(path.read_text()), drop), indent=1)


@pytest.fixture(scope="module")
def sweep_runs(tmp_path_factory):
    """Per executor: ``evaluate-alignment`` (cold cache), then ``reproduce`` (same cache) -> outputs and stderr."""
    runs = {}
    for name, options in EXECUTORS.items():
        if name == "ray" and not _ray_available():
            continue
        root = tmp_path_factory.mktemp(f"sweep-{name}")
        cache = root / "cache"
        evaluated = gift_cli(["evaluate-alignment", "--suite", SUITE, "--kernels", ",".join(KERNELS),
                              "--out", root / "alignment.json", *options], cache)
        reproduced = gift_cli(["reproduce", "--suite", SUITE, *REPRODUCE, "--out", root / "reproduce", *options], cache)
        runs[name] = {"alignment": root / "alignment.json", "results": root / "reproduce" / "results.json",
                      "stages": root / "reproduce" / "stages", "eval_stderr": evaluated.stderr,
                      "reproduce_stderr": reproduced.stderr}
    return runs


def test_evaluate_alignment_json_is_identical_on_serial_local_and_ray(sweep_runs):
    ref = sweep_runs["serial"]
    result = json.loads(ref["alignment"].read_text())
    # the reference is a real result: both kernels on both intents, the failures reported per kernel
    assert list(result["kernels"]) == list(KERNELS)
    for k in ("language", "vision"):
        assert not result["kernels"][k]["errors"] and list(result["kernels"][k]["intents"]) == list(INTENTS)
        assert result["kernels"][k]["overall"]["oracle"]["all"]["n"] == 12
    assert result["kernels"]["language:use_descriptions=maybe"]["errors"]["*"].startswith("GiftError")
    assert result["kernels"]["no-such-kernel"]["errors"]["*"].startswith("UnknownComponentError")
    want = canonical(ref["alignment"], {"seconds", "manifest"})
    for name, run in sweep_runs.items():
        assert canonical(run["alignment"], {"seconds", "manifest"}) == want, \
            f"evaluate-alignment on {name} differs from serial"
        manifest = json.loads(run["alignment"].read_text())["manifest"]
        assert manifest["executor"]["name"] == name and manifest["suite"]["sha256"] and manifest["code_version"]
    if "local" not in sweep_runs:
        pytest.fail("the local executor did not run")


def test_evaluate_alignment_progress_lines_on_every_executor(sweep_runs):
    for name, run in sweep_runs.items():
        lines = run["eval_stderr"]
        for k in ("language", "vision"):
            for intent in INTENTS:
                assert f"{k} / {intent}: F1 oracle=" in lines, (name, k, intent)
        assert "language:use_descriptions=maybe: FAILED to build: GiftError" in lines, name
        assert "no-such-kernel: FAILED to build: UnknownComponentError" in lines, name


def test_reproduce_results_json_is_identical_on_serial_local_and_ray(sweep_runs):
    ref = sweep_runs["serial"]
    results = json.loads(ref["results"].read_text())
    assert list(results["rq1"]) == list(INTENTS) and list(results["rq3"]) == list(INTENTS)
    for intent in INTENTS:
        assert set(results["rq1"][intent]) == {"language", "vision", "oracle-labels"}
        assert len(results["scatter"][intent]["points"]) == 6
    assert "errors" not in results and "lm" not in results["manifest"]  # no LM was needed
    want = canonical(ref["results"], {"timing", "manifest", "seconds"})
    for name, run in sweep_runs.items():
        assert canonical(run["results"], {"timing", "manifest", "seconds"}) == want, f"reproduce on {name} differs from serial"
        manifest = json.loads(run["results"].read_text())["manifest"]
        assert manifest["executor"] == {"name": name, "max_workers": 1 if name == "serial" else 2}
        # executor options are not part of the stage keys: the same stage files on every executor
        stages = sorted(p.relative_to(run["stages"]).as_posix() for p in run["stages"].rglob("*.json"))
        assert [s.rsplit("-", 1)[0] for s in stages] == [f"{i}/align-{k}" for i in INTENTS for k in ("language", "vision")]
        assert stages == sorted(p.relative_to(ref["stages"]).as_posix() for p in ref["stages"].rglob("*.json"))


def test_reproduce_logs_a_line_per_intent_on_every_executor(sweep_runs):
    for name, run in sweep_runs.items():
        lines = run["reproduce_stderr"]
        for intent in INTENTS:
            assert f"[{intent}] training scenes and demonstrations on jaco" in lines, name
            assert f"[{intent}] done: language=" in lines, name
    serial = sweep_runs["serial"]["reproduce_stderr"]
    assert serial.index("[art_supplies] done") < serial.index("[valuables] training")  # one intent after the other


# ------------------------------------------------------------------ failures, progress, LM usage, threads
def _suite_with_a_failing_intent(path: Path) -> Path:
    """The sweep suite, but every test object of `valuables` is relevant: its RQ1 test scene cannot be built."""
    text = SUITE.read_text().replace("relevant: false", "relevant: true")
    art = SUITE.read_text().split("  - id: valuables")[0]
    path.write_text(art + "  - id: valuables" + text.split("  - id: valuables")[1])
    return path


def test_reproduce_failure_serial_raises_the_error_and_a_pool_names_the_intent(tmp_path, capfd, local_executor):
    from gift.study.chain import StudyConfig
    from gift.study.progress import Progress
    from gift.study.sweeps import run_study

    cfg = StudyConfig(suite=str(_suite_with_a_failing_intent(tmp_path / "suite.yaml")), kernels=("language",),
                          intent_source="ground-truth", pairs=10, seeds=1, train_scenes=1, demos_per_scene=2,
                          alternatives_per_scene=4, trajectories_per_generator=2, sanity_reps=0, rq3=False)
    lines: list[str] = []
    with pytest.raises(GiftError, match="valuables.*needs relevant and irrelevant test objects") as info:
        run_study(cfg, tmp_path / "serial", Progress(enabled=True), log_line=lines.append, executor="serial")
    assert not isinstance(info.value, ExecutionError)  # serial raises what the intent raised
    assert lines[0] == "[art_supplies] training scenes and demonstrations on jaco"
    done = [i for i, line in enumerate(lines) if line.startswith("[art_supplies] done: language=")]
    assert len(done) == 1 and all(line.startswith("[valuables]") for line in lines[done[0] + 1:])
    assert not any(line.startswith("[valuables] done") for line in lines)
    err = capfd.readouterr().err
    assert "intents" in err and "art_supplies: kernels" in err and "art_supplies: RQ1 seeds" in err  # tqdm bars

    with pytest.raises(ExecutionError, match=r"item 1 of 2 \(IntentJob\('valuables'") as info:
        run_study(cfg, tmp_path / "pool", Progress(enabled=False), log_line=lines.append, executor=local_executor)
    assert list(info.value.completed) == [0]  # art_supplies finished, and its stages are cached for a resume
    assert len(list((tmp_path / "pool" / "stages" / "art_supplies").glob("align-language-*.json"))) == 1


def test_lm_usage_of_the_workers_is_summed_into_the_manifest():
    from gift.study.chain import _usage_delta
    from gift.study.sweeps import manifest
    from gift.study.sweeps import merge_lm as _merge_lm

    before = {"requests": 4, "hits": 1, "misses": 3, "calls": 3, "latency_s": 2.0, "cost_usd": None}
    after = {"requests": 7, "hits": 3, "misses": 4, "calls": 4, "latency_s": 2.5, "cost_usd": None}
    first = {"identity": "llamacpp:m.gguf", "usage": _usage_delta(before, after)}   # a worker that had used the LM
    second = {"identity": "llamacpp:m.gguf", "usage": _usage_delta(None, {**before, "cost_usd": 0.25})}
    assert first["usage"] == {"requests": 3, "hits": 2, "misses": 1, "calls": 1, "latency_s": 0.5, "cost_usd": None}
    merged = _merge_lm([first, None, second])
    assert merged == {"identity": "llamacpp:m.gguf", "usage": {"requests": 7, "hits": 3, "misses": 4, "calls": 4,
                                                                "latency_s": 2.5, "cost_usd": 0.25}}
    assert _merge_lm([None, None]) is None
    # a resumed run: the manifest keeps every run and sums their LM usage
    m = manifest([{"lm": first, "started": "a"}, {"lm": second, "started": "b"}], "key")
    assert m["lm"] == {"identity": "llamacpp:m.gguf", "usage": merged["usage"]}
    assert [r["started"] for r in m["runs"]] == ["a", "b"] and m["config_key"] == "key"
    assert "lm" not in manifest([{"started": "a"}], "key")


def test_answers_per_build_are_counted_between_snapshots_and_summed_over_workers():
    """``made_by`` (answers per build of the model runtime) is a mapping of counts: a snapshot does not share it
    with the live counters, deltas and sums go key by key, and builds left at 0 are dropped."""
    from gift.study.chain import _usage_delta
    from gift.study.components import _public_counters
    from gift.study.sweeps import merge_lm as _merge_lm
    from gift_llm.usage import UsageStats

    stats = UsageStats()
    stats.add_made_by("A")
    before = _public_counters(stats)
    stats.add_made_by("A")
    stats.add_made_by("unrecorded")
    assert before["made_by"] == {"A": 1}  # not the live dict
    first = {"identity": "llamacpp:m.gguf", "usage": _usage_delta(before, _public_counters(stats))}
    assert first["usage"]["made_by"] == {"A": 1, "unrecorded": 1}
    second = {"identity": "llamacpp:m.gguf", "usage": {"requests": 1, "made_by": {"B": 1}}}
    merged = _merge_lm([first, second])
    assert merged["usage"]["made_by"] == {"A": 1, "unrecorded": 1, "B": 1}
    assert _usage_delta({"made_by": {"A": 2}}, {"made_by": {"A": 2, "B": 1}})["made_by"] == {"B": 1}


def test_llamacpp_threads_follow_the_worker_budget(local_executor, monkeypatch, tmp_path):
    """Two local workers on N cores: each gets N // 2 threads, so two embedded models do not oversubscribe."""
    budget = max(1, (os.cpu_count() or 1) // local_executor.max_workers)
    assert local_executor.map(sweeps.llama_threads, [0, 1], chunksize=1) == [(budget, str(budget))] * 2

    llama_cpp = pytest.importorskip("llama_cpp")
    from gift_llm.backends import llamacpp

    made: list[dict] = []

    class Recorder:  # records the options; never loads a model
        def __init__(self, **options):
            made.append(options)

    monkeypatch.setattr(llama_cpp, "Llama", Recorder)
    monkeypatch.setattr(llamacpp, "_MODELS", {})
    monkeypatch.setattr(llamacpp, "LOAD_COUNT", llamacpp.LOAD_COUNT)
    model = tmp_path / "m.gguf"
    model.write_bytes(b"GGUF")
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    llamacpp.LlamaCppLM(model, n_ctx=512).llama
    llamacpp.LlamaCppLM(model, n_ctx=1024, n_threads=3).llama      # an explicit count still wins
    monkeypatch.delenv("OMP_NUM_THREADS")
    llamacpp.LlamaCppLM(model, n_ctx=2048).llama
    assert [(m["n_threads"], m["n_threads_batch"]) for m in made] == [(1, 1), (3, 3), (os.cpu_count(),) * 2]


def test_evaluate_alignment_inferred_intents_failing_the_same_way_on_serial_and_local(local_executor):
    """Inferred intents run as their own items first (on a pool); an LM that cannot be built fails every
    intent of every kernel, reported in the result, the same on both executors."""
    from gift.study.sweeps import evaluate_alignment

    got = {}
    for name, executor in (("serial", "serial"), ("local", local_executor)):
        lines: list[str] = []
        result = evaluate_alignment(str(SUITE), ["language", "vision"], intent_source="inferred",
                                    lm="no-such-backend:x", progress=lines.append, executor=executor)
        assert len(lines) == 4 and all(": FAILED LMError: unknown LM 'no-such-backend:x'" in line for line in lines)
        got[name] = json.dumps(without(result, {"seconds", "manifest"}))
    assert got["serial"] == got["local"]
    kernels = json.loads(got["serial"])["kernels"]
    assert all(set(k["errors"]) == set(INTENTS) and not k["intents"] for k in kernels.values())
