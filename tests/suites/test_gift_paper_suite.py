"""The shipped ``gift-paper`` suite: it loads by name and its data keeps the benchmark's promises.

These check the data itself (catalog, splits, subset sizes, sibling intents, look-alikes), the things a
strict loader cannot know. No simulator is involved.
"""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import pytest
from suite_checks import MAX_EXTENT_M, extent, labels, looks_alike, names_alike

import gift
from gift.core.data import slug
from gift.core.suite import CONFOUNDS, load_suite_file
from gift.plugins.manager import get_manager

SUITE = "gift-paper"

#: The paper's six ground-truth intents: suite id -> (task family, intent text).
PAPER_INTENTS = {
    "water_sensitive": ("place_mug", "avoid carrying fluids near water-sensitive objects"),
    "paper_based": ("sweep_spill", "sweep paper-based items away from the spill"),
    "art_supplies": ("pack_backpack", "pack art supplies"),
    "reading_material": ("pack_backpack", "pack reading material"),
    "valuables": ("store_drawer", "store valuables"),
    "electronics": ("store_drawer", "store electronics"),
}
SIBLINGS = [("art_supplies", "reading_material"), ("valuables", "electronics")]
CONFOUNDED = [i for pair in SIBLINGS for i in pair]

#: Every object the paper names.
PAPER_OBJECTS = [
    "paintbrush", "sketchbook", "canvas", "molding clay", "tablet with stylus", "toothbrush", "broomstick",
    "dish scrubber", "pepper grinder", "watercolor", "easel", "metal paintbrush", "wooden pencil", "screwdriver",
    "diamond ring", "paper ring", "MacBook Pro", "iPad Pro", "iPhone Pro", "desk clock", "hand sanitizer",
    "coffee mug", "laptop",
]

#: Words that would hand a description-reading kernel the labels.
LABEL_WORDS = re.compile(r"valuabl|art[- ]suppl|reading[- ]material|electronic|paper[- ]based|water[- ]sensitiv",
                         re.IGNORECASE)



@pytest.fixture(scope="module")
def suite():
    return gift.load_suite(SUITE)


# ----------------------------------------------------------------------------- loading


def test_suite_loads_by_name_and_by_path(suite):
    assert suite.name == SUITE
    assert SUITE in get_manager().suites()
    path = Path(suite.path)
    assert path.name == "gift-paper.yaml" and path.parent.name == "suites"
    again = load_suite_file(path, known_tasks=get_manager().names("task"))
    assert again.objects == suite.objects and again.intents == suite.intents
    assert suite.description.strip()


def test_the_six_paper_intents_on_registered_tasks(suite):
    assert {i.id: (i.task, i.text) for i in suite.intents} == PAPER_INTENTS
    registered = set(get_manager().names("task"))
    assert {i.task for i in suite.intents} <= registered
    for i in suite.intents:
        assert i.notes.strip(), f"{i.id}: the label rule belongs in notes"


# ----------------------------------------------------------------------------- catalog


def test_catalog_has_sixty_objects_including_every_one_the_paper_names(suite):
    assert len(suite.objects) >= 60
    missing = [o for o in PAPER_OBJECTS if o not in suite.objects]
    assert not missing, f"paper objects missing from the catalog: {missing}"


def test_every_object_referenced_is_in_the_catalog_and_every_catalog_object_is_used(suite):
    used = set()
    for i in suite.intents:
        names = set(i.train_objects) | set(i.relevant_train) | set(i.test_objects)
        assert names <= set(suite.objects), f"{i.id}: {sorted(names - set(suite.objects))}"
        used |= names
    assert not set(suite.objects) - used, f"catalog objects no intent uses: {sorted(set(suite.objects) - used)}"


def test_descriptions_are_single_neutral_lines(suite):
    for name, spec in suite.objects.items():
        d = spec.description
        assert d.strip() and "\n" not in d and len(d) <= 160, f"{name}: {d!r}"
        assert not LABEL_WORDS.search(d), f"{name}: description gives a label away: {d!r}"


