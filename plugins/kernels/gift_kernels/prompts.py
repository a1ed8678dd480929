"""All LM prompt text of gift_kernels, in our own words.

- Call 1 (intent): demonstration pairs as feature traces -> 3 ranked motivations with their features,
  plus semantic similarities.
- Call 2 (axes): motivations -> short yes/no questions grouping the objects that exist.
- Call 3 (mapping): test objects -> a training object or ``distractor``, with or without the intent.
- Relevance (``gift-prob``): one yes/no question per object under the goal; read through
  ``choice_probabilities``.

Each builder returns a tuple of :class:`gift.core.data.Message`.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence

from gift.core.data import DISTRACTOR, Intent, Message, ObjectSpec
from gift.core.errors import GiftError

# ----------------------------------------------------------------------------- Call 1: intent

INTENT_SYSTEM = """\
You read recordings of a robot arm and explain what a person wanted. For each scene you get two \
recordings: the robot's default behaviour and the behaviour the person preferred. Each recording lists, \
per time step, feature values between 0 and 1. A feature named "a_proximity_to_b" is 1.0 when a and b \
touch and 0.0 when they are far apart or one of them is missing.

Find why the person preferred their version: the purpose, not the motion. Name the kind of objects that \
matter: the category or property they share, not one object's name.

Reply with one JSON object and nothing else:
{"motivations": [{"text": "<one or two sentences>", "features": ["<feature name>", ...]}, ... three entries, \
most likely first],
 "semantic_similarities": [{"question": "<a short yes/no question>", "features": ["<feature name>", ...]}, ...]}
Name one to four features per entry and at most three semantic similarities. Use only feature names that \
appear in the recordings or in the list of other features."""


def intent_messages(pairs_text: Sequence[tuple[str, str]], descriptions: Mapping[str, str],
                    other_features: Sequence[str], task_context: str = "") -> tuple[Message, ...]:
    """Call 1. ``pairs_text``: (default trace text, preferred trace text) per demonstration pair."""
    lines = []
    if task_context:
        lines.append(f"Task: {task_context}")
    if descriptions:
        lines.append("Features:")
        lines += [f"- {n}: {d}" if d else f"- {n}" for n, d in descriptions.items()]
    for k, (default, preferred) in enumerate(pairs_text, 1):
        lines.append(f"\nScene {k}, default recording:\n{default}")
        lines.append(f"Scene {k}, preferred recording:\n{preferred}")
    if other_features:
        lines.append("\nOther features (objects that appear in other scenes):")
        lines += [f"- {n}" for n in other_features]
    lines.append("\nWhat did the person want? Give three motivations, most likely first, each with the "
                 "features it explains, and the semantic similarities, as the JSON object described.")
    return (Message("system", INTENT_SYSTEM), Message("user", "\n".join(lines)))


# ----------------------------------------------------------------------------- Call 2: axes

AXES_SYSTEM = """\
You group objects by what they have in common with respect to a person's goal. You get the person's \
motivations and a list of object names. Write short yes/no questions (for example "is it a fruit?") \
and, for each question, the objects for which the answer is yes. Use only the given object names; put \
each object under at most one question; avoid vague questions such as "is it an object?".

Reply with one JSON object and nothing else: {"axes": [{"question": "...", "objects": ["...", ...]}, ...]} \
with one to six questions, each with at least one object."""


def axes_messages(motivations: Sequence[tuple[str, Sequence[str]]], objects: Sequence[str]) -> tuple[Message, ...]:
    """Call 2. ``motivations``: (text, features) in rank order; ``objects``: the names that may be used."""
    mot = {text: list(feats) for text, feats in motivations}
    user = (f"Motivations and the features they concern:\n{json.dumps(mot, indent=1)}\n\n"
            f"Objects: {json.dumps(list(objects))}\n\nGroup the objects with yes/no questions.")
    return (Message("system", AXES_SYSTEM), Message("user", user))


# ----------------------------------------------------------------------------- Call 3: mapping

MAP_SYSTEM = f"""\
You carry what a robot learned about some objects over to new objects. You get the objects the robot \
was trained with and the objects of a new scene, and sometimes what the person wants (motivations and \
yes/no grouping questions). Map every new object either to the training object whose role it takes, \
judged by purpose and use rather than by name or looks, or to "{DISTRACTOR}" when it takes no training \
object's role. Several new objects may map to the same training object.

