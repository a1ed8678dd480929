"""The gift data model: small frozen attrs classes with validators.

Arrays are numpy, batch-first: ``[N, T, ...]`` for N trajectories of T time steps.
Positions are in metres, in the world frame of the scene.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any

import attrs
import numpy as np

from gift.core.errors import ValidationError

#: The alignment target of a test object that plays no role of any training object.
DISTRACTOR = "distractor"

SHAPES = ("box", "cylinder", "sphere")

# ----------------------------------------------------------------------------- helpers


def _nonempty_str(inst: Any, attribute: attrs.Attribute, value: Any) -> None:
    if not isinstance(value, str) or not value.strip():
        raise ValidationError(f"{type(inst).__name__}.{attribute.name} must be a non-empty string, "
                              f"got {value!r}")


def _str_tuple(value: Any) -> tuple[str, ...]:
    if isinstance(value, str):
        raise ValidationError(f"expected a list of strings, got the string {value!r}")
    return tuple(value)


def _all_str(inst: Any, attribute: attrs.Attribute, value: tuple) -> None:
    for v in value:
        if not isinstance(v, str) or not v.strip():
            raise ValidationError(f"{type(inst).__name__}.{attribute.name} must hold non-empty "
                                  f"strings, got {v!r}")


def _unique(inst: Any, attribute: attrs.Attribute, value: tuple) -> None:
    seen: set = set()
    for v in value:
        if v in seen:
            raise ValidationError(f"{type(inst).__name__}.{attribute.name} has duplicate {v!r}")
        seen.add(v)


def _float_array(value: Any) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    arr.setflags(write=False)
    return arr


def slug(name: str) -> str:
    """Feature-name form of an object name: ``"coffee mug"`` -> ``"coffee_mug"``."""
    return re.sub(r"[^0-9a-zA-Z]+", "_", name.strip()).strip("_").lower()


# ----------------------------------------------------------------------------- objects


@attrs.frozen
class Appearance:
    """Primitive geometry of an object: ``shape`` in SHAPES, ``size`` in metres, ``color`` RGB in [0, 1].

    ``size`` is ``[x, y, z]`` for a box, ``[radius, length]`` for a cylinder, ``[radius]`` for a sphere.
    """

    shape: str = attrs.field(default="box")
    size: tuple[float, ...] = attrs.field(default=(0.08, 0.08, 0.08), converter=lambda v: tuple(float(x) for x in v))
    color: tuple[float, float, float] = attrs.field(default=(0.6, 0.6, 0.6), converter=lambda v: tuple(float(x) for x in v))

    @shape.validator
    def _check_shape(self, attribute, value):
        if value not in SHAPES:
            raise ValidationError(f"Appearance.shape must be one of {SHAPES}, got {value!r}")

    @size.validator
    def _check_size(self, attribute, value):
        want = {"box": 3, "cylinder": 2, "sphere": 1}.get(self.shape)
        if want is not None and len(value) != want:
            raise ValidationError(f"Appearance.size for a {self.shape} needs {want} numbers, got {list(value)}")
        if any(not (0.0 < v <= 2.0) for v in value):
            raise ValidationError(f"Appearance.size must be in (0, 2] metres, got {list(value)}")

    @color.validator
    def _check_color(self, attribute, value):
        if len(value) != 3 or any(not (0.0 <= v <= 1.0) for v in value):
            raise ValidationError(f"Appearance.color must be 3 numbers in [0, 1], got {list(value)}")


#: The appearance an object gets when its catalog entry names none: a grey 8 cm cube.
DEFAULT_APPEARANCE = Appearance()


@attrs.frozen
class ObjectSpec:
    """A named object: ``name``, a one-line ``description``, and its ``appearance``."""

    name: str = attrs.field(validator=_nonempty_str)
    description: str = attrs.field(default="", validator=attrs.validators.instance_of(str))
    appearance: Appearance = attrs.field(default=DEFAULT_APPEARANCE,
                                         validator=attrs.validators.instance_of(Appearance))

    @property
    def slug(self) -> str:
        return slug(self.name)


@attrs.frozen
class Scene:
    """One tabletop scene of a task family.

    ``objects``: the scene's objects, one per slot; ``relevant``: names of the objects the human acts on
    (ground truth); ``positions``: ``[n_objects, 3]`` initial positions in metres; ``landmarks``: landmark
    name -> ``[3]`` position; ``seed`` makes the scene reproducible.
    """

    task: str = attrs.field(validator=_nonempty_str)
    objects: tuple[ObjectSpec, ...] = attrs.field(converter=tuple)
    relevant: frozenset[str] = attrs.field(converter=frozenset, factory=frozenset)
    positions: np.ndarray = attrs.field(converter=_float_array, factory=lambda: np.zeros((0, 3)), eq=False)
    landmarks: Mapping[str, tuple[float, float, float]] = attrs.field(factory=dict, eq=False)
    seed: int = attrs.field(default=0, validator=attrs.validators.instance_of(int))

    @objects.validator
    def _check_objects(self, attribute, value):
        names = [o.name for o in value]
        if len(set(names)) != len(names):
            raise ValidationError(f"Scene.objects has duplicate names: {names}")

    @relevant.validator
    def _check_relevant(self, attribute, value):
        unknown = set(value) - {o.name for o in self.objects}
        if unknown:
            raise ValidationError(f"Scene.relevant names objects not in the scene: {sorted(unknown)}")

    @positions.validator
    def _check_positions(self, attribute, value):
        if value.size and value.shape != (len(self.objects), 3):
            raise ValidationError(f"Scene.positions must be [n_objects={len(self.objects)}, 3], got {value.shape}")

    @property
    def object_names(self) -> tuple[str, ...]:
        return tuple(o.name for o in self.objects)


# ----------------------------------------------------------------------------- trajectories


@attrs.frozen
class TrajectoryBatch:
    """N trajectories of T steps in one scene layout (the same object slots for the whole batch).

    - ``joint_positions``: ``[N, T, dof]`` radians
    - ``ee_positions``: ``[N, T, 3]`` metres (end effector)
    - ``object_positions``: ``[N, T, n_objects, 3]`` metres
    - ``landmark_positions``: ``[N, T, n_landmarks, 3]`` metres (backpack, drawer, spill, ...)
    - ``object_names``: ``(n_objects,)``, ``landmark_names``: ``(n_landmarks,)``
    - ``meta``: free-form provenance (robot, task, seed, generator, ...)
    """

    joint_positions: np.ndarray = attrs.field(converter=_float_array, eq=False)
    ee_positions: np.ndarray = attrs.field(converter=_float_array, eq=False)
    object_positions: np.ndarray = attrs.field(converter=_float_array, eq=False)
    object_names: tuple[str, ...] = attrs.field(converter=_str_tuple, validator=[_all_str, _unique])
    landmark_positions: np.ndarray = attrs.field(converter=_float_array, eq=False,
                                                 factory=lambda: np.zeros((0, 0, 0, 3)))
    landmark_names: tuple[str, ...] = attrs.field(converter=_str_tuple, factory=tuple,
                                                  validator=[_all_str, _unique])
    meta: Mapping[str, Any] = attrs.field(factory=dict, eq=False)

    def __attrs_post_init__(self) -> None:
        jp, ee, op = self.joint_positions, self.ee_positions, self.object_positions
        if jp.ndim != 3:
            raise ValidationError(f"joint_positions must be [N, T, dof], got shape {jp.shape}")
        n, t = jp.shape[:2]
        if ee.shape != (n, t, 3):
            raise ValidationError(f"ee_positions must be [N={n}, T={t}, 3], got {ee.shape}")
        if op.shape != (n, t, len(self.object_names), 3):
            raise ValidationError(f"object_positions must be [N={n}, T={t}, n_objects={len(self.object_names)}, 3],"
                                  f" got {op.shape}")
        lp = self.landmark_positions
        if self.landmark_names and lp.shape != (n, t, len(self.landmark_names), 3):
            raise ValidationError(f"landmark_positions must be [N={n}, T={t}, n_landmarks={len(self.landmark_names)},"
                                  f" 3], got {lp.shape}")

    def __len__(self) -> int:
        return self.joint_positions.shape[0]

    @property
    def n_steps(self) -> int:
        return self.joint_positions.shape[1]

    def __getitem__(self, index) -> "TrajectoryBatch":
        """Select trajectories (int, slice, or index array), keeping the batch dimension."""
        idx = np.atleast_1d(np.arange(len(self))[index])
        lp = self.landmark_positions[idx] if self.landmark_names else self.landmark_positions
        return attrs.evolve(self, joint_positions=self.joint_positions[idx], ee_positions=self.ee_positions[idx],
                            object_positions=self.object_positions[idx], landmark_positions=lp)


def Trajectory(joint_positions, ee_positions, object_positions, object_names, **kw) -> TrajectoryBatch:
    """One trajectory (``[T, dof]``, ``[T, 3]``, ``[T, n_objects, 3]``) as a batch of one."""
    lp = kw.pop("landmark_positions", None)
    if lp is not None:
        kw["landmark_positions"] = np.asarray(lp)[None]
    return TrajectoryBatch(np.asarray(joint_positions)[None], np.asarray(ee_positions)[None],
                           np.asarray(object_positions)[None], object_names, **kw)


# ----------------------------------------------------------------------------- features


@attrs.frozen
class FeatureSpec:
    """One per-time-step feature.

    ``name`` e.g. ``"coffee_mug_proximity_to_laptop"``; ``description`` one line of natural language;
    ``subject``: the object whose identity the feature is about (a *semantic* component, renamed by
    alignment), or None for continuous features (end effector, ...) that alignment leaves untouched;
    ``reference``: the landmark or second object, if any.
    """

    name: str = attrs.field(validator=_nonempty_str)
    description: str = attrs.field(default="", validator=attrs.validators.instance_of(str))
    subject: str | None = attrs.field(default=None)
    reference: str | None = attrs.field(default=None)
    kind: str = attrs.field(default="proximity", validator=_nonempty_str)

    @property
    def semantic(self) -> bool:
        return self.subject is not None

    @property
    def role(self) -> tuple[str, str | None]:
        """What the feature measures apart from its subject: ``(kind, reference)``."""
        return (self.kind, self.reference)


def proximity_feature(first: str, second: str, *, subject: str | None = None) -> FeatureSpec:
    """``first_proximity_to_second`` in [0, 1]: 1 when the two touch, 0 when far or either is absent.

    ``subject`` names which of the two is the scene object that alignment renames (default ``first``);
    the other one is the landmark (backpack, drawer, spill, the carried mug).
    """
    subject = first if subject is None else subject
    if subject not in (first, second):
        raise ValidationError(f"proximity_feature: subject {subject!r} is neither {first!r} nor {second!r}")
    reference = second if subject == first else first
    return FeatureSpec(name=f"{slug(first)}_proximity_to_{slug(second)}",
                       description=f"closeness of the {first} to the {second} (1 = touching, 0 = far or absent)",
                       subject=subject, reference=reference, kind="proximity")


@attrs.frozen
class FeatureBatch:
    """Per-time-step features of N trajectories: ``values`` ``[N, T, F]`` with ``specs`` ``(F,)``."""

    specs: tuple[FeatureSpec, ...] = attrs.field(converter=tuple)
    values: np.ndarray = attrs.field(converter=_float_array, eq=False)
    meta: Mapping[str, Any] = attrs.field(factory=dict, eq=False)

    def __attrs_post_init__(self) -> None:
        if self.values.ndim != 3 or self.values.shape[2] != len(self.specs):
            raise ValidationError(f"FeatureBatch.values must be [N, T, F={len(self.specs)}], got {self.values.shape}")
        names = self.names
        if len(set(names)) != len(names):
            raise ValidationError(f"FeatureBatch has duplicate feature names: {names}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.specs)

    @property
    def descriptions(self) -> dict[str, str]:
        return {s.name: s.description for s in self.specs}

    def __len__(self) -> int:
        return self.values.shape[0]

    def __getitem__(self, index) -> "FeatureBatch":
        idx = np.atleast_1d(np.arange(len(self))[index])
        return attrs.evolve(self, values=self.values[idx])

    def reindex(self, specs: Sequence[FeatureSpec]) -> "FeatureBatch":
        """The columns ``specs`` in that order; a column this batch lacks is 0 (its object is absent)."""
        index = {n: i for i, n in enumerate(self.names)}
        out = np.zeros(self.values.shape[:2] + (len(specs),))
        for j, spec in enumerate(specs):
            i = index.get(spec.name)
            if i is not None:
                out[..., j] = self.values[..., i]
        return FeatureBatch(tuple(specs), out, dict(self.meta))

    def trace(self, i: int) -> "FeatureTrace":
        return FeatureTrace(self.specs, self.values[i])

    @classmethod
    def concat(cls, batches: Sequence["FeatureBatch"]) -> "FeatureBatch":
        """Stack batches that share the same feature columns."""
        first = batches[0]
        for b in batches[1:]:
            if b.names != first.names:
                raise ValidationError(f"cannot concatenate feature batches with different columns: "
                                      f"{first.names} vs {b.names}")
        return cls(first.specs, np.concatenate([b.values for b in batches], axis=0), dict(first.meta))


@attrs.frozen
class FeatureTrace:
    """The features of one trajectory: ``values`` ``[T, F]`` with ``specs`` ``(F,)``."""

    specs: tuple[FeatureSpec, ...] = attrs.field(converter=tuple)
    values: np.ndarray = attrs.field(converter=_float_array, eq=False)

    def __attrs_post_init__(self) -> None:
        if self.values.ndim != 2 or self.values.shape[1] != len(self.specs):
            raise ValidationError(f"FeatureTrace.values must be [T, F={len(self.specs)}], got {self.values.shape}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.specs)

    def to_text(self, features: Sequence[str] | None = None, decimals: int = 2, every: int = 1) -> str:
        """One line per time step, ``Timestep t: name: value, ...`` for the LM prompts."""
        cols = [i for i, s in enumerate(self.specs) if features is None or s.name in features]
        lines = []
        for t in range(0, self.values.shape[0], every):
            parts = ", ".join(f"{self.specs[i].name}: {self.values[t, i]:.{decimals}f}" for i in cols)
            lines.append(f"Timestep {t}: {parts}")
        return "\n".join(lines)


@attrs.frozen
class DemonstrationPair:
    """A human-preferred and a default (nominal-controller) trajectory in the same scene."""

    preferred: FeatureTrace
    default: FeatureTrace
    scene: Scene | None = attrs.field(default=None, eq=False)

    def __attrs_post_init__(self) -> None:
        if self.preferred.names != self.default.names:
            raise ValidationError("DemonstrationPair: preferred and default traces must share feature columns")


# ----------------------------------------------------------------------------- intent and alignment


@attrs.frozen
class Motivation:
    """One inferred motivation: a sentence and the features it concerns."""

    text: str = attrs.field(validator=_nonempty_str)
    features: tuple[str, ...] = attrs.field(converter=_str_tuple, factory=tuple, validator=_all_str)


@attrs.frozen
class SemanticAxis:
    """A yes/no question that groups objects under an intent (e.g. "is this an art supply?")."""

    question: str = attrs.field(validator=_nonempty_str)
    objects: tuple[str, ...] = attrs.field(converter=_str_tuple, factory=tuple, validator=_all_str)


@attrs.frozen
class Intent:
    """The human's high-level intent ω: a ``text``, ranked ``motivations`` and semantic ``axes``."""

    text: str = attrs.field(validator=_nonempty_str)
    motivations: tuple[Motivation, ...] = attrs.field(converter=tuple, factory=tuple)
    axes: tuple[SemanticAxis, ...] = attrs.field(converter=tuple, factory=tuple)
    source: str = attrs.field(default="given")  # "given", "ground-truth", "inferred", ...

    @property
    def relevant_features(self) -> tuple[str, ...]:
        seen: dict[str, None] = {}
        for m in self.motivations:
            seen.update(dict.fromkeys(m.features))
        return tuple(seen)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``{text, source, motivations: [{text, features}], axes: [{question, objects}]}``."""
        return {"text": self.text, "source": self.source,
                "motivations": [{"text": m.text, "features": list(m.features)} for m in self.motivations],
                "axes": [{"question": a.question, "objects": list(a.objects)} for a in self.axes]}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Intent":
        """Inverse of :meth:`to_dict`; ``motivations``, ``axes`` and ``source`` may be left out."""
        try:
            return cls(d["text"], [Motivation(m["text"], m.get("features", ())) for m in d.get("motivations", ())],
                       [SemanticAxis(a["question"], a.get("objects", ())) for a in d.get("axes", ())],
                       source=d.get("source", "given"))
        except (KeyError, TypeError, AttributeError) as e:
            raise ValidationError(f"not an intent dict ({type(e).__name__}: {e}): {str(d)[:200]}") from None


@attrs.frozen
class Alignment:
    """f_ω on the semantic components: test object -> training object or DISTRACTOR.

    ``mapping[test] = target``; ``scores[test]`` = K(f_ω(s'), s' | ω) in [0, 1] for the chosen target
    (for a distractor: the best score, which stayed below the threshold); ``threshold`` the cut used.
    """

    mapping: Mapping[str, str] = attrs.field(converter=dict)
    scores: Mapping[str, float] = attrs.field(converter=dict, factory=dict)
    threshold: float | None = None
    kernel: str = ""

    @scores.validator
    def _check_scores(self, attribute, value):
        for k, v in value.items():
            if not (0.0 <= float(v) <= 1.0):
                raise ValidationError(f"Alignment score of {k!r} must be in [0, 1], got {v}")
            if k not in self.mapping:
                raise ValidationError(f"Alignment has a score for {k!r} which it does not map")

    def target(self, test_object: str) -> str:
        return self.mapping.get(test_object, DISTRACTOR)

    def relevant(self, relevant_train: Sequence[str] | None = None) -> dict[str, bool]:
        """Per test object: is it aligned to a (relevant) training object?"""
        rel = None if relevant_train is None else set(relevant_train)
        return {k: (v != DISTRACTOR and (rel is None or v in rel)) for k, v in self.mapping.items()}

    def error_bound(self, lipschitz: float = 1.0, n_steps: int = 1,
                    objects: Sequence[str] | None = None) -> float:
        """The paper's bound L · Σ_t (1 − K(f_ω(s'_t), s'_t | ω)) for a trajectory of ``n_steps`` states.

        Each state holds ``objects`` (default: every mapped test object); its dissimilarity is the
        largest ``1 − K`` over its aligned objects (distractors are dropped, not aligned, so they add 0).
        """
        names = self.mapping.keys() if objects is None else objects
        gaps = [1.0 - float(self.scores.get(n, 1.0)) for n in names if self.target(n) != DISTRACTOR]
        return float(lipschitz * n_steps * (max(gaps) if gaps else 0.0))


def _unit_interval(instance: Any, attribute: attrs.Attribute, value: float) -> None:
    if not (isinstance(value, (int, float)) and 0.0 <= float(value) <= 1.0):
        raise ValidationError(f"{type(instance).__name__}.{attribute.name} must be a number in [0, 1], got {value!r}")


def _vector(value: Any) -> np.ndarray:
    return np.asarray(value, dtype=float).reshape(-1)


@attrs.frozen
class RelevanceScores:
    """One scoring pass of a relevance kernel over a test scene (:meth:`RelevanceKernel.score`).

    ``relevance`` ``[n_test]`` in [0, 1]: how much each test object is one of the things the intent is
    about (0.5 = undecided). ``train_loo`` ``[n_train]`` in [0, 1]: the same score for each training
    object, computed as if it were new, against the *other* training objects (leave-one-out), on the
    test objects' scale: what a training-set threshold separates. ``relevant`` ``[n_train]`` bool: the
    training objects the scores treat as relevant (the given ``relevant_train``, or the kernel's own
    guess when none was given). ``details``: JSON-able notes for reports (e.g. the category asked about
    and the weight of each term). ``cut``: see below.
    """

    relevance: np.ndarray = attrs.field(converter=_vector, eq=False)
    train_loo: np.ndarray = attrs.field(converter=_vector, eq=False)
    relevant: np.ndarray = attrs.field(converter=lambda v: np.asarray(v, dtype=bool).reshape(-1), eq=False)
    details: Mapping[str, Any] = attrs.field(factory=dict, converter=dict, eq=False)
    #: The cut the scores call for when they are calibrated probabilities with the intent's training evidence
    #: already folded in (1/2); None: the train-calibrated cut is placed on the training scores.
    cut: float | None = None
    #: Where the scores' own scale puts the boundary before any training evidence (e.g. 1/2 for scores that
    #: are 1/2 at the scene's mean), and its weight in the train-calibrated cut: ``prior_weight * prior_cut +
    #: (1 - prior_weight) * leave-one-out cut`` (3-6 training objects place a cut noisily). None: the
    #: leave-one-out cut alone.
    prior_cut: float | None = attrs.field(default=None, validator=attrs.validators.optional(_unit_interval))
    prior_weight: float = attrs.field(default=0.5, converter=float, validator=_unit_interval)

    def __attrs_post_init__(self) -> None:
        for name in ("relevance", "train_loo"):
            v = getattr(self, name)
            if v.size and (not np.all(np.isfinite(v)) or v.min() < -1e-9 or v.max() > 1 + 1e-9):
                raise ValidationError(f"RelevanceScores.{name} must be finite values in [0, 1], got {v}")
        if self.relevant.shape != self.train_loo.shape:
            raise ValidationError(f"RelevanceScores: relevant has {self.relevant.size} entries for "
                                  f"{self.train_loo.size} training objects")

    @property
    def K(self) -> np.ndarray:
        """``[n_test, n_train]``: the relevance of each test object in the relevant training columns, 0 elsewhere."""
        return np.where(self.relevant[None, :], self.relevance[:, None], 0.0)


# ----------------------------------------------------------------------------- LM messages


def _cut_within(instance: Any, attribute: Any, cut: int) -> None:
    if not 0 <= cut <= len(instance.content):
        raise ValueError(f"Message.cut {cut} is outside the content's {len(instance.content)} characters")


@attrs.frozen
class Message:
    """One chat message. ``cut``: a hint, not text. The first ``cut`` characters of ``content`` are a piece
    that many prompts share, such as the object in "Is a <object> one of the <category>?". A backend that
    evaluates prompts in pieces may evaluate that piece on its own and reuse it. 0 means no hint. It is
    part of an LM request's cache key, since another split can give slightly different numbers, but it is
    never sent to a model."""

    role: str = attrs.field(validator=attrs.validators.in_(("system", "user", "assistant")))
    content: str = attrs.field(validator=attrs.validators.instance_of(str))
    cut: int = attrs.field(default=0, converter=int, validator=_cut_within, kw_only=True)

    def to_dict(self) -> dict[str, str]:
        """The message as a chat API takes it (the ``cut`` hint left out)."""
        return {"role": self.role, "content": self.content}


def as_messages(messages: Sequence[Message | Mapping[str, str]] | str) -> tuple[Message, ...]:
    """Normalise a prompt: a string (one user message), dicts, or Message objects."""
    if isinstance(messages, str):
        return (Message("user", messages),)
    out = []
    for m in messages:
        out.append(m if isinstance(m, Message) else Message(m["role"], m["content"], cut=m.get("cut", 0)))
    return tuple(out)


@attrs.frozen
class Usage:
    """Accounting of one LM call: tokens, wall-clock ``latency_s``, ``cost_usd`` when the provider prices it."""

    prompt_tokens: int = 0
    completion_tokens: int = 0
    latency_s: float = 0.0
    cost_usd: float | None = None
    cached: bool = False


@attrs.frozen
class Completion:
    text: str = attrs.field(validator=attrs.validators.instance_of(str))
    usage: Usage = attrs.field(factory=Usage)
    model: str = ""
