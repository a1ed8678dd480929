"""Speed of loading a large suite file: what gift does now against what it did before, in the same session.

A generated suite of ``N_OBJECTS`` objects (each with a description and an appearance) and ``N_INTENTS``
intents, each with ``N_TRAIN`` training objects and every other object as a labelled test item (about
1 MB: the shape of the 5.5 MB, 2,000-object suite of issue 21 at a fifth of its size, so the session stays
short). Three ways to parse the same text, all with gift's duplicate-key check:

- ``python-yaml-gc-running``: the baseline, as gift parsed before: PyYAML's pure-Python parser with the
  garbage collector running;
- ``c-yaml-gc-running``: libyaml's C parser alone;
- ``gift``: :func:`gift.core.suite.parse_suite_yaml`: the C parser with the collector paused.

(pytest-benchmark runs with ``--benchmark-disable-gc`` here; the two baselines switch the collector back on
inside the timed call, as it is in a real run.) ``gift`` records ``speedup_vs_python`` and
``speedup_vs_c_gc_running`` (ratios of medians) in ``extra_info`` and prints them; every variant checks it
built the document that was written. ``full-load`` times all of :func:`gift.load_suite` (read, parse,
validate). Nothing asserts anything about time. The gap from the collector grows with the file and with
everything else the process holds: on the 6.3 MB suite, 28 s with the collector running, 7 s paused.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_suite_loading_benchmark.py``.
"""

from __future__ import annotations

import gc
import random

import pytest
import yaml

from gift.core.suite import CONFOUNDS, _PyStrictLoader, _StrictLoader, load_suite_file, parse_suite_yaml

N_OBJECTS, N_INTENTS, N_TRAIN = 600, 12, 20
GROUP = f"suite file, {N_OBJECTS} objects x {N_INTENTS} intents"

_median_s: dict[str, float] = {}


def big_suite(seed: int = 0) -> dict:
    rng = random.Random(seed)
    names = [f"object {i:04d} {rng.choice(['red', 'blue', 'wooden', 'metal'])} {rng.choice(['box', 'cup', 'brush'])}"
             for i in range(N_OBJECTS)]
    objects = {n: {"description": f"a {n}, one of many objects of a large generated suite",
                   "appearance": {"shape": "box", "size": [0.05, 0.06, 0.07], "color": [0.1, 0.5, 0.9]}}
               for n in names}
    intents = []
    for k in range(N_INTENTS):
        order = names[:]
        rng.shuffle(order)
        train, test = order[:N_TRAIN], order[N_TRAIN:]
        intents.append({"id": f"intent_{k}", "task": "pack_backpack", "text": f"pack the things of kind {k}",
                        "train_objects": train, "relevant_train": train[: N_TRAIN // 2],
                        "test": [{"object": o, "relevant": rng.random() < 0.3,
                                  "confounds": rng.sample(CONFOUNDS, rng.randint(0, 1))} for o in test]})
    return {"suite": "big", "objects": objects, "intents": intents}


@pytest.fixture(scope="module")
def suite_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("big-suite") / "big.yaml"
    path.write_text(yaml.safe_dump(big_suite(), sort_keys=False, width=200), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def text(suite_file):
    return suite_file.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def expected():
    return big_suite()


def _with_gc_running(loader):
    def parse(text: str):
        was = gc.isenabled()
        gc.enable()
        try:
            return yaml.load(text, Loader=loader)  # noqa: S506 - SafeLoader subclasses
        finally:
            if not was:
                gc.disable()

    return parse


def _record(benchmark, key: str, text: str) -> None:
    benchmark.group = GROUP
    benchmark.extra_info["megabytes"] = round(len(text.encode()) / 1e6, 2)
    stats = getattr(benchmark, "stats", None)
    if stats is not None:  # None with --benchmark-disable
        _median_s[key] = stats.stats.median


def test_parse_python_yaml_gc_running(benchmark, text, expected):
    """The baseline: how gift parsed suites before (pure-Python PyYAML, collector running)."""
    doc = benchmark.pedantic(_with_gc_running(_PyStrictLoader), args=(text,), rounds=1, iterations=1)
    assert doc == expected
    _record(benchmark, "python", text)


def test_parse_c_yaml_gc_running(benchmark, text, expected):
    doc = benchmark.pedantic(_with_gc_running(_StrictLoader), args=(text,), rounds=2, iterations=1)
    assert doc == expected
    _record(benchmark, "c-gc", text)


def test_parse_gift(benchmark, text, expected, capsys):
    doc = benchmark.pedantic(parse_suite_yaml, args=(text,), rounds=3, iterations=1, warmup_rounds=1)
    assert doc == expected
    _record(benchmark, "gift", text)
    if {"python", "c-gc", "gift"} <= set(_median_s):
        mine = _median_s["gift"]
        benchmark.extra_info["speedup_vs_python"] = _median_s["python"] / mine
        benchmark.extra_info["speedup_vs_c_gc_running"] = _median_s["c-gc"] / mine
        with capsys.disabled():
            print(f"\n[{GROUP}] YAML parse: gift (C, collector paused) {mine:.2f} s; C with the collector running "
                  f"{_median_s['c-gc']:.2f} s; pure Python with it running (before) {_median_s['python']:.2f} s "
                  f"-> speed-up {_median_s['python'] / mine:.1f}x")


def test_full_load(benchmark, suite_file, text):
    suite = benchmark.pedantic(load_suite_file, args=(suite_file,), kwargs={"known_tasks": ["pack_backpack"]},
                               rounds=3, iterations=1)
    assert len(suite.intents) == N_INTENTS and len(suite.intents[0].test) == N_OBJECTS - N_TRAIN
    _record(benchmark, "full", text)
