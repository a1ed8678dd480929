"""LM kernels: ``gift``, ``lm-no-intent`` and ``gift-prob``.

Parsing and control flow use a scripted fake LM defined here; the features themselves are shown on the
embedded model (tests marked ``slow``).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import gift
from gift.core.data import DISTRACTOR, Completion, Intent, ObjectSpec
from gift.core.errors import GiftError, LMAnswerError, ValidationError
from gift.core.interfaces import LMBackend, SimilarityKernel
from gift.core.suite import load_suite
from gift_kernels import prompts
from gift_kernels.lm_kernels import (RUNGS, GiftProbKernel, MappingKernel, NoIntentMappingKernel, parse_category_answer,
                                     parse_mapping)

SUITE = str(Path(__file__).parent / "data" / "lm_dev_suite.yaml")

TRAIN = [ObjectSpec("paintbrush", "a brush for paint"), ObjectSpec("sketchbook", "a book of drawing paper"),
         ObjectSpec("banana", "a yellow fruit"), ObjectSpec("coffee mug", "a cup for hot drinks")]
TEST = [ObjectSpec("crayons", "sticks of colored wax"), ObjectSpec("toothbrush", "a brush for teeth"),
        ObjectSpec("apple", "a round red fruit")]
ART = Intent(text="pack art supplies", source="ground-truth")


class ScriptedLM(LMBackend):
    """Fake LM for control-flow tests: ``answer(messages, seed)`` returns the text; records every call."""

    name = "scripted"
    model = "scripted"
    supports_choice_probabilities = True

    def __init__(self, answer=None, probs=None):
        self.answer, self.probs, self.calls = answer, probs, []

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self.calls.append((list(messages), seed, temperature))
        return Completion(self.answer(messages, seed))

    def choice_probabilities(self, messages, choices):
        self.calls.append((list(messages), None, 0.0))
        return self.probs(messages[-1].content)


class PlainLM(ScriptedLM):
    supports_choice_probabilities = False


def category_json(category: str) -> str:
    """A category answer in the JSON of ``schemas.category_schema``."""
    return json.dumps({"category": category})


def fixed_ladder(breadth: tuple[str, str, str], facets: tuple[str, str, str] | None = None, category: str = "fruit"):
    """A scripted LM's ``answer``: every breadth ladder call names ``breadth`` (narrow, middle, broad), every facet
    call ``facets`` (kind, material, property), every category call ``category``."""
    def answer(messages, seed):
        if messages[0].content == prompts.LADDER_SYSTEM:
            return json.dumps(dict(zip(prompts.LADDER_LEVELS, breadth)))
        if facets is not None and messages[0].content == prompts.FACET_SYSTEM:
            return json.dumps(dict(zip(prompts.FACET_LEVELS, facets)))
        return category_json(category)

    return answer


#: An intent as the 1.5B model infers it from the demonstrations: it names one object, not the class.
PICKED_BANANA = Intent(text="The person wanted to pick up the banana.", source="inferred")

#: P("yes") by category and object for the evidence tests: "brush things" fits the training objects but also
#: says yes to the toothbrush; anything not listed gets 0.3.
BRUSH_YES = {"fruit": {"banana": 0.9, "apple": 0.9},
             "brush things": {"paintbrush": 0.9, "sketchbook": 0.6, "toothbrush": 0.9},
             "art supplies": {"paintbrush": 0.9, "sketchbook": 0.9, "crayons": 0.9}}


def _names_in_order(text: str, key: str) -> list[str]:
    line = next(ln for ln in text.splitlines() if ln.startswith(key))
    return json.loads(line.split(":", 1)[1])


# ----------------------------------------------------------------------------- Call 3 parsing and votes


def test_parse_mapping_normalises_names_and_rejects_unknown_or_missing_objects():
    test, train = ["coffee mug", "TV remote"], ["laptop", "glass vase"]
    assert parse_mapping({"Coffee_Mug": "Glass Vase", "tv remote": "distractor", "ghost": "laptop"}, test, train) \
        == {"coffee mug": "glass vase", "TV remote": DISTRACTOR}
    with pytest.raises(ValidationError, match=r"unknown targets .*'spaceship'"):
        parse_mapping({"coffee mug": "spaceship", "TV remote": "laptop"}, test, train)
    with pytest.raises(ValidationError, match=r"not mapped: \['TV remote'\]"):
        parse_mapping({"coffee mug": "laptop"}, test, train)
    assert issubclass(ValidationError, ValueError)  # so gift_llm's ask_dict turns it into a repair request


def test_gift_kernel_counts_votes_over_shuffled_seeded_samples_and_repairs_bad_answers():
    bad_once = {"done": False}

    def answer(messages, seed):
        if not bad_once["done"]:  # the first answer forgets an object: a repair request must follow
            bad_once["done"] = True
            return '{"crayons": "paintbrush"}'
        target = "paintbrush" if seed % 2 == 0 else "sketchbook"
        return json.dumps({"crayons": target, "toothbrush": "distractor", "apple": "banana"})

    lm = ScriptedLM(answer)
    k = gift.get_kernel("gift", lm=lm, samples=4)
    votes = k.votes(TEST, TRAIN, ART)
    assert votes.counts.sum(axis=1).tolist() == [4, 4, 4]
    K = k.similarity(TEST, TRAIN, ART)
    assert K.shape == (3, 4) and np.all((K >= 0) & (K <= 1))
    assert K[0].tolist() == [0.5, 0.5, 0.0, 0.0] and K[1].sum() == 0.0 and K[2, 2] == 1.0
    assert votes.mode() == {"crayons": "paintbrush", "toothbrush": DISTRACTOR, "apple": "banana"}
    assert votes.agreement() == {"crayons": 0.5, "toothbrush": 1.0, "apple": 1.0}
    # one call per sample (+1 repair on the first), each with its own seed; the intent is in the prompt
    user_msgs = [c[0][1].content for c in lm.calls if len(c[0]) == 2]
    assert len(lm.calls) == 4 + 1 + 4 and k.calls == 8
    assert all("pack art supplies" in m for m in user_msgs)
    assert {c[1] for c in lm.calls} == {0, 1, 2, 3}
    orders = {tuple(_names_in_order(m, "New objects")) for m in user_msgs}
    assert len(orders) > 1 and all(sorted(o) == sorted(t.name for t in TEST) for o in orders)
    assert "did not" in lm.calls[1][0][-1].content or "not mapped" in lm.calls[1][0][-1].content


def test_lm_no_intent_sends_no_intent_and_gift_requires_one():
    lm = ScriptedLM(lambda m, s: json.dumps({t.name: "distractor" for t in TEST}))
    k = NoIntentMappingKernel(lm=lm, samples=2)
    assert not k.uses_intent and k.similarity(TEST, TRAIN, ART).sum() == 0.0
    assert all("pack art supplies" not in c[0][1].content and "No goal" in c[0][1].content for c in lm.calls)
    with pytest.raises(GiftError, match="conditions on an intent"):
        MappingKernel(lm=lm).similarity(TEST, TRAIN, None)
    with pytest.raises(GiftError, match="positive integer"):
        MappingKernel(lm=lm, samples=0)


def test_gift_kernel_gives_up_with_the_raw_answer_after_the_repairs():
    lm = ScriptedLM(lambda m, s: "I think crayons are art.")
    with pytest.raises(LMAnswerError, match="repair") as e:
        MappingKernel(lm=lm, samples=1, max_repairs=1).similarity(TEST, TRAIN, ART)
    assert "crayons are art" in str(e.value) and len(lm.calls) == 2


def test_gift_kernel_keeps_the_valid_part_of_an_answer_still_incomplete_after_the_repairs():
    # the 1.5B model often writes 'none' or leaves objects out, also when asked again
    answer = json.dumps({"crayons": "paintbrush", "toothbrush": "none"})
    lm = ScriptedLM(lambda m, s: answer)
    kernel = MappingKernel(lm=lm, samples=2, max_repairs=1)
    with pytest.warns(RuntimeWarning, match="2 of 3 objects defaulted to 'distractor' after 1 repairs"):
        votes = kernel.votes(TEST, TRAIN, ART)
    assert votes.mode() == {"crayons": "paintbrush", "toothbrush": DISTRACTOR, "apple": DISTRACTOR}
    assert len(lm.calls) == 4 and len(kernel.fallbacks) == 2  # 2 samples x (answer + 1 repair)
    assert kernel.fallbacks[0].startswith("sample 0: 2 of 3 objects")


# ----------------------------------------------------------------------------- gift-prob control flow


NAME_OF = {o.description: o.name for o in (*TRAIN, *TEST)}


def _asked(text):
    """(object name, category) of a yes/no question in either form of ``ask_text``: "Is a <name> (<description>)
    one of the <category>?" or "Is a thing described as "<description>" one of the <category>?"."""
    described = re.search(r'Is a thing described as "(.+?)" one of the (.+?)\?', text)
    if described:
        return NAME_OF[described.group(1)], described.group(2)
    return re.search(r"Is a (.+?) \(.*\) one of the (.+?)\?", text).groups()


def _probs_by_name(table):
    def probs(text):
        name = _asked(text)[0]
        return {"yes": table[name], "no": 1.0 - table[name]}
    return probs


def _probs_by_category(table, default):
    """P(yes) of the question about <object> under <category> from ``table[category][object]``, else ``default``
    (both forms of the question get the same answer)."""
    def probs(text):
        name, cat = _asked(text)
        p = table.get(cat, {}).get(name, default)
        return {"yes": p, "no": 1.0 - p}
    return probs


