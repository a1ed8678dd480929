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
    # an intent without test items or without relevant training objects has nothing to evaluate: rejected here
    # instead of failing later (KeyError 'all' in the evaluation report) or silently giving no result
    ("    test:\n      - {object: molding clay, relevant: true}\n      - {object: toothbrush, relevant: false, "
     "confounds: [lang, vis]}\n", "    test: []\n", "needs at least one test item", "art_supplies", "test"),
    ("    relevant_train: [paintbrush, sketchbook]", "    relevant_train: []",
     "needs at least one relevant training object", "art_supplies", "relevant_train"),
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


def test_non_utf8_bytes_name_the_file_and_the_line(tmp_path):
    p = tmp_path / "latin1.yaml"
    p.write_bytes(GOOD.replace("a yellow fruit", "a yellow fruit, caf\xe9 style").encode("latin-1"))
    with pytest.raises(SuiteError) as err:
        gift.load_suite(p)
    line = GOOD.split("\n").index("  banana: {description: a yellow fruit, appearance: {shape: cylinder}}") + 1
    assert str(p) in str(err.value) and "not UTF-8" in str(err.value) and f"line {line}," in str(err.value)
    assert "e9" in str(err.value)


def test_gift_align_reports_a_non_utf8_suite_without_a_traceback(tmp_path, capsys):
    from gift.cli import main

    p = tmp_path / "latin1.yaml"
    p.write_bytes(GOOD.replace("a yellow fruit", "caf\xe9").encode("latin-1"))
    code = main(["align", "--train", "paintbrush", "banana", "--test", "toothbrush", "--kernel", "vision",
                 "--suite", str(p)])
    err = capsys.readouterr().err
    assert code == 1 and "not UTF-8" in err and str(p) in err and "Traceback" not in err


def test_the_paper_suite_and_the_test_suites_still_load():
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    assert gift.load_suite("gift-paper").intents
    for f in sorted((root / "kernels" / "data").glob("*.yaml")) + [root / "executor" / "data" / "sweep_suite.yaml"]:
        assert gift.load_suite(f).intents, f


def test_the_c_and_the_python_yaml_parsers_give_the_same_suite():
    from gift.core.suite import _StrictLoader, parse_suite_yaml, read_suite_text

    text = read_suite_text(gift.get_manager().suites()["gift-paper"])
    assert parse_suite_yaml(text) == parse_suite_yaml(text, pure_python=True)
    assert _StrictLoader.__mro__[1].__name__ == "CSafeLoader"  # PyYAML here is built with libyaml
