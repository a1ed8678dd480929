"""Fuzzing the suite loader: any file, valid or damaged, loads or raises SuiteError, and nothing else.

Valid suites are generated at random (they must load); then one of them is damaged either in its structure
(a key removed or renamed, a value replaced by any YAML value) or in its bytes (cut short, bytes inserted,
a line repeated, a character replaced). The loader may accept a damaged file only if the damage left it
valid; it must never raise anything but :class:`SuiteError`.
"""

from __future__ import annotations

import string
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gift.core.errors import SuiteError
from gift.core.suite import CONFOUNDS, Suite, load_suite_file

TASKS = ("pack_backpack", "store_drawer")
FUZZ = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])

names = st.one_of(
    st.text(string.ascii_lowercase + " -'", min_size=1, max_size=12),
    st.text(st.characters(blacklist_categories=("Cs", "Cc")), min_size=1, max_size=8),
).filter(lambda s: s.strip() != "").map(str.strip)

sizes = {"box": 3, "cylinder": 2, "sphere": 1}
unit = st.floats(0.01, 1.0, allow_nan=False)


@st.composite
def appearances(draw) -> dict[str, Any]:
    shape = draw(st.sampled_from(sorted(sizes)))
    out: dict[str, Any] = {"shape": shape}
    if draw(st.booleans()):
        out["size"] = draw(st.lists(st.floats(0.01, 2.0), min_size=sizes[shape], max_size=sizes[shape]))
    if draw(st.booleans()):
        out["color"] = draw(st.lists(unit, min_size=3, max_size=3))
    return out


object_attrs = st.one_of(st.none(), st.fixed_dictionaries({}, optional={"description": st.text(max_size=30),
                                                                         "appearance": appearances()}))


@st.composite
def valid_suites(draw) -> dict[str, Any]:
    catalog = draw(st.lists(names, min_size=2, max_size=8, unique=True))
    doc: dict[str, Any] = {"suite": draw(names), "objects": {n: draw(object_attrs) for n in catalog}, "intents": []}
    for k in range(draw(st.integers(1, 3))):
        order = draw(st.permutations(catalog))
        n_train = draw(st.integers(1, len(order) - 1))
        train, rest = list(order[:n_train]), list(order[n_train:])
        relevant = draw(st.lists(st.sampled_from(train), min_size=1, unique=True))
        test = [{"object": o, "relevant": draw(st.booleans()),
                 "confounds": draw(st.lists(st.sampled_from(CONFOUNDS), unique=True))}
                for o in rest[:draw(st.integers(1, len(rest)))]]
        doc["intents"].append({"id": f"intent{k}", "task": draw(st.sampled_from(TASKS)), "text": draw(names),
                               "train_objects": train, "relevant_train": relevant, "test": test})
    return doc


yaml_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10, 10**20), st.floats(), st.text(max_size=10)),
    lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=5), inner, max_size=3)),
    max_leaves=6)


def _paths(value: Any, path: tuple = ()) -> list[tuple]:
    out = [path] if path else []
    if isinstance(value, dict):
        for k, v in value.items():
            out += _paths(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            out += _paths(v, path + (i,))
    return out


@st.composite
def damaged_structures(draw) -> dict[str, Any]:
    doc = draw(valid_suites())
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        if not paths:
            break
        *parent_path, last = draw(st.sampled_from(paths))
        parent = doc
        for p in parent_path:
            parent = parent[p]
        action = draw(st.sampled_from(("delete", "replace", "rename")))
        if action == "delete":
            del parent[last]
        elif action == "replace":
            parent[last] = draw(yaml_values)
        elif isinstance(parent, dict):
            parent[draw(st.one_of(st.text(max_size=6), st.integers()))] = parent.pop(last)
    return doc


@st.composite
def damaged_bytes(draw) -> bytes:
    data = yaml.safe_dump(draw(valid_suites()), allow_unicode=True, sort_keys=False).encode("utf-8")
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(data)))
        action = draw(st.sampled_from(("cut", "insert", "repeat-line", "replace")))
        if action == "cut":
            data = data[:at]
        elif action == "insert":
            data = data[:at] + draw(st.binary(min_size=1, max_size=8)) + data[at:]
        elif action == "repeat-line":
            lines = data.split(b"\n")
            i = draw(st.integers(0, len(lines) - 1))
            data = b"\n".join(lines[:i + 1] + lines[i:])
        else:
            data = data[:at] + draw(st.sampled_from([b":", b"-", b"[", b"{", b"&a", b"*a", b"!!python/name:os.system",
                                                     b"\t", b"'", b"\xff", b"<<: *a"])) + data[at + 1:]
    return data


@pytest.fixture(scope="module")
def fuzz_file(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz") / "suite.yaml"


def _load_or_suite_error(path) -> Suite | SuiteError:
    try:
        suite = load_suite_file(path, known_tasks=TASKS)
    except SuiteError as e:
        assert str(path) in str(e), f"the error does not name the file: {e}"
        return e
    assert isinstance(suite, Suite)
    return suite


@FUZZ
@given(doc=valid_suites())
def test_generated_valid_suites_load(fuzz_file, doc):
    fuzz_file.write_text(yaml.safe_dump(doc, allow_unicode=True, sort_keys=False), encoding="utf-8")
    suite = load_suite_file(fuzz_file, known_tasks=TASKS)
    assert [i.id for i in suite.intents] == [i["id"] for i in doc["intents"]]
    assert set(suite.objects) == set(doc["objects"])


@FUZZ
@given(doc=damaged_structures())
def test_damaged_structures_load_or_raise_suite_error(fuzz_file, doc):
    fuzz_file.write_text(yaml.safe_dump(doc, allow_unicode=True, sort_keys=False), encoding="utf-8")
    _load_or_suite_error(fuzz_file)


@FUZZ
@given(data=damaged_bytes())
def test_damaged_bytes_load_or_raise_suite_error(fuzz_file, data):
    fuzz_file.write_bytes(data)
    _load_or_suite_error(fuzz_file)
