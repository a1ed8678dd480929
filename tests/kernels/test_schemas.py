"""The JSON schemas of the structured LM calls and the parsers that read their answers.

Hypothesis builds schemas from random feature and object names and draws answers from them; every
valid answer must pass its parser (through ``ask_dict``, with no repair), and near misses (an unknown
name, a missing object, a missing key) must be rejected with an error that names the problem, then
repaired. A scripted LM feeds ``ask_dict`` here (control flow only); the real model answers the four
calls under their grammars in the ``slow`` tests at the end.
"""

from __future__ import annotations

import json
import re

import jsonschema
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from gift.core.data import DISTRACTOR, Completion, Intent, Motivation, ObjectSpec
from gift.core.errors import GiftError, LMAnswerError, ValidationError
from gift.core.interfaces import LMBackend
from gift_kernels import prompts, schemas
from gift_kernels.intent import parse_axes, parse_motivations
from gift_kernels.lm_kernels import parse_category_answer, parse_mapping
from gift_llm.structured import AskStats, ask_dict

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def norm(s: str) -> str:
    """The parsers' name matching: case, underscores and repeated spaces do not count."""
    return " ".join(s.replace("_", " ").lower().split())


# ----------------------------------------------------------------------------- strategies

NAME_CHARS = st.sampled_from("abcdefghijklmnopqrstuvwxyzABCXYZ0123456789 _-'&.éü")
NAME = st.text(NAME_CHARS, min_size=1, max_size=24).filter(lambda s: s.strip() and norm(s))


def name_sets(min_size: int = 1, max_size: int = 8):
    """Distinct names, also distinct as the parsers match them (case, underscores, spaces)."""
    return st.lists(NAME, min_size=min_size, max_size=max_size, unique_by=norm)


def instances(schema: dict) -> st.SearchStrategy:
    """Every JSON value the schema subset of ``gift_kernels.schemas`` allows."""
    if "enum" in schema:
        return st.sampled_from(schema["enum"])
    kind = schema["type"]
    if kind == "string":
        return st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), min_size=schema.get("minLength", 0),
                       max_size=schema.get("maxLength", 50))
    if kind == "array":
        return st.lists(instances(schema["items"]), min_size=schema.get("minItems", 0),
                        max_size=schema.get("maxItems", 5))
    if kind == "object":
        return st.fixed_dictionaries({k: instances(v) for k, v in schema["properties"].items()})
    raise AssertionError(f"the schemas use no type {kind!r}")


class ScriptedLM(LMBackend):
    """Answers with ``answers`` in turn; records each request's schema (control flow only)."""

    name = "scripted"
    model = "scripted"
    supports_choice_probabilities = True

    def __init__(self, answers):
        self.answers, self.schemas, self.prompts = list(answers), [], []

    def complete(self, messages, *, temperature=0.0, seed=None, max_tokens=512, stop=None, json_schema=None):
        self.schemas.append(json_schema)
        self.prompts.append(list(messages))
        return Completion(self.answers.pop(0))


def ask(answers, schema, validate, **kw):
    """``ask_dict`` on a scripted LM answering ``answers``: (result, stats, lm)."""
    lm, stats = ScriptedLM([a if isinstance(a, str) else json.dumps(a) for a in answers]), AskStats()
    out = ask_dict(lm, "question", validate=validate, json_schema=schema, stats=stats, **kw)
    assert all(s == schema for s in lm.schemas)  # the schema goes with the first request and every repair
    return out, stats, lm


def unknown_name(known):
    """A name no parser can match to ``known``."""
    return st.text(st.sampled_from("qwxz"), min_size=3, max_size=10).map(lambda s: "unknown " + s).filter(
        lambda s: norm(s) not in {norm(k) for k in known})


# ----------------------------------------------------------------------------- schema shape