def test_gift_prob_matrix_rule_log_odds_and_leave_one_out_scores():
    table = {"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2, "coffee mug": 0.1, "crayons": 0.7,
             "toothbrush": 0.4, "apple": 0.05}
    lm = ScriptedLM(answer=lambda m, s: category_json("Art supplies."), probs=_probs_by_name(table))
    k = GiftProbKernel(lm=lm, combine="none", category_from="goal")
    lo = k.log_odds(TEST, ART)
    assert np.allclose(lo, [np.log(0.7 / 0.3), np.log(0.4 / 0.6), np.log(0.05 / 0.95)])
    rs = k.score(TEST, TRAIN, ART, ("paintbrush", "sketchbook"))
    assert np.allclose(rs.relevance, [0.7, 0.4, 0.05])
    assert np.allclose(rs.train_loo, [0.9, 0.8, 0.2, 0.1])  # the same questions of the training objects
    # K: r_i in the relevant columns (given, or the training objects the LM itself calls relevant), 0 elsewhere
    for K in (k.similarity(TEST, TRAIN, ART), rs.K):
        assert np.allclose(K, np.outer([0.7, 0.4, 0.05], [1, 1, 0, 0]))
    n_calls = len(lm.calls)
    k.score(TEST, TRAIN, ART, ("paintbrush", "sketchbook"))
    # each question asked once: the category, then per object the question with its name and the one with its
    # description alone (ask_text="both", the default)
    assert len(lm.calls) == n_calls == k.calls == 1 + 2 * (len(TEST) + len(TRAIN))
    # first the category, once per goal (greedy, few-shot), then the yes/no questions
    first, questions = lm.calls[0], lm.calls[1:]
    assert first[0][0].content == prompts.CATEGORY_SYSTEM and first[2] == 0.0
    assert first[0][-1].content.startswith("Goal: pack art supplies.") and rs.details["category"] == "Art supplies"
    assert all(m[0][0].content == prompts.RELEVANCE_SYSTEM for m in questions)
    assert questions[0][0][1].content.startswith("Is a crayons (sticks of colored wax) one of the Art supplies?")
    assert questions[1][0][1].content.startswith('Is a thing described as "sticks of colored wax" one of the Art')


def test_gift_prob_ask_text_combines_the_name_only_question_with_the_other_forms():
    """ask_text="name": the name alone; "all": the three forms averaged; "both&name": the smaller of the default's
    mean and the name-only log-odds, so a look-alike (a toothbrush described like crayons) must pass its name."""
    p = {"name+description": {"toothbrush": 0.8}, "description": {"toothbrush": 0.9}, "name": {"toothbrush": 0.1}}

    def probs(text):
        m = re.search(r'Is a thing described as "(.+?)" one of', text)
        if m:
            name, form = NAME_OF[m.group(1)], "description"
        else:
            m = re.search(r"Is a (.+?)( \(.*\))? one of the", text)
            name, form = m.group(1), "name+description" if m.group(2) else "name"
        q = p[form].get(name, 0.7 if name == "crayons" else 0.2)
        return {"yes": q, "no": 1.0 - q}

    def lo(q):
        return np.log(q / (1 - q))

    asked = {}
    for ask_text in ("name", "both", "all", "both&name"):
        lm = ScriptedLM(answer=lambda m, s: category_json("Art supplies."), probs=probs)
        k = GiftProbKernel(lm=lm, combine="none", category_from="goal", ask_text=ask_text)
        asked[ask_text] = (k.log_odds(TEST[:2], ART), k.calls)
    # calls: the category, then a question per object and form
    assert np.allclose(asked["name"][0], [lo(0.7), lo(0.1)]) and asked["name"][1] == 1 + 2
    assert np.allclose(asked["both"][0], [lo(0.7), (lo(0.8) + lo(0.9)) / 2]) and asked["both"][1] == 1 + 4
    assert np.allclose(asked["all"][0], [lo(0.7), (lo(0.8) + lo(0.9) + lo(0.1)) / 3]) and asked["all"][1] == 1 + 6
    assert np.allclose(asked["both&name"][0], [lo(0.7), lo(0.1)]) and asked["both&name"][1] == 1 + 6
    assert "Is a crayons one of the Art supplies?" in prompts.relevance_messages(
        TEST[0], ART.text, category="Art supplies", object_text="name")[1].content


def test_gift_prob_names_the_category_from_the_goal_and_the_demonstrated_objects_leaving_each_one_out():
    def answer(messages, seed):  # the category the scripted LM names: from the last question's handled objects
        m = re.search(r"kept clear of them\): (.*)\.\n", messages[-1].content)
        return category_json("drawing books" if m and "paintbrush" not in m.group(1) else "art supplies")

    lm = ScriptedLM(answer=answer, probs=_probs_by_name({"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2,
                                                          "coffee mug": 0.1, "crayons": 0.7, "toothbrush": 0.4,
                                                          "apple": 0.05}))
    k = GiftProbKernel(lm=lm, combine="none")  # category_from="goal+objects" is the default
    intent = Intent(text="The person wanted to pick up the sketchbook.", source="inferred")
    rs = k.score(TEST, TRAIN, intent, ("paintbrush", "sketchbook"))
    assert np.allclose(rs.relevance, [0.7, 0.4, 0.05])
    cats = [c[0][-1].content for c in lm.calls if c[0][0].content == prompts.CATEGORY_SYSTEM]
    # the full question, then one per training object, named without it
    assert len(cats) == 1 + len(TRAIN)
    assert cats[0].startswith("Goal: pick up the sketchbook.\n") and \
        "them): paintbrush, sketchbook.\nObjects it did not concern: banana, coffee mug." in cats[0]
    assert "them): sketchbook.\nObjects it did not concern: banana, coffee mug." in cats[1]
    assert "did not concern: coffee mug." in cats[3] and "did not concern: banana." in cats[4]
    questions = {c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM}
    assert "Is a crayons (sticks of colored wax) one of the art supplies? Answer yes or no." in questions
    assert any(q.startswith("Is a paintbrush (a brush for paint) one of the drawing books?") for q in questions)
    assert rs.details["category"] == "art supplies"  # what the test objects were asked about
    # without demonstrated objects it names the category from the goal alone
    k.score(TEST, TRAIN, ART)
    last_category = [c for c in lm.calls if c[0][0].content == prompts.CATEGORY_SYSTEM][-1]
    assert last_category[0][-1].content == "Goal: pack art supplies.\nWhich objects is this goal about?"
    with pytest.raises(GiftError, match="category_from"):
        GiftProbKernel(category_from="objects")
    with pytest.raises(ValueError, match="handled object"):
        prompts.category_from_objects_messages("pack art supplies", [], ["banana"])


def test_gift_prob_alignment_of_a_scene_asks_only_the_demonstrated_objects_questions_each_once():
    from gift.core.alignment import score_alignment

    lm = ScriptedLM(answer=lambda m, s: category_json("art supplies" if "concerned" in m[-1].content else "art things"),
                    probs=_probs_by_name({"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2, "coffee mug": 0.1,
                                          "crayons": 0.7, "toothbrush": 0.4, "apple": 0.05}))
    k = GiftProbKernel(lm=lm, combine="none")
    sc = score_alignment(k, TEST, TRAIN, ART, relevant_train=("paintbrush", "sketchbook"))
    assert np.allclose(sc.decision, [0.7, 0.4, 0.05])
    asked = [tuple(m.content for m in c[0]) for c in lm.calls]
    assert len(asked) == len(set(asked)) == k.calls  # no question twice
    # no goal-only category: K, the relevance and the leave-one-out scores share one scoring pass
    assert not any(a[-1].endswith("Which objects is this goal about?") for a in asked)
    # 1 + 4 categories (the full one, one without each training object), then two questions (ask_text="both")
    # of each of the 3 test and 4 held-out training objects
    assert len(asked) == 1 + len(TRAIN) + 2 * (len(TEST) + len(TRAIN))
    assert sc.details["category"] == "art supplies"


def test_gift_prob_asks_the_semantic_axes_when_told_and_keeps_the_best_answer():
    intent = Intent(text="pack art supplies", axes=(gift.SemanticAxis("is it used to make art?", ("crayons",)),))

    def probs(text):
        return {"yes": 0.9, "no": 0.1} if text.startswith("is it used to make art?") else {"yes": 0.3, "no": 0.7}

    k = GiftProbKernel(lm=ScriptedLM(probs=probs), template="goal", combine="none", axes=True)
    assert np.allclose(k.log_odds(TEST[:1], intent), [np.log(9)])
    assert np.allclose(GiftProbKernel(lm=ScriptedLM(probs=probs), template="goal", combine="none"
                                      ).log_odds(TEST[:1], intent),
                       [np.log(0.3 / 0.7)])


def test_gift_prob_fails_clearly_without_log_probabilities_or_intent_and_on_bad_options():
    with pytest.raises(GiftError, match="log-probabilities.*scripted:scripted.*'gift' kernel"):
        GiftProbKernel(lm=PlainLM(lambda m, s: "{}"), combine="none").score(TEST, TRAIN, ART)
    with pytest.raises(GiftError, match="conditions on an intent"):
        GiftProbKernel(lm=ScriptedLM(probs=lambda t: {"yes": .5, "no": .5})).score(TEST, TRAIN, None)
    for bad in ({"template": "nope"}, {"combine": "mean"}, {"weight": 2.0}, {"embed_reference": "x"},
                {"standardize": "y"}, {"embed_text": "name"}, {"ask_text": "names"}):
        with pytest.raises(GiftError, match="gift-prob"):
            GiftProbKernel(**bad)
    with pytest.raises(GiftError, match="not training objects"):
        GiftProbKernel(lm=ScriptedLM(answer=lambda m, s: category_json("art supplies"),
                                     probs=lambda t: {"yes": .5, "no": .5}),
                       combine="none").score(TEST, TRAIN, ART, relevant_train=("ghost",))


