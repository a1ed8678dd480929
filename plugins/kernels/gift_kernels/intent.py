"""``lm-contrastive``: the intent estimator J_LM(D_H, D_¬H) of GIFT (Calls 1 and 2).

Call 1 shows the LM demonstration pairs as textual feature traces (default vs preferred), the features'
descriptions and the features of other scenes, and asks for three ranked motivations, each with the
features it concerns (only features that exist), plus semantic similarities. Call 2 turns the
motivations into semantic axes: short yes/no questions with the objects (that exist) answering yes.
Both answers go through ``gift_llm.structured.ask_dict`` with the JSON schema of
:mod:`gift_kernels.schemas` (on llama.cpp a grammar: only known feature and object names can be written)
and a validator, so on a backend without grammar an unknown feature or object triggers a repair request
naming it.

To fit a 1.5B model with a 4k context, each trace shows only the features whose preferred and default
values differ (at most ``max_features`` per pair, largest difference first), at about ``max_steps``
evenly spaced time steps; every other feature is listed by name. When the prompt still exceeds
``max_prompt_chars`` (about 2.5 characters per token for these traces), fewer time steps (down to 4)
and then fewer features per pair (down to 2) are shown until it fits.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

import gift

from gift.core.data import DemonstrationPair, Intent, Motivation, SemanticAxis
from gift.core.errors import GiftError, LMAnswerError, ValidationError
from gift.core.interfaces import IntentEstimator, LMBackend
from gift_kernels import prompts, schemas


#: Answer budgets in tokens. Call 1's prompt is held to ``max_prompt_chars`` (8000 by default, about
#: 3200 tokens), so that prompt and answer fit the embedded model's 4096-token context.
CALL1_MAX_TOKENS = 640
CALL2_MAX_TOKENS = 768


def _norm(s: Any) -> str:
    return " ".join(str(s).replace("_", " ").lower().split())


def _entries(value: Any, key: str) -> list[tuple[str, list]]:
    """``[{"text"|"question": ..., "features"|"objects": [...]}, ...]`` or ``{text: [...]}`` -> pairs."""
    if isinstance(value, Mapping):
        return [(str(k), v if isinstance(v, list) else [v]) for k, v in value.items()]
    if not isinstance(value, list):
        raise ValidationError(f"expected a list of entries, got {type(value).__name__}")
    out = []
    for e in value:
        if not isinstance(e, Mapping):
            raise ValidationError(f"each entry must be an object with a text and a list, got {e!r}")
        text = e.get("text", e.get("question", e.get("motivation", e.get("axis"))))
        items = e.get(key, [])
        if not isinstance(text, str) or not text.strip():
            raise ValidationError(f"an entry has no text: {dict(e)!r}")
        out.append((text.strip(), items if isinstance(items, list) else [items]))
    return out


def parse_motivations(answer: Mapping[str, Any], features: Sequence[str]) -> tuple[list[Motivation],
                                                                                    list[SemanticAxis]]:
    """Validate Call 1: up to 3 motivations whose features all exist (+ semantic similarities).

    Raises :class:`ValidationError` (a ValueError) naming unknown features or a missing ``motivations`` entry.
    """
    known = {_norm(f): f for f in features}
    if "motivations" not in answer:
        raise ValidationError(f"the answer has no 'motivations' key (keys: {list(answer)})")
    mots, unknown = [], []
    for text, feats in _entries(answer["motivations"], "features"):
        mots.append(Motivation(text=text, features=_canonical(feats, known, unknown)))
    if unknown:
        raise ValidationError(f"features {sorted(set(unknown))} do not exist; use only: {list(features)}")
    if not mots:
        raise ValidationError("no motivation was given; give three")
    sims = []
    raw = answer.get("semantic_similarities", [])
    try:
        for q, feats in _entries(raw, "features"):
            sims.append(SemanticAxis(question=q, objects=_canonical(feats, known, [])))  # unknown names dropped
    except ValidationError:
        sims = []  # optional part: a malformed one is dropped, the motivations are kept
    return mots[:3], sims


def _canonical(raw: Sequence[Any], known: Mapping[str, str], unknown: list[str]) -> tuple[str, ...]:
    """The known names in ``raw`` (canonical spelling, first occurrence kept); the others go to ``unknown``."""
    names: list[str] = []
    for item in raw:
        name = known.get(_norm(item))
        if name is None:
            unknown.append(str(item))
        elif name not in names:
            names.append(name)
    return tuple(names)


def parse_axes(answer: Mapping[str, Any], objects: Sequence[str], strict: bool = True) -> list[SemanticAxis]:
    """Validate Call 2: axes (yes/no questions) over object names that exist.

    ``strict``: unknown names raise (the repair request names them); else they are dropped, and so are
    axes left without an object.
    """
    known = {_norm(o): o for o in objects}
    if "axes" not in answer:
        raise ValidationError(f"the answer has no 'axes' key (keys: {list(answer)})")
    axes, unknown = [], []
    for q, objs in _entries(answer["axes"], "objects"):
        axes.append(SemanticAxis(question=q, objects=_canonical(objs, known, unknown)))
    if unknown and strict:
        raise ValidationError(f"objects {sorted(set(unknown))} do not exist; use only: {list(objects)}")
    return axes if strict else [a for a in axes if a.objects]


class LMContrastiveIntentEstimator(IntentEstimator):
    """Calls 1 and 2 of GIFT: motivations from preferred-vs-default feature traces, then semantic axes."""

    name: ClassVar[str] = "lm-contrastive"

    def __init__(self, lm: LMBackend | str | None = None, max_steps: int = 8, max_features: int = 6,
                 temperature: float = 0.0, seed: int = 0, max_repairs: int = 2, axes: bool = True,
                 max_prompt_chars: int = 8000, constrained: bool = True) -> None:
        from gift_llm.structured import AskStats

        if max_steps < 2 or max_features < 1:
            raise GiftError(f"lm-contrastive: max_steps must be >= 2 and max_features >= 1, got {max_steps}, "
                            f"{max_features}")
        self._lm_spec, self._lm = lm, None
        self.max_steps, self.max_features = int(max_steps), int(max_features)
        self.max_prompt_chars = int(max_prompt_chars)
        self.temperature, self.seed, self.max_repairs, self.with_axes = float(temperature), int(seed), \
            int(max_repairs), bool(axes)
        #: Send the JSON schemas of Calls 1 and 2 (``gift_kernels.schemas``) with every request.
        self.constrained = bool(constrained)
        self.calls = 0
        self.stats = AskStats()  # answers read, repair requests and failures of Calls 1 and 2

    @property
    def lm(self) -> LMBackend:
        if self._lm is None:
            self._lm = gift.resolve_lm(self._lm_spec)
        return self._lm

    # ------------------------------------------------------------------ prompt material
    def shown_features(self, pair: DemonstrationPair, max_features: int | None = None) -> list[str]:
        """Features of ``pair`` whose preferred and default traces differ most (at most ``max_features``)."""
        diff = np.abs(pair.preferred.values - pair.default.values).max(axis=0)
        order = [i for i in np.argsort(-diff, kind="stable") if diff[i] > 1e-3][: max_features or self.max_features]
        return [pair.preferred.specs[i].name for i in sorted(order)]

    def pair_texts(self, demonstrations: Sequence[DemonstrationPair], max_steps: int | None = None,
                   max_features: int | None = None) -> tuple[list[tuple[str, str]], dict, list]:
        """(default, preferred) texts per pair, descriptions of the shown features, the other features."""
        texts, desc, every_name = [], {}, {}
        for pair in demonstrations:
            shown = self.shown_features(pair, max_features)
            every = max(1, math.ceil(pair.preferred.values.shape[0] / (max_steps or self.max_steps)))
            texts.append((pair.default.to_text(shown, every=every), pair.preferred.to_text(shown, every=every)))
            for s in pair.preferred.specs:
                every_name.setdefault(s.name, s.description)
                if s.name in shown:
                    desc[s.name] = s.description
        others = [n for n in every_name if n not in desc]
        return texts, desc, others

    def intent_prompt(self, demonstrations: Sequence[DemonstrationPair], task_context: str = ""
                      ) -> tuple[list, list[str]]:
        """Call 1's messages, shrunk (steps, then features per pair) to ``max_prompt_chars``; and every feature."""
        steps, feats = self.max_steps, self.max_features
        while True:
            texts, desc, others = self.pair_texts(demonstrations, steps, feats)
            messages = prompts.intent_messages(texts, desc, others, task_context)
            if sum(len(m.content) for m in messages) <= self.max_prompt_chars or (steps <= 4 and feats <= 2):
                return messages, list(dict.fromkeys([*desc, *others]))
            if steps > 4:
                steps -= 1
            else:
                feats -= 1

    # ------------------------------------------------------------------ calls
    def motivations(self, demonstrations: Sequence[DemonstrationPair], task_context: str = ""
                    ) -> tuple[list[Motivation], list[SemanticAxis]]:
        """Call 1: ranked motivations (features validated) and semantic similarities."""
        from gift_llm.structured import ask_dict

        if not demonstrations:
            raise GiftError("lm-contrastive: no demonstration pairs given")
        messages, features = self.intent_prompt(demonstrations, task_context)
        self.calls += 1
        answer = ask_dict(self.lm, messages, validate=lambda d: parse_motivations(d, features) and None,
                          max_repairs=self.max_repairs, temperature=self.temperature, seed=self.seed,
                          required_keys=("motivations",), max_tokens=CALL1_MAX_TOKENS, stats=self.stats,
                          json_schema=schemas.intent_schema(features) if self.constrained else None)
        return parse_motivations(answer, features)

    def semantic_axes(self, motivations: Sequence[Motivation], objects: Sequence[str]) -> list[SemanticAxis]:
        """Call 2: yes/no questions grouping ``objects`` under the motivations (names validated)."""
        from gift_llm.structured import ask_dict, last_dict

        if not objects:
            return []
        messages = prompts.axes_messages([(m.text, m.features) for m in motivations], objects)
        self.calls += 1
        try:
            answer = ask_dict(self.lm, messages, validate=lambda d: parse_axes(d, objects) and None,
                              max_repairs=self.max_repairs, temperature=self.temperature, seed=self.seed,
                              required_keys=("axes",), max_tokens=CALL2_MAX_TOKENS, stats=self.stats,
                              json_schema=schemas.axes_schema(objects) if self.constrained else None)
        except LMAnswerError as e:
            # the axes refine the intent: keep the last answer's axes without the names that do not exist;
            # with none left, the intent keeps Call 1's similarities (see estimate)
            partial = last_dict(e)
            try:
                kept = parse_axes(partial, objects, strict=False) if partial is not None else []
            except ValidationError:  # no 'axes' key
                kept = []
            what = (f"kept {len(kept)} axes without the unknown names" if kept
                    else "no valid semantic axes, keeping Call 1's similarities")
            warnings.warn(f"lm-contrastive: Call 2 still invalid after {self.max_repairs} repairs: {what} "
                          f"({str(e).splitlines()[0]})", RuntimeWarning, stacklevel=2)
            return kept
        return parse_axes(answer, objects)

    def estimate(self, demonstrations: Sequence[DemonstrationPair], *, task_context: str = "",
                 objects: Sequence[str] = ()) -> Intent:
        """The inferred intent: text = the top motivation; motivations ranked; axes over ``objects``.

        ``objects`` defaults to the subjects of the demonstrations' semantic features.
        """
        mots, sims = self.motivations(demonstrations, task_context)
        if not objects:
            objects = list(dict.fromkeys(s.subject for p in demonstrations for s in p.preferred.specs
                                         if s.subject is not None))
        axes = self.semantic_axes(mots, list(objects)) if self.with_axes else []
        return Intent(text=mots[0].text, motivations=tuple(mots), axes=tuple(axes or sims), source="inferred")