def test_schemas_are_closed_objects_whose_enums_list_the_known_names():
    s = schemas.mapping_schema(["crayons", "apple"], ["paintbrush", "banana"])
    assert s["required"] == ["crayons", "apple"] and s["additionalProperties"] is False
    assert s["properties"]["crayons"]["enum"] == ["paintbrush", "banana", DISTRACTOR]
    s = schemas.intent_schema(["a_proximity_to_b", "ee_speed"])
    mot = s["properties"]["motivations"]
    assert mot["minItems"] == mot["maxItems"] == schemas.MOTIVATIONS
    assert mot["items"]["properties"]["features"]["items"]["enum"] == ["a_proximity_to_b", "ee_speed"]
    assert mot["items"]["properties"]["features"]["maxItems"] == 2  # no more than there are names
    axes = schemas.axes_schema(["paintbrush", "paintbrush", "banana"])["properties"]["axes"]
    assert axes["items"]["properties"]["objects"]["items"]["enum"] == ["paintbrush", "banana"]  # duplicates once
    assert schemas.category_schema()["properties"]["category"]["maxLength"] == schemas.CATEGORY_MAX_CHARS
    for bad in ([], ["ok", "  "], ['12" ruler'], ["back\\slash"]):
        with pytest.raises(GiftError, match="schemas: "):
            schemas.mapping_schema(bad, ["x"])


@SETTINGS
@given(features=name_sets(), objects=name_sets(), train=name_sets(max_size=6))
def test_every_schema_is_valid_json_schema_and_compiles_to_a_llama_cpp_grammar(features, objects, train):
    from llama_cpp.llama_grammar import json_schema_to_gbnf

    for s in (schemas.intent_schema(features), schemas.axes_schema(objects), schemas.mapping_schema(objects, train),
              schemas.category_schema()):
        jsonschema.Draft202012Validator.check_schema(s)
        gbnf = json_schema_to_gbnf(json.dumps(s))
        assert "root ::=" in gbnf
    # every name is a literal of the grammar, spelt as JSON (a quote in a literal is written \")
    for s, names in ((schemas.intent_schema(features), features), (schemas.axes_schema(objects), objects),
                     (schemas.mapping_schema(objects, train), [*objects, *train])):
        gbnf = json_schema_to_gbnf(json.dumps(s))
        for name in names:
            assert '"' + json.dumps(name).replace('"', '\\"') + '"' in gbnf, name


# ----------------------------------------------------------------------------- valid answers pass


@SETTINGS
@given(data=st.data(), features=name_sets())
def test_call1_every_schema_valid_answer_is_accepted_without_repair(data, features):
    schema = schemas.intent_schema(features)
    answer = data.draw(instances(schema))
    jsonschema.validate(answer, schema)
    # the parser strips texts and drops the (optional) similarities when one has no question
    assume(all(m["text"].strip() for m in answer["motivations"]))
    assume(all(s["question"].strip() for s in answer["semantic_similarities"]))
    d, stats, _ = ask([answer], schema, lambda d: parse_motivations(d, features) and None,
                      required_keys=("motivations",))
    assert stats.as_dict() == {"asked": 1, "answers": 1, "repairs": 0, "failed": 0}
    mots, sims = parse_motivations(d, features)
    assert [m.text for m in mots] == [m["text"].strip() for m in answer["motivations"]]
    for m, raw in zip(mots, answer["motivations"]):
        assert m.features == tuple(dict.fromkeys(raw["features"]))
    assert [s.objects for s in sims] == [tuple(dict.fromkeys(s["features"])) for s in answer["semantic_similarities"]]


@SETTINGS
@given(data=st.data(), objects=name_sets())
def test_call2_every_schema_valid_answer_is_accepted_without_repair(data, objects):
    schema = schemas.axes_schema(objects)
    answer = data.draw(instances(schema))
    assume(all(a["question"].strip() for a in answer["axes"]))
    d, stats, _ = ask([answer], schema, lambda d: parse_axes(d, objects) and None, required_keys=("axes",))
    assert stats.repairs == 0
    axes = parse_axes(d, objects)
    assert [a.objects for a in axes] == [tuple(dict.fromkeys(a["objects"])) for a in answer["axes"]]


@SETTINGS
@given(data=st.data(), test=name_sets(max_size=12), train=name_sets(max_size=6))
def test_call3_every_schema_valid_answer_is_accepted_without_repair(data, test, train):
    assume(not {norm(t) for t in test} & {norm(DISTRACTOR)})
    schema = schemas.mapping_schema(test, train)
    answer = data.draw(instances(schema))
    d, stats, _ = ask([answer], schema, lambda d: parse_mapping(d, test, train))
    assert stats.repairs == 0 and d == answer and set(d) == set(test)


