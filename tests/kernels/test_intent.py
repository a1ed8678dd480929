"""``lm-contrastive`` intent estimation (Calls 1 and 2) and ``gift infer-intent``.

Parsing and control flow use a scripted fake LM; the estimator itself is shown on the embedded model
(``slow``) on preferred-vs-default traces of the pack-backpack family.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import gift
from gift.cli import main
from gift.core.data import Completion, DemonstrationPair, FeatureTrace
from gift.core.errors import GiftError, ValidationError
from gift.core.interfaces import LMBackend
from gift_kernels.intent import LMContrastiveIntentEstimator, parse_axes, parse_motivations
from gift_kernels.intent_cli import load_demonstrations, save_demonstrations

OBJECTS = ["paintbrush", "sketchbook", "banana", "coffee mug"]


def pack_pair(relevant=("paintbrush", "sketchbook"), t: int = 61) -> DemonstrationPair:
    """Preferred: the relevant objects end in the backpack; default: the other ones do."""
    specs = gift.get_task("pack_backpack").feature_specs(OBJECTS)
    ramp = np.linspace(0.05, 1.0, t)

    def trace(into):
        v = np.full((t, len(specs)), 0.05)
        for j, s in enumerate(specs):
            if s.subject in into:
                v[:, j] = ramp
        v[:, -2] = 0.5 + 0.3 * np.sin(np.linspace(0, np.pi, t))  # ee_height
        v[:, -1] = 0.2  # ee_speed
        return FeatureTrace(specs, v)

    others = [o for o in OBJECTS if o not in relevant]
    return DemonstrationPair(preferred=trace(relevant), default=trace(others))


class ScriptedLM(LMBackend):
    name = "scripted"
    model = "scripted"

    def __init__(self, answers):
        self.answers, self.calls = list(answers), []

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self.calls.append(list(messages))
        return Completion(self.answers.pop(0))


def test_parse_motivations_keeps_existing_features_and_rejects_invented_ones():
    feats = ["paintbrush_proximity_to_backpack", "banana_proximity_to_backpack"]
    mots, sims = parse_motivations({"motivations": {"Pack art supplies for class.": ["Paintbrush_proximity_to_backpack"],
                                                    "Leave food at home.": ["banana_proximity_to_backpack"]},
                                    "semantic_similarities": [{"question": "is it for art?",
                                                               "features": ["paintbrush_proximity_to_backpack"]}]},
                                   feats)
    assert [m.text for m in mots] == ["Pack art supplies for class.", "Leave food at home."]
    assert mots[0].features == ("paintbrush_proximity_to_backpack",) and sims[0].question == "is it for art?"
    with pytest.raises(ValidationError, match=r"\['laptop_proximity_to_backpack'\] do not exist"):
        parse_motivations({"motivations": [{"text": "x", "features": ["laptop_proximity_to_backpack"]}]}, feats)
    with pytest.raises(ValidationError, match="no 'motivations' key"):
        parse_motivations({"goals": []}, feats)


def test_parse_axes_matches_object_names_and_rejects_unknown_ones():
    axes = parse_axes({"axes": [{"question": "is it an art supply?", "objects": ["Paintbrush", "sketchbook"]}]},
                      OBJECTS)
    assert axes[0].objects == ("paintbrush", "sketchbook")
    with pytest.raises(ValidationError, match=r"\['easel'\] do not exist"):
        parse_axes({"axes": [{"question": "art?", "objects": ["easel"]}]}, OBJECTS)


def test_estimator_builds_the_intent_from_both_calls_and_repairs_an_invented_feature():
    good1 = {"motivations": [{"text": "The human packs art supplies for a drawing class.",
                              "features": ["paintbrush_proximity_to_backpack", "sketchbook_proximity_to_backpack"]},
                             {"text": "The human leaves food out of the bag.", "features": ["banana_proximity_to_backpack"]},
                             {"text": "The human keeps drinkware out of the bag.",
                              "features": ["coffee_mug_proximity_to_backpack"]}],
             "semantic_similarities": []}
    bad1 = {"motivations": [{"text": "x", "features": ["easel_proximity_to_backpack"]}]}
    axes = {"axes": [{"question": "is it an art supply?", "objects": ["paintbrush", "sketchbook"]}]}
    lm = ScriptedLM([json.dumps(bad1), json.dumps(good1), json.dumps(axes)])
    est = gift.get_intent_estimator("lm-contrastive", lm=lm)
    intent = est.estimate([pack_pair()], task_context="Pack a backpack.")
    assert intent.source == "inferred" and intent.text == good1["motivations"][0]["text"]
    assert len(intent.motivations) == 3 and intent.axes[0].objects == ("paintbrush", "sketchbook")
    assert len(lm.calls) == 3 and est.calls == 2  # Call 1 + one repair, Call 2
    assert "easel_proximity_to_backpack" in lm.calls[1][-1].content  # the repair names the invented feature
    call1 = lm.calls[0][1].content
    # only the features that differ are shown as traces, subsampled; the rest listed by name
    assert "Timestep 0:" in call1 and "Timestep 56:" in call1 and "Timestep 57:" not in call1
    assert "ee_speed" in call1.split("Other features")[1]


def test_demonstrations_file_roundtrip_and_clear_errors(tmp_path):
    p = save_demonstrations(tmp_path / "demos.json", [pack_pair()], task_context="Pack.", objects=OBJECTS)
    pairs, ctx, objs = load_demonstrations(p)
    assert ctx == "Pack." and objs == OBJECTS and np.allclose(pairs[0].preferred.values, pack_pair().preferred.values)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"pairs": [{"features": [{"name": "a"}], "preferred": [[1, 2]], "default": [[1]]}]}))
    with pytest.raises(GiftError, match=r"bad.json, pair 0"):
        load_demonstrations(bad)
    with pytest.raises(GiftError, match="cannot read"):
        load_demonstrations(tmp_path / "missing.json")


# ----------------------------------------------------------------------------- the embedded model


@pytest.mark.slow
def test_infer_intent_command_on_the_embedded_model(tmp_path, capsys):
    pytest.importorskip("gift_llm")
    path = save_demonstrations(tmp_path / "demos.json", [pack_pair()],
                               task_context=gift.get_task("pack_backpack").context(), objects=OBJECTS)
    assert main(["infer-intent", str(path), "--json"]) == 0
    intent = json.loads(capsys.readouterr().out)
    feats = set(pack_pair().preferred.names)
    assert intent["source"] == "inferred" and intent["text"].strip()
    assert 1 <= len(intent["motivations"]) <= 3
    assert all(set(m["features"]) <= feats for m in intent["motivations"])
    assert all(set(a["objects"]) <= set(OBJECTS) for a in intent["axes"])
    assert main(["infer-intent", str(tmp_path / "nope.json")]) == 1


def test_call1_prompt_shrinks_steps_then_features_to_fit_the_budget():
    pairs = [pack_pair(), pack_pair(("banana", "coffee mug")), pack_pair(("paintbrush",))]
    full = LMContrastiveIntentEstimator(lm=None, max_prompt_chars=10**6)
    msgs, features = full.intent_prompt(pairs)
    size = sum(len(m.content) for m in msgs)
    assert "Timestep 56" in msgs[-1].content  # 8 steps of 61: every 8th

    est = LMContrastiveIntentEstimator(lm=None, max_prompt_chars=int(size * 0.8))
    small, small_features = est.intent_prompt(pairs)
    assert sum(len(m.content) for m in small) <= size * 0.8
    assert small_features == features  # every feature is still named, shown or not
    assert "Timestep 56" not in small[-1].content and "Timestep 0" in small[-1].content

    # an impossible budget stops at 4 steps and 2 features per pair instead of looping
    tiny, _ = LMContrastiveIntentEstimator(lm=None, max_prompt_chars=10).intent_prompt(pairs)
    text = tiny[-1].content
    assert "Timestep 48" in text and "Timestep 56" not in text  # every 16th of 61 -> 0, 16, 32, 48
    assert all(line.count(": ") <= 3 for line in text.splitlines() if line.startswith("Timestep"))


def test_call2_still_invalid_after_repairs_keeps_what_is_valid_and_warns():
    call1 = {"motivations": [{"text": "The human packs art supplies.", "features": ["paintbrush_proximity_to_backpack"]}],
             "semantic_similarities": [{"question": "is it for drawing?",
                                        "features": ["paintbrush_proximity_to_backpack"]}]}
    # the 1.5B model sometimes names a landmark or a feature instead of objects, also after repairs
    partly = {"axes": [{"question": "is it an art supply?", "objects": ["paintbrush", "Sketchbook", "backpack"]},
                       {"question": "is it near the goal?", "objects": ["ee_speed"]}]}
    lm = ScriptedLM([json.dumps(call1)] + [json.dumps(partly)] * 3)
    est = gift.get_intent_estimator("lm-contrastive", lm=lm, max_repairs=2)
    with pytest.warns(RuntimeWarning, match="kept 1 axes without the unknown names"):
        intent = est.estimate([pack_pair()], objects=OBJECTS)
    assert intent.text == "The human packs art supplies."
    assert len(lm.calls) == 4  # Call 1, then Call 2 and its two repairs
    assert [(a.question, a.objects) for a in intent.axes] == [("is it an art supply?", ("paintbrush", "sketchbook"))]

    nothing = {"axes": [{"question": "is it near the goal?", "objects": ["ee_speed"]}]}
    lm = ScriptedLM([json.dumps(call1)] + [json.dumps(nothing)] * 3)
    est = gift.get_intent_estimator("lm-contrastive", lm=lm, max_repairs=2)
    with pytest.warns(RuntimeWarning, match="no valid semantic axes, keeping Call 1's similarities"):
        intent = est.estimate([pack_pair()], objects=OBJECTS)
    assert [a.question for a in intent.axes] == ["is it for drawing?"]  # Call 1's similarities