def test_every_relevance_template_asks_one_yes_no_question_about_the_object():
    obj = gift.ObjectSpec("cheese grater", description="a steel box with rasps")
    for name, template in prompts.RELEVANCE_TEMPLATES.items():
        system, user = prompts.relevance_messages(obj, "keep the mug away from the cheese", name, category="cheeses")
        assert system.role == "system" and user.content.endswith("Answer yes or no.") and "cheese grater" in user.content
        assert ("cheeses" in user.content) == ("{category}" in template)
    kind = prompts.relevance_messages(obj, "keep the mug away from the cheese", "kind", category="cheeses")[1].content
    assert "(a steel box with rasps)" in kind and "itself one of the cheeses" in kind


def test_a_question_on_the_description_alone_never_shows_the_name():
    obj = gift.ObjectSpec("cheese grater", description="A steel box with rasps for shredding hard blocks.")
    for name in prompts.RELEVANCE_TEMPLATES:
        user = prompts.relevance_messages(obj, "keep the mug away from the cheese", name, category="cheeses",
                                          object_text="description")[1].content
        assert "grater" not in user and 'a thing described as "A steel box with rasps for shredding hard blocks"' \
            in user and user.endswith("Answer yes or no."), user
    bare = gift.ObjectSpec("cheese grater")  # no description: the name is all there is to show
    assert "a cheese grater one of the cheeses" in prompts.relevance_messages(
        bare, "g", category="cheeses", object_text="description")[1].content
    with pytest.raises(GiftError, match="object_text must be one of"):
        prompts.relevance_messages(obj, "g", object_text="name only")


def test_ask_text_both_averages_the_log_odds_of_the_named_and_the_described_question():
    def probs(text):  # 0.9 when the question names the object, 0.2 when it shows the description alone
        return {"yes": 0.2, "no": 0.8} if "described as" in text else {"yes": 0.9, "no": 0.1}

    lo = {t: GiftProbKernel(lm=ScriptedLM(lambda m, s: category_json("art supplies"), probs), combine="none",
                            ask_text=t).log_odds(TEST[:2], ART)
          for t in ("name+description", "description", "both")}
    assert np.allclose(lo["name+description"], np.log(9)) and np.allclose(lo["description"], np.log(0.25))
    assert np.allclose(lo["both"], (np.log(9) + np.log(0.25)) / 2)
    assert "ask_text='both'" in repr(GiftProbKernel(ask_text="both"))


def test_goal_text_turns_motivation_sentences_into_goal_clauses():
    assert prompts.goal_text("The human prefers to keep sharp tools away from food.") == \
        "keep sharp tools away from food"
    assert prompts.goal_text("The person wanted to store the pearl necklace in the drawer.") == \
        "store the pearl necklace in the drawer"
    assert prompts.goal_text("The user would like to tidy the desk") == "tidy the desk"
    assert prompts.goal_text("pack art supplies") == "pack art supplies"
    assert prompts.goal_text("People in the room prefer quiet") == "People in the room prefer quiet"


def test_category_answers_are_parsed_or_fall_back_to_the_goal_with_a_warning():
    assert prompts.parse_category('"Electronics."\nThey run on power.') == "Electronics"
    assert prompts.parse_category("Answer: the valuables") == "valuables"
    for bad in ("", "   \n ", "these are all the objects that the goal could possibly be about here"):
        assert prompts.parse_category(bad) is None
    # an answer that is no short noun phrase is asked again once, then the goal stands in
    answers = iter(["", category_json("these are all the objects that the goal could possibly be about here")])
    lm = ScriptedLM(answer=lambda m, s: next(answers), probs=lambda t: {"yes": 0.6, "no": 0.4})
    k = GiftProbKernel(lm=lm, combine="none")
    with pytest.warns(UserWarning, match="no object category.*pack art supplies"):
        k.log_odds(TEST[:1], ART)
    assert 'one of the things the goal "pack art supplies" is about?' in lm.calls[-1][0][1].content
    k.log_odds(TEST[1:], ART)  # the goal's category is asked once (the first answer and one repair)
    asked = [c[0] for c in lm.calls if c[0][0].content == prompts.CATEGORY_SYSTEM]
    assert len(asked) == 2 and "no Python dictionary" in asked[1][-1].content
    assert parse_category_answer({"category": "the Art supplies."}) == {"category": "Art supplies"}


class TableKernel(SimilarityKernel):
    """Scripted stand-in for the MiniLM term: ``K[i, j]`` from a name -> vector table (cosines)."""

    name = "table"

    def __init__(self, vec):
        self.vec = vec

    def similarity(self, test, train, intent=None, relevant_train=()):
        a = np.array([self.vec[o.name] for o in test], float)
        b = np.array([self.vec[o.name] for o in train], float)
        a, b = a / np.linalg.norm(a, axis=1, keepdims=True), b / np.linalg.norm(b, axis=1, keepdims=True)
        return a @ b.T


def test_reliability_weighting_drops_a_term_that_inverts_the_training_labels():
    # the LM term inverts the demonstrated labels (paintbrush/sketchbook low), the language term separates them
    table = {"paintbrush": 0.1, "sketchbook": 0.2, "banana": 0.8, "coffee mug": 0.9, "crayons": 0.3,
             "toothbrush": 0.6, "apple": 0.7}
    vec = {"paintbrush": [1, 0, 0], "sketchbook": [0.9, 0.1, 0], "banana": [0, 1, 0], "coffee mug": [0, 0.2, 1],
           "crayons": [0.95, 0.05, 0], "toothbrush": [0.3, 0.3, 0.6], "apple": [0, 1, 0.1]}
    rel = ("paintbrush", "sketchbook")

    def kernel(weighting):
        return GiftProbKernel(lm=ScriptedLM(answer=lambda m, s: category_json("art supplies"),
                                            probs=_probs_by_name(table)),
                              weighting=weighting, language_kernel=TableKernel(vec), calibration="none")

    k = kernel("reliability")
    rs = k.score(TEST, TRAIN, ART, rel)
    r = rs.relevance
    assert rs.details["weights"] == {"lm": 0.0, "language": 1.0}
    assert r[0] > 0.5 > max(r[1:])  # crayons relevant, the brush for teeth and the fruit not
    assert kernel("equal").score(TEST, TRAIN, ART, rel).details["weights"] == {"lm": 0.5, "language": 0.5}
    # no evidence (no irrelevant training object): the plain weights
    assert k.score(TEST, TRAIN[:2], ART, rel).details["weights"] == {"lm": 0.5, "language": 0.5}
    with pytest.raises(GiftError, match="gift-prob: weighting"):
        GiftProbKernel(weighting="auc")


def test_the_lm_veto_puts_a_look_alike_the_lm_rejects_below_the_cut():
    """veto="lm": the toothbrush here looks like a paintbrush to the MiniLM stand-in but the LM says no; with both
    terms separating the training objects, the veto puts it below the boundary and leaves the other decisions."""
    table = {"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2, "coffee mug": 0.1, "crayons": 0.7,
             "toothbrush": 0.3, "apple": 0.2}
    vec = {"paintbrush": [1, 0, 0], "sketchbook": [0.9, 0.1, 0], "banana": [0, 1, 0], "coffee mug": [0, 0.2, 1],
           "crayons": [0.9, 0.1, 0.1], "toothbrush": [1, 0.02, 0], "apple": [0.1, 1, 0.1]}
    rel = ("paintbrush", "sketchbook")

    def scores(veto, vectors=vec):
        k = GiftProbKernel(lm=ScriptedLM(answer=lambda m, s: category_json("art supplies"),
                                         probs=_probs_by_name(table)),
                           language_kernel=TableKernel(vectors), veto=veto)
        return k.score(TEST, TRAIN, ART, rel)

    plain, vetoed = scores("none"), scores("lm")
    assert plain.details["weights"] == vetoed.details["weights"] == {"lm": 0.5, "language": 0.5}
    assert plain.relevance[1] > 0.5 and vetoed.relevance[1] < 0.5  # the toothbrush, let in without the veto
    assert plain.relevance[0] > 0.5 and vetoed.relevance[0] == pytest.approx(plain.relevance[0])  # crayons kept
    assert vetoed.relevance[2] <= plain.relevance[2] < 0.5  # the apple stays out
    assert "veto='lm'" in repr(GiftProbKernel(veto="lm")) and "veto='none'" in repr(GiftProbKernel())
    # the MiniLM term separates the training objects better than the LM term: no veto
    table["sketchbook"] = 0.15
    assert scores("lm").relevance == pytest.approx(scores("none").relevance)
    with pytest.raises(GiftError, match="gift-prob: veto"):
        GiftProbKernel(veto="always")


