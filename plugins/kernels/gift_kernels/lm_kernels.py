"""LM kernels: ``gift`` (Call 3 with the intent), ``lm-no-intent`` (Call 3 without), and ``gift-prob``.

``gift`` / ``lm-no-intent`` (:class:`MappingKernel`): one LM call per sample lists every test object
(so the calls per intent are ``samples``, independent of the number of trajectories), each sample lists
the objects in its own shuffled order with its own seed, and sends the JSON schema of that answer
(:func:`gift_kernels.schemas.mapping_schema`: every test object a key, each value a training object or
distractor; on llama.cpp a grammar); ``K[i, j]`` = fraction of samples mapping test
object i to training object j. The mode over {training objects, distractor} is the binary decision and
its share the agreement rate (:meth:`MappingKernel.votes`).

``gift-prob`` (:class:`GiftProbKernel`): a continuous kernel. The LM names, once per intent, the kind of
object the goal is about (``{"category": "art supplies"}``, :func:`gift_kernels.schemas.category_schema`), then answers one yes/no question per object, "is a <object>
(<description>) one of the <category>?", read through ``choice_probabilities``. Its score is the log-odds
``log P(yes) - log P(no)``; by default it is averaged, as z-scores, with a contrastive MiniLM description
similarity (the largest cosine to a training object that is relevant under the intent minus the largest
cosine to one that is not), each term weighted by how well it separates the relevant training objects
from the others. ``docs/results/gift_prob.md`` has the variants measured and why this won. Training
objects are never shown to the LM as labelled examples, so they can calibrate the threshold by
leave-one-out.

Matrix rule of the relevance kernels (``gift-prob``): ``K[i, j] = r_i`` for the training objects j that
are relevant under the intent (``relevant_train`` when given, else the training objects whose own
log-odds is positive, at least the best one), 0 for the others; ``r_i`` in [0, 1] is the relevance of
test object i. :meth:`GiftProbKernel.relevance` returns ``r`` ``[n_test]`` directly.
"""

from __future__ import annotations

import math
import threading
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

import attrs
import numpy as np

import gift

from gift.core.data import DISTRACTOR, Intent, Message, ObjectSpec, RelevanceScores
from gift.core.errors import GiftError, LMAnswerError, ValidationError
from gift.core.interfaces import LMBackend, RelevanceKernel, SimilarityKernel
from gift_kernels import prompts, schemas

#: Log-odds are clipped to ±LOGIT_CLIP (probabilities of exactly 0 or 1 would be infinite).
LOGIT_CLIP = 12.0


def _object_names(objs: Sequence[ObjectSpec | str]) -> list[str]:
    return [o.name if isinstance(o, ObjectSpec) else str(o) for o in objs]


# ============================================================================= Call 3 mapping kernels


def _valid_part(answer: Mapping[str, Any], test: Sequence[str], train: Sequence[str]
                ) -> tuple[dict[str, str], list[str]]:
    """``({test object: target}`` for the valid entries of a Call-3 answer, ``[unknown target entries])``."""
    def norm(s: Any) -> str:
        return " ".join(str(s).replace("_", " ").lower().split())

    tests = {norm(t): t for t in test}
    targets = {norm(t): t for t in train}
    targets[norm(DISTRACTOR)] = DISTRACTOR
    out: dict[str, str] = {}
    unknown_targets = []
    for k, v in answer.items():
        t = tests.get(norm(k))
        if t is None:
            continue  # an object that is not in the scene: ignored
        if isinstance(v, (list, tuple)) and len(v) == 1:
            v = v[0]
        target = targets.get(norm(v)) if isinstance(v, str) else None
        if target is None:
            unknown_targets.append(f"{k!r} -> {v!r}")
            continue
        out[t] = target
    return out, unknown_targets


def mapping_max_tokens(test: Sequence[str], train: Sequence[str]) -> int:
    """Token budget of one Call-3 answer: every test object with the longest target, at about 3
    characters per token, plus room; at least 512."""
    longest = max([len(DISTRACTOR), *map(len, train)])
    return max(512, 64 + sum(len(t) + longest + 8 for t in test) // 3)


def parse_mapping(answer: Mapping[str, Any], test: Sequence[str], train: Sequence[str]) -> dict[str, str]:
    """Validate a Call-3 answer: every test object mapped, targets only training objects or distractor.

    Names are matched case- and whitespace-insensitively. Raises :class:`ValidationError` (a ValueError) naming what is
    missing or unknown (``ask_dict`` turns that into a repair request).
    """
    out, unknown_targets = _valid_part(answer, test, train)
    problems = []
    missing = [t for t in test if t not in out]
    if unknown_targets:
        problems.append(f"unknown targets {unknown_targets}; allowed: {list(train)} or {DISTRACTOR!r}")
    if missing:
        problems.append(f"these new objects are not mapped: {missing}")
    if problems:
        raise ValidationError("; ".join(problems))
    return out


@attrs.frozen
class MappingVotes:
    """Votes of N samples: ``counts`` ``[n_test, n_train + 1]`` (last column: distractor)."""

    test: tuple[str, ...]
    train: tuple[str, ...]
    counts: np.ndarray = attrs.field(eq=False)
    samples: int

    @property
    def shares(self) -> np.ndarray:
        return self.counts / max(self.samples, 1)

    def mode(self) -> dict[str, str]:
        """Binary decision per test object: the most voted target (ties: training objects first)."""
        targets = (*self.train, DISTRACTOR)
        return {t: targets[int(np.argmax(self.counts[i]))] for i, t in enumerate(self.test)}

    def agreement(self) -> dict[str, float]:
        """Share of samples that agree with the mode, per test object (the confidence)."""
        return {t: float(self.shares[i].max()) for i, t in enumerate(self.test)}


class MappingKernel(SimilarityKernel):
    """Call 3: the LM maps all test objects at once, ``samples`` times; K = vote shares."""

    name: ClassVar[str] = "gift"
    uses_intent: ClassVar[bool] = True

    def __init__(self, lm: LMBackend | str | None = None, samples: int = 10, temperature: float = 0.7,
                 seed: int = 0, use_intent: bool = True, max_repairs: int = 2, constrained: bool = True) -> None:
        from gift_llm.structured import AskStats

        if not isinstance(samples, int) or samples < 1:
            raise GiftError(f"{self.name} kernel: samples must be a positive integer, got {samples!r}")
        self._lm_spec, self._lm = lm, None
        self.samples, self.temperature, self.seed = samples, float(temperature), int(seed)
        self.use_intent, self.max_repairs = bool(use_intent), int(max_repairs)
        #: Send Call 3's JSON schema (``schemas.mapping_schema``) with every request (False: free text).
        self.constrained = bool(constrained)
        self.calls = 0  # LM calls made (including those served from the LM cache)
        self.fallbacks: list[str] = []  # samples completed by default (see _sample)
        self.stats = AskStats()  # answers read, repair requests, samples still invalid after the repairs

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(samples={self.samples}, temperature={self.temperature}, seed={self.seed}, "
                f"use_intent={self.use_intent}, max_repairs={self.max_repairs}, constrained={self.constrained})")

    @property
    def lm(self) -> LMBackend:
        if self._lm is None:
            self._lm = gift.resolve_lm(self._lm_spec)
        return self._lm

    def _sample(self, test: list[str], train: list[str], intent: Intent | None, k: int) -> dict[str, str]:
        from gift_llm.structured import ask_dict, last_dict

        rng = np.random.default_rng(self.seed * 1000 + k)
        t_order = [test[i] for i in rng.permutation(len(test))]
        s_order = [train[i] for i in rng.permutation(len(train))]
        messages = prompts.mapping_messages(t_order, s_order, intent)
        schema = schemas.mapping_schema(t_order, s_order) if self.constrained else None
        self.calls += 1
        try:
            answer = ask_dict(self.lm, messages, validate=lambda d: parse_mapping(d, test, train),
                              max_repairs=self.max_repairs, temperature=self.temperature, seed=self.seed + k,
                              max_tokens=mapping_max_tokens(test, train), json_schema=schema, stats=self.stats)
        except LMAnswerError as e:
            # still incomplete after the repairs: keep the valid part of the last answer; an object it
            # leaves unmapped (or maps to an unknown name) aligns to nothing, i.e. distractor. An answer
            # without any dictionary is not a mapping at all: that error stands.
            partial = last_dict(e)
            if partial is None:
                raise
            valid, _ = _valid_part(partial, test, train)
            note = (f"sample {k}: {len(test) - len(valid)} of {len(test)} objects defaulted to {DISTRACTOR!r} "
                    f"after {self.max_repairs} repairs")
            self.fallbacks.append(note)
            warnings.warn(f"{self.name} kernel: {note} ({str(e).splitlines()[0][:300]})", RuntimeWarning,
                          stacklevel=2)
            return {t: valid.get(t, DISTRACTOR) for t in test}
        return parse_mapping(answer, test, train)

    def votes(self, test: Sequence[ObjectSpec | str], train: Sequence[ObjectSpec | str],
              intent: Intent | None = None) -> MappingVotes:
        """Run the ``samples`` Call-3 samples and count where each test object went."""
        if self.use_intent and intent is None:
            raise GiftError(f"the {self.name!r} kernel conditions on an intent; pass one (or use 'lm-no-intent')")
        tests, trains = _object_names(test), _object_names(train)
        counts = np.zeros((len(tests), len(trains) + 1))
        col = {n: j for j, n in enumerate(trains)} | {DISTRACTOR: len(trains)}
        row = {n: i for i, n in enumerate(tests)}
        if tests and trains:
            for k in range(self.samples):
                for t, target in self._sample(tests, trains, intent if self.use_intent else None, k).items():
                    counts[row[t], col[target]] += 1
        return MappingVotes(tuple(tests), tuple(trains), counts, self.samples if tests and trains else 0)

    def similarity(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                   intent: Intent | None = None) -> np.ndarray:
        """``[n_test, n_train]``: share of samples mapping test object i to training object j."""
        v = self.votes(test, train, intent)
        return v.shares[:, : len(v.train)] if v.samples else np.zeros((len(test), len(train)))


class NoIntentMappingKernel(MappingKernel):
    """Call 3 without the intent (the paper's LM-no-intent ablation); K = vote shares."""

    name: ClassVar[str] = "lm-no-intent"
    uses_intent: ClassVar[bool] = False

    def __init__(self, lm: LMBackend | str | None = None, samples: int = 10, temperature: float = 0.7,
                 seed: int = 0, max_repairs: int = 2, constrained: bool = True) -> None:
        super().__init__(lm=lm, samples=samples, temperature=temperature, seed=seed, use_intent=False,
                         max_repairs=max_repairs, constrained=constrained)


# ============================================================================= gift-prob


def _zscore(x: np.ndarray, ref: slice = slice(None)) -> np.ndarray:
    """``(x - mean) / sd`` with the statistics of ``x[ref]``."""
    mu, sd = x[ref].mean(), x[ref].std()
    return (x - mu) / sd if sd > 1e-9 else x - mu


def _one_of(option: str, value: object, allowed: Sequence[object]) -> None:
    """Raise a :class:`GiftError` naming ``gift-prob``'s ``option`` unless ``value`` is one of ``allowed``."""
    if value not in allowed:
        raise GiftError(f"gift-prob: {option} must be one of {allowed}, got {value!r}")


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.asarray(x, dtype=float)))