@SETTINGS
@given(answer=instances(schemas.category_schema()))
def test_category_answers_within_the_schema_are_accepted_or_rejected_by_the_noun_phrase_rule(answer):
    category = answer["category"]
    expected = prompts.parse_category(category)
    if expected is None:  # the schema allows any short string; the parser wants a noun phrase of <= 8 words
        with pytest.raises(ValidationError, match="'category' must be a short plural noun phrase"):
            parse_category_answer({"category": category})
    else:
        assert parse_category_answer({"category": category}) == {"category": expected}


# ----------------------------------------------------------------------------- near misses are repaired


@SETTINGS
@given(data=st.data(), features=name_sets())
def test_call1_unknown_feature_is_named_in_the_repair_and_the_valid_answer_follows(data, features):
    schema = schemas.intent_schema(features)
    good = data.draw(instances(schema))
    assume(all(m["text"].strip() for m in good["motivations"]))
    bad = json.loads(json.dumps(good))
    ghost = data.draw(unknown_name(features))
    bad["motivations"][0]["features"].append(ghost)
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)
    d, stats, lm = ask([bad, good], schema, lambda d: parse_motivations(d, features) and None,
                       required_keys=("motivations",))
    assert stats.repairs == 1 and d["motivations"] == good["motivations"]
    repair = lm.prompts[1][-1].content
    assert f"features [{ghost!r}] do not exist" in repair


@SETTINGS
@given(data=st.data(), objects=name_sets(min_size=2))
def test_call2_unknown_object_is_named_in_the_repair(data, objects):
    schema = schemas.axes_schema(objects)
    good = data.draw(instances(schema))
    assume(all(a["question"].strip() for a in good["axes"]))
    ghost = data.draw(unknown_name(objects))
    bad = {"axes": [{"question": "is it one?", "objects": [objects[0], ghost]}]}
    with pytest.raises(ValidationError, match=re.escape(f"objects [{ghost!r}] do not exist")):
        parse_axes(bad, objects)
    assert [a.objects for a in parse_axes(bad, objects, strict=False)] == [(objects[0],)]
    d, stats, _ = ask([bad, good], schema, lambda d: parse_axes(d, objects) and None, required_keys=("axes",))
    assert stats.repairs == 1 and d == good


@SETTINGS
@given(data=st.data(), test=name_sets(min_size=2, max_size=10), train=name_sets(max_size=6))
def test_call3_unmapped_object_unknown_target_or_none_is_rejected_with_its_name(data, test, train):
    assume(not {norm(t) for t in test} & {norm(DISTRACTOR), "none"})
    schema = schemas.mapping_schema(test, train)
    good = data.draw(instances(schema))
    dropped = data.draw(st.sampled_from(test))
    missing = {k: v for k, v in good.items() if k != dropped}
    with pytest.raises(ValidationError, match=re.escape(f"not mapped: [{dropped!r}]")):
        parse_mapping(missing, test, train)
    target = data.draw(st.one_of(st.just("none"), unknown_name(train)))
    assume(norm(target) not in {norm(t) for t in train})
    wrong = {**good, dropped: target}
    with pytest.raises(ValidationError, match=re.escape(f"unknown targets [{f'{dropped!r} -> {target!r}'!r}]")):
        parse_mapping(wrong, test, train)
    for near in (missing, wrong):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(near, schema)
    d, stats, lm = ask([missing, wrong, good], schema, lambda d: parse_mapping(d, test, train))
    assert stats.as_dict() == {"asked": 1, "answers": 3, "repairs": 2, "failed": 0} and d == good
    assert "not mapped" in lm.prompts[1][-1].content and "unknown targets" in lm.prompts[2][-1].content


def test_no_dictionary_or_a_missing_key_is_repaired_then_fails_clearly():
    schema = schemas.intent_schema(["ee_speed"])
    with pytest.raises(LMAnswerError, match="after 1 repair request") as e:
        ask(["I think they wanted speed.", {"goals": []}], schema,
            lambda d: parse_motivations(d, ["ee_speed"]) and None, required_keys=("motivations",), max_repairs=1)
    assert "attempt 1: it contains no Python dictionary" in str(e.value)
    assert "attempt 2: the key 'motivations' is missing" in str(e.value) and e.value.raw == '{"goals": []}'


# ----------------------------------------------------------------------------- the kernels send the schemas