def test_the_prototype_reference_prefers_an_object_like_every_member_to_one_like_a_single_member():
    """embed_reference="prototype": the mean cosine to the relevant training objects less the mean to the others
    (``[n]``); the toothbrush, a near copy of the paintbrush alone, outranks the crayons under the nearest-member
    reference and falls below them under the prototype."""
    vec = {"paintbrush": [1, 0, 0, 0], "sketchbook": [0, 1, 0, 0], "banana": [0, 0, 1, 0], "coffee mug": [0, 0, 0, 1],
           "crayons": [0.7, 0.7, 0.1, 0.1], "toothbrush": [1, 0.05, 0.05, 0.05], "apple": [0.1, 0.1, 1, 0.1]}
    rel = np.array([True, True, False, False])

    def emb(reference):
        k = GiftProbKernel(language_kernel=TableKernel(vec), embed_reference=reference)
        return k._embed_scores(TEST, TRAIN, rel, exclude_self=False)

    unit = {n: np.asarray(v, float) / np.linalg.norm(v) for n, v in vec.items()}
    want = [np.mean([unit[t] @ unit[m] for m in ("paintbrush", "sketchbook")])
            - np.mean([unit[t] @ unit[o] for o in ("banana", "coffee mug")])
            for t in ("crayons", "toothbrush", "apple")]
    proto, nearest = emb("prototype"), emb("contrastive")
    assert proto == pytest.approx(want)
    assert nearest[1] > nearest[0] and proto[0] > proto[1] > proto[2]
    # leave-one-out on the training objects (orthonormal here): with its own cosine of 1 left out every one scores
    # 0; counted, it would give the paintbrush and the sketchbook +1/2 and the other two -1/2
    loo = GiftProbKernel(language_kernel=TableKernel(vec), embed_reference="prototype")._embed_scores(
        TRAIN, TRAIN, rel, exclude_self=True)
    assert loo == pytest.approx([0.0, 0.0, 0.0, 0.0])
    assert "embed_reference='prototype'" in repr(GiftProbKernel(embed_reference="prototype"))


def test_gift_prob_gives_the_prior_cut_one_half_with_the_weight_cut_prior():
    """The train-calibrated cut of gift-prob: the leave-one-out cut averaged with 1/2 (cut_prior: its weight;
    by default 1, the scale's boundary alone)."""
    from gift.core.alignment import best_separating_cut, score_alignment

    table = {"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2, "coffee mug": 0.1, "crayons": 0.7,
             "toothbrush": 0.4, "apple": 0.05}
    rel = ("paintbrush", "sketchbook")

    def scores(**opts):
        k = GiftProbKernel(lm=ScriptedLM(answer=lambda m, s: category_json("art supplies"),
                                         probs=_probs_by_name(table)), combine="none", **opts)
        return k.score(TEST, TRAIN, ART, rel), score_alignment(k, TEST, TRAIN, ART, relevant_train=rel,
                                                                 need=("train-calibrated",))

    rs, al = scores()
    assert rs.prior_cut == 0.5 and rs.prior_weight == 1.0 and al.prior_cut == 0.5
    assert al.threshold("train-calibrated")[0] == pytest.approx(0.5)
    loo = best_separating_cut([0.9, 0.8], [0.2, 0.1])
    rs, al = scores(cut_prior=0.5)
    cut, note = al.threshold("train-calibrated")
    assert cut == pytest.approx(0.5 * 0.5 + 0.5 * loo) and "prior cut 0.5 (weight 0.5)" in note
    rs0, al0 = scores(cut_prior=0.0)
    assert rs0.prior_cut is None and al0.threshold("train-calibrated") == (pytest.approx(loo), pytest.approx(
        "leave-one-out over 2 relevant / 2 other training objects"))
    with pytest.raises(GiftError, match="gift-prob: cut_prior must be in"):
        GiftProbKernel(cut_prior=1.5)


# ----------------------------------------------------------------------------- the embedded model


@pytest.fixture(scope="session")
def embedded_lm():
    gift_llm = pytest.importorskip("gift_llm")
    return gift_llm.get_default_lm()


@pytest.mark.slow
def test_gift_prob_on_the_embedded_model_ranks_and_aligns_art_supplies(embedded_lm):
    suite = load_suite(SUITE)
    spec = suite.intent("art_supplies")
    test = suite.specs(["colored pencils", "crayons", "toothbrush", "apple"])
    train = suite.specs(spec.train_objects)
    intent = Intent(text=spec.text, source="ground-truth")
    k = gift.get_kernel("gift-prob", lm=embedded_lm)
    r = k.score(test, train, intent, spec.relevant_train).relevance
    assert r.shape == (4,) and np.all((r > 0) & (r < 1))
    assert min(r[:2]) > max(r[2:]), r  # the art supplies above the brush for teeth and the fruit
    lm_only = GiftProbKernel(lm=embedded_lm, combine="none").log_odds(test, intent)
    assert lm_only[:2].mean() > lm_only[2:].mean()
    op = gift.get_alignment_operator("argmax-threshold", threshold="train-calibrated")
    al = op.align(k, test, train, intent, relevant_train=spec.relevant_train)
    assert al.target("colored pencils") in spec.relevant_train and al.target("apple") not in spec.relevant_train


@pytest.mark.slow
def test_gift_prob_default_on_the_embedded_model_names_each_goals_category_and_ranks_every_dev_intent(embedded_lm):
    """The default recipe on every dev-suite intent: a category per goal, then a ranking of test objects."""
    from gift.core.metrics import roc_auc

    suite = load_suite(SUITE)
    k = gift.get_kernel("gift-prob", lm=embedded_lm)
    aucs, cats = {}, {}
    for spec in suite.intents:
        intent = Intent(text=spec.text, source="ground-truth")
        test, train = suite.specs(spec.test_objects), suite.specs(spec.train_objects)
        rs = k.score(test, train, intent, spec.relevant_train)
        r, weights = rs.relevance, rs.details["weights"]
        assert r.shape == (len(test),) and np.all((r > 0) & (r < 1))
        assert sum(weights.values()) == pytest.approx(1.0) and min(weights.values()) >= 0
        aucs[spec.id] = roc_auc(r, [o.name in spec.relevant_test for o in test])
        cats[spec.text] = rs.details["category"].lower()
    assert len(cats) == len(aucs)  # the category each goal's test objects were asked about
    assert "electronic" in cats["keep the coffee away from electronics"]
    assert "art" in cats["pack art supplies"] and "sharp" in cats["put sharp tools away in the drawer"]
    assert all(len(c.split()) <= 6 for c in cats.values()), cats  # a short noun phrase, not a sentence
    # measured: 0.88 to 1.00 per intent (mean 0.95); the pre-category recipe gave a mean of 0.81
    assert min(aucs.values()) >= 0.75 and np.mean(list(aucs.values())) >= 0.9, aucs


@pytest.mark.slow
def test_gift_prob_on_the_embedded_model_recovers_the_category_of_an_object_bound_inferred_intent(embedded_lm):
    """Call 1 of the 1.5B model often names one demonstrated object; the demonstrated objects give the class.

    gift-dev's leather_goods (a development suite) with a goal naming one of its two relevant training objects,
    as Call 1 writes them. Measured with the category examples chosen on gift-dev: the category named from
    the goal alone is about the belt; with the objects it is "leather items" (LM-only test AUC 0.98)."""
    from gift.core.metrics import roc_auc

    suite = load_suite("gift-dev")
    spec = suite.intent("leather_goods")  # relevant training objects: leather wallet, leather belt
    test, train = suite.specs(spec.test_objects), suite.specs(spec.train_objects)
    labels = [t.relevant for t in spec.test]
    intent = Intent(text="sweep the leather belt away from the spill", source="inferred")
    auc, cats = {}, {}
    for source in ("goal", "goal+objects"):
        rs = GiftProbKernel(lm=embedded_lm, category_from=source, combine="none", ladder="never").score(
            test, train, intent, spec.relevant_train)  # the goal's category alone, without the ladder
        auc[source], cats[source] = roc_auc(rs.relevance, labels), rs.details["category"].lower()
    assert "leather" in cats["goal+objects"] and "belt" not in cats["goal+objects"], cats
    assert auc["goal+objects"] >= 0.9 and auc["goal+objects"] >= auc["goal"], (auc, cats)


@pytest.mark.slow
def test_gift_prob_ladder_on_the_embedded_model_names_the_class_a_generic_inferred_goal_misses(embedded_lm):
    """lm-dev's protect_electronics (a development suite) with the generic goal Call 1 of the 1.5B model wrote
    for it. Measured (docs/results/front_half.md): the goal's category ("objects to carry") ranks the test
    objects at LM-only AUC 0.64; the ladder's rungs, named from the laptop and the phone, at 0.96. The
    ladder's rungs (three breadths and the facets that are not "none" or a repeat) also come back as intent
    candidates for the questions of gift.core.queries."""
    from gift.core.alignment import score_alignment
    from gift.core.metrics import roc_auc
    from gift.core.queries import QueryProblem

    suite = load_suite(SUITE)
    spec = suite.intent("protect_electronics")
    test, train = suite.specs(spec.test_objects), suite.specs(spec.train_objects)
    labels = [t.relevant for t in spec.test]
    intent = Intent(text="The person wanted to carry the mug to the goal spot as quickly as possible.",
                    source="inferred")
    plain = GiftProbKernel(lm=embedded_lm, combine="none", ladder="never").score(test, train, intent,
                                                                               spec.relevant_train)
    k = GiftProbKernel(lm=embedded_lm)  # the default: the ladder for an inferred intent
    sc = score_alignment(k, test, train, intent, relevant_train=spec.relevant_train)
    rungs = [c.lower() for c in sc.details["ladder"]["categories"]]
    assert 2 <= len(rungs) <= 6 and not any(o in c for c in rungs for o in ("laptop", "phone")), rungs
    assert any(w in " ".join(rungs) for w in ("electronic", "digital", "device", "comput", "gadget")), rungs
    lm_ladder = np.asarray(sc.details["terms"]["lm"]["test"])
    assert roc_auc(lm_ladder, labels) >= 0.85 and roc_auc(lm_ladder, labels) > roc_auc(plain.relevance, labels) + 0.1
    problem = QueryProblem.of(sc)
    assert len(problem.candidates) == 2 + len(rungs)  # the averaged kernel, the goal's category, each rung
    assert any(name.startswith("rung 1: ") for name in problem.candidates)