COMBINE = ("none", "language")
EMBED_REFERENCE = ("relevant", "contrastive", "prototype")
EMBED_TEXT = ("name+description", "description")
#: ``ask_text``: one form of :data:`gift_kernels.prompts.OBJECT_TEXT`, or several combined (:data:`ASK_FORMS`).
ASK_TEXT = (*prompts.OBJECT_TEXT, "both", "all", "both&name")
#: The forms each combined ``ask_text`` asks, and how their log-odds are combined ("mean"; "min-name": the smaller
#: of the mean of the other forms and the name-only form's, so an object must pass both).
ASK_FORMS = {"both": (("name+description", "description"), "mean"),
             "all": (("name+description", "description", "name"), "mean"),
             "both&name": (("name+description", "description", "name"), "min-name")}
STANDARDIZE = ("pooled", "train")
WEIGHTING = ("reliability", "equal")
CATEGORY_FROM = ("goal+objects", "goal")
CANDIDATES = ("text", "all")
SELECT = ("first", "margin")
LADDER = ("never", "inferred", "always")
RUNGS = ("breadth", "facets", "both", "all", "both+names")
CHECK = ("none", "fit", "weight", "margin", "fit-best")
#: How :meth:`GiftProbKernel.score_with_answers` uses the human's answers: ``"ladder"`` names the category ladder
#: again with the answered objects (LM calls); ``"evidence"`` asks nothing new and weighs the answered objects
#: as labelled evidence beside the training objects.
RESCORE_WITH = ("ladder", "evidence")
VETO = ("none", "lm")
LADDER_TEXT = prompts.LADDER_TEXT  # how the ladder's questions show each object


def parse_category_answer(answer: Mapping[str, Any]) -> dict[str, str]:
    """Validate a category answer ``{"category": <noun phrase>}``: the phrase cleaned by
    :func:`gift_kernels.prompts.parse_category`; :class:`ValidationError` when it is no short noun phrase."""
    value = answer.get("category")
    cat = prompts.parse_category(value) if isinstance(value, str) else None
    if cat is None:
        raise ValidationError(f"'category' must be a short plural noun phrase (at most 8 words), got {value!r}")
    return {"category": cat}


def separation_weight(train_scores: np.ndarray, relevant: np.ndarray) -> float:
    """How far one score separates the relevant training objects from the others: ``max(AUC - 1/2, 0)``.

    ``train_scores`` ``[n_train]`` (leave-one-out), ``relevant`` ``[n_train]`` bool. ``nan`` when one
    class is empty (no evidence either way).
    """
    from gift.core.metrics import roc_auc

    auc = roc_auc(train_scores, relevant)
    return float("nan") if math.isnan(auc) else max(auc - 0.5, 0.0)