Reply with one JSON object and nothing else: {{"<new object>": "<training object or {DISTRACTOR}>", ...}} \
with every new object as a key, in the order they are listed."""


def intent_context(intent: Intent) -> str:
    """The intent as prompt text: its text, ranked motivations and semantic axes."""
    lines = [f"The person's goal: {intent.text}"]
    if intent.motivations:
        lines.append("Motivations, most likely first:")
        lines += [f"{k}. {m.text}" for k, m in enumerate(intent.motivations, 1)]
    if intent.axes:
        lines.append("Grouping questions:")
        lines += [f"- {a.question}" + (f" (yes for: {', '.join(a.objects)})" if a.objects else "")
                  for a in intent.axes]
    return "\n".join(lines)


def mapping_messages(test: Sequence[str], train: Sequence[str], intent: Intent | None) -> tuple[Message, ...]:
    """Call 3 (``intent=None``: the no-intent ablation, common sense only)."""
    head = (intent_context(intent) + "\nUse the goal to decide which roles matter.\n\n" if intent is not None
            else "No goal is given: use common sense.\n\n")
    user = (f"{head}Training objects: {json.dumps(list(train))}\n"
            f"New objects: {json.dumps(list(test))}\n\n"
            f"Map every new object to a training object or to \"{DISTRACTOR}\".")
    return (Message("system", MAP_SYSTEM), Message("user", user))


# ----------------------------------------------------------------------------- relevance (gift-prob)

RELEVANCE_SYSTEM = "You answer questions about everyday objects with a single word: yes or no."

#: Question templates of gift-prob; ``{goal}``, ``{name}``, ``{desc}`` (" (description)" or ""),
#: ``{category}`` (the kind of object the goal is about, from :func:`category_messages`).
RELEVANCE_TEMPLATES: dict[str, str] = {
    # Is the object an instance of the goal's object category (the default: see docs/results/gift_prob.md).
    "category": "Is a {name}{desc} one of the {category}? Answer yes or no.",
    # The goal's own words and the object's description (the winner of the first held-out probe).
    "goal": "Goal: {goal}.\nIs a {name}{desc} one of the things this goal is about? Answer yes or no.",
    # The same, phrased as "does the goal concern it".
    "about": "Goal: {goal}.\nDoes this goal concern a {name}{desc}? Answer yes or no.",
    # Without the description (names only).
    "goal-name": "Goal: {goal}.\nIs a {name} one of the things this goal is about? Answer yes or no.",
    # The category question, told that a thing used with, holding or named after the category is not one of it
    # (against distractors named like the class: a grater for cheese; docs/results/front_half.md, section 18).
    "kind": ("Is a {name}{desc} itself one of the {category}? A thing only used with them, made to hold them or "
             "sharing a word with them is not. Answer yes or no."),
}

AXIS_TEMPLATE = "{question}\nThe object: a {name}{desc}. Answer yes or no."


#: A leading "The human prefers to" / "The person wanted to" / "The user would like to" of a motivation.
_GOAL_LEAD = re.compile(r"^(the\s+)?(human|person|user|people)\s+(would\s+(rather|like\s+to|prefer\s+to)\s+|"
                        r"(prefers|preferred|prefer|wants|wanted|want|likes|liked|tried|tries|intended|intends)"
                        r"\s+to\s+)", re.IGNORECASE)


def goal_text(text: str) -> str:
    """An intent text as a goal clause: strip a trailing period and a lead such as "The human prefers to"."""
    t = text.strip().rstrip(".")
    m = _GOAL_LEAD.match(t)
    return t[m.end():].strip() if m else t


# ----------------------------------------------------------------------------- goal category (gift-prob)

CATEGORY_SYSTEM = ("You name the kind of object a household goal is about, as a short plural noun phrase. "
                   'Reply with one JSON object and nothing else: {"category": "<noun phrase>"}')


def category_answer(category: str) -> str:
    """A worked example's answer, in the JSON of ``schemas.category_schema``."""
    return json.dumps({"category": category})

