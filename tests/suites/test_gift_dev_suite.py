"""The shipped ``gift-dev`` suite: new intents and objects, none borrowed from the suites it is checked against.

Like ``test_gift_paper_suite.py`` these check the data (catalog, splits, subsets, look-alikes, the
document's tables); they also check by name that nothing is shared with ``gift-paper`` or the LM test
suite. Placement on the robots is checked in ``tests/experiments/test_scene_placement.py``.
"""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import pytest
from suite_checks import MAX_EXTENT_M, extent, labels, looks_alike, names_alike

import gift
from gift.core.data import slug
from gift.core.suite import CONFOUNDS
from gift.plugins.manager import get_manager

ROOT = Path(__file__).resolve().parents[2]
SUITE = "gift-dev"
OTHER_SUITES = ("gift-paper", str(ROOT / "tests" / "kernels" / "data" / "lm_dev_suite.yaml"))
FAMILIES = {"place_mug", "sweep_spill", "pack_backpack", "store_drawer"}
SIBLINGS = [("cloth_items", "breakables"), ("leather_goods", "wooden_items"), ("toiletries", "sewing_supplies"),
            ("baking_tools", "gardening_supplies")]
#: Goal patterns of the other suites (gift-paper and lm-dev), which no gift-dev goal may repeat.
FOREIGN_GOALS = re.compile(r"art|read|valuab|electron|paper|water|sharp|picnic|food|first aid|medic",
                           re.IGNORECASE)
#: The gift-dev goals' own words, which would hand a description-reading kernel the labels.
LABEL_WORDS = re.compile(r"fabric|cloth|textile|fragil|breakab|leather|\bwood|toiletr|sewing|baking|garden",
                         re.IGNORECASE)
DOC = ROOT / "docs" / "suites.md"


@pytest.fixture(scope="module")
def suite():
    return gift.load_suite(SUITE)


@pytest.fixture(scope="module")
def others():
    return [gift.load_suite(s) for s in OTHER_SUITES]


def test_loads_by_name_with_eight_intents_over_the_four_families(suite):
    assert SUITE in get_manager().suites() and Path(suite.path).name == "gift-dev.yaml"
    assert len(suite.intents) >= 6
    assert {i.task for i in suite.intents} == FAMILIES
    for i in suite.intents:
        assert i.notes.strip(), f"{i.id}: the label rule belongs in notes"


def test_no_object_and_no_goal_is_shared_with_the_other_suites(suite, others):
    for other in others:
        shared = set(suite.objects) & set(other.objects)
        assert not shared, f"objects shared with {other.name}: {sorted(shared)}"
        shared_slugs = {slug(n) for n in suite.objects} & {slug(n) for n in other.objects}
        assert not shared_slugs, f"feature names shared with {other.name}: {sorted(shared_slugs)}"
        assert not {i.text for i in suite.intents} & {i.text for i in other.intents}
        assert not {i.id for i in suite.intents} & {i.id for i in other.intents}
    for i in suite.intents:
        assert not FOREIGN_GOALS.search(i.text) and not FOREIGN_GOALS.search(i.id), f"{i.id}: {i.text!r}"


def test_goals_are_phrased_as_avoidance_and_sweeping(suite):
    mug = [i.text for i in suite.intents if i.task == "place_mug"]
    sweep = [i.text for i in suite.intents if i.task == "sweep_spill"]
    assert mug and all(re.search(r"\baway from\b|\bwide of\b|\bclear of\b", t) for t in mug), mug
    assert sweep and all(t.startswith("sweep ") for t in sweep), sweep


@pytest.mark.parametrize("intent_id", [i for pair in SIBLINGS for i in pair])
def test_split_sizes(suite, intent_id):
    i = suite.intent(intent_id)
    assert 5 <= len(i.train_objects) <= 6 and 2 <= len(i.relevant_train) <= 3
    assert 12 <= len(i.test) <= 16
    assert 0.4 <= len(i.relevant_test) / len(i.test) <= 0.6, "about half the test objects are relevant"
    assert not set(i.train_objects) & set(i.test_objects)
    s_r = i.subset("R")
    assert any(t.relevant for t in s_r) and any(not t.relevant for t in s_r)