def test_each_call_sends_its_schema_and_unconstrained_kernels_send_none():
    from gift_kernels.intent import LMContrastiveIntentEstimator
    from gift_kernels.lm_kernels import GiftProbKernel, MappingKernel

    test, train = ["crayons", "apple"], ["paintbrush", "banana"]
    for constrained in (True, False):
        lm = ScriptedLM([json.dumps({"crayons": "paintbrush", "apple": "banana"})] * 2)
        k = MappingKernel(lm=lm, samples=2, constrained=constrained)
        k.votes(test, train, Intent("pack art supplies"))
        for sent, msgs in zip(lm.schemas, lm.prompts):
            new = json.loads(next(ln for ln in msgs[1].content.splitlines() if ln.startswith("New objects")
                                  ).split(":", 1)[1])
            # the keys in the order the prompt lists the new objects (each sample has its own order)
            assert sent == (schemas.mapping_schema(new, json.loads(next(
                ln for ln in msgs[1].content.splitlines() if ln.startswith("Training objects")).split(":", 1)[1]))
                if constrained else None)
        assert k.stats.as_dict() == {"asked": 2, "answers": 2, "repairs": 0, "failed": 0}

        lm = ScriptedLM([json.dumps({"category": "art supplies"})])
        GiftProbKernel(lm=lm, constrained=constrained).category(Intent("pack art supplies"))
        assert lm.schemas == [schemas.category_schema() if constrained else None]
        assert json.loads(lm.prompts[0][2].content) == {"category": prompts.CATEGORY_EXAMPLES[0][1]}

        est = LMContrastiveIntentEstimator(lm=ScriptedLM([json.dumps({"axes": [
            {"question": "is it for art?", "objects": ["paintbrush"]}]})]), constrained=constrained)
        est.semantic_axes([Motivation("pack art", ())], ["paintbrush", "banana"])
        assert est.lm.schemas == [schemas.axes_schema(["paintbrush", "banana"]) if constrained else None]


# ----------------------------------------------------------------------------- the embedded model


class Capture(LMBackend):
    """Passes every call to the real model and keeps each (schema, answer text)."""

    name = "capture"
    supports_choice_probabilities = True

    def __init__(self, inner):
        self.inner, self.model, self.seen = inner, inner.model, []

    def identity(self):
        return self.inner.identity()

    def complete(self, messages, **kw):
        out = self.inner.complete(messages, **kw)
        self.seen.append((kw.get("json_schema"), out.text))
        return out

    def choice_probabilities(self, messages, choices):
        return self.inner.choice_probabilities(messages, choices)


@pytest.fixture(scope="module")
def embedded_lm():
    gift_llm = pytest.importorskip("gift_llm")
    return gift_llm.get_default_lm()


@pytest.mark.slow
@pytest.mark.lm
def test_the_four_calls_of_the_embedded_model_answer_within_their_schemas_with_no_repair(embedded_lm):
    from test_intent import OBJECTS, pack_pair  # this directory's demonstration traces (pack family)

    import gift
    from gift_kernels.intent import LMContrastiveIntentEstimator
    from gift_kernels.lm_kernels import GiftProbKernel, MappingKernel

    lm = Capture(embedded_lm)
    est = LMContrastiveIntentEstimator(lm=lm)
    intent = est.estimate([pack_pair()], task_context=gift.get_task("pack_backpack").context(), objects=OBJECTS)
    k = MappingKernel(lm=lm, samples=2)
    votes = k.votes(["crayons", "apple", "toothbrush"], OBJECTS, intent)
    gp = GiftProbKernel(lm=lm)
    cat = gp.category(Intent("pack art supplies"), ["paintbrush", "sketchbook"], ["banana", "coffee mug"])
    assert [s["required"] for s, _ in lm.seen[:2]] == [["motivations", "semantic_similarities"], ["axes"]]
    assert len(lm.seen) == 1 + 1 + 2 + 1  # Call 1, Call 2, two Call-3 samples, the category: no repair
    for schema, text in lm.seen:
        jsonschema.validate(json.loads(text), schema)  # the answer is exactly JSON of its schema
    assert est.stats.repairs == k.stats.repairs == 0 and not k.fallbacks
    assert 1 <= len(intent.motivations) <= 3 and intent.axes
    assert votes.counts.sum(axis=1).tolist() == [2, 2, 2]
    assert "art" in cat.lower(), cat