@pytest.mark.slow
def test_gift_and_lm_no_intent_on_the_embedded_model_map_every_object_within_the_call_budget(embedded_lm):
    test = [ObjectSpec("crayons", "sticks of colored wax"), ObjectSpec("apple", "a round red fruit")]
    k = MappingKernel(lm=embedded_lm, samples=2)
    votes = k.votes(test, TRAIN, ART)
    assert votes.counts.sum(axis=1).tolist() == [2, 2]  # every object mapped in every sample
    assert k.calls == 2  # one call per sample, whatever the number of objects
    K = k.similarity(test, TRAIN, ART)  # served from the LM cache: same seeds, same prompts
    assert K.shape == (2, 4) and np.all(np.isin(K, [0.0, 0.5, 1.0]))
    k0 = gift.get_kernel("lm-no-intent", lm=embedded_lm, samples=1)
    assert k0.similarity(test, TRAIN, ART).shape == (2, 4) and k0.calls == 1


def test_gift_prob_candidates_are_verified_on_the_training_objects_and_only_the_chosen_one_asks_the_test_objects():
    """candidates="all": the intent's text, its other motivations and the objects alone each name a category;
    the one whose leave-one-out log-odds separate the demonstrated objects best names the test questions."""
    def answer(messages, seed):
        q = messages[-1].content
        if q.startswith("Goal: pick up the sketchbook"):
            return category_json("sketchbooks")
        if q.startswith("Goal: tidy the table"):
            return category_json("table things")
        return category_json("art supplies")  # from the objects alone

    yes = {("sketchbooks", "sketchbook"): 0.9, ("sketchbooks", "paintbrush"): 0.2,
           ("table things", "banana"): 0.8, ("table things", "coffee mug"): 0.8,
           ("art supplies", "paintbrush"): 0.9, ("art supplies", "sketchbook"): 0.8, ("art supplies", "crayons"): 0.85}

    def probs(text):
        name, cat = _asked(text)
        p = yes.get((cat, name), 0.1)
        return {"yes": p, "no": 1.0 - p}

    lm = ScriptedLM(answer=answer, probs=probs)
    intent = Intent(text="The person wanted to pick up the sketchbook.", source="inferred",
                    motivations=(gift.Motivation("The person wanted to pick up the sketchbook."),
                                 gift.Motivation("The person wanted to tidy the table.")))
    k = GiftProbKernel(lm=lm, combine="none", candidates="all", select="margin")
    assert k.candidate_goals(intent, ("paintbrush", "sketchbook")) == [intent.text, "The person wanted to tidy the table.",
                                                                        None]
    rs = k.score(TEST, TRAIN, intent, ("paintbrush", "sketchbook"))
    cands = {c["category"]: c for c in rs.details["candidates"]}
    assert set(cands) == {"sketchbooks", "table things", "art supplies"}
    assert cands["art supplies"]["chosen"] and cands["art supplies"]["auc"] == 1.0
    assert cands["table things"]["auc"] == 0.0  # inverts the demonstrated objects
    # the goal naming one member separates them too, by a smaller margin: the objects' category wins the tie
    assert cands["sketchbooks"]["auc"] == 1.0 and cands["sketchbooks"]["margin"] < cands["art supplies"]["margin"]
    assert rs.details["category"] == "art supplies" and rs.details["goal"] is None
    assert np.allclose(rs.relevance, [0.85, 0.1, 0.1])
    asked = [c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM]
    test_questions = [q for q in asked if any(f"Is a {o.name} (" in q for o in TEST)]
    assert len(test_questions) == len(TEST) and all("art supplies" in q for q in test_questions)
    # the objects-only category question carries no goal line
    objects_only = [c[0][-1].content for c in lm.calls
                    if c[0][0].content == prompts.CATEGORY_SYSTEM and not c[0][-1].content.startswith("Goal:")]
    assert objects_only and objects_only[0].endswith("Which kind of objects is the goal about?")
    with pytest.raises(GiftError, match="candidates"):
        GiftProbKernel(candidates="some")
    # select="first" (the default): the first candidate with the best AUC, in order: here the intent's text
    lm.calls.clear()
    first = GiftProbKernel(lm=lm, combine="none", candidates="all").score(TEST, TRAIN, intent, ("paintbrush",
                                                                                              "sketchbook"))
    assert first.details["category"] == "sketchbooks" and first.details["candidates"][0]["chosen"]