@pytest.mark.parametrize("intent_id", [i for pair in SIBLINGS for i in pair])
def test_every_confound_subset_is_present_and_real(suite, intent_id):
    i = suite.intent(intent_id)
    lab = labels(i)
    goal_words = set(re.findall(r"[a-z]+", i.text.lower()))
    for c in CONFOUNDS:
        assert i.subset(c), f"{intent_id}: empty S_{c}"
    for t in i.subset("lang"):
        twins = [o for o, r in lab.items() if r != t.relevant and names_alike(t.object, o)]
        named_like_goal = not t.relevant and set(re.findall(r"[a-z]+", t.object.lower())) & goal_words
        assert twins or named_like_goal, f"{intent_id}: {t.object!r} is named like nothing of the opposite label"
    for t in i.subset("vis"):
        app = suite.objects[t.object].appearance
        twins = [o for o, r in lab.items() if r != t.relevant and looks_alike(app, suite.objects[o].appearance)]
        assert twins, f"{intent_id}: {t.object!r} looks like nothing labelled {not t.relevant}"
    assert all(t.relevant for t in i.subset("unk")), "S_unk holds members whose membership is indirect"


@pytest.mark.parametrize("a,b", SIBLINGS)
def test_sibling_intents_share_training_objects_but_not_relevance(suite, a, b):
    ia, ib = suite.intent(a), suite.intent(b)
    assert ia.task == ib.task and ia.train_objects == ib.train_objects
    assert not set(ia.relevant_train) & set(ib.relevant_train)


def test_catalog_descriptions_and_appearances(suite):
    used = set()
    for i in suite.intents:
        used |= set(i.train_objects) | set(i.test_objects)
    assert used == set(suite.objects), f"unused catalog objects: {sorted(set(suite.objects) - used)}"
    for name, spec in suite.objects.items():
        d = spec.description
        assert d.strip() and "\n" not in d and len(d) <= 160, f"{name}: {d!r}"
        assert not LABEL_WORDS.search(d), f"{name}: description gives a label away: {d!r}"
        assert extent(spec.appearance) <= MAX_EXTENT_M, f"{name} is {extent(spec.appearance)} m across"
    for (a, sa), (b, sb) in itertools.combinations(suite.objects.items(), 2):
        assert sa.appearance != sb.appearance, f"{a} and {b} have identical appearances"
    slugs = [slug(n) for n in suite.objects]
    assert len(set(slugs)) == len(slugs)
    landmarks = {lm for t in get_manager().names("task") for lm in get_manager().create("task", t).landmarks}
    assert not set(slugs) & landmarks


def test_doc_tables_match_the_suite(suite):
    """docs/suites.md shows every label and subset of the file (regenerate: scripts/suite_doc_tables.py)."""
    text = DOC.read_text(encoding="utf-8").split("## The `gift-dev` suite", 1)[1].split("\n## ", 1)[0]
    assert f"its catalog holds {len(suite.objects)} objects" in text.replace("\n", " ")
    for i in suite.intents:
        section = text.split(f"#### `{i.id}`", 1)[1].split("\n#### ", 1)[0]
        rows = {m[0]: (m[1], m[2]) for m in re.findall(r"^\| ([^|]+?) \| (yes|no) \| ([^|]+?) \|$", section, re.MULTILINE)}
        want = {t.object: ("yes" if t.relevant else "no",
                           ", ".join(f"S_{c}" for c in t.confounds) if t.confounds else "S_R") for t in i.test}
        assert rows == want, i.id
        assert f"**relevant** {', '.join(i.relevant_train)};" in section, i.id
        assert f"| `{i.id}` |" in text.split("### Per-intent tables", 1)[0], f"summary row of {i.id}"
