"""Speed of loading a large suite file: libyaml's C parser (what gift uses) vs PyYAML's pure-Python parser.

A generated suite of ``N_OBJECTS`` objects (each with a description and an appearance) and ``N_INTENTS``
intents, each with ``N_TRAIN`` training objects and every other object as a labelled test item (about
1 MB; the same shape as the 5.5 MB, 2,000-object suite of issue 21 at a fifth of the size, so the session
stays short). Both parsers run in the same session on the same text, with the same duplicate-key check;
``c-yaml`` records ``speedup_vs_python`` (ratio of medians) in ``extra_info`` and prints it, and both check
they build the document that was written. ``full-load`` times everything :func:`gift.load_suite` does (read, parse,
validate) with the C parser. Nothing asserts anything about time.
Run: ``.venv/bin/python -m pytest tests/benchmarks/test_suite_loading_benchmark.py``.
"""

from __future__ import annotations

import random

import pytest
import yaml

from gift.core.suite import CONFOUNDS, load_suite_file, parse_suite_yaml

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


def _record(benchmark, key: str) -> None:
    stats = getattr(benchmark, "stats", None)
    if stats is not None:  # None with --benchmark-disable
        _median_s[key] = stats.stats.median


def test_parse_pure_python(benchmark, text):
    """The baseline: PyYAML's Python scanner and parser."""
    benchmark.group = GROUP
    benchmark.extra_info["megabytes"] = len(text.encode()) / 1e6
    doc = benchmark.pedantic(parse_suite_yaml, args=(text,), kwargs={"pure_python": True}, rounds=1, iterations=1)
    assert doc == big_suite()
    _record(benchmark, "python")


def test_parse_c_yaml(benchmark, text, capsys):
    benchmark.group = GROUP
    benchmark.extra_info["megabytes"] = len(text.encode()) / 1e6
    doc = benchmark.pedantic(parse_suite_yaml, args=(text,), rounds=3, iterations=1, warmup_rounds=1)
    assert doc == big_suite()
    _record(benchmark, "c")
    if "python" in _median_s and "c" in _median_s:
        ratio = _median_s["python"] / _median_s["c"]
        benchmark.extra_info["speedup_vs_python"] = ratio
        with capsys.disabled():
            print(f"\n[{GROUP}] YAML parse: C {_median_s['c']:.2f} s, pure Python {_median_s['python']:.2f} s "
                  f"-> speed-up {ratio:.1f}x")


def test_full_load(benchmark, suite_file):
    benchmark.group = GROUP
    suite = benchmark.pedantic(load_suite_file, args=(suite_file,), kwargs={"known_tasks": ["pack_backpack"]},
                               rounds=3, iterations=1)
    assert len(suite.intents) == N_INTENTS and len(suite.intents[0].test) == N_OBJECTS - N_TRAIN