def test_gift_prob_ladder_averages_the_goals_category_with_rungs_named_from_the_objects_leaving_each_one_out():
    """ladder="inferred": for an inferred intent the LM names three rungs (narrow to broad) of what the
    demonstrated objects share, one ladder per training object without it; the LM term is the mean of the
    z-scored log-odds under the goal's category and each rung. A stated intent is scored as before."""
    def answer(messages, seed):
        if messages[0].content == prompts.LADDER_SYSTEM:
            q = messages[-1].content
            if "specially: sketchbook.\n" in q:
                return json.dumps({"narrow": "drawing books", "middle": "paper goods", "broad": "Paper goods."})
            return json.dumps({"narrow": "painting tools", "middle": "art supplies", "broad": "creative things"})
        return category_json("fruit")

    yes = {"fruit": {"banana": 0.9, "apple": 0.9}, "art supplies": {"paintbrush": 0.9, "sketchbook": 0.9, "crayons": 0.9},
           "creative things": {"paintbrush": 0.8, "sketchbook": 0.8, "crayons": 0.8}}

    lm = ScriptedLM(answer=answer, probs=_probs_by_category(yes, 0.3))
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, combine="none", ladder="inferred", rungs="breadth")
    rs = k.score(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"))
    assert rs.details["ladder"]["categories"] == ["painting tools", "art supplies", "creative things"]
    ladders = [c[0][-1].content for c in lm.calls if c[0][0].content == prompts.LADDER_SYSTEM]
    assert len(ladders) == 1 + len(TRAIN)  # the full ladder, then one without each training object
    assert ladders[0].startswith("Objects the person treated specially: paintbrush, sketchbook.\n"
                                 "Objects they treated like any other: banana, coffee mug.")
    # the paintbrush's rungs are named without it; a repeated name ("paper goods" twice) is dropped, and its
    # missing third rung repeats the last one
    assert k.ladder(["sketchbook"], ["banana", "coffee mug"]) == ("drawing books", "paper goods")
    asked = {c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM}
    assert any(q.startswith("Is a paintbrush (a brush for paint) one of the paper goods?") for q in asked)
    # the goal's category ranks the banana first; the rungs outvote it: crayons first, apple below
    order = np.argsort(-rs.relevance)
    assert TEST[order[0]].name == "crayons" and rs.relevance[2] < rs.relevance[0]
    lo = [np.array(t["test"] + t["train"]) for t in rs.details["ladder"]["terms"]]
    assert len(lo) == 3 and np.allclose(lo[1][:3], np.log(np.array([0.9, 0.3, 0.3]) / np.array([0.1, 0.7, 0.7])))
    # a stated intent: no ladder; ladder="always" asks it for a stated intent too; bad option named
    stated = GiftProbKernel(lm=lm, combine="none", ladder="inferred").score(TEST, TRAIN, ART, ("paintbrush", "sketchbook"))
    assert "ladder" not in stated.details
    assert "ladder" in GiftProbKernel(lm=lm, combine="none", ladder="always", rungs="breadth").score(
        TEST, TRAIN, ART, ("paintbrush", "sketchbook")).details
    with pytest.raises(GiftError, match="ladder"):
        GiftProbKernel(ladder="sometimes")
    with pytest.raises(GiftError, match="calibration"):
        GiftProbKernel(ladder="inferred", calibration="pooled")
    # the default: the ladder for inferred intents, none with a calibration (fitted on one category's log-odds)
    assert GiftProbKernel().ladder_mode == "inferred" and GiftProbKernel(calibration="pooled").ladder_mode == "never"
    assert GiftProbKernel().rungs == "both"  # breadth and facets (front_half.md, section 11)
    with pytest.raises(ValueError, match="handled object"):
        prompts.ladder_messages([], ["banana"])


def test_gift_prob_asks_a_scenes_questions_object_by_object_with_the_scores_of_asking_them_category_by_category():
    """score() first collects the scene's yes/no questions (no LM call for them), then asks them grouped by
    object: each question carries a cut hint ending before its category, and the questions sharing the text
    before it are asked one after another, each once. The scores are those of asking category by category."""
    answer = fixed_ladder(("painting tools", "art supplies", "creative things"))

    yes = {"fruit": {"banana": 0.9, "apple": 0.9}, "art supplies": {"paintbrush": 0.9, "sketchbook": 0.9, "crayons": 0.8},
           "creative things": {"paintbrush": 0.8, "sketchbook": 0.7, "crayons": 0.8}}
    inferred = PICKED_BANANA

    def run(by_object: bool):
        lm = ScriptedLM(answer=answer, probs=_probs_by_category(yes, 0.3))
        k = GiftProbKernel(lm=lm, combine="none", rungs="breadth")
        if not by_object:
            k._in_object_order = lambda run: None  # the order before: category by category
        rs = k.score(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"))
        asked = [c[0][-1] for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM]
        return rs, asked

    rs, asked = run(True)
    before, asked_before = run(False)
    assert len({m.content for m in asked}) == len(asked) == len(asked_before)  # each question once, no extra
    assert sorted(m.content for m in asked) == sorted(m.content for m in asked_before)
    for m in asked:  # the hint ends right before the category, after the object as shown
        assert m.cut > 0 and m.content[: m.cut].startswith("Is a ") and m.content[: m.cut].endswith(" one of the ")
    heads = [m.content[: m.cut] for m in asked]
    runs = [h for i, h in enumerate(heads) if i == 0 or heads[i - 1] != h]
    assert len(runs) == len(set(heads)) < len(heads)  # one run of questions per object (as shown)
    heads_before = [m.content[: m.cut] for m in asked_before]
    assert len([h for i, h in enumerate(heads_before) if i == 0 or heads_before[i - 1] != h]) > len(runs)
    np.testing.assert_array_equal(rs.relevance, before.relevance)
    np.testing.assert_array_equal(rs.train_loo, before.train_loo)
    assert rs.details == before.details


def test_gift_prob_ladder_that_names_nothing_warns_and_keeps_the_goals_category():
    """A ladder answer with no usable name (after the repairs) is no rung: a warning names the objects, and the
    scene is scored under the goal's category alone, as without the ladder."""
    def answer(messages, seed):
        if messages[0].content == prompts.LADDER_SYSTEM:
            return "I cannot tell."
        return category_json("art supplies")

    lm = ScriptedLM(answer=answer, probs=_probs_by_name({"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2,
                                                          "coffee mug": 0.1, "crayons": 0.7, "toothbrush": 0.4,
                                                          "apple": 0.05}))
    inferred = Intent(text="The person wanted to pick up the sketchbook.", source="inferred")
    with pytest.warns(UserWarning, match="no category ladder for paintbrush, sketchbook"):
        rs = GiftProbKernel(lm=lm, combine="none", ladder="inferred").score(TEST, TRAIN, inferred,
                                                                            ("paintbrush", "sketchbook"))
    plain = GiftProbKernel(lm=lm, combine="none").score(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"))
    assert "ladder" not in rs.details and np.allclose(rs.relevance, plain.relevance)


def test_few_shot_examples_share_no_object_and_no_kind_of_goal_with_any_shipped_suite():
    """The category prompts' worked examples: none of their objects is in a suite catalog, and no word of
    their goals and categories is a content word of a suite's goal (beyond function words and generic nouns
    such as "supplies")."""
    from gift.plugins.manager import get_manager

    suites = [load_suite(s) for s in get_manager().suites()] + [load_suite(SUITE)]
    objects = {o.lower() for s in suites for o in s.objects}
    stop = {"the", "things", "thing", "and", "with", "from", "to", "of", "a", "an", "for", "anything", "away",
            "put", "keep", "pack", "store", "get", "in", "on", "it", "that", "would", "if",
            "supplies", "items", "objects", "goods"}  # generic nouns of a kind, not a kind themselves
    goal_words = {w for s in suites for i in s.intents for w in re.findall(r"[a-z]+", i.text.lower())} - stop
    examples = [(g, h + a, c) for g, h, a, c in prompts.CATEGORY_EXAMPLES_WITH_OBJECTS]
    examples += [(g, (), c) for g, c in prompts.CATEGORY_EXAMPLES]
    examples += [("", h + a, " ".join(names)) for h, a, names in prompts.LADDER_EXAMPLES]
    examples += [("", h + a, " ".join(names)) for h, a, names in prompts.FACET_EXAMPLES]
    examples += [("", h + a, " ".join(names)) for h, a, names in prompts.PART_EXAMPLES]
    for goal, objs, category in examples:
        assert not {o.lower() for o in objs} & objects, objs
        words = set(re.findall(r"[a-z]+", f"{goal} {category}".lower())) - stop
        assert not words & goal_words, (goal, words & goal_words)


@pytest.mark.parametrize("ladder_text", ["name", "name+description"])
def test_gift_prob_ladder_shows_the_training_objects_descriptions_only_with_ladder_text(ladder_text):
    """ladder_text="name+description": every ladder question (the full ladder and each leave-one-out one, both
    kinds of rungs) shows each training object as "name (description)", the worked examples with theirs;
    the default shows names alone, as before."""
    answer = fixed_ladder(("art supplies", "drawing things", "hobby things"), ("art tools", "none", "none"))

    lm = ScriptedLM(answer=answer, probs=lambda text: {"yes": 0.6, "no": 0.4})
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, combine="none", ladder_text=ladder_text)
    k.score(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"))
    ladder_calls = [c[0] for c in lm.calls if c[0][0].content in (prompts.LADDER_SYSTEM, prompts.FACET_SYSTEM)]
    assert len(ladder_calls) == 2 * (1 + len(TRAIN))  # both kinds: the full ladder and one per training object
    described = ladder_text == "name+description"
    for msgs in ladder_calls:
        question = msgs[-1].content
        assert ("paintbrush (a brush for paint)" in question) == (described and "paintbrush" in question)
        assert ("(" in question) == described
        assert ("coffee mug (a cup for hot drinks)" in question) == (described and "coffee mug" in question)
        assert ("aquarium net (A small square of fine green mesh" in msgs[1].content) == described
    full = next(m[-1].content for m in ladder_calls if "sketchbook" in m[-1].content and "paintbrush" in m[-1].content
                and "banana" in m[-1].content)
    assert full.startswith("Objects the person treated specially: paintbrush (a brush for paint); sketchbook (a book "
                           "of drawing paper).\n") == described
    with pytest.raises(GiftError, match="ladder_text"):
        GiftProbKernel(lm=lm, ladder_text="description")


def test_gift_prob_faceted_ladder_drops_none_and_matches_each_training_objects_rungs_by_facet():
    """rungs="facets": the LM names the kind, the material and a property the demonstrated objects share;
    "none" is no rung, and a training object's own ladder (named without it) is matched to the full one by
    facet, the full ladder's name standing in where its own names none."""
    def answer(messages, seed):
        assert messages[0].content != prompts.LADDER_SYSTEM  # the breadth prompt is not asked
        if messages[0].content == prompts.FACET_SYSTEM:
            if "specially: sketchbook.\n" in messages[-1].content:
                return json.dumps({"kind": "drawing books", "material": "N/A", "property": "paper goods"})
            return json.dumps({"kind": "art supplies", "material": "none", "property": "things that stain"})
        return category_json("fruit")

    lm = ScriptedLM(answer=answer, probs=lambda text: {"yes": 0.6, "no": 0.4})
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, combine="none", rungs="facets")
    rs = k.score(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"))
    assert rs.details["ladder"]["categories"] == ["art supplies", "things that stain"]
    assert k.ladder(["sketchbook"], ["banana", "coffee mug"]) == ("drawing books", "paper goods")
    asked = {c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM}
    # the paintbrush (left out) is asked about its own kind and property; the test objects about the full ones
    assert any(q.startswith("Is a paintbrush (a brush for paint) one of the drawing books?") for q in asked)
    assert any(q.startswith("Is a paintbrush (a brush for paint) one of the paper goods?") for q in asked)
    assert any(q.startswith("Is a crayons (") and "one of the things that stain?" in q for q in asked)
    assert not any("one of the none?" in q or "one of the N/A?" in q for q in asked)
    assert prompts.is_no_name("None") and prompts.is_no_name("no material") and not prompts.is_no_name("nonstick pans")
    with pytest.raises(GiftError, match="rungs"):
        GiftProbKernel(rungs="depth")
    with pytest.raises(ValueError, match="handled object"):
        prompts.facet_messages([], ["banana"])


def test_gift_prob_both_ladders_average_the_breadth_and_the_facet_rungs_without_repeats():
    """rungs="both": one breadth and one facet call per ladder; their rungs, a name given twice once."""
    answer = fixed_ladder(("painting tools", "art supplies", "creative things"),
                          ("Art supplies", "none", "things that stain"))

    lm = ScriptedLM(answer=answer, probs=lambda text: {"yes": 0.6, "no": 0.4})
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, combine="none", rungs="both")
    rs = k.score(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"))
    assert rs.details["ladder"]["categories"] == ["painting tools", "art supplies", "creative things",
                                                  "things that stain"]
    assert len(rs.details["ladder"]["terms"]) == 4
    systems = [c[0][0].content for c in lm.calls]
    assert systems.count(prompts.LADDER_SYSTEM) == systems.count(prompts.FACET_SYSTEM) == 1 + len(TRAIN)


def test_gift_prob_all_rungs_add_a_part_the_demonstrated_objects_have_from_a_third_call():
    """rungs="all": besides the breadth and the facet calls, one part call per ladder ("things with ..."); its
    name is one more rung, asked of the test objects and, named without each, of the training objects."""
    base = fixed_ladder(("painting tools", "art supplies", "creative things"), ("none", "none", "things that stain"))

    def answer(messages, seed):
        if messages[0].content == prompts.PART_SYSTEM:
            assert "What do the specially treated objects have in common?" in messages[-1].content
            return json.dumps({"part": "things with a handle" if "paintbrush" in messages[-1].content else "none"})
        return base(messages, seed)

    lm = ScriptedLM(answer=answer, probs=lambda text: {"yes": 0.6, "no": 0.4})
    k = GiftProbKernel(lm=lm, combine="none", rungs="all")
    rs = k.score(TEST, TRAIN, PICKED_BANANA, ("paintbrush", "sketchbook"))
    assert rs.details["ladder"]["categories"] == ["painting tools", "art supplies", "creative things",
                                                  "things that stain", "things with a handle"]
    systems = [c[0][0].content for c in lm.calls]
    assert systems.count(prompts.PART_SYSTEM) == systems.count(prompts.FACET_SYSTEM) == 1 + len(TRAIN)
    asked = {c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM}
    assert any(q.startswith("Is a crayons (") and "one of the things with a handle?" in q for q in asked)
    # the paintbrush named without it: its sketchbook-only part call says "none", so the full ladder's part stands in
    assert any(q.startswith("Is a paintbrush (a brush for paint) one of the things with a handle?") for q in asked)
    assert k.ladder(["sketchbook"], ["banana", "coffee mug"]) == ("painting tools", "art supplies",
                                                                  "creative things", "things that stain")
    with pytest.raises(ValueError, match="handled object"):
        prompts.part_messages([], ["banana"])


@pytest.mark.parametrize("check", ["fit", "weight", "margin", "fit-best"])
def test_gift_prob_check_weighs_each_category_by_how_it_separates_the_training_objects_it_was_named_from(check):
    """check="fit" / "weight" / "margin" / "fit-best": the goal's category and every rung are asked of the
    training objects as named (in-sample); a category whose answers invert the demonstrated objects (the goal's
    "fruit") gets no weight, "fit" keeps only the categories that put every demonstrated object above every
    left-alone one, "weight" weighs each by AUC - 1/2, "margin" weighs those "fit" keeps by the log-odds gap
    between the lowest demonstrated object and the highest left-alone one, "fit-best" keeps the widest gap
    alone. The LM term is the weighted mean of the z-scored log-odds."""
    answer = fixed_ladder(("painting tools", "art supplies", "creative things"))

    yes = {"fruit": {"banana": 0.9, "apple": 0.9}, "painting tools": {"paintbrush": 0.9},
           "art supplies": {"paintbrush": 0.9, "sketchbook": 0.9, "crayons": 0.9},
           "creative things": {"paintbrush": 0.8, "sketchbook": 0.7, "crayons": 0.6}}

    lm = ScriptedLM(answer=answer, probs=_probs_by_category(yes, 0.3))
    inferred = PICKED_BANANA
    rs = GiftProbKernel(lm=lm, combine="none", rungs="breadth", check=check).score(TEST, TRAIN, inferred,
                                                                                  ("paintbrush", "sketchbook"))
    lad = rs.details["ladder"]
    # in-sample AUC on the training objects: fruit ranks the banana first, painting tools ties the sketchbook with
    # the left-alone objects
    assert lad["check"]["in_sample_auc"] == [0.25, 0.75, 1.0, 1.0]
    logit = lambda p: np.log(p / (1 - p))  # noqa: E731
    gaps = [logit(0.9) - logit(0.3), logit(0.7) - logit(0.3)]  # art supplies, creative things
    assert np.allclose(lad["check"]["margin"][2:], gaps)
    assert lad["check"]["margin"][0] < 0 and lad["check"]["margin"][1] == 0.0  # the sketchbook ties at 0.3
    expected = {"fit": [0.0, 0.0, 0.5, 0.5], "weight": [0.0, 0.25 / 1.25, 0.5 / 1.25, 0.5 / 1.25],
                "margin": [0.0, 0.0, gaps[0] / sum(gaps), gaps[1] / sum(gaps)], "fit-best": [0.0, 0.0, 1.0, 0.0]}[check]
    assert np.allclose(lad["check"]["weights"], expected)
    views = [np.asarray(lad["goal"])] + [np.asarray(t["test"] + t["train"]) for t in lad["terms"]]
    z = [(v - v.mean()) / v.std() for v in views]
    lo = sum(w * v for w, v in zip(expected, z))
    assert np.allclose(rs.relevance, 1.0 / (1.0 + np.exp(-lo[: len(TEST)])))
    # the full rungs were asked of the training objects (the paintbrush's own rungs are named without it)
    asked = {c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM}
    assert any(q.startswith("Is a paintbrush (a brush for paint) one of the painting tools?") for q in asked)
    assert GiftProbKernel().check == "fit"  # the default (front_half.md, section 14)
    with pytest.raises(GiftError, match="check"):
        GiftProbKernel(check="vote")


def test_gift_prob_answers_re_weigh_the_re_named_rungs_by_the_same_check():
    """score_with_answers with check="fit": the rungs named again with the answered test objects are weighed
    exactly as in score (the goal's inverted "fruit" gets no weight), and the check is recorded."""
    def answer(messages, seed):
        if messages[0].content == prompts.LADDER_SYSTEM:
            if "crayons" in messages[-1].content:  # named again with the answer "crayons: yes"
                return json.dumps({"narrow": "coloring tools", "middle": "art supplies", "broad": "none"})
            return json.dumps({"narrow": "painting tools", "middle": "art supplies", "broad": "creative things"})
        return category_json("fruit")

    yes = {"fruit": {"banana": 0.9, "apple": 0.9}, "painting tools": {"paintbrush": 0.9},
           "coloring tools": {"paintbrush": 0.8, "crayons": 0.9, "sketchbook": 0.4},
           "art supplies": {"paintbrush": 0.9, "sketchbook": 0.9, "crayons": 0.9},
           "creative things": {"paintbrush": 0.8, "sketchbook": 0.7, "crayons": 0.6}}
    lm = ScriptedLM(answer=answer, probs=_probs_by_category(yes, 0.3))
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, combine="none", rungs="breadth", check="fit", rescore_with="ladder")
    rs = k.score_with_answers(TEST, TRAIN, inferred, ("paintbrush", "sketchbook"), {"crayons": True})
    lad = rs.details["ladder"]
    assert lad["categories"] == ["coloring tools", "art supplies"]
    # in-sample AUC of fruit, coloring tools, art supplies on the training objects (paintbrush, sketchbook relevant)
    assert lad["check"]["in_sample_auc"] == [0.25, 1.0, 1.0]
    assert np.allclose(lad["check"]["weights"], [0.0, 0.5, 0.5])
    views = [np.asarray(lad["goal"])] + [np.asarray(t["test"] + t["train"]) for t in lad["terms"]]
    z = [(v - v.mean()) / v.std() for v in views]
    lo = 0.5 * z[1] + 0.5 * z[2]
    assert np.allclose(rs.relevance, 1.0 / (1.0 + np.exp(-lo[: len(TEST)])))


def test_gift_prob_answers_as_evidence_drop_a_category_that_ranks_an_answered_no_high_without_lm_calls():
    """rescore_with="evidence": no LM call; the answered test objects join the training objects in the check,
    so a rung that fits the training objects but puts the toothbrush (answered "no") with them is dropped."""
    answer, yes = fixed_ladder(("brush things", "art supplies", "none")), BRUSH_YES
    lm = ScriptedLM(answer=answer, probs=_probs_by_category(yes, 0.3))
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, combine="none", rungs="breadth", check="fit", rescore_with="evidence")
    rel = ("paintbrush", "sketchbook")
    base = k.score(TEST, TRAIN, inferred, rel)
    assert base.details["ladder"]["check"]["in_sample_auc"] == [0.25, 1.0, 1.0]
    assert np.allclose(base.details["ladder"]["check"]["weights"], [0.0, 0.5, 0.5])
    n_calls = len(lm.calls)
    rs = k.score_with_answers(TEST, TRAIN, inferred, rel, {"toothbrush": False})
    assert len(lm.calls) == n_calls  # nothing new asked
    assert rs.details["evidence"] == {"yes": [], "no": ["toothbrush"]}
    check = rs.details["ladder"]["check"]
    # brush things: paintbrush ties the toothbrush, the sketchbook is under it -> AUC (2 + 2 + 0.5) / 6
    assert check["in_sample_auc"][1] == pytest.approx(0.75) and check["in_sample_auc"][2] == 1.0
    assert np.allclose(check["weights"], [0.0, 0.0, 1.0])
    art = np.asarray(rs.details["ladder"]["terms"][1]["test"] + rs.details["ladder"]["terms"][1]["train"])
    z = (art - art.mean()) / art.std()
    assert np.allclose(rs.relevance, 1.0 / (1.0 + np.exp(-z[: len(TEST)])))
    assert k.score_with_answers(TEST, TRAIN, inferred, rel, {}) is None
    with pytest.raises(GiftError, match="rescore_with"):
        GiftProbKernel(rescore_with="again")


def test_gift_prob_answers_as_evidence_weigh_the_ladders_views_too():
    """After answers as evidence, the scene under each category alone (the intent candidates answers can pick)
    is combined with the MiniLM term under the same weights as the kernel's own score: the answered objects
    count in them."""
    answer, yes = fixed_ladder(("brush things", "art supplies", "none")), BRUSH_YES
    vec = {"paintbrush": [1, 0, 0], "sketchbook": [0.9, 0.1, 0], "banana": [0, 1, 0], "coffee mug": [0, 0.2, 1],
           "crayons": [0.95, 0.05, 0], "toothbrush": [0.2, 0, 0.9], "apple": [0, 1, 0.1]}
    lm = ScriptedLM(answer=answer, probs=_probs_by_category(yes, 0.3))
    inferred = PICKED_BANANA
    k = GiftProbKernel(lm=lm, language_kernel=TableKernel(vec), rungs="breadth", rescore_with="evidence")
    rel = ("paintbrush", "sketchbook")
    k.score(TEST, TRAIN, inferred, rel)
    rs = k.score_with_answers(TEST, TRAIN, inferred, rel, {"toothbrush": False, "crayons": True})
    emb = np.asarray(rs.details["terms"]["language"]["test"] + rs.details["terms"]["language"]["train"])
    relv = np.asarray(rs.relevant, dtype=bool)
    evidence = (np.array([0, 1]), np.array([True, False]))  # crayons "yes", toothbrush "no", in test order
    views = {c["name"]: np.asarray(c["relevance"]) for c in rs.details["candidates"]}
    brush = rs.details["ladder"]["terms"][0]
    lo = np.asarray(brush["test"] + brush["train"])
    want, w = k._combine(lo, emb, relv, len(TEST), evidence=evidence)
    assert np.allclose(views["rung 1: brush things"], 1.0 / (1.0 + np.exp(-want[: len(TEST)])))
    without, w0 = k._combine(lo, emb, relv, len(TEST))
    # the crayons (answered "yes") sit beside the paintbrush for MiniLM but not for the LM under "brush things":
    # MiniLM's weight in this view rises, and the view moves
    assert w["language"] > w0["language"] and not np.allclose(want, without)


def test_gift_prob_answers_as_evidence_are_references_of_the_minilm_term_and_weigh_the_terms():
    """rescore_with="evidence" with the MiniLM term (true intent, no ladder): an object answered "no" is a
    reference of the left-alone side (never its own), and the answered objects count in the reliability weights."""
    table = {"paintbrush": 0.9, "sketchbook": 0.8, "banana": 0.2, "coffee mug": 0.1, "crayons": 0.7,
             "toothbrush": 0.6, "apple": 0.05}
    vec = {"paintbrush": [1, 0, 0], "sketchbook": [0.9, 0.1, 0], "banana": [0, 1, 0], "coffee mug": [0, 0.2, 1],
           "crayons": [0.95, 0.05, 0], "toothbrush": [0.8, 0, 0.6], "apple": [0, 1, 0.1]}
    lm = ScriptedLM(answer=lambda m, s: category_json("art supplies"), probs=_probs_by_name(table))
    # the nearest-reference MiniLM term, where one answered object moves a score visibly (the default's mean
    # reference takes the same references: test_queries_lm.py checks it on the real kernel)
    k = GiftProbKernel(lm=lm, language_kernel=TableKernel(vec), rescore_with="evidence", embed_reference="contrastive")
    rel = ("paintbrush", "sketchbook")
    base = k.score(TEST, TRAIN, ART, rel)
    n_calls = len(lm.calls)
    rs = k.score_with_answers(TEST, TRAIN, ART, rel, {"toothbrush": False, "crayons": True})
    assert len(lm.calls) == n_calls
    sim = TableKernel(vec).similarity
    refs = TRAIN + [TEST[1], TEST[0]]  # the training objects, then the answered ones in test order
    ref_rel = np.array([True, True, False, False, False, True])

    def contrast(obj, own):
        s = sim([obj], refs)[0]
        s[own] = np.nan
        return np.nanmax(np.where(ref_rel, s, np.nan)) - np.nanmax(np.where(~ref_rel, s, np.nan))

    want_test = [contrast(TEST[0], [5]), contrast(TEST[1], [4]), contrast(TEST[2], [])]
    want_train = [contrast(o, [i]) for i, o in enumerate(TRAIN)]
    assert np.allclose(rs.details["terms"]["language"]["test"], want_test)
    assert np.allclose(rs.details["terms"]["language"]["train"], want_train)
    # the toothbrush (answered "no") is now the sketchbook's nearest left-alone reference: its score falls
    assert rs.details["terms"]["language"]["train"][1] < base.details["terms"]["language"]["train"][1] - 0.5
    # the reliability weights: each term's max(AUC - 1/2, 0) over the training and the answered objects
    from gift.core.metrics import roc_auc

    lab = np.array([True, True, False, False, True, False])  # TRAIN, then crayons (yes), toothbrush (no)
    sep = {}
    for t in ("lm", "language"):
        v = np.asarray(rs.details["terms"][t]["test"] + rs.details["terms"][t]["train"])
        z = (v - v.mean()) / v.std()
        sep[t] = max(roc_auc(np.concatenate([z[3:], z[[0, 1]]]), lab) - 0.5, 0.0) * 0.5
    assert rs.details["weights"] == pytest.approx({t: sep[t] / sum(sep.values()) for t in sep})
    assert rs.details["evidence"] == {"yes": ["crayons"], "no": ["toothbrush"]}
    assert GiftProbKernel().rescore_with == "evidence"  # the default (docs/results/queries.md, gift-dev10)


def test_shared_name_category_reads_the_word_every_demonstrated_name_has_and_no_other_has():
    """The name rung (rungs="both+names") asks no LM: the word every handled name has and no left-alone name
    has, in the singular; containers before "of", possessives and stopwords are not words of the kind."""
    f = prompts.shared_name_category
    assert f(["wicker shopping basket", "coiled seagrass storage baskets"], ["brass carriage clock"]) == "basket things"
    assert f(["red plastic dustpan", "white plastic coat hanger"], ["box of cornflakes"]) == "plastic things"
    assert f(["box of cornflakes", "box of muesli"]) is None  # the container is not the kind
    assert f(["potter's wire cutter", "potter's rib"]) == "potter things"
    assert f(["wire cutter", "wire brush"], ["wire coat hanger"]) is None  # a left-alone object has it too
    assert f(["bundle of paper straws", "reusable glass straw"]) == "straw things"
    assert f(["cut glasses", "glass jar"]) == "glass things"
    assert f(["dried red roses", "dried red sunflower"]) == "red things"  # the last shared word of the first name
    assert f(["fencing mask"]) is None and f([]) is None  # one name shares everything with itself: no rung


@settings(max_examples=200, deadline=None)
@given(st.lists(st.text(alphabet="abcdefghij 'sof-", max_size=30), min_size=0, max_size=4),
       st.lists(st.text(alphabet="abcdefghij 'sof-", max_size=30), max_size=4))
def test_shared_name_category_is_none_or_a_word_of_every_handled_name(handled, left_alone):
    cat = prompts.shared_name_category(handled, left_alone)
    if cat is not None:
        word = cat.removesuffix(" things")
        assert len(handled) >= 2 and " " not in word and len(word) >= 2
        assert all(word in n.lower() for n in handled)


def test_gift_prob_name_rung_joins_the_ladder_without_an_lm_call():
    """rungs="both+names": the breadth and facet calls as with "both", and the demonstrated objects' shared name
    word as one more rung, asked like the others; a training object left out falls back to the full rung."""
    train = [ObjectSpec("felt pen", "a pen with a felt tip"), ObjectSpec("felt coaster", "a coaster of felt"),
             ObjectSpec("banana", "a yellow fruit"), ObjectSpec("coffee mug", "a ceramic mug")]
    test = [ObjectSpec("felt hat", "a hat of felt"), ObjectSpec("apple", "a red fruit")]

    def answer(messages, seed):
        if messages[0].content == prompts.LADDER_SYSTEM:
            return json.dumps({"narrow": "pens", "middle": "stationery", "broad": "office things"})
        if messages[0].content == prompts.FACET_SYSTEM:
            return json.dumps({"kind": "none", "material": "none", "property": "none"})
        return category_json("stationery")

    def run(rungs):
        lm = ScriptedLM(answer=answer, probs=lambda text: {"yes": 0.6, "no": 0.4})
        rs = GiftProbKernel(lm=lm, combine="none", rungs=rungs).score(test, train, PICKED_BANANA,
                                                                       ("felt pen", "felt coaster"))
        ladder_calls = sum(c[0][0].content in (prompts.LADDER_SYSTEM, prompts.FACET_SYSTEM) for c in lm.calls)
        asked = {c[0][1].content for c in lm.calls if c[0][0].content == prompts.RELEVANCE_SYSTEM}
        return rs, ladder_calls, asked

    rs, calls, asked = run("both+names")
    base, base_calls, base_asked = run("both")
    assert rs.details["ladder"]["categories"] == [*base.details["ladder"]["categories"], "felt things"]
    assert calls == base_calls > 0  # the name rung costs no ladder call
    assert any(q.startswith("Is a felt hat (a hat of felt) one of the felt things?") for q in asked - base_asked)
    # the felt pen's own ladder (named without it) has no shared word: the full rung stands in
    assert any(q.startswith("Is a felt pen (a pen with a felt tip) one of the felt things?") for q in asked)
    assert "both+names" in RUNGS


@pytest.mark.parametrize("option", ["combine", "embed_reference", "embed_text", "ask_text", "rescore_with",
                                    "ladder_text", "veto", "standardize", "weighting", "category_from",
                                    "candidates", "select", "ladder", "rungs", "check"])
def test_gift_prob_names_the_option_and_its_choices_when_a_value_is_unknown(option):
    with pytest.raises(GiftError, match=rf"gift-prob: {option} must be one of \(.*\), got 'bogus'"):
        GiftProbKernel(**{option: "bogus"})