def test_feature_names_stay_unique(suite):
    """Object names map to distinct feature slugs, none of which collides with a task landmark."""
    slugs = [slug(n) for n in suite.objects]
    assert len(set(slugs)) == len(slugs)
    landmarks = {lm for t in get_manager().names("task") for lm in get_manager().create("task", t).landmarks}
    assert not set(slugs) & landmarks


def test_appearances_fit_the_table_and_are_all_distinct(suite):
    for name, spec in suite.objects.items():
        assert extent(spec.appearance) <= MAX_EXTENT_M, f"{name} is {extent(spec.appearance)} m across"
    for (a, sa), (b, sb) in itertools.combinations(suite.objects.items(), 2):
        assert sa.appearance != sb.appearance, f"{a} and {b} have identical appearances"


# ----------------------------------------------------------------------------- splits and labels


@pytest.mark.parametrize("intent_id", sorted(PAPER_INTENTS))
def test_split_sizes_and_disjointness(suite, intent_id):
    i = suite.intent(intent_id)
    assert 4 <= len(i.train_objects) <= 6
    assert 2 <= len(i.relevant_train) <= 3 and len(i.relevant_train) < len(i.train_objects)
    assert 14 <= len(i.test) <= 24
    assert not set(i.train_objects) & set(i.test_objects), "train and test must be disjoint"
    assert len(set(i.test_objects)) == len(i.test_objects)


@pytest.mark.parametrize("intent_id", sorted(PAPER_INTENTS))
def test_every_intent_has_positives_and_negatives_in_s_r(suite, intent_id):
    i = suite.intent(intent_id)
    s_r = i.subset("R")
    assert any(t.relevant for t in s_r) and any(not t.relevant for t in s_r)
    assert any(t.relevant for t in i.test) and any(not t.relevant for t in i.test)


@pytest.mark.parametrize("intent_id", CONFOUNDED)
def test_confound_subsets_meet_their_minimum(suite, intent_id):
    i = suite.intent(intent_id)
    sizes = {c: len(i.subset(c)) for c in CONFOUNDS}
    assert all(n >= 4 for n in sizes.values()), sizes


@pytest.mark.parametrize("intent_id", ["water_sensitive", "paper_based"])
def test_place_and_sweep_are_s_r_only(suite, intent_id):
    i = suite.intent(intent_id)
    assert i.subset("R") == i.test


@pytest.mark.parametrize("a,b", SIBLINGS)
def test_sibling_intents_share_training_scenes_but_not_relevance(suite, a, b):
    ia, ib = suite.intent(a), suite.intent(b)
    assert ia.task == ib.task
    assert ia.train_objects == ib.train_objects
    assert not set(ia.relevant_train) & set(ib.relevant_train)


@pytest.mark.parametrize("a,b", SIBLINGS)
def test_sibling_intents_disagree_on_their_s_unk_items(suite, a, b):
    ia, ib = suite.intent(a), suite.intent(b)
    unk_a = {t.object: t.relevant for t in ia.subset("unk")}
    unk_b = {t.object: t.relevant for t in ib.subset("unk")}
    assert set(unk_a) == set(unk_b)
    for obj, rel in unk_a.items():
        assert unk_b[obj] is (not rel), f"{obj}: {a}={rel}, {b}={unk_b[obj]}"
    # both labels occur, so S_unk tests false positives and false negatives alike
    assert set(unk_a.values()) == {True, False}


# ----------------------------------------------------------------------------- confounds are real confounds


@pytest.mark.parametrize("intent_id", CONFOUNDED)
def test_visual_confounds_look_like_an_object_of_the_opposite_label(suite, intent_id):
    i = suite.intent(intent_id)
    lab = labels(i)
    for t in i.subset("vis"):
        app = suite.objects[t.object].appearance
        twins = [o for o, r in lab.items() if r != t.relevant and looks_alike(app, suite.objects[o].appearance)]
        assert twins, f"{intent_id}: {t.object!r} looks like nothing labelled {not t.relevant}"


