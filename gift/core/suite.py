"""Benchmark suites: the suite-file format (YAML) and its strict loader.

A suite file::

    suite: NAME
    description: TEXT                  # optional
    objects:                           # catalog, name -> attributes
      molding clay: {description: TEXT, appearance: {shape: box, size: [0.08, 0.08, 0.04], color: [0.8, 0.3, 0.2]}}
    intents:
      - id: art_supplies
        task: pack_backpack            # a registered task family
        text: pack art supplies        # ground-truth intent
        train_objects: [paintbrush, sketchbook, banana, coffee mug]
        relevant_train: [paintbrush, sketchbook]
        test:
          - {object: molding clay, relevant: true}
          - {object: toothbrush, relevant: false, confounds: [lang]}   # lang | vis | unk
        notes: TEXT                    # optional: how the labels were decided

Every intent needs at least one training object, one relevant training object and one test item.
The file must be UTF-8.

``appearance`` is optional; a missing one is :data:`gift.core.data.DEFAULT_APPEARANCE` (a grey 8 cm
cube); a missing ``shape``/``size``/``color`` inside it takes that default's value (for a shape other
than box, the default size is 4 cm radius and, for a cylinder, 10 cm length).

Loading validates everything and raises one :class:`SuiteError` naming the file, intent and field;
nothing is half-loaded.
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

import attrs
import yaml

from gift.core.data import DEFAULT_APPEARANCE, SHAPES, Appearance, ObjectSpec
from gift.core.errors import SuiteError, ValidationError

CONFOUNDS = ("lang", "vis", "unk")
SUBSETS = ("R",) + CONFOUNDS  # S_R, S_lang, S_vis, S_unk

_DEFAULT_SIZES = {"box": (0.08, 0.08, 0.08), "cylinder": (0.04, 0.10), "sphere": (0.04,)}


@attrs.frozen
class TestItem:
    """A labelled test object of one intent. ``confounds`` ⊆ {lang, vis, unk}; none means S_R."""

    __test__ = False  # not a pytest test class

    object: str
    relevant: bool
    confounds: tuple[str, ...] = ()

    def in_subset(self, subset: str) -> bool:
        return not self.confounds if subset == "R" else subset in self.confounds


@attrs.frozen
class IntentSpec:
    """One ground-truth intent of a suite with its training objects and labelled test objects."""

    id: str
    task: str
    text: str
    train_objects: tuple[str, ...]
    relevant_train: tuple[str, ...]
    test: tuple[TestItem, ...]
    notes: str = ""

    @property
    def test_objects(self) -> tuple[str, ...]:
        return tuple(t.object for t in self.test)

    @property
    def relevant_test(self) -> tuple[str, ...]:
        return tuple(t.object for t in self.test if t.relevant)

    def subset(self, name: str) -> tuple[TestItem, ...]:
        """Test items of S_R (``"R"``), S_lang, S_vis or S_unk."""
        if name not in SUBSETS:
            raise ValueError(f"unknown subset {name!r}; one of {SUBSETS}")
        return tuple(t for t in self.test if t.in_subset(name))


@attrs.frozen
class Suite:
    name: str
    objects: Mapping[str, ObjectSpec]
    intents: tuple[IntentSpec, ...]
    description: str = ""
    path: str | None = None

    def intent(self, intent_id: str) -> IntentSpec:
        for i in self.intents:
            if i.id == intent_id:
                return i
        raise KeyError(f"suite {self.name!r} has no intent {intent_id!r}; it has {[i.id for i in self.intents]}")

    def specs(self, names: Iterable[str]) -> tuple[ObjectSpec, ...]:
        """Catalog entries for ``names``, in order."""
        return tuple(self.objects[n] for n in names)


# ----------------------------------------------------------------------------- YAML with duplicate-key check


#: libyaml's C parser when PyYAML was built with it (about 10x faster on large suites), else pure Python.
_BaseLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _StrictLoader(_BaseLoader):  # type: ignore[misc, valid-type]
    pass


class _PyStrictLoader(yaml.SafeLoader):
    """The pure-Python loader with the same checks (the benchmark's baseline)."""


def _construct_mapping(loader: yaml.SafeLoader, node: yaml.MappingNode, deep: bool = False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise SuiteError(f"duplicate key {key!r} at line {key_node.start_mark.line + 1}")
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


for _loader in (_StrictLoader, _PyStrictLoader):
    _loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


# ----------------------------------------------------------------------------- parsing


def _expect(value: Any, kind: type | tuple[type, ...], what: str, **where) -> Any:
    if not isinstance(value, kind) or (kind is not bool and isinstance(value, bool) and bool not in
                                       (kind if isinstance(kind, tuple) else (kind,))):
        names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
        raise SuiteError(f"expected {names}, got {type(value).__name__} {value!r}", field=what, **where)
    return value


def _keys(d: Mapping, allowed: Iterable[str], required: Iterable[str], what: str, **where) -> None:
    unknown = sorted(set(d) - set(allowed), key=repr)  # keys may be of any YAML type
    if unknown:
        raise SuiteError(f"unknown key(s) {unknown} in {what}; allowed: {sorted(allowed)}", **where)
    missing = [k for k in required if k not in d]
    if missing:
        raise SuiteError(f"missing key(s) {missing} in {what}", **where)


def _str_list(value: Any, field: str, **where) -> tuple[str, ...]:
    _expect(value, list, field, **where)
    out = []
    for v in value:
        if not isinstance(v, str) or not v.strip():
            raise SuiteError(f"expected a list of non-empty strings, found {v!r}", field=field, **where)
        out.append(v)
    if len(set(out)) != len(out):
        dup = sorted({v for v in out if out.count(v) > 1})
        raise SuiteError(f"duplicate entries {dup}", field=field, **where)
    return tuple(out)


def _parse_object(name: Any, attrs_: Any, path: str) -> ObjectSpec:
    where = {"path": path}
    if not isinstance(name, str) or not name.strip():
        raise SuiteError(f"object names must be non-empty strings, got {name!r}", field="objects", **where)
    field = f"objects.{name}"
    if attrs_ is None:
        attrs_ = {}
    _expect(attrs_, dict, field, **where)
    _keys(attrs_, ("description", "appearance"), (), f"object {name!r}", field=field, **where)
    desc = attrs_.get("description", "")
    _expect(desc, str, f"{field}.description", **where)
    app = DEFAULT_APPEARANCE
    if "appearance" in attrs_:
        a = _expect(attrs_["appearance"], dict, f"{field}.appearance", **where)
        _keys(a, ("shape", "size", "color"), (), f"appearance of {name!r}", field=f"{field}.appearance", **where)
        shape = a.get("shape", "box")
        if not isinstance(shape, str) or shape not in SHAPES:
            raise SuiteError(f"shape must be one of {list(SHAPES)}, got {shape!r}", field=f"{field}.appearance",
                             **where)
        size = a.get("size", _DEFAULT_SIZES.get(shape, DEFAULT_APPEARANCE.size))
        color = a.get("color", DEFAULT_APPEARANCE.color)
        for key, val in (("size", size), ("color", color)):
            if not isinstance(val, (list, tuple)) or not all(
                    isinstance(x, (int, float)) and not isinstance(x, bool) for x in val):
                raise SuiteError(f"expected a list of numbers, got {val!r}", field=f"{field}.appearance.{key}", **where)
        try:
            app = Appearance(shape=shape, size=size, color=color)
        except ValidationError as e:
            raise SuiteError(str(e), field=f"{field}.appearance", **where) from None
    return ObjectSpec(name=name, description=desc, appearance=app)


def _parse_intent(raw: Any, index: int, catalog: Mapping[str, ObjectSpec], known_tasks: set[str] | None,
                  path: str) -> IntentSpec:
    if not isinstance(raw, dict):
        raise SuiteError(f"intent #{index} must be a mapping, got {type(raw).__name__}", path=path,
                         field=f"intents[{index}]")
    iid = raw.get("id", f"#{index}")
    where = {"path": path, "intent": str(iid)}
    _keys(raw, ("id", "task", "text", "train_objects", "relevant_train", "test", "notes"),
          ("id", "task", "text", "train_objects", "relevant_train", "test"), "an intent", **where)
    for key in ("id", "task", "text"):
        if not isinstance(raw[key], str) or not raw[key].strip():
            raise SuiteError(f"expected a non-empty string, got {raw[key]!r}", field=key, **where)
    notes = raw.get("notes", "")
    _expect(notes, str, "notes", **where)
    if known_tasks is not None and raw["task"] not in known_tasks:
        raise SuiteError(f"unknown task {raw['task']!r}; registered tasks: {sorted(known_tasks)}", field="task",
                         **where)
    train = _str_list(raw["train_objects"], "train_objects", **where)
    if not train:
        raise SuiteError("needs at least one training object", field="train_objects", **where)
    rel = _str_list(raw["relevant_train"], "relevant_train", **where)
    if not rel:
        raise SuiteError("needs at least one relevant training object (the intent is defined by what the "
                         "demonstrations act on; with none, every test object would align to the distractor)",
                         field="relevant_train", **where)
    for field, names in (("train_objects", train), ("relevant_train", rel)):
        for n in names:
            if n not in catalog:
                raise SuiteError(f"object {n!r} is not in the suite's catalog", field=field, **where)
    train_set = set(train)
    stray = [n for n in rel if n not in train_set]
    if stray:
        raise SuiteError(f"{stray} are not among train_objects", field="relevant_train", **where)
    tests_raw = _expect(raw["test"], list, "test", **where)
    if not tests_raw:
        raise SuiteError("needs at least one test item ({object: NAME, relevant: true|false})", field="test",
                         **where)
    items, seen = [], set()
    for k, t in enumerate(tests_raw):
        f = f"test[{k}]"
        _expect(t, dict, f, **where)
        _keys(t, ("object", "relevant", "confounds"), ("object", "relevant"), f"test item {k}", field=f, **where)
        obj = t["object"]
        if not isinstance(obj, str) or obj not in catalog:
            raise SuiteError(f"object {obj!r} is not in the suite's catalog", field=f"{f}.object", **where)
        if obj in train_set:
            raise SuiteError(f"test object {obj!r} is also a training object; train and test must be disjoint",
                             field=f"{f}.object", **where)
        if obj in seen:
            raise SuiteError(f"test object {obj!r} is listed twice", field=f"{f}.object", **where)
        seen.add(obj)
        if not isinstance(t["relevant"], bool):
            raise SuiteError(f"expected true or false, got {t['relevant']!r}", field=f"{f}.relevant", **where)
        conf = _str_list(t.get("confounds", []), f"{f}.confounds", **where)
        bad = [c for c in conf if c not in CONFOUNDS]
        if bad:
            raise SuiteError(f"unknown confound(s) {bad}; allowed: {list(CONFOUNDS)}", field=f"{f}.confounds",
                             **where)
        items.append(TestItem(obj, t["relevant"], conf))
    return IntentSpec(id=raw["id"], task=raw["task"], text=raw["text"], train_objects=train, relevant_train=rel,
                      test=tuple(items), notes=notes)


def parse_suite(data: Any, *, path: str = "<memory>", known_tasks: Iterable[str] | None = None) -> Suite:
    """Validate an already-parsed suite document. ``known_tasks=None`` skips the task-name check."""
    if not isinstance(data, dict):
        raise SuiteError(f"a suite file must be a mapping at the top level, got {type(data).__name__}", path=path)
    _keys(data, ("suite", "description", "objects", "intents"), ("suite", "objects", "intents"), "the suite",
          path=path)
    name = data["suite"]
    if not isinstance(name, str) or not name.strip():
        raise SuiteError(f"expected a non-empty string, got {name!r}", path=path, field="suite")
    desc = data.get("description", "")
    _expect(desc, str, "description", path=path)
    objs = _expect(data["objects"], dict, "objects", path=path)
    catalog = {n: _parse_object(n, a, path) for n, a in objs.items()}
    intents_raw = _expect(data["intents"], list, "intents", path=path)
    if not intents_raw:
        raise SuiteError("a suite needs at least one intent", path=path, field="intents")
    tasks = set(known_tasks) if known_tasks is not None else None
    intents, ids = [], set()
    for k, raw in enumerate(intents_raw):
        spec = _parse_intent(raw, k, catalog, tasks, path)
        if spec.id in ids:
            raise SuiteError("duplicate intent id", path=path, intent=spec.id, field="id")
        ids.add(spec.id)
        intents.append(spec)
    return Suite(name=name, objects=catalog, intents=tuple(intents), description=desc, path=path)


def read_suite_text(path: str | Path) -> str:
    """The text of a suite file (UTF-8); unreadable files and bytes that are not UTF-8 are a :class:`SuiteError`
    naming the line and column."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as e:
        raise SuiteError(f"cannot read suite file: {e.strerror or e}", path=str(p)) from None
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw.count(b"\n", 0, e.start) + 1
        col = e.start - (raw.rfind(b"\n", 0, e.start) + 1) + 1
        bad = raw[e.start:e.end].hex(" ")
        raise SuiteError(f"not UTF-8 text: byte(s) {bad} at line {line}, column {col} (byte offset {e.start}); "
                         f"save the file as UTF-8", path=str(p)) from None


@contextlib.contextmanager
def _gc_paused() -> Iterator[None]:
    """Pause Python's cyclic garbage collector while a suite is built.

    Building a large document allocates millions of objects, each allocation burst triggers a collection,
    and each full collection walks every object of the process: the cost grows with the square of the file
    (a 6.3 MB suite parsed in 28 s with the collector running, 7 s paused). Reference counting still frees
    everything; the collector resumes afterwards.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def parse_suite_yaml(text: str, *, path: str = "<memory>", pure_python: bool = False) -> Any:
    """The YAML document of a suite file (duplicate keys are an error). ``pure_python`` forces PyYAML's
    Python parser instead of libyaml's (same result; for comparisons)."""
    loader = _PyStrictLoader if pure_python else _StrictLoader
    try:
        with _gc_paused():
            return yaml.load(text, Loader=loader)  # noqa: S506 - SafeLoader subclasses
    except SuiteError as e:
        raise SuiteError(str(e), path=path) from None
    except yaml.YAMLError as e:
        raise SuiteError(f"not valid YAML: {e}", path=path) from None
    except (RecursionError, ValueError, TypeError, OverflowError) as e:  # e.g. a timestamp like 2024-99-99
        raise SuiteError(f"not a valid suite document: {type(e).__name__}: {e}", path=path) from None


def load_suite_file(path: str | Path, *, known_tasks: Iterable[str] | None = None) -> Suite:
    """Load and validate a suite file."""
    p = Path(path)
    with _gc_paused():
        data = parse_suite_yaml(read_suite_text(p), path=str(p))
        return parse_suite(data, path=str(p), known_tasks=known_tasks)


def load_suite(name_or_path: str | Path, *, known_tasks: Iterable[str] | None | Callable = "registered") -> Suite:
    """Load a suite by registered name (e.g. ``"gift-paper"``) or by file path.

    Task names are checked against the registered task families unless ``known_tasks`` is given
    (``None`` skips the check).
    """
    from gift.plugins.manager import get_manager

    manager = get_manager()
    if known_tasks == "registered":
        known_tasks = manager.names("task")
    registered = manager.suites()
    if str(name_or_path) in registered:
        return load_suite_file(registered[str(name_or_path)], known_tasks=known_tasks)
    p = Path(name_or_path)
    if p.suffix in (".yaml", ".yml") or p.exists():
        return load_suite_file(p, known_tasks=known_tasks)
    raise SuiteError(f"no registered suite {str(name_or_path)!r} and no such file; "
                     f"registered suites: {sorted(registered)}")
