"""LM kernels: ``gift`` (Call 3 with the intent), ``lm-no-intent`` (Call 3 without), and ``gift-prob``.

``gift`` / ``lm-no-intent`` (:class:`MappingKernel`): one LM call per sample lists every test object
(so the calls per intent are ``samples``, independent of the number of trajectories), each sample lists
the objects in its own shuffled order with its own seed; ``K[i, j]`` = fraction of samples mapping test
object i to training object j. The mode over {training objects, distractor} is the binary decision and
its share the agreement rate (:meth:`MappingKernel.votes`).

``gift-prob`` (:class:`GiftProbKernel`): a continuous kernel. The LM names, once per intent, the kind of
object the goal is about ("art supplies"), then answers one yes/no question per object, "is a <object>
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
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import attrs
import numpy as np

import gift

from gift.core.data import DISTRACTOR, Intent, Message, ObjectSpec, RelevanceScores
from gift.core.errors import GiftError, LMAnswerError, ValidationError
from gift.core.interfaces import LMBackend, RelevanceKernel, SimilarityKernel
from gift_kernels import prompts

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
                 seed: int = 0, use_intent: bool = True, max_repairs: int = 2) -> None:
        if not isinstance(samples, int) or samples < 1:
            raise GiftError(f"{self.name} kernel: samples must be a positive integer, got {samples!r}")
        self._lm_spec, self._lm = lm, None
        self.samples, self.temperature, self.seed = samples, float(temperature), int(seed)
        self.use_intent, self.max_repairs = bool(use_intent), int(max_repairs)
        self.calls = 0  # LM calls made (including those served from the LM cache)
        self.fallbacks: list[str] = []  # samples completed by default (see _sample)

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
        self.calls += 1
        try:
            answer = ask_dict(self.lm, messages, validate=lambda d: parse_mapping(d, test, train),
                              max_repairs=self.max_repairs, temperature=self.temperature, seed=self.seed + k)
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
                 seed: int = 0, max_repairs: int = 2) -> None:
        super().__init__(lm=lm, samples=samples, temperature=temperature, seed=seed, use_intent=False,
                         max_repairs=max_repairs)


# ============================================================================= gift-prob


def _zscore(x: np.ndarray, ref: slice = slice(None)) -> np.ndarray:
    """``(x - mean) / sd`` with the statistics of ``x[ref]``."""
    mu, sd = x[ref].mean(), x[ref].std()
    return (x - mu) / sd if sd > 1e-9 else x - mu


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.asarray(x, dtype=float)))


COMBINE = ("none", "language")
EMBED_REFERENCE = ("relevant", "contrastive")
STANDARDIZE = ("pooled", "train")
WEIGHTING = ("reliability", "equal")
CATEGORY_FROM = ("goal+objects", "goal")


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
    object "is a <object> (<description>) one of the <category>?"; the log-odds and a contrastive MiniLM description
    similarity are z-scored and averaged, each weighted by how well it separates the relevant training
    objects from the others (leave-one-out; ``weighting="reliability"``).

    Options: ``template`` (a key of :data:`gift_kernels.prompts.RELEVANCE_TEMPLATES`), ``use_descriptions``,
    ``axes`` (also ask the intent's semantic-axis questions and keep the highest log-odds per object),
    ``combine`` (``"language"``: average the z-scored log-odds with z-scored MiniLM description
    similarity; ``"none"``: the log-odds alone), ``embed_reference`` (``"relevant"``: the largest cosine
    to a relevant training object; ``"contrastive"``: that minus the largest cosine to another training
    object), ``weight`` of the language term in the average, ``weighting`` (``"reliability"``: scale each
    term's weight by ``max(AUC - 1/2, 0)`` of its leave-one-out scores on the training objects, so a term
    that inverts the demonstrated labels for this intent is dropped; all zero falls back to the plain
    weights; ``"equal"``: the plain weights), ``category_from`` (``"goal+objects"``: name the category from
    the goal and the demonstrated training objects when ``relevant_train`` is given; ``"goal"``: from the
    goal alone).
    """

    name: ClassVar[str] = "gift-prob"
    uses_intent: ClassVar[bool] = True

    def __init__(self, lm: LMBackend | str | None = None, template: str = "category", use_descriptions: bool = True,
                 axes: bool = False, combine: str = "language", embed_reference: str = "contrastive",
                 weight: float = 0.5, standardize: str = "pooled", weighting: str = "reliability",
                 category_from: str = "goal+objects", language_kernel: SimilarityKernel | None = None) -> None:
        if template not in prompts.RELEVANCE_TEMPLATES:
            raise GiftError(f"gift-prob: unknown template {template!r}; one of {sorted(prompts.RELEVANCE_TEMPLATES)}")
        if combine not in COMBINE:
            raise GiftError(f"gift-prob: combine must be one of {COMBINE}, got {combine!r}")
        if embed_reference not in EMBED_REFERENCE:
            raise GiftError(f"gift-prob: embed_reference must be one of {EMBED_REFERENCE}, got {embed_reference!r}")
        if standardize not in STANDARDIZE:
            raise GiftError(f"gift-prob: standardize must be one of {STANDARDIZE}, got {standardize!r}")
        if weighting not in WEIGHTING:
            raise GiftError(f"gift-prob: weighting must be one of {WEIGHTING}, got {weighting!r}")
        if category_from not in CATEGORY_FROM:
            raise GiftError(f"gift-prob: category_from must be one of {CATEGORY_FROM}, got {category_from!r}")
        if not 0.0 <= float(weight) <= 1.0:
            raise GiftError(f"gift-prob: weight must be in [0, 1], got {weight!r}")
        self._lm_spec, self._lm = lm, None
        self.template, self.use_descriptions, self.axes = template, bool(use_descriptions), bool(axes)
        self.combine, self.embed_reference, self.weight = combine, embed_reference, float(weight)
        self.standardize, self.weighting, self.category_from = standardize, weighting, category_from
        self._category_memo: dict[tuple, str] = {}
        self._language = language_kernel
        self._memo: dict[tuple, float] = {}
        self._lock = threading.Lock()
        self.calls = 0  # distinct yes/no questions sent to the LM

    def __repr__(self) -> str:
        return (f"GiftProbKernel(template={self.template!r}, use_descriptions={self.use_descriptions}, "
                f"axes={self.axes}, combine={self.combine!r}, embed_reference={self.embed_reference!r}, "
                f"weight={self.weight}, weighting={self.weighting!r}, category_from={self.category_from!r})")

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
            from gift.core.errors import UnknownComponentError

            try:
                self._language = gift.get_kernel("language", use_descriptions=True)
            except UnknownComponentError:  # the plugin's registration not loaded (e.g. GIFT_PLUGINS filter)
                from gift_kernels.language import LanguageKernel

                self._language = LanguageKernel(use_descriptions=True)
        return self._language

    def _ask(self, messages: tuple[Message, ...]) -> float:
        key = (self.lm.identity(), tuple((m.role, m.content) for m in messages))
        with self._lock:
            if key in self._memo:
                return self._memo[key]
        probs = self.lm.choice_probabilities(messages, ["yes", "no"])
        self.calls += 1
        p_yes, p_no = float(probs.get("yes", 0.0)), float(probs.get("no", 0.0))
        lo = math.log(max(p_yes, 1e-12)) - math.log(max(p_no, 1e-12))
        lo = float(np.clip(lo, -LOGIT_CLIP, LOGIT_CLIP))
        with self._lock:
            self._memo[key] = lo
        return lo

    def category(self, intent: Intent, handled: Sequence[str] = (), left_alone: Sequence[str] = ()) -> str:
        """The kind of object the intent's goal is about ("art supplies"), asked once per question (greedy).

        With ``category_from="goal+objects"`` and at least one ``handled`` training object (one the
        demonstrations treat as part of the goal; ``left_alone``: the others) the LM names the kind
        from the goal and those objects; else from the goal alone. An answer that is not a short noun
        phrase falls back, with a warning, to the goal itself.
        """
        goal = prompts.goal_text(intent.text)
        use_objects = self.category_from == "goal+objects" and len(handled) > 0
        key = (goal, tuple(handled), tuple(left_alone)) if use_objects else (goal,)
        with self._lock:
            if key in self._category_memo:
                return self._category_memo[key]
        msgs = (prompts.category_from_objects_messages(goal, handled, left_alone) if use_objects
                else prompts.category_messages(goal))
        answer = self.lm.complete(msgs, temperature=0.0, max_tokens=24, stop=["\n"]).text
        self.calls += 1
        cat = prompts.parse_category(answer)
        if cat is None:
            warnings.warn(f"gift-prob: the LM named no object category for the goal {goal!r} (answer "
                          f"{answer[:80]!r}); asking about the goal itself", stacklevel=2)
            cat = prompts.fallback_category(goal)
        with self._lock:
            self._category_memo[key] = cat
        return cat

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
        for i, o in enumerate(objects):
            s = self._ask(prompts.relevance_messages(o, intent.text, self.template, self.use_descriptions,
                                                     categories[i]))
            if self.axes:
                for a in intent.axes:
                    s = max(s, self._ask(prompts.axis_messages(o, a.question, self.use_descriptions)))
            out[i] = s
        return out

    def _categories(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent,
                    relevant_train: Sequence[str]) -> list[str] | None:
        """Per object of ``test + train``, the category it is asked about; a training object's is named
        without it (leave-one-out), so its score can calibrate a threshold. ``None``: the goal's alone."""
        if (self.category_from != "goal+objects" or not relevant_train
                or "{category}" not in prompts.RELEVANCE_TEMPLATES[self.template]):
            return None
        rel = set(relevant_train)
        handled = [o.name for o in train if o.name in rel]
        alone = [o.name for o in train if o.name not in rel]
        full = self.category(intent, handled, alone)
        loo = [self.category(intent, [n for n in handled if n != o.name], [n for n in alone if n != o.name])
               for o in train]
        return [full] * len(test) + loo

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
                      exclude_self: bool) -> np.ndarray:
        """Description similarity of each object to the relevant training objects (``[n]``)."""
        sim = np.asarray(self.language.similarity(list(objs), list(train)), dtype=float)
        if exclude_self:
            np.fill_diagonal(sim, np.nan)
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows (no partner left) become 0 below
            pos = np.nanmax(np.where(rel[None, :], sim, np.nan), axis=1) if rel.any() else np.zeros(len(objs))
            out = pos
            if self.embed_reference == "contrastive" and (~rel).any():
                out = pos - np.nanmax(np.where(~rel[None, :], sim, np.nan), axis=1)
        return np.nan_to_num(out, nan=0.0)

    # ------------------------------------------------------------------ kernel API
    def score(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec], intent: Intent | None = None,
              relevant_train: Sequence[str] = ()) -> RelevanceScores:
        """One pass over a scene: relevance of the test objects ``[n_test]`` and, leave-one-out, of the
        training objects ``[n_train]`` (a training object is never compared with itself, and its question
        uses a category named without it), on one scale, so the training scores can calibrate a cut.

        ``details``: the category the test objects were asked about, the weight of each term and each
        term alone (``terms``: ``{name: {"relevance": [n_test], "train_loo": [n_train]}}``, sigmoids of its
        z-scores).
        """
        test, train = list(test), list(train)
        if intent is None:
            raise GiftError("the 'gift-prob' kernel conditions on an intent; pass one")
        rel = self._relevant_mask(train, relevant_train) if relevant_train else None  # unknown names fail first
        categories = self._categories(test, train, intent, relevant_train)
        lo = self.log_odds(test + train, intent, categories)
        lo_test, lo_train = lo[: len(test)], lo[len(test):]
        if rel is None:
            rel = self._relevant_mask(train, (), lo_train)
        details: dict[str, Any] = {}
        if categories is not None:
            details["category"] = categories[0] if test else None
        elif "{category}" in prompts.RELEVANCE_TEMPLATES[self.template]:
            details["category"] = self.category(intent)
        if self.combine == "none":
            return RelevanceScores(_sigmoid(lo_test), _sigmoid(lo_train), rel, details)
        emb = np.concatenate([self._embed_scores(test, train, rel, False) if test else np.zeros(0),
                              self._embed_scores(train, train, rel, True)])
        ref = slice(None) if self.standardize == "pooled" else slice(len(test), None)
        terms = {"lm": _zscore(lo, ref), "language": _zscore(emb, ref)}
        w = {"lm": 1.0 - self.weight, "language": self.weight}
        if self.weighting == "reliability":
            sep = {t: separation_weight(v[len(test):], rel) for t, v in terms.items()}
            scaled = {t: w[t] * sep[t] for t in terms}
            if not any(math.isnan(v) for v in scaled.values()) and sum(scaled.values()) > 0:
                w = scaled
        total = sum(w.values())
        weights = {t: v / total for t, v in w.items()}
        z = sum(weights[t] * terms[t] for t in terms)
        details["weights"] = weights
        # each term alone, on the relevance scale (for the disagreement query policy, gift.core.queries)
        details["terms"] = {t: {"relevance": _sigmoid(v[: len(test)]).tolist(),
                                "train_loo": _sigmoid(v[len(test):]).tolist()} for t, v in terms.items()}
        return RelevanceScores(_sigmoid(z[: len(test)]), _sigmoid(z[len(test):]), rel, details)