#: Worked examples shown before the goal. Written before any result was seen, from household goals that share
#: no object and no kind of goal with any shipped suite (gift-paper, gift-dev, lm-dev; checked by a test).
#: They show the answer's form: the kind of object in the goal's own words, as a plural noun phrase.
CATEGORY_EXAMPLES: tuple[tuple[str, str], ...] = (
    ("put the aquarium supplies on the shelf", "aquarium supplies"),
    ("get the car cleaning things ready", "car cleaning things"),
    ("keep the toddler away from anything with small parts", "things with small parts"),
    ("bring me something to hang the picture with", "things to hang a picture with"),
)


def category_messages(goal: str) -> tuple[Message, ...]:
    """Ask which kind of object ``goal`` is about (few-shot, answered with a plural noun phrase)."""
    msgs = [Message("system", CATEGORY_SYSTEM)]
    for g, c in CATEGORY_EXAMPLES:
        msgs += [Message("user", f"Goal: {g}.\nWhich objects is this goal about?"),
                 Message("assistant", category_answer(c))]
    msgs.append(Message("user", f"Goal: {goal_text(goal)}.\nWhich objects is this goal about?"))
    return tuple(msgs)


#: Worked examples for naming the kind of object from the objects a goal concerned and those it did not
#: (and, when there is one, the goal). Same rules as :data:`CATEGORY_EXAMPLES`: no object and no kind of
#: goal of any shipped suite. The goals are phrased in different ways, none naming the kind's members.
CATEGORY_EXAMPLES_WITH_OBJECTS: tuple[tuple[str, tuple[str, ...], tuple[str, ...], str], ...] = (
    ("put the aquarium supplies on the shelf", ("aquarium net", "fish food flakes"), ("tripod", "kettle"),
     "aquarium supplies"),
    ("put the windshield squeegee in the trunk", ("car wax tin", "windshield squeegee"), ("toaster", "desk lamp"),
     "car cleaning things"),
    ("move around the bag of marbles", ("bag of marbles", "box of push pins"),
     ("beach ball", "floor cushion"), "things with small parts"),
    ("get ready for the party", ("party hat", "confetti cannon"), ("tire gauge", "bath mat"), "party supplies"),
)


def _objects_question(goal: str | None, handled: Sequence[str], left_alone: Sequence[str]) -> str:
    head = f"Goal: {goal_text(goal)}.\n" if goal else ""
    return (f"{head}Objects the person's goal concerned (they acted on them or kept clear of them): "
            f"{', '.join(handled)}.\nObjects it did not concern: {', '.join(left_alone) or 'none'}.\n"
            f"Which kind of objects is {'this goal' if goal else 'the goal'} about?")


def category_from_objects_messages(goal: str | None, handled: Sequence[str],
                                   left_alone: Sequence[str]) -> tuple[Message, ...]:
    """Ask which kind of object a goal is about, given the training objects the demonstrations treated as
    part of it (``handled``, at least one) and the others, and the goal's text when there is one
    (``goal=None``: from the objects alone, the easiest question for a small model)."""
    if not handled:
        raise ValueError("category_from_objects_messages needs at least one handled object")
    msgs = [Message("system", CATEGORY_SYSTEM)]
    for g, h, a, c in CATEGORY_EXAMPLES_WITH_OBJECTS:
        msgs += [Message("user", _objects_question(g if goal else None, h, a)),
                 Message("assistant", category_answer(c))]
    msgs.append(Message("user", _objects_question(goal, handled, left_alone)))
    return tuple(msgs)


#: The breadths of the category ladder (:func:`ladder_messages`), narrowest first.
LADDER_LEVELS: tuple[str, ...] = ("narrow", "middle", "broad")

LADDER_SYSTEM = ("You name what a set of household objects have in common, at three breadths: narrow (just "
                 "this kind), middle, and broad (a wider family that still leaves the other objects out). Each "
                 "name is a short plural noun phrase, never one object's name. Reply with one JSON object and "
                 'nothing else: {"narrow": "...", "middle": "...", "broad": "..."}')

