"""Every suite-file error gives one clear SuiteError naming file, intent and field; nothing half-loads."""

import textwrap

import pytest

import gift
from gift.core.data import DEFAULT_APPEARANCE
from gift.core.errors import SuiteError
from gift.core.suite import load_suite_file

GOOD = """
suite: tiny
objects:
  paintbrush: {description: a brush for paint, appearance: {shape: cylinder, size: [0.01, 0.2], color: [0.6, 0.4, 0.2]}}
  sketchbook: {description: a bound pad of drawing paper}
  banana: {description: a yellow fruit, appearance: {shape: cylinder}}
  molding clay: {description: soft modelling material}
  toothbrush: {description: a small brush for teeth}
intents:
  - id: art_supplies
    task: pack_backpack
    text: pack art supplies
    train_objects: [paintbrush, sketchbook, banana]
    relevant_train: [paintbrush, sketchbook]
    test:
      - {object: molding clay, relevant: true}
      - {object: toothbrush, relevant: false, confounds: [lang, vis]}
"""


def write(tmp_path, text, name="suite.yaml"):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def test_good_suite_loads_with_defaults(tmp_path):
    s = gift.load_suite(write(tmp_path, GOOD))
    assert s.name == "tiny" and len(s.intents) == 1
    i = s.intent("art_supplies")
    assert i.relevant_test == ("molding clay",)
    assert [t.object for t in i.subset("R")] == ["molding clay"]
    assert [t.object for t in i.subset("lang")] == ["toothbrush"]
    assert s.objects["sketchbook"].appearance == DEFAULT_APPEARANCE
    assert s.objects["banana"].appearance.size == (0.04, 0.10)
    assert s.specs(["banana"])[0].name == "banana"


@pytest.mark.parametrize("old,new,match,intent,field", [
    ("    task: pack_backpack", "    task: pack_boxes", "unknown task 'pack_boxes'", "art_supplies", "task"),
    ("      - {object: molding clay, relevant: true}", "      - {object: clay pot, relevant: true}",
     "'clay pot' is not in the suite's catalog", "art_supplies", "test[0].object"),
    ("    train_objects: [paintbrush, sketchbook, banana]", "    train_objects: [paintbrush, sketchbook, violin]",
     "'violin' is not in the suite's catalog", "art_supplies", "train_objects"),
    ("    text: pack art supplies", "    text: pack art supplies\n    colour: red", "unknown key(s) ['colour']",
     "art_supplies", None),
    ("      - {object: molding clay, relevant: true}", "      - {object: molding clay, relevant: yes please}",
     "expected true or false", "art_supplies", "test[0].relevant"),
    ("      - {object: molding clay, relevant: true}", "      - {object: banana, relevant: true}",
     "also a training object", "art_supplies", "test[0].object"),
    ("confounds: [lang, vis]", "confounds: [smell]", "unknown confound", "art_supplies", "test[1].confounds"),
    ("    relevant_train: [paintbrush, sketchbook]", "    relevant_train: [paintbrush, toothbrush]",
     "not among train_objects", "art_supplies", "relevant_train"),
    ("    train_objects: [paintbrush, sketchbook, banana]", "    train_objects: paintbrush",
     "expected list", "art_supplies", "train_objects"),
    ("{shape: cylinder, size: [0.01, 0.2], color: [0.6, 0.4, 0.2]}", "{shape: cone}", "shape must be one of",
     None, "objects.paintbrush.appearance"),
    ("{shape: cylinder, size: [0.01, 0.2], color: [0.6, 0.4, 0.2]}", "{shape: box, size: [a, b, c]}",
     "list of numbers", None, "objects.paintbrush.appearance.size"),
    ("    text: pack art supplies", "    text: 42", "non-empty string", "art_supplies", "text"),
])
def test_each_error_names_file_intent_and_field(tmp_path, old, new, match, intent, field):
    assert old in GOOD
    p = write(tmp_path, GOOD.replace(old, new))
    with pytest.raises(SuiteError) as err:
        gift.load_suite(p)
    e = err.value
    assert match in str(e)
    assert e.path == str(p) and str(p) in str(e)
    assert e.intent == intent
    assert e.field == field


def test_duplicate_intent_id_and_duplicate_catalog_key(tmp_path):
    doubled = GOOD + GOOD[GOOD.index("  - id: art_supplies"):]
    with pytest.raises(SuiteError, match="duplicate intent id") as err:
        gift.load_suite(write(tmp_path, doubled))
    assert err.value.intent == "art_supplies"
    dup_key = GOOD.replace("  banana: {description: a yellow fruit, appearance: {shape: cylinder}}",
                           "  banana: {description: a yellow fruit}\n  banana: {description: again}")
    with pytest.raises(SuiteError, match="duplicate key 'banana'"):
        gift.load_suite(write(tmp_path, dup_key))


def test_top_level_errors(tmp_path):
    with pytest.raises(SuiteError, match="not valid YAML"):
        gift.load_suite(write(tmp_path, "suite: [unclosed"))
    with pytest.raises(SuiteError, match="missing key"):
        gift.load_suite(write(tmp_path, "suite: x\nobjects: {}\n"))
    with pytest.raises(SuiteError, match="mapping at the top level"):
        gift.load_suite(write(tmp_path, "- a\n- b\n"))
    with pytest.raises(SuiteError, match="cannot read"):
        load_suite_file(tmp_path / "missing.yaml")
    with pytest.raises(SuiteError, match="no registered suite 'nonexistent-suite'"):
        gift.load_suite("nonexistent-suite")


def test_task_check_can_be_skipped_for_simulator_free_use(tmp_path):
    p = write(tmp_path, GOOD.replace("task: pack_backpack", "task: my_own_family"))
    assert gift.load_suite(p, known_tasks=None).intents[0].task == "my_own_family"
