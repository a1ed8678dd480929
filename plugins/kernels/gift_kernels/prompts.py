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
from collections.abc import Mapping, Sequence

from gift.core.data import DISTRACTOR, Intent, Message, ObjectSpec

# ----------------------------------------------------------------------------- Call 1: intent

INTENT_SYSTEM = """\
You read recordings of a robot arm and explain what a person wanted. For each scene you get two \
recordings: the robot's default behaviour and the behaviour the person preferred. Each recording lists, \
per time step, feature values between 0 and 1. A feature named "a_proximity_to_b" is 1.0 when a and b \
touch and 0.0 when they are far apart or one of them is missing.

Find why the person preferred their version: the purpose, not the motion. Name the kind of objects that \
matter (describe their category or property, e.g. "fragile items" rather than one object's name).

Reply with one JSON object and nothing else:
{"motivations": [{"text": "<one or two sentences>", "features": ["<feature name>", ...]}, ... three entries, \
most likely first],
 "semantic_similarities": [{"question": "<a short yes/no question>", "features": ["<feature name>", ...]}, ...]}
Use only feature names that appear in the recordings or in the list of other features."""


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

Reply with one JSON object and nothing else: {"axes": [{"question": "...", "objects": ["...", ...]}, ...]}"""


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

Reply with one JSON object and nothing else: {{"<new object>": "<training object or {DISTRACTOR}>", ...}}"""


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

#: Question templates of gift-prob; ``{goal}``, ``{name}``, ``{desc}`` (" (description)" or "").
RELEVANCE_TEMPLATES: dict[str, str] = {
    # The goal's own words and the object's description (the winner of the held-out probe).
    "goal": "Goal: {goal}.\nIs a {name}{desc} one of the things this goal is about? Answer yes or no.",
    # The same, phrased as "does the goal concern it".
    "about": "Goal: {goal}.\nDoes this goal concern a {name}{desc}? Answer yes or no.",
    # Without the description (names only).
    "goal-name": "Goal: {goal}.\nIs a {name} one of the things this goal is about? Answer yes or no.",
}

AXIS_TEMPLATE = "{question}\nThe object: a {name}{desc}. Answer yes or no."


def goal_text(text: str) -> str:
    """An intent text as a goal clause: strip a trailing period and a leading "The human prefers to"."""
    t = text.strip().rstrip(".")
    for lead in ("the human prefers to ", "the person prefers to ", "the human wants to ", "the person wants to "):
        if t.lower().startswith(lead):
            t = t[len(lead):]
            break
    return t


def relevance_messages(obj: ObjectSpec, goal: str, template: str = "goal",
                       use_description: bool = True) -> tuple[Message, ...]:
    """One yes/no question: is ``obj`` something the goal is about?"""
    desc = f" ({obj.description.strip()})" if use_description and obj.description.strip() else ""
    body = RELEVANCE_TEMPLATES[template].format(goal=goal_text(goal), name=obj.name, desc=desc)
    return (Message("system", RELEVANCE_SYSTEM), Message("user", body))


def axis_messages(obj: ObjectSpec, question: str, use_description: bool = True) -> tuple[Message, ...]:
    """One semantic-axis question (from Call 2) asked about ``obj``."""
    desc = f" ({obj.description.strip()})" if use_description and obj.description.strip() else ""
    q = question.strip()
    q = q if q.endswith("?") else q + "?"
    return (Message("system", RELEVANCE_SYSTEM), Message("user", AXIS_TEMPLATE.format(question=q, name=obj.name,
                                                                                       desc=desc)))