#: Worked examples of the ladder: the objects of :data:`CATEGORY_EXAMPLES_WITH_OBJECTS` (no object and no
#: kind of goal of any shipped suite; checked by a test), named at three breadths.
LADDER_EXAMPLES: tuple[tuple[tuple[str, ...], tuple[str, ...], tuple[str, str, str]], ...] = (
    (("aquarium net", "fish food flakes"), ("tripod", "kettle"),
     ("aquarium supplies", "pet care supplies", "things for looking after animals")),
    (("car wax tin", "windshield squeegee"), ("toaster", "desk lamp"),
     ("car cleaning things", "vehicle care products", "things for maintenance")),
    (("bag of marbles", "box of push pins"), ("beach ball", "floor cushion"),
     ("things with small parts", "loose little pieces", "choking hazards")),
    (("party hat", "confetti cannon"), ("tire gauge", "bath mat"),
     ("party supplies", "celebration things", "things for entertainment")),
)


#: How the ladder's questions show each object (:func:`ladder_messages`, :func:`facet_messages`): its name, or
#: its name and its description.
LADDER_TEXT = ("name", "name+description")

#: One-sentence descriptions of the objects of :data:`LADDER_EXAMPLES` and :data:`FACET_EXAMPLES`, shown when
#: the ladder's questions show descriptions (written for these examples; no object of any shipped suite).
LADDER_EXAMPLE_DESCRIPTIONS: dict[str, str] = {
    "aquarium net": "A small square of fine green mesh on a long plastic handle, for lifting fish out of a tank.",
    "fish food flakes": "A shaker tub of dry coloured flakes sprinkled on the water of a tank at feeding time.",
    "tripod": "Three telescoping aluminium legs with a screw mount on top that holds a camera steady.",
    "kettle": "A stainless steel jug with a spout and a base that plugs in to boil water for tea.",
    "car wax tin": "A flat round tin of pale paste rubbed onto paintwork with a cloth to make it shine.",
    "windshield squeegee": "A rubber blade on a short handle, with a sponge side, for clearing a car's front window.",
    "toaster": "A chrome box with two slots and a lever that browns slices of bread.",
    "desk lamp": "A lamp on an adjustable arm with a weighted base, clamped to a work table.",
    "bag of marbles": "A drawstring pouch of small glass spheres with coloured swirls inside.",
    "box of push pins": "A little clear box of pins with round plastic heads for pinning notes to a cork board.",
    "beach ball": "A large light ball of inflated striped vinyl.",
    "floor cushion": "A big flat square cushion covered in thick fabric, for sitting on the floor.",
    "party hat": "A cone of shiny card with an elastic chin strap and a paper tassel on top.",
    "confetti cannon": "A cardboard tube that pops out a burst of paper confetti when its base is twisted.",
    "tire gauge": "A pen-sized metal tool pressed onto a valve to read the air pressure in a tyre.",
    "bath mat": "A soft rectangle of absorbent cotton with a rubber backing, laid beside the tub.",
    "bamboo steamer basket": "A round woven basket with a lid, stacked over a pan of simmering water to cook dumplings.",
    "bamboo back scratcher": "A long thin stick with a small curled hand at one end for reaching an itch.",
    "steel colander": "A metal bowl punched with holes and with two handles, for draining boiled pasta.",
    "plastic back massager": "A hooked rod of hard plastic with knobs for pressing on sore back muscles.",
    "cork notice board": "A framed sheet of pressed brown bark granules hung on a wall to pin papers to.",
    "cork yoga block": "A brick-shaped block of pressed tree bark that props up a pose on the mat.",
    "foam yoga mat": "A long rubbery foam sheet rolled out on the floor for stretching.",
    "glass pitcher": "A clear jug with a handle and a lip for pouring water at the table.",
    "ice pack": "A flat sealed pouch of blue gel kept in the freezer and held against a bruise.",
    "bag of frozen peas": "A plastic bag of small green peas, frosted over, straight from the freezer.",
    "bread roll": "A small round loaf with a golden crust, baked that morning.",
    "oven mitt": "A thick quilted glove for taking hot dishes out of the oven.",
    "padlock": "A heavy brass lock with a curved steel shackle that snaps shut and opens with a small key.",
    "jewellery box with a lock": "A little lacquered wooden case lined with velvet, with a tiny keyhole in its front.",
    "garden gloves with a wrist strap": "A pair of canvas work gloves closed at the wrist by a hook-and-loop band.",
    "camera with a neck strap": "A compact black camera hanging from a woven band worn around the neck.",
    "table lamp with a dimmer dial": "A ceramic lamp with a linen shade and a round knob on its cord to dim it.",
    "radio with a tuning dial": "A small wooden-cased radio with a large round knob for finding stations.",
}