@pytest.mark.parametrize("intent_id", CONFOUNDED)
def test_language_confounds_are_named_like_an_object_of_the_opposite_label(suite, intent_id):
    i = suite.intent(intent_id)
    lab = labels(i)
    for t in i.subset("lang"):
        twins = [o for o, r in lab.items() if r != t.relevant and names_alike(t.object, o)]
        assert twins, f"{intent_id}: {t.object!r} is named like nothing labelled {not t.relevant}"


def test_paper_examples_keep_their_roles(suite):
    """The confounds the paper discusses are in the subsets it puts them in, with its labels."""
    art, val = suite.intent("art_supplies"), suite.intent("valuables")
    item = {t.object: t for t in art.test} | {t.object: t for t in val.test}
    assert "paintbrush" in art.relevant_train and "diamond ring" in val.relevant_train
    assert "lang" in item["toothbrush"].confounds and not item["toothbrush"].relevant
    assert "vis" in item["broomstick"].confounds and not item["broomstick"].relevant
    assert "vis" in item["dish scrubber"].confounds and not item["dish scrubber"].relevant
    assert item["molding clay"].relevant and item["tablet with stylus"].relevant
    assert {"lang", "vis"} <= set(item["paper ring"].confounds) and not item["paper ring"].relevant
    assert item["MacBook Pro"].relevant and item["iPad Pro"].relevant and item["iPhone Pro"].relevant
    assert "unk" in item["metal paintbrush"].confounds and "unk" in item["wooden pencil"].confounds


def test_look_alike_check_is_not_vacuous(suite):
    """The helpers above reject obviously different pairs, so passing them means something."""
    objs = suite.objects
    assert looks_alike(objs["broomstick"].appearance, objs["paintbrush"].appearance)
    assert not looks_alike(objs["molding clay"].appearance, objs["paintbrush"].appearance)
    assert not looks_alike(objs["apple"].appearance, objs["tennis ball"].appearance)
    assert names_alike("toothbrush", "paintbrush") and not names_alike("molding clay", "paintbrush")


# ----------------------------------------------------------------------------- the document


DOC = Path(__file__).resolve().parents[2] / "docs" / "suites.md"


def test_doc_example_suite_loads(tmp_path):
    blocks = re.findall(r"```yaml\n(.*?)```", DOC.read_text(encoding="utf-8"), re.DOTALL)
    example = [b for b in blocks if b.startswith("suite: my-lab-suite")]
    assert len(example) == 1
    path = tmp_path / "my-lab-suite.yaml"
    path.write_text(example[0], encoding="utf-8")
    s = gift.load_suite(path)
    assert s.name == "my-lab-suite"
    art = s.intent("art")
    assert art.relevant_test == ("crayon box",) and [t.object for t in art.subset("lang")] == ["toothbrush"]


def test_doc_tables_match_the_suite(suite):
    """Every test item's row in docs/suites.md shows the suite's label and subsets (regenerate: scripts/suite_doc_tables.py)."""
    text = DOC.read_text(encoding="utf-8")
    for i in suite.intents:
        section = text.split(f"#### `{i.id}`", 1)[1].split("\n#### ", 1)[0].split("\n## ", 1)[0]
        rows = {m[0]: (m[1], m[2]) for m in re.findall(r"^\| ([^|]+?) \| (yes|no) \| ([^|]+?) \|$", section, re.M)}
        want = {t.object: ("yes" if t.relevant else "no",
                           ", ".join(f"S_{c}" for c in t.confounds) if t.confounds else "S_R") for t in i.test}
        assert rows == want, i.id
        rel = ", ".join(i.relevant_train)
        assert f"**relevant** {rel};" in section, i.id
        sizes = [len(i.subset(c)) or "–" for c in ("R", "lang", "vis", "unk")]
        summary = (f"| `{i.id}` | {{}} | `{i.task}` | {len(i.train_objects)} ({len(i.relevant_train)}) | "
                   f"{len(i.test)} ({len(i.relevant_test)}) | " + " | ".join(map(str, sizes)) + " |")
        assert re.search(re.escape(summary).replace(r"\{\}", r"\S+"), text), f"summary row of {i.id}"
    assert f"a catalog of {len(suite.objects)} objects" in text