class GiftProbKernel(RelevanceKernel):
    """Continuous GIFT kernel: P(yes) that an object is what the goal is about, as log-odds.

    Default recipe (``docs/results/gift_prob.md``): the LM names the kind of object the goal is about
    from the goal and the training objects the demonstrations treat as part of it (one few-shot call per
    intent, plus one per training object with that object left out; :meth:`category`), then answers per
    object "is a <object> (<description>) one of the <category>?"; the log-odds and a contrastive MiniLM similarity
    of the descriptions (without the names; the mean cosine to the relevant training objects less the mean to the
    others) are z-scored and averaged, each weighted by how well it separates the relevant training
    objects from the others (leave-one-out; ``weighting="reliability"``). ``calibration="pooled"`` instead
    puts both terms through one logistic model fitted on pooled development-suite intents and updated with
    this intent's relevant training objects (cut 1/2); measured better with true intents, worse with
    inferred ones, so it is not the default.

    Options: ``template`` (a key of :data:`gift_kernels.prompts.RELEVANCE_TEMPLATES`), ``use_descriptions``,
    ``axes`` (also ask the intent's semantic-axis questions and keep the highest log-odds per object),
    ``combine`` (``"language"``: average the z-scored log-odds with z-scored MiniLM description
    similarity; ``"none"``: the log-odds alone), ``embed_reference`` (``"relevant"``: the largest cosine
    to a relevant training object; ``"contrastive"``: that minus the largest cosine to another training
    object; ``"prototype"``, the default since 2026-12-07: the mean cosine to the relevant training objects
    minus the mean to the others, so an object must resemble the class, not one member), ``embed_text``
    (what MiniLM embeds: ``"description"``, the default, or ``"name+description"``),
    ``ask_text`` (how the LM's yes/no questions show each object: ``"both"``, the default, the mean log-odds
    of the question with the name and the one with the description alone; ``"name+description"``;
    ``"description"``; ``"name"``; ``"all"``, the mean of those three; ``"both&name"``, the smaller of "both"'s
    log-odds and the name-only question's, so that a look-alike must pass its name too), ``weight`` of the
    language term in the average, ``weighting`` (``"reliability"``: scale each
    term's weight by ``max(AUC - 1/2, 0)`` of its leave-one-out scores on the training objects, so a term
    that inverts the demonstrated labels for this intent is dropped; all zero falls back to the plain
    weights; ``"equal"``: the plain weights), ``category_from`` (``"goal+objects"``: name the category from
    the goal and the demonstrated training objects when ``relevant_train`` is given; ``"goal"``: from the
    goal alone), ``cut_prior`` (weight of the scores' own boundary 1/2 against the leave-one-out cut in the
    train-calibrated threshold; 0: the leave-one-out cut alone; default 1, the boundary alone), ``ladder``
    (``"inferred"``, the default: for an intent inferred from demonstrations, also name categories from the
    demonstrated objects alone, the rungs, and average the z-scored log-odds under them and the goal's;
    the scene under each category alone is reported as an intent candidate that answers can pick, see
    :mod:`gift.core.queries`; ``"always"``; ``"never"``, the default with a ``calibration``), ``rungs``
    (``"both"``, the default: the ladder's rungs are three breadths of one kind and, from a second call, the
    kind, material and property the objects share, "none" dropped; ``"breadth"``; ``"facets"``; ``"all"``: those and
    a part the objects have, from a third call), ``check``
    (``"fit"``, the default: each of the ladder's categories is first asked of the training objects as named and
    kept only if it puts every demonstrated object above every left-alone one; ``"weight"``: weighted by its
    AUC - 1/2 there; ``"margin"``: those "fit" keeps, weighted by their log-odds gap between the lowest
    demonstrated and the highest left-alone object; ``"fit-best"``: the widest gap alone; ``"none"``: all
    averaged as they are), ``rescore_with`` (what the human's answers do when the
    scene is re-scored with them, :meth:`score_with_answers`: ``"ladder"`` names the ladder again with
    them; ``"evidence"``, the default, asks the LM nothing new and counts them beside the training objects),
    ``ladder_text`` (how the ladder's questions show each object: ``"name"``, the default, or
    ``"name+description"``), ``veto`` (``"none"``, the default; ``"lm"``: when the LM term separates the training
    objects at least as well as the MiniLM term, an object the LM term puts below the scene's mean is put below the
    cut whatever the MiniLM term says; against look-alike distractors, front_half.md section 43). The defaults
    were chosen on the development suites, docs/results/front_half.md (sections 10-14).
    """

    name: ClassVar[str] = "gift-prob"
    uses_intent: ClassVar[bool] = True

    def __init__(self, lm: LMBackend | str | None = None, template: str = "category", use_descriptions: bool = True,
                 axes: bool = False, combine: str = "language", embed_reference: str = "prototype",
                 weight: float = 0.5, standardize: str = "pooled", weighting: str = "reliability",
                 category_from: str = "goal+objects", language_kernel: SimilarityKernel | None = None,
                 constrained: bool = True, candidates: str = "text", candidate_terms: bool = False,
                 select: str = "first", calibration: str = "none", cut_prior: float = 1.0,
                 ladder: str | None = None, rungs: str = "both", check: str = "fit",
                 embed_text: str = "description", ask_text: str = "both", rescore_with: str = "evidence",
                 ladder_text: str = "name", veto: str = "none") -> None:
        if template not in prompts.RELEVANCE_TEMPLATES:
            raise GiftError(f"gift-prob: unknown template {template!r}; one of {sorted(prompts.RELEVANCE_TEMPLATES)}")
        _one_of("combine", combine, COMBINE)
        _one_of("embed_reference", embed_reference, EMBED_REFERENCE)
        _one_of("embed_text", embed_text, EMBED_TEXT)
        #: What the MiniLM term embeds of each object: ``"description"`` (the default: the name left out, so
        #: the LM's question, which carries the name, and the MiniLM term do not both read it; a distractor
        #: named like the class is then judged by what it is) or ``"name+description"``. Chosen on gift-dev7
        #: by a rule written before it was run (train-calibrated F1 0.767 -> 0.788 pooled over both intent
        #: sources; docs/results/front_half.md, section 19).
        self.embed_text = embed_text
        _one_of("ask_text", ask_text, ASK_TEXT)
        #: How each object is shown in the LM's yes/no questions (:data:`gift_kernels.prompts.OBJECT_TEXT`):
        #: ``"both"`` (the default: both questions below asked, their log-odds averaged; twice the questions),
        #: ``"name+description"``, ``"description"`` (no name: "a thing described as ...") or ``"name"`` (no
        #: description); ``"all"`` (the three, averaged) or ``"both&name"`` (the smaller of "both"'s mean and the
        #: name-only log-odds: a look-alike described like a member must pass its name too). Chosen on
        #: gift-dev8 by a rule written before it was run (train-calibrated F1 0.825 -> 0.838 pooled over both
        #: intent sources; docs/results/front_half.md, section 20).
        self.ask_text = ask_text
        _one_of("rescore_with", rescore_with, RESCORE_WITH)
        #: What answers do when the scene is re-scored with them (:meth:`score_with_answers`; callers re-score
        #: by default, ``--no-rescore`` turns it off): ``"evidence"`` (the default: no LM call; the answered
        #: test objects join the training objects as labelled evidence in the check of the categories, the
        #: MiniLM term's references and the terms' weights) or ``"ladder"`` (the ladder named again with them,
        #: LM calls). "evidence" was chosen on gift-dev10 by a rule written before it was run (pooled F1 after
        #: 2 questions, mean over both intent sources, 0.882 -> 0.908; docs/results/queries.md).
        self.rescore_with = rescore_with
        _one_of("ladder_text", ladder_text, LADDER_TEXT)
        #: How the ladder's questions (:meth:`ladder`) show each object: ``"name"`` (the default) or
        #: ``"name+description"`` ("cast-iron dog (A heavy ...)"; the worked examples with descriptions too).
        self.ladder_text = ladder_text
        _one_of("veto", veto, VETO)
        #: ``"lm"``: in :meth:`_combine`, when the LM term's reliability on the training objects is at least the
        #: MiniLM term's, an object whose z-scored LM term is below 0 gets the smaller of its combined score and that
        #: z-score, so it falls below the scale's boundary (a look-alike whose description MiniLM ranks with the
        #: members, which the LM's questions reject; front_half.md, section 42). ``"none"``: the default; "lm" was
        #: not adopted on the blind gift-dev24 (-0.001 pooled F1 over both intent sources where its rule asked for
        #: +0.010; section 43).
        self.veto = veto
        _one_of("standardize", standardize, STANDARDIZE)
        _one_of("weighting", weighting, WEIGHTING)
        _one_of("category_from", category_from, CATEGORY_FROM)
        if not 0.0 <= float(weight) <= 1.0:
            raise GiftError(f"gift-prob: weight must be in [0, 1], got {weight!r}")
        _one_of("candidates", candidates, CANDIDATES)
        _one_of("select", select, SELECT)
        self.select = select
        if ladder is None:  # the ladder's averaged z-scores are not what a calibration was fitted on
            ladder = "inferred" if calibration == "none" else "never"
        _one_of("ladder", ladder, LADDER)
        if ladder != "never" and calibration != "none":
            raise GiftError("gift-prob: a calibration is fitted on one category's log-odds; the ladder averages "
                            "z-scores of several, so use ladder='never' with calibration")
        #: When to add the category ladder (:meth:`ladder`): three names, narrow to broad, of what the
        #: demonstrated training objects share, asked without the goal; the LM term becomes the mean of the
        #: z-scored log-odds under the goal's category and each rung. ``"inferred"``: only for an intent
        #: inferred from demonstrations (whose goal text the small model wrote; the default, chosen on gift-dev,
        #: gift-dev2 and lm-dev: mean train-calibrated F1 0.764 -> 0.808 with cut_prior=1); ``"always"``;
        #: ``"never"`` (the default with a calibration).
        self.ladder_mode = ladder
        _one_of("rungs", rungs, RUNGS)
        #: What the ladder's rungs are: ``"breadth"``, one kind named narrow, middle and broad;
        #: ``"facets"``, the kind, the material and a property the demonstrated objects share, each possibly
        #: none (:func:`gift_kernels.prompts.facet_messages`); ``"both"``, the default: the rungs of the two
        #: (two calls per ladder). Chosen on gift-dev, gift-dev2 and lm-dev by a rule written before the runs
        #: (mean inferred train-calibrated F1 0.808 -> 0.813, no suite loses; facets alone lose 0.029 on
        #: gift-dev2); docs/results/front_half.md, section 11. ``"all"``: those and, from a third call, a part
        #: or feature the objects have ("things with a chain"; :func:`gift_kernels.prompts.part_messages`).
        #: ``"both+names"``: ``"both"`` and, with no LM call, the word every demonstrated object's name has and no
        #: other training object's ("basket things"; :func:`gift_kernels.prompts.shared_name_category`); not
        #: adopted: +0.008 inferred F1 on the blind gift-dev22 where its rule asked for +0.010 (front_half.md, 40).
        self.rungs = rungs
        _one_of("check", check, CHECK)
        #: How the ladder's categories (the goal's and each rung) are checked against the training objects they
        #: were named from before they are averaged: each is asked of every training object as named (in-sample)
        #: and scored by its AUC separating the demonstrated objects from the left-alone ones. ``"none"``: the
        #: plain mean of all; ``"fit"``: the mean of those with AUC 1 (else those with the best AUC);
        #: ``"weight"``: weights ``max(AUC - 1/2, 0)`` (all zero: the plain mean); ``"margin"``: of those "fit"
        #: keeps, each weighted by its in-sample gap (lowest demonstrated minus highest left-alone log-odds; no
        #: positive gap: as "fit"); ``"fit-best"``: the widest gap alone. Costs ``n_train`` yes/no
        #: questions per category. "fit" is the default since front_half.md section 14 (a rule written before a
        #: fifth development suite was seen: level or better there, and better pooled over all 38 dev intents).
        self.check = check
        self._ladder_memo: dict[tuple, dict[str, str]] = {}
        if not 0.0 <= float(cut_prior) <= 1.0:
            raise GiftError(f"gift-prob: cut_prior must be in [0, 1], got {cut_prior!r}")
        #: Weight of the scale's own boundary, 1/2 (the scene's mean combined z-score; for ``combine="none"``
        #: P(yes) = P(no)), against the leave-one-out cut in the train-calibrated threshold (0: that cut
        #: alone; 1: the boundary alone, the default). Chosen with the ladder on gift-dev, gift-dev2 and lm-dev:
        #: 3-6 training objects place a cut more noisily than the scale's own boundary
        #: (docs/results/front_half.md, section 10).
        self.cut_prior = float(cut_prior)
        #: ``"none"``: z-scores per intent with reliability weights, the cut placed on the training scores;
        #: ``"pooled"``: the shipped :class:`~gift_kernels.calibration.TermCalibration`, updated per intent with
        #: the relevant training objects (cut 1/2); or the path of a calibration file. Default ``"none"``: the
        #: pooled calibration, fitted on gift-dev with the true intents, lifted train-calibrated F1 there
        #: (0.78 -> 0.84) but collapsed with inferred intents (0.65 -> 0.35: their categories put the LM
        #: log-odds on another scale); docs/results/front_half.md.
        if calibration != "none" and combine != "language":
            raise GiftError("gift-prob: calibration needs both terms (combine='language')")
        self.calibration_spec = calibration
        if calibration == "none":
            self.calibration = None
        else:
            from gift_kernels.calibration import TermCalibration

            self.calibration = TermCalibration.load(None if calibration == "pooled" else calibration)
        #: ``"text"``: the intent's text names the category; ``"all"``: every motivation and the objects alone
        #: are candidates, and the training objects verify them (:meth:`candidate_goals`).
        self.candidates = candidates
        #: Also ask every candidate's category about the test objects and report it (for studies; costs LM calls).
        self.candidate_terms = bool(candidate_terms)
        self._lm_spec, self._lm = lm, None
        self.template, self.use_descriptions, self.axes = template, bool(use_descriptions), bool(axes)
        self.combine, self.embed_reference, self.weight = combine, embed_reference, float(weight)
        self.standardize, self.weighting, self.category_from = standardize, weighting, category_from
        self._category_memo: dict[tuple, str] = {}
        #: Send the category call's JSON schema (``schemas.category_schema``) with each request.
        self.constrained = bool(constrained)
        self._language = language_kernel
        self._memo: dict[tuple, float] = {}
        self._lock = threading.Lock()
        #: Per thread, while :meth:`score` collects its questions (:meth:`_in_object_order`): the questions
        #: not yet answered, in the order asked; None otherwise.
        self._collecting = threading.local()
        self.calls = 0  # distinct yes/no questions sent to the LM

    def __repr__(self) -> str:
        return (f"GiftProbKernel(template={self.template!r}, use_descriptions={self.use_descriptions}, "
                f"axes={self.axes}, combine={self.combine!r}, embed_reference={self.embed_reference!r}, "
                f"weight={self.weight}, weighting={self.weighting!r}, category_from={self.category_from!r}, "
                f"cut_prior={self.cut_prior}, ladder={self.ladder_mode!r}, rungs={self.rungs!r}, check={self.check!r}, "
                f"embed_text={self.embed_text!r}, ask_text={self.ask_text!r}, rescore_with={self.rescore_with!r}, "
                f"ladder_text={self.ladder_text!r}, veto={self.veto!r}, standardize={self.standardize!r}, "
                f"constrained={self.constrained}, "
                f"candidates={self.candidates!r}, candidate_terms={self.candidate_terms}, select={self.select!r}, "
                f"calibration={self.calibration_spec!r}, "
                f"language_kernel={'default' if self._language is None else repr(self._language)})")

    # ------------------------------------------------------------------ pieces
    @property
    def lm(self) -> LMBackend:
        if self._lm is None:
            lm = gift.resolve_lm(self._lm_spec)
            if not getattr(lm, "supports_choice_probabilities", False):
                raise GiftError(
                    f"gift-prob needs token log-probabilities, which the LM backend {lm.identity()!r} does not "
                    f"provide; use the embedded llama.cpp model (the default) or another backend with "
                    f"supports_choice_probabilities=True, or the binary 'gift' kernel on this backend")
            self._lm = lm
        return self._lm

    @property
    def language(self) -> SimilarityKernel:
        if self._language is None:
            import gift

            names = self.embed_text != "description"
            from gift.core.errors import UnknownComponentError

            try:
                self._language = gift.get_kernel("language", use_descriptions=True, names=names)
            except UnknownComponentError:  # the plugin's registration not loaded (e.g. GIFT_PLUGINS filter)
                from gift_kernels.language import LanguageKernel

                self._language = LanguageKernel(use_descriptions=True, names=names)
        return self._language

    def _ask(self, messages: tuple[Message, ...]) -> float:
        key = (self.lm.identity(), tuple((m.role, m.content, m.cut) for m in messages))
        with self._lock:
            if key in self._memo:
                return self._memo[key]
        pending = getattr(self._collecting, "questions", None)
        if pending is not None:  # collecting: remembered, answered later (the value is a placeholder)
            pending.append(messages)
            return 0.0
        probs = self.lm.choice_probabilities(messages, ["yes", "no"])
        self.calls += 1
        p_yes, p_no = float(probs.get("yes", 0.0)), float(probs.get("no", 0.0))
        lo = math.log(max(p_yes, 1e-12)) - math.log(max(p_no, 1e-12))
        lo = float(np.clip(lo, -LOGIT_CLIP, LOGIT_CLIP))
        with self._lock:
            self._memo[key] = lo
        return lo

    def category(self, intent: Intent | str | None, handled: Sequence[str] = (), left_alone: Sequence[str] = ()
                 ) -> str:
        """The kind of object a goal is about ("art supplies"), asked once per question (greedy).

        ``intent``: an Intent, its goal text, or None (no goal: name the kind from the objects alone). With
        ``category_from="goal+objects"`` and at least one ``handled`` training object (one the
        demonstrations treat as part of the goal; ``left_alone``: the others) the LM names the kind
        from the goal (if any) and those objects; else from the goal alone. An answer that is not a short
        noun phrase falls back, with a warning, to the goal itself.
        """
        text = intent.text if isinstance(intent, Intent) else intent
        goal = prompts.goal_text(text) if text else None
        use_objects = (self.category_from == "goal+objects" or goal is None) and len(handled) > 0
        if goal is None and not use_objects:
            raise GiftError("gift-prob: naming a category without a goal needs at least one handled object")
        key = (goal, tuple(handled), tuple(left_alone)) if use_objects else (goal,)
        with self._lock:
            if key in self._category_memo:
                return self._category_memo[key]
        from gift_llm.structured import ask_dict

        msgs = (prompts.category_from_objects_messages(goal, handled, left_alone) if use_objects
                else prompts.category_messages(goal))
        self.calls += 1
        try:
            cat = ask_dict(self.lm, msgs, validate=parse_category_answer, max_repairs=1, temperature=0.0,
                           max_tokens=32, json_schema=schemas.category_schema() if self.constrained else None,
                           required_keys=("category",))["category"]
        except LMAnswerError as e:
            shown = goal or f"the objects {', '.join(handled)}"
            warnings.warn(f"gift-prob: the LM named no object category for {shown!r} (answer "
                          f"{e.raw[:80]!r}); asking about the goal itself", stacklevel=2)
            cat = prompts.fallback_category(goal or f"handle the {', '.join(handled)}")
        with self._lock:
            self._category_memo[key] = cat
        return cat

    def ladder(self, handled: Sequence[str], left_alone: Sequence[str] = (),
               descriptions: Mapping[str, str] | None = None) -> tuple[str, ...]:
        """Names of what the ``handled`` training objects share that the ``left_alone`` ones do not: narrow to
        broad (``rungs="breadth"``) or kind, material, property (``"facets"``); one greedy call per pair of
        lists, no goal text; duplicates and "none" dropped. An answer with no usable name gives ``()``, with a
        warning. ``descriptions`` (name -> description): shown beside the names when ``ladder_text`` says so."""
        return tuple(self._ladder_levels(handled, left_alone, descriptions).values())

    def _ladder_levels(self, handled: Sequence[str], left_alone: Sequence[str] = (),
                       descriptions: Mapping[str, str] | None = None) -> dict[str, str]:
        """:meth:`ladder` by level (``prompts.LADDER_LEVELS``, ``FACET_LEVELS``, ``PART_LEVELS``, as ``rungs``
        says), levels without a name, or repeating an earlier level's name, left out."""
        names: dict[str, str] = {}
        for kind in self._ladder_kinds():
            for lv, cat in self._ask_ladder(kind, handled, left_alone, descriptions).items():
                if cat.lower() not in [n.lower() for n in names.values()]:
                    names[lv] = cat
        return names

    def _ladder_kinds(self) -> tuple[str, ...]:
        return {"breadth": ("breadth",), "facets": ("facets",), "both": ("breadth", "facets"),
                "all": ("breadth", "facets", "parts"), "both+names": ("breadth", "facets", "names")}[self.rungs]

    def _ask_ladder(self, kind: str, handled: Sequence[str], left_alone: Sequence[str],
                    descriptions: Mapping[str, str] | None = None) -> dict[str, str]:
        """One ladder call (``kind``: ``"breadth"``, ``"facets"`` or ``"parts"``), memoized: its named levels. The
        objects are shown with ``descriptions`` when ``ladder_text="name+description"``. ``"names"`` asks no LM: the
        word the handled names share (:func:`gift_kernels.prompts.shared_name_category`), if any."""
        if kind == "names":
            cat = prompts.shared_name_category(handled, left_alone)
            return {prompts.NAME_LEVELS[0]: cat} if cat else {}
        descriptions = None if self.ladder_text == "name" else {n: (descriptions or {}).get(n, "")
                                                                 for n in (*handled, *left_alone)}
        key = (kind, tuple(handled), tuple(left_alone), descriptions and tuple(descriptions.values()))
        with self._lock:
            if key in self._ladder_memo:
                return self._ladder_memo[key]
        from gift_llm.structured import ask_dict

        self.calls += 1
        levels, ask = {"breadth": (prompts.LADDER_LEVELS, prompts.ladder_messages),
                       "facets": (prompts.FACET_LEVELS, prompts.facet_messages),
                       "parts": (prompts.PART_LEVELS, prompts.part_messages)}[kind]
        msgs = ask(handled, left_alone, descriptions)
        try:
            ans = ask_dict(self.lm, msgs, temperature=0.0, max_tokens=96,
                           json_schema=schemas.ladder_schema(levels) if self.constrained else None,
                           required_keys=levels)
        except LMAnswerError as e:
            warnings.warn(f"gift-prob: the LM named no category ladder for {', '.join(handled)} (answer "
                          f"{e.raw[:80]!r}); using the goal's category alone", stacklevel=3)
            ans = {}
        names: dict[str, str] = {}
        for lv in levels:
            cat = prompts.parse_category(ans[lv]) if isinstance(ans.get(lv), str) else None
            if cat and not prompts.is_no_name(cat):  # repeats are dropped by _ladder_levels
                names[lv] = cat
        with self._lock:
            self._ladder_memo[key] = names
        return names

    def _uses_ladder(self, intent: Intent) -> bool:
        return self.ladder_mode == "always" or (self.ladder_mode == "inferred" and intent.source == "inferred")

    def _ladder_term(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent,
                     rel: np.ndarray, lo: np.ndarray, details: dict[str, Any]) -> np.ndarray:
        """The LM term ``[n_test + n_train]`` with the ladder: the mean of the z-scored log-odds ``lo`` (the
        goal's category) and of each rung's log-odds; a training object's rungs are named without it
        (leave-one-out; with no relevant partner left, the full ladder, as in :meth:`_categories`)."""
        handled, alone = self._split(train, rel)
        described = {o.name: o.description for o in train}
        # every call of one kind before the other's: consecutive calls with the same system message and worked
        # examples reuse them from llama.cpp's KV cache (the answers depend on the prompt alone)
        sets = [(handled, alone)] + [([n for n in handled if n != o.name], [n for n in alone if n != o.name])
                                     for o in train]
        for kind in self._ladder_kinds():
            for h, a in sets:
                if h:
                    self._ask_ladder(kind, h, a, described)
        levels = self._ladder_levels(handled, alone, described)
        full = tuple(levels.values())
        if not full:
            return lo
        loo = []  # per training object, its ladder named without it
        for h, a in sets[1:]:
            if self.rungs != "breadth":  # the same level; the full ladder's name where it names none
                own_lv = self._ladder_levels(h, a, described) if h else levels
                loo.append([own_lv.get(lv, levels[lv]) for lv in levels])
            else:  # breadth: the same position; a shorter ladder repeats its last rung
                own = (self.ladder(h, a, described) if h else full) or full
                loo.append([own[min(r, len(own) - 1)] for r in range(len(full))])
        rungs = [self.log_odds(list(test) + list(train), intent, [name] * len(test) + [lad[r] for lad in loo])
                 for r, name in enumerate(full)]
        details["ladder"] = {"categories": list(full), "goal": lo.tolist(),
                             "terms": [{"test": v[: len(test)].tolist(), "train": v[len(test):].tolist()}
                                       for v in rungs]}
        return self._mix_views(train, intent, rel, [lo, *rungs], [details.get("category"), *full], details["ladder"])

    def _mix_views(self, train: Sequence[ObjectSpec], intent: Intent, rel: np.ndarray, views: Sequence[np.ndarray],
                   categories: Sequence[str | None], record: dict[str, Any],
                   evidence: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """The LM term ``[n_test + n_train]``: the z-scored log-odds ``views`` (one per category: the goal's,
        then each rung's) averaged, with ``check`` weighted by :meth:`_check_weights`. The one place where the
        ladder's categories are weighed, used by :meth:`score` and :meth:`score_with_answers`. ``evidence``:
        (indices of labelled test objects, their labels), checked beside the training objects."""
        z = np.stack([_zscore(v) for v in views])
        if self.check == "none":
            return z.mean(axis=0)
        extra = None if evidence is None else ([np.asarray(v)[evidence[0]] for v in views], evidence[1])
        weights = self._check_weights(train, intent, rel, categories, record, extra)
        return np.tensordot(weights, z, axes=1) / weights.sum()

    def _check_weights(self, train: Sequence[ObjectSpec], intent: Intent, rel: np.ndarray,
                       categories: Sequence[str | None], record: dict[str, Any],
                       evidence: tuple[Sequence[np.ndarray], np.ndarray] | None = None) -> np.ndarray:
        """``[n_categories]`` weights of the ladder's categories (``check``), from each category's in-sample AUC
        on the training objects (``rel`` ``[n_train]``: demonstrated or not); recorded in ``record["check"]``.
        ``evidence``: more labelled objects, as (per category its log-odds ``[m]``, labels ``[m]``), pooled
        with the training objects (answered test objects, :meth:`score_with_answers`)."""
        from gift.core.metrics import roc_auc

        extra, labels = evidence if evidence is not None else ([np.zeros(0)] * len(categories), np.zeros(0, bool))
        labels = np.asarray(labels, dtype=bool)
        pos, neg = rel.any() or labels.any(), (~rel).any() or (~labels).any()
        y = np.concatenate([rel, labels])
        scored = [np.concatenate([self.log_odds(train, intent, [c] * len(train)), x])
                  if c is not None and pos and neg else None for c, x in zip(categories, extra)]
        aucs = np.array([float("nan") if v is None else roc_auc(v, y) for v in scored])
        # the gap between the lowest-scored demonstrated object and the highest-scored other one (log-odds)
        margins = np.array([float("nan") if v is None else float(v[y].min() - v[~y].max()) for v in scored])
        known = ~np.isnan(aucs)
        weights = np.ones(len(categories))
        if known.any():
            if self.check in ("fit", "margin", "fit-best"):
                top = 1.0 if (aucs[known] >= 1.0 - 1e-12).any() else aucs[known].max()
                weights = (known & (np.nan_to_num(aucs, nan=-1.0) >= top - 1e-12)).astype(float)
                gap = np.where(weights > 0, np.nan_to_num(margins, nan=-np.inf), -np.inf)
                if self.check == "margin" and (gap > 0).any():
                    weights = np.clip(gap, 0.0, None)
                elif self.check == "fit-best":
                    weights = (np.arange(len(weights)) == int(np.argmax(gap))).astype(float)
            else:
                sep = np.clip(np.nan_to_num(aucs, nan=0.5) - 0.5, 0.0, None)
                weights = sep if sep.sum() > 0 else weights
        record["check"] = {"mode": self.check, "in_sample_auc": [None if np.isnan(a) else float(a) for a in aucs],
                           "margin": [None if np.isnan(m) else float(m) for m in margins],
                           "weights": (weights / weights.sum()).tolist()}
        return weights

    def log_odds(self, objects: Sequence[ObjectSpec], intent: Intent,
                 categories: Sequence[str] | None = None) -> np.ndarray:
        """``[n]`` log P(yes) − log P(no) that each object is what the goal is about (clipped to ±12).

        ``categories`` (``[n]``, for the ``category`` template): the category each object is asked
        about; default: :meth:`category` of the goal alone for every object.
        """
        if intent is None:
            raise GiftError("the 'gift-prob' kernel conditions on an intent; pass one")
        uses_category = "{category}" in prompts.RELEVANCE_TEMPLATES[self.template]
        if categories is None:
            categories = [self.category(intent) if uses_category else None] * len(objects)
        elif len(categories) != len(objects):
            raise GiftError(f"gift-prob: {len(categories)} categories for {len(objects)} objects")
        out = np.empty(len(objects))
        shown, how = ASK_FORMS.get(self.ask_text, ((self.ask_text,), "mean"))
        for i, o in enumerate(objects):
            lo = {text: self._ask(prompts.relevance_messages(o, intent.text, self.template, self.use_descriptions,
                                                             categories[i], text)) for text in shown}
            if how == "min-name":
                s = min(float(np.mean([v for t, v in lo.items() if t != "name"])), lo["name"])
            else:
                s = float(np.mean(list(lo.values())))
            if self.axes:
                for a in intent.axes:
                    s = max(s, self._ask(prompts.axis_messages(o, a.question, self.use_descriptions)))
            out[i] = s
        return out

    def _categories(self, n_test: int, train: Sequence[ObjectSpec], goal: str | None,
                    relevant_train: Sequence[str]) -> list[str | None]:
        """Per object of ``test + train``, the category it is asked about under one candidate ``goal`` (None:
        from the objects alone): the full category for the test objects, and for each training object one
        named without it (leave-one-out), so its score can calibrate a threshold and verify the candidate.
        A relevant training object with no relevant partner left gets the goal's own category (or, without
        a goal, the full one: its score is then not a fair leave-one-out score, and the alignment and the
        verifier do not use it)."""
        rel = set(relevant_train)
        handled = [o.name for o in train if o.name in rel]
        alone = [o.name for o in train if o.name not in rel]
        full = self.category(goal, handled, alone)
        loo = []
        for o in train:
            h = [n for n in handled if n != o.name]
            a = [n for n in alone if n != o.name]
            loo.append(self.category(goal, h, a) if (h or goal) else full)
        return [full] * n_test + loo

    def candidate_goals(self, intent: Intent, relevant_train: Sequence[str]) -> list[str | None]:
        """The goals gift-prob names a category from (``candidates``): the intent's text; with ``"all"`` also
        its other motivations and, when relevant training objects are known, no goal at all (the category
        of the objects the demonstrations single out). Duplicates are dropped, in that order."""
        goals: list[str | None] = [intent.text]
        if self.candidates == "all":
            goals += [m.text for m in intent.motivations]
            if relevant_train:
                goals.append(None)
        out: list[str | None] = []
        for g in goals:
            key = None if g is None else prompts.goal_text(g).lower()
            if key not in [None if x is None else prompts.goal_text(x).lower() for x in out]:
                out.append(g)
        return out

    @staticmethod
    def _relevant_mask(train: Sequence[ObjectSpec], relevant_train: Sequence[str],
                       train_lo: np.ndarray | None = None) -> np.ndarray:
        """``[n_train]`` bool: the given ``relevant_train``, else the objects the LM calls relevant
        (``train_lo > 0``, at least the best one; ``train_lo`` is needed only then)."""
        names = [o.name for o in train]
        if relevant_train:
            unknown = set(relevant_train) - set(names)
            if unknown:
                raise GiftError(f"gift-prob: relevant_train names objects that are not training objects: "
                                f"{sorted(unknown)}")
            return np.array([n in set(relevant_train) for n in names])
        mask = train_lo > 0.0
        if not mask.any() and len(train):
            mask[int(np.argmax(train_lo))] = True
        return mask

    def _embed_scores(self, objs: Sequence[ObjectSpec], train: Sequence[ObjectSpec], rel: np.ndarray,
                      exclude_self: bool | np.ndarray) -> np.ndarray:
        """Description similarity of each object to the relevant training objects (``[n]``), less (contrastive)
        that to the others: the nearest object's cosine on each side, or (``embed_reference="prototype"``) the
        mean cosine over each side. ``exclude_self``: True when ``objs`` is ``train`` (each object's own pair
        left out), or a bool mask ``[n, n_train]`` of the pairs left out."""
        sim = np.asarray(self.language.similarity(list(objs), list(train)), dtype=float)
        if isinstance(exclude_self, np.ndarray):
            sim[exclude_self] = np.nan
        elif exclude_self:
            np.fill_diagonal(sim, np.nan)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows (no partner left) become 0 below
            pool = np.nanmean if self.embed_reference == "prototype" else np.nanmax
            pos = pool(np.where(rel[None, :], sim, np.nan), axis=1) if rel.any() else np.zeros(len(objs))
            out = pos
            if self.embed_reference != "relevant" and (~rel).any():
                out = pos - pool(np.where(~rel[None, :], sim, np.nan), axis=1)
        return np.nan_to_num(out, nan=0.0)

    # ------------------------------------------------------------------ kernel API
    def _verify(self, lo_train: np.ndarray, rel: np.ndarray, usable: np.ndarray) -> dict[str, float]:
        """How well one candidate's leave-one-out log-odds separate the relevant training objects from the
        others: AUC over the usable objects, and the margin (mean relevant minus mean other log-odds)."""
        from gift.core.metrics import roc_auc

        pos, neg = lo_train[rel & usable], lo_train[~rel & usable]
        auc = roc_auc(lo_train[usable], rel[usable]) if pos.size and neg.size else float("nan")
        margin = float(pos.mean() - neg.mean()) if pos.size and neg.size else float("nan")
        return {"auc": auc, "margin": margin}

    def _select(self, cands: Sequence[dict[str, Any]]) -> int:
        """The candidate to keep: ``select="first"``, the first (in :meth:`candidate_goals` order: the intent's
        text, its other motivations, the objects alone) whose leave-one-out AUC is the best of all;
        ``"margin"``: the best AUC, ties broken by the larger margin. Measured in docs/results/front_half.md."""
        aucs = [np.nan_to_num(c["auc"], nan=-1.0) for c in cands]
        top = max(aucs)
        if self.select == "first":
            return next(k for k, a in enumerate(aucs) if a >= top - 1e-12)
        return max(range(len(cands)), key=lambda k: (aucs[k], np.nan_to_num(cands[k]["margin"], nan=-np.inf), -k))

    def score(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None = None,
              relevant_train: Sequence[str] = ()) -> RelevanceScores:
        """One pass over a scene: relevance of the test objects ``[n_test]`` and, leave-one-out, of the
        training objects ``[n_train]`` (a training object is never compared with itself, and its question
        uses a category named without it), on one scale, so the training scores can calibrate a cut.

        With several candidate goals (``candidates="all"``) each one names a category and asks the
        training objects' questions; the verifier keeps the candidate whose leave-one-out log-odds best
        separate the relevant training objects from the others (AUC, then margin), and only its category
        is asked about the test objects. ``details``: the category, the candidates with their verifier
        scores, the weight of each term and each term per object (``terms``: ``lm`` log-odds and
        ``language`` scores of the test and the training objects).
        """
        test, train = list(test), list(train)
        if intent is None:
            raise GiftError("the 'gift-prob' kernel conditions on an intent; pass one")
        rel = self._relevant_mask(train, relevant_train) if relevant_train else None  # unknown names fail first
        if rel is not None and self.candidates == "text":
            # which questions get asked does not depend on the answers here: collect them, then ask them
            # object by object, so each object's text is evaluated once for all its categories
            self._in_object_order(lambda: self._lm_term(test, train, intent, rel, relevant_train, {}))
        details: dict[str, Any] = {}
        lo, rel = self._lm_term(test, train, intent, rel, relevant_train, details)
        return self._finish(test, train, rel, lo, details)

    def _in_object_order(self, run: Callable[[], Any]) -> None:
        """Run ``run`` with the yes/no questions collected instead of asked (each answered 0), then ask the
        collected questions grouped by what they share before their ``cut`` hint (the object as shown), so an
        LM that evaluates prompts in pieces (``llamacpp``) evaluates each object's text once and only the
        category after it per question: about half the CPU time of asking category by category (measured:
        docs/performance.md). The answers do not depend on the order; only what was asked is memoized."""
        self._collecting.questions = pending = []
        try:
            run()
        finally:
            self._collecting.questions = None
        seen: dict[tuple, tuple[Message, ...]] = {}
        for msgs in pending:
            seen.setdefault(tuple((m.role, m.content, m.cut) for m in msgs), msgs)

        def shared(msgs: tuple[Message, ...]) -> tuple:
            *head, last = msgs
            return (tuple((m.role, m.content) for m in head), last.content[: last.cut])

        groups: dict[tuple, list[tuple[Message, ...]]] = {}
        for msgs in seen.values():
            groups.setdefault(shared(msgs), []).append(msgs)
        for group in groups.values():
            for msgs in group:
                self._ask(msgs)

    def _lm_term(self, test: list[ObjectSpec], train: list[ObjectSpec], intent: Intent, rel: np.ndarray | None,
                 relevant_train: Sequence[str], details: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        """The LM term ``[n_test + n_train]`` of :meth:`score` and the relevant-training mask ``[n_train]``
        (``rel``, or from the LM's answers when None); ``details`` gets the category, candidates, ladder."""
        uses_category = "{category}" in prompts.RELEVANCE_TEMPLATES[self.template]
        if relevant_train and uses_category and self.category_from == "goal+objects":
            usable = ~(rel & (rel.sum() < 2))  # a relevant object with no relevant partner left is no evidence
            cands = []
            for goal in self.candidate_goals(intent, relevant_train):
                cats = self._categories(0, train, goal, relevant_train)
                lo_train = self.log_odds(train, intent, cats)
                cands.append({"goal": goal, "category": self.category(goal, *self._split(train, rel)),
                              "lo_train": lo_train, **self._verify(lo_train, rel, usable)})
            best = self._select(cands)
            chosen = cands[best]
            lo = np.concatenate([self.log_odds(test, intent, [chosen["category"]] * len(test)), chosen["lo_train"]])
            details["category"] = chosen["category"]
            details["goal"] = chosen["goal"]
            details["candidates"] = [{"goal": c["goal"], "category": c["category"], "auc": c["auc"],
                                      "margin": c["margin"], "chosen": k == best} for k, c in enumerate(cands)]
            if self.candidate_terms:
                for c in details["candidates"]:
                    k = details["candidates"].index(c)
                    c["lm_train"] = cands[k]["lo_train"].tolist()
                    c["lm_test"] = self.log_odds(test, intent, [c["category"]] * len(test)).tolist()
        else:
            lo = self.log_odds(test + train, intent)
            if uses_category:
                details["category"] = self.category(intent)
        if rel is None:
            rel = self._relevant_mask(train, (), lo[len(test):])
        if self._uses_ladder(intent) and rel.any() and uses_category:
            lo = self._ladder_term(test, train, intent, rel, lo, details)
        return lo, rel

    def score_with_answers(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None,
                           relevant_train: Sequence[str], answers: Mapping[str, bool]) -> RelevanceScores | None:
        """The scene scored again with the human's answers (rule 5 of :mod:`gift.core.queries`). With
        ``rescore_with="evidence"``: :meth:`_rescore_with_evidence` (no LM call). With ``"ladder"``: the category
        ladder is named again with the test objects answered "yes" beside the demonstrated ones and those
        answered "no" beside the left-alone ones, every object is asked about the new rungs, and the LM term
        is the mean of the z-scored log-odds under the goal's category (unchanged) and the new rungs; then
        the terms are combined as in :meth:`score`. Cost: a ladder call (two with ``rungs="both"``) and
        ``n_test + n_train`` yes/no questions per rung. The training objects are asked about the new rungs as
        named with them (not held out: an answer adds test objects to the evidence, and naming the rungs once
        per training object would cost a ladder call each). None when the scene does not use the ladder (``ladder="never"``, or a
        ground-truth intent with ``"inferred"``) or the LM names no rung: answers then only re-threshold.
        ``details["ladder"]["answers"]`` lists the answers used."""
        test, train = list(test), list(train)
        names = [o.name for o in test]
        unknown = sorted(set(answers) - set(names))
        if unknown:
            raise GiftError(f"gift-prob: answers about {unknown}, which are not test objects {names}")
        base = self.score(test, train, intent, relevant_train)  # every LM answer of it is memoized
        if self.rescore_with == "evidence":
            return self._rescore_with_evidence(test, train, intent, base, answers) if answers else None
        lad = base.details.get("ladder")
        if lad is None or not answers:
            return None
        yes = [n for n in names if answers.get(n) is True]
        no = [n for n in names if answers.get(n) is False]
        rel = np.asarray(base.relevant, dtype=bool)
        handled, alone = self._split(train, rel)
        rungs = self.ladder(handled + yes, alone + no, {o.name: o.description for o in train + test})
        if not rungs:
            return None
        goal = np.asarray(lad["goal"], dtype=float)
        n_all = len(test) + len(train)
        self._in_object_order(lambda: [self.log_odds(test + train, intent, [r] * n_all) for r in rungs])
        terms = [self.log_odds(test + train, intent, [r] * n_all) for r in rungs]
        details = {k: v for k, v in base.details.items() if k in ("category", "goal")}
        details["ladder"] = {"categories": list(rungs), "goal": goal.tolist(),
                             "terms": [{"test": v[: len(test)].tolist(), "train": v[len(test):].tolist()}
                                       for v in terms],
                             "answers": {"yes": yes, "no": no}, "train_held_out": False,
                             "categories_before": list(lad["categories"])}
        lo = self._mix_views(train, intent, rel, [goal, *terms], [details.get("category"), *rungs], details["ladder"])
        return self._finish(test, train, rel, lo, details)

    def _rescore_with_evidence(self, test: list[ObjectSpec], train: list[ObjectSpec], intent: Intent,
                               base: RelevanceScores, answers: Mapping[str, bool]) -> RelevanceScores | None:
        """:meth:`score_with_answers` with ``rescore_with="evidence"``: no new LM question. The answered test
        objects are labelled evidence beside the training objects ("yes" with the demonstrated ones, "no"
        with the left-alone ones) in the check of the ladder's categories (:meth:`_check_weights`, with their
        log-odds under each category), as references of the MiniLM term (an object is not its own reference)
        and in the terms' reliability weights; then the terms are combined as in :meth:`score`. None (answers
        only re-threshold) with a calibration, or with neither the MiniLM term nor the ladder to re-weigh."""
        lad = base.details.get("ladder")
        if self.calibration is not None or (self.combine == "none" and lad is None):
            return None
        names = [o.name for o in test]
        idx = np.array([i for i, n in enumerate(names) if answers.get(n) is not None], dtype=int)
        labels = np.array([bool(answers[names[i]]) for i in idx], dtype=bool)
        rel = np.asarray(base.relevant, dtype=bool)
        n_test = len(test)
        details: dict[str, Any] = {k: v for k, v in base.details.items() if k in ("category", "goal")}
        details["evidence"] = {"yes": [names[i] for i in idx[labels]], "no": [names[i] for i in idx[~labels]]}
        terms = base.details["terms"]["lm"]
        lo = np.asarray(terms["test"] + terms["train"], dtype=float)
        if lad is not None:
            views = [np.asarray(lad["goal"], dtype=float)] + [np.asarray(t["test"] + t["train"], dtype=float)
                                                               for t in lad["terms"]]
            details["ladder"] = {k: lad[k] for k in ("categories", "goal", "terms")}
            lo = self._mix_views(train, intent, rel, views, [details.get("category"), *lad["categories"]],
                                 details["ladder"], evidence=(idx, labels))
        details["terms"] = {"lm": {"test": lo[:n_test].tolist(), "train": lo[n_test:].tolist()}}
        if self.combine == "none":
            return RelevanceScores(_sigmoid(lo[:n_test]), _sigmoid(lo[n_test:]), rel, details, **self._prior())
        refs = list(train) + [test[i] for i in idx]
        ref_rel = np.concatenate([rel, labels])
        own_test = np.zeros((n_test, len(refs)), dtype=bool)
        own_test[idx, len(train) + np.arange(len(idx))] = True
        own_train = np.zeros((len(train), len(refs)), dtype=bool)
        own_train[np.arange(len(train)), np.arange(len(train))] = True
        emb = np.concatenate([self._embed_scores(test, refs, ref_rel, own_test) if test else np.zeros(0),
                              self._embed_scores(train, refs, ref_rel, own_train)])
        details["terms"]["language"] = {"test": emb[:n_test].tolist(), "train": emb[n_test:].tolist()}
        z, details["weights"] = self._combine(lo, emb, rel, n_test, evidence=(idx, labels))
        if "ladder" in details:
            self._ladder_views(details, emb, rel, n_test, evidence=(idx, labels))
        return RelevanceScores(_sigmoid(z[:n_test]), _sigmoid(z[n_test:]), rel, details, **self._prior())

    def _finish(self, test: list[ObjectSpec], train: list[ObjectSpec], rel: np.ndarray, lo: np.ndarray,
                details: dict[str, Any]) -> RelevanceScores:
        """The scores from the LM term ``lo`` ``[n_test + n_train]``: combined with the MiniLM term (or
        calibrated, or alone), with the terms, weights and ladder views in ``details``."""
        lo_test, lo_train = lo[: len(test)], lo[len(test):]
        details["terms"] = {"lm": {"test": lo_test.tolist(), "train": lo_train.tolist()}}
        if self.combine == "none":
            return RelevanceScores(_sigmoid(lo_test), _sigmoid(lo_train), rel, details, **self._prior())
        emb = np.concatenate([self._embed_scores(test, train, rel, False) if test else np.zeros(0),
                              self._embed_scores(train, train, rel, True)])
        details["terms"]["language"] = {"test": emb[: len(test)].tolist(), "train": emb[len(test):].tolist()}
        if self.calibration is not None and rel.any() and (~rel).any():
            X = np.stack([lo, emb], axis=1)
            cal = self.calibration.update(X[len(test):], rel)
            details["calibration"] = {"coef": cal.coef.tolist(), "intercept": cal.intercept,
                                      "pooled_coef": self.calibration.coef.tolist(),
                                      "pooled_intercept": self.calibration.intercept}
            p = cal.probability(X)
            return RelevanceScores(p[: len(test)], p[len(test):], rel, details, cut=0.5)
        z, details["weights"] = self._combine(lo, emb, rel, len(test))
        if "ladder" in details:
            self._ladder_views(details, emb, rel, len(test))
        return RelevanceScores(_sigmoid(z[: len(test)]), _sigmoid(z[len(test):]), rel, details, **self._prior())

    def _combine(self, lo: np.ndarray, emb: np.ndarray, rel: np.ndarray, n_test: int,
                 evidence: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, dict[str, float]]:
        """The combined z-score ``[n_test + n_train]`` of the LM log-odds ``lo`` and the MiniLM term ``emb``
        (test objects first), and the weight of each term. ``evidence``: (indices of labelled test objects,
        their labels), weighed beside the training objects in the reliability weights."""
        ref = slice(None) if self.standardize == "pooled" else slice(n_test, None)
        terms = {"lm": _zscore(lo, ref), "language": _zscore(emb, ref)}
        w = {"lm": 1.0 - self.weight, "language": self.weight}
        idx, labels = evidence if evidence is not None else (np.zeros(0, int), np.zeros(0, bool))
        sep = {t: separation_weight(np.concatenate([v[n_test:], v[idx]]), np.concatenate([rel, labels]))
               for t, v in terms.items()}
        if self.weighting == "reliability":
            scaled = {t: w[t] * sep[t] for t in terms}
            if not any(math.isnan(v) for v in scaled.values()) and sum(scaled.values()) > 0:
                w = scaled
        total = sum(w.values())
        weights = {t: v / total for t, v in w.items()}
        z = sum(weights[t] * terms[t] for t in terms)
        if self.veto == "lm" and sep["lm"] >= sep["language"]:  # False when either is nan (no evidence)
            z = np.where(terms["lm"] < 0.0, np.minimum(z, terms["lm"]), z)
        return z, weights

    def _ladder_views(self, details: dict[str, Any], emb: np.ndarray, rel: np.ndarray, n_test: int,
                      evidence: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """Report the scene under the goal's category alone and under each rung alone (each combined with
        the MiniLM term as the kernel's own score is, the answered ``evidence`` in the weights too) as intent
        candidates (``details["candidates"]``, on the relevance scale), so answers from the human can pick one
        (:mod:`gift.core.queries`, rule 3)."""
        lad = details["ladder"]
        views = [("goal's category: " + str(details.get("category")), np.asarray(lad["goal"]))]
        views += [(f"rung {k + 1}: {cat}", np.asarray(t["test"] + t["train"]))
                  for k, (cat, t) in enumerate(zip(lad["categories"], lad["terms"]))]
        cands = details.setdefault("candidates", [])
        for name, lo in views:
            z, _ = self._combine(lo, emb, rel, n_test, evidence=evidence)
            cands.append({"name": name, "relevance": _sigmoid(z[:n_test]).tolist(),
                          "train_loo": _sigmoid(z[n_test:]).tolist(), "chosen": False})

    def _prior(self) -> dict[str, Any]:
        """The prior cut of the scores (1/2, where the log-odds or the combined z-score is 0) and its weight."""
        return {"prior_cut": 0.5, "prior_weight": self.cut_prior} if self.cut_prior > 0 else {}

    @staticmethod
    def _split(train: Sequence[ObjectSpec], rel: np.ndarray) -> tuple[list[str], list[str]]:
        return ([o.name for o, r in zip(train, rel) if r], [o.name for o, r in zip(train, rel) if not r])