def shown(name: str, description: str | None) -> str:
    """An object as the ladder's questions show it: ``name`` or ``name (description)``."""
    d = (description or "").strip().rstrip(".")
    return f"{name} ({d})" if d else name


def _ladder_question(handled: Sequence[str], left_alone: Sequence[str], sep: str = ", ") -> str:
    return (f"Objects the person treated specially: {sep.join(handled)}.\n"
            f"Objects they treated like any other: {sep.join(left_alone) or 'none'}.\n"
            "What do the specially treated objects have in common?")


def ladder_messages(handled: Sequence[str], left_alone: Sequence[str],
                    descriptions: Mapping[str, str] | None = None) -> tuple[Message, ...]:
    """Ask for three names, narrow to broad, of what the ``handled`` training objects share that the
    ``left_alone`` ones do not (no goal text: the question a small model answers best). ``descriptions``
    (object name -> description): show every object, the worked examples' too, with its description."""
    return _shared_names_messages("ladder_messages", LADDER_SYSTEM, LADDER_LEVELS, LADDER_EXAMPLES, handled,
                                  left_alone, descriptions)


def _shared_names_messages(caller: str, system: str, levels: Sequence[str],
                           examples: Sequence[tuple[Sequence[str], Sequence[str], Sequence[str]]],
                           handled: Sequence[str], left_alone: Sequence[str],
                           descriptions: Mapping[str, str] | None = None) -> tuple[Message, ...]:
    """A few-shot conversation asking what ``handled`` objects share that ``left_alone`` ones do not, answered
    with one name per level (the worked ``examples`` as JSON answers); with ``descriptions``, each object is
    shown as ``name (description)`` (:func:`shown`)."""
    if not handled:
        raise ValueError(f"{caller} needs at least one handled object")

    def show(names: Sequence[str], known: Mapping[str, str]) -> list[str]:
        return list(names) if descriptions is None else [shown(n, known.get(n)) for n in names]

    sep = ", " if descriptions is None else "; "  # descriptions have commas of their own
    msgs = [Message("system", system)]
    for h, a, names in examples:
        msgs += [Message("user", _ladder_question(show(h, LADDER_EXAMPLE_DESCRIPTIONS),
                                                  show(a, LADDER_EXAMPLE_DESCRIPTIONS), sep)),
                 Message("assistant", json.dumps(dict(zip(levels, names))))]
    msgs.append(Message("user", _ladder_question(show(handled, descriptions or {}),
                                                 show(left_alone, descriptions or {}), sep)))
    return tuple(msgs)


#: The facets of the faceted ladder (:func:`facet_messages`): what kind of thing, what it is made of, a trait.
FACET_LEVELS: tuple[str, ...] = ("kind", "material", "property")

FACET_SYSTEM = ("You say what a set of household objects have in common that the other objects do not, in three "
                'ways: "kind" (what sort of thing they are or what they are used for), "material" (what they are '
                'mostly made of) and "property" (a trait they share, such as how they behave or what care they '
                'need). Each is a short plural noun phrase, never one object\'s name, or "none" when the objects '
                "share nothing of that sort or the other objects share it too. Reply with one JSON object and "
                'nothing else: {"kind": "...", "material": "...", "property": "..."}')

#: Worked examples of the faceted ladder, written before any faceted run: three sets of
#: :data:`LADDER_EXAMPLES` and three more (no object and no goal word of any shipped suite; checked by a test).
#: Most facets are "none": the answer names only what the sets share.
FACET_EXAMPLES: tuple[tuple[tuple[str, ...], tuple[str, ...], tuple[str, str, str]], ...] = (
    (("aquarium net", "fish food flakes"), ("tripod", "kettle"),
     ("aquarium supplies", "none", "things for keeping fish")),
    (("bamboo steamer basket", "bamboo back scratcher"), ("steel colander", "plastic back massager"),
     ("none", "bamboo things", "none")),
    (("bag of marbles", "box of push pins"), ("beach ball", "floor cushion"),
     ("small loose pieces", "none", "choking hazards")),
    (("cork notice board", "cork yoga block"), ("foam yoga mat", "glass pitcher"),
     ("none", "cork things", "light things that float")),
    (("ice pack", "bag of frozen peas"), ("bread roll", "oven mitt"),
     ("freezer things", "none", "cold things")),
    (("party hat", "confetti cannon"), ("tire gauge", "bath mat"),
     ("party supplies", "none", "things for celebrations")),
)


def facet_messages(handled: Sequence[str], left_alone: Sequence[str],
                   descriptions: Mapping[str, str] | None = None) -> tuple[Message, ...]:
    """Ask for the kind, the material and a property that the ``handled`` training objects share and the
    ``left_alone`` ones do not, each possibly "none" (no goal text); ``descriptions`` as in
    :func:`ladder_messages`."""
    return _shared_names_messages("facet_messages", FACET_SYSTEM, FACET_LEVELS, FACET_EXAMPLES, handled,
                                  left_alone, descriptions)


#: The one level of the part rung (:func:`part_messages`): a part or feature every demonstrated object has.
PART_LEVELS: tuple[str, ...] = ("part",)

PART_SYSTEM = ("You name a part or feature that every one of a set of household objects has and the other objects "
               'lack, as a short plural noun phrase of the form "things with ...", never one object\'s name. Reply '
               'with one JSON object and nothing else: {"part": "..."}')

#: Worked examples of the part rung, written for it before any run with it (no object and no goal word of any
#: shipped suite; checked by a test). All name a part: with "none" among them the embedded model answered "none"
#: for every set in a probe, so a wrong part is left to the check on the training objects (``check="fit"``).
PART_EXAMPLES: tuple[tuple[tuple[str, ...], tuple[str, ...], tuple[str]], ...] = (
    (("padlock", "jewellery box with a lock"), ("beach ball", "floor cushion"), ("things with a lock",)),
    (("garden gloves with a wrist strap", "camera with a neck strap"), ("toaster", "desk lamp"),
     ("things with a strap",)),
    (("table lamp with a dimmer dial", "radio with a tuning dial"), ("tripod", "kettle"), ("things with a dial",)),
)


def part_messages(handled: Sequence[str], left_alone: Sequence[str],
                  descriptions: Mapping[str, str] | None = None) -> tuple[Message, ...]:
    """Ask for a part or feature ("things with ...") that the ``handled`` training objects have and the
    ``left_alone`` ones lack (no goal text); ``descriptions`` as in :func:`ladder_messages`."""
    return _shared_names_messages("part_messages", PART_SYSTEM, PART_LEVELS, PART_EXAMPLES, handled, left_alone,
                                  descriptions)


NAME_LEVELS: tuple[str, ...] = ("shared word",)

#: Words that never name what objects share on their own (articles, prepositions, conjunctions).
_NAME_STOPWORDS = frozenset({"a", "an", "the", "and", "or", "with", "without", "in", "on", "for", "to", "of", "from",
                             "by", "at", "into"})


def _name_words(name: str) -> list[str]:
    """The content words of an object's name, in order and in the singular ("baskets" and "basket" match): lower
    case, a possessive ``'s`` dropped, the word before an "of" dropped as a container or quantity ("box of
    cornflakes", "pair of gloves"), stopwords and words under three letters dropped."""
    words = re.findall(r"[a-z]+", re.sub(r"'s\b", "", name.lower()))
    return [_singular(w) for i, w in enumerate(words)
            if w not in _NAME_STOPWORDS and len(w) >= 3 and not (i + 1 < len(words) and words[i + 1] == "of")]


def _singular(word: str) -> str:
    """A crude singular: "boxes" -> "box", "glasses" -> "glass", "baskets" -> "basket", "glass" stays."""
    if word.endswith(("sses", "shes", "ches", "xes", "zes")):
        return word[:-2]
    return word[:-1] if word.endswith("s") and not word.endswith(("ss", "us", "is")) else word


def shared_name_category(handled: Sequence[str], left_alone: Sequence[str] = ()) -> str | None:
    """A category read off the names alone, no LM: ``"<word> things"`` for a word every one of the (at least two)
    ``handled`` names has and no ``left_alone`` name has ("wicker shopping basket", "coiled seagrass storage
    basket" -> "basket things"; the word in the singular); the last such word of the first name where several are
    shared; ``None`` where none is (or fewer than two names are handled)."""
    if len(handled) < 2:
        return None
    rest = [set(_name_words(n)) for n in handled[1:]]
    others = {w for n in left_alone for w in _name_words(n)}
    shared = [w for w in _name_words(handled[0]) if all(w in ws for ws in rest) and w not in others]
    return f"{shared[-1]} things" if shared else None


_NO_NAME = re.compile(r"^(none|nothing|n/?a|no \w+|not applicable|unknown)$", re.IGNORECASE)


def is_no_name(name: str) -> bool:
    """Whether a ladder answer says the objects share nothing at that level ("none", "n/a", ...)."""
    return bool(_NO_NAME.match(name.strip()))


def parse_category(answer: str, max_words: int = 8) -> str | None:
    """The noun phrase of a category answer (first line, quotes, a leading "the" and end punctuation
    removed), or ``None`` when there is none or it is longer than ``max_words`` words."""
    line = next((ln for ln in answer.strip().splitlines() if ln.strip()), "").strip()
    line = re.sub(r"^(answer|category|objects)\s*:\s*", "", line, flags=re.IGNORECASE)
    line = line.strip(" \t\"'`*.,;:!").strip()
    line = re.sub(r"^the\s+", "", line, flags=re.IGNORECASE)
    if not line or len(line.split()) > max_words:
        return None
    return line


def fallback_category(goal: str) -> str:
    """The category phrase used when the LM gives none: the goal itself."""
    return f'things the goal "{goal_text(goal)}" is about'


#: How the object is shown in a yes/no question: ``"name+description"`` ("a cheese grater (A four-sided steel box
#: ...)") or ``"description"`` ("a thing described as "A four-sided steel box ..."": no name, so that a word the
#: name shares with the category cannot carry the answer; the name when the object has no description) or
#: ``"name"`` ("a cheese grater": the name alone, so that a description that reads like a member's cannot carry
#: the answer either).
OBJECT_TEXT = ("name+description", "description", "name")


def relevance_messages(obj: ObjectSpec, goal: str, template: str = "category",
                       use_description: bool = True, category: str | None = None,
                       object_text: str = "name+description") -> tuple[Message, ...]:
    """One yes/no question: is ``obj`` something the goal is about (one of its ``category``)?
    ``object_text``: one of :data:`OBJECT_TEXT`."""
    if object_text not in OBJECT_TEXT:
        raise GiftError(f"relevance question: object_text must be one of {OBJECT_TEXT}, got {object_text!r}")
    described = obj.description.strip()
    if object_text == "description" and described:
        name, desc = f'thing described as "{described.rstrip(".")}"', ""
    elif object_text == "name":
        name, desc = obj.name, ""
    else:
        name = obj.name
        desc = f" ({described})" if use_description and described else ""
    fields = dict(goal=goal_text(goal), name=name, desc=desc)
    body = RELEVANCE_TEMPLATES[template].format(**fields, category=category or fallback_category(goal))
    # the cut hint: the text before the category, which every question about this object under this
    # template shares (0 when the category does not come after the object)
    head = RELEVANCE_TEMPLATES[template].split("{category}")[0]
    cut = len(head.format(**fields)) if "{category}" in RELEVANCE_TEMPLATES[template] and "{name}" in head else 0
    return (Message("system", RELEVANCE_SYSTEM), Message("user", body, cut=cut))


def axis_messages(obj: ObjectSpec, question: str, use_description: bool = True) -> tuple[Message, ...]:
    """One semantic-axis question (from Call 2) asked about ``obj``."""
    desc = f" ({obj.description.strip()})" if use_description and obj.description.strip() else ""
    q = question.strip()
    q = q if q.endswith("?") else q + "?"
    return (Message("system", RELEVANCE_SYSTEM), Message("user", AXIS_TEMPLATE.format(question=q, name=obj.name,
                                                                                       desc=desc)))
