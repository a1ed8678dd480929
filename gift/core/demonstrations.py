"""What demonstrations say about objects: which training objects the human treated specially.

:func:`infer_relevant_objects` decides, from preferred-vs-default :class:`~gift.core.data.DemonstrationPair`\\ s
alone (no LM, no labels), which training objects the human acted on or kept away from. It reads only the
per-object (semantic) feature columns, grouped by their :attr:`~gift.core.data.FeatureSpec.role`
``(kind, reference)``; it never looks at a task family's name, a scene's ground-truth ``relevant`` field or
a suite. Call it with the study's demonstration pairs and the intent's training object names::

    result = infer_relevant_objects(pairs, spec.train_objects)
    result.relevant        # ("paintbrush", "sketchbook")
    result.scores          # {"paintbrush": 1.0, ..., "banana": 0.0}: posterior P(relevant)

The procedure, per role:

1. **Mode.** In the *default* (intent-blind) trajectories, does the role's column of most objects change
   over time? If not, the robot moves objects one at a time relative to a fixed reference (*acting*:
   packing, storing, pushing); if so, the reference moves past every object (*passing*: carrying a mug
   over the table). A majority vote over (default trajectory, object present) entries decides.
2. **Activity** ``A`` of an object's column in one trajectory: acting roles, its total variation
   ``Σ_t |c_{t+1} − c_t|`` (0 for an object nobody touched); passing roles, its closeness summed over time
   ``Σ_t c_t``.
3. **What the human did differently**, scene by scene (the pairs of one scene share its layout):

   - *Acting*: an untouched object's activity is exactly 0, so every pair can be read on its own (the
     human may pick a different object in each demonstration): its *choice* is the object its preferred
     trajectory acted on that no default trajectory of the scene acts on. A pair that acted only on what
     the default acts on chose the default's object, if the human chose differently in another pair of the
     scene.
   - *Passing*: every column carries the perturbation noise of the trajectories, so a scene is read as a
     whole, against the range of its default trajectories (which differ only by that noise): an object is
     *avoided* when every preferred trajectory stayed further from it than every default trajectory did,
     *approached* in the opposite case; each pair's choice is the avoided object whose closeness it cut
     by the largest fraction. Pair by pair, the model also counts which objects each preferred trajectory
     kept further from than every default did (:func:`pair_avoidance`): a second relevant object, avoided
     in every pair but never the one a pair steered by most, shows there.

   A scene carries no evidence when the human never deviates (they did what the default does), and a
   deviation in the mode's direction on every object of the scene (e.g. a carry raised over the whole
   table) singles out none: which object it was for cannot be told.
4. **A likelihood over relevant sets.** For a candidate set R, the evidence of one scene is either
   *explained* or the scene is an *outlier* (e.g. its only relevant object was out of the robot's reach and
   the human acted on something else). Explained: every choice is an object of R present in the scene (and,
   passing, no object of R was approached); the human's preferences among those objects are unknown, a
   Dirichlet-multinomial with a flat prior, so an object of R that is present but never chosen costs
   likelihood. Outlier: the choices are arbitrary among all the scene's objects. The outlier rate ε has a
   flat prior on [0, 1] and is integrated out. Passing roles add, per scene, the pairs' avoidances: each
   relevant object the defaults pass is avoided at one rate p, each irrelevant one (incidentally, beside a
   relevant one) at a rate q <= p, flat prior on the ordered pair, both integrated out. Every subset R of
   the observed objects is scored under a flat prior over subsets, which gives each object's posterior
   probability of being relevant.
5. **The cut.** An object is relevant when its posterior exceeds 1/2, the decision that minimises the
   expected number of misclassified objects. Nothing is tuned: the only numbers are the flat priors. A lower
   cut was tried (0.35, 2026-12-05; ``docs/results/front_half.md`` section 30) for a second relevant object
   that is nobody's choice (the human always steered by the first one beside it), which the choices alone
   leave near the prior; but with fewer demonstrations perturbation noise puts irrelevant objects in the same
   band (an acting family at two scenes of three pairs), so it was reverted. The pairs' avoidances (step 4)
   are what now tells that second object apart (section 32).

Edge cases:

- *none relevant*: a human with nothing to care about does what the default does, and pairs without
  deviation carry no evidence: if no scene is informative, nothing is relevant and every observed object is
  reported as ``undetermined``.
- *all relevant*: choices spread over every object with no preference are better explained by "all
  relevant" than by an outlier in every scene, so all observed objects come out relevant.
- *unobserved*: a training object that is in no pair's scene (without scenes: whose columns are zero in
  every trace) has no evidence; it is reported in ``unobserved``, never as relevant or irrelevant.
- *undetermined*: an observed object whose posterior stayed at the prior 1/2 (it was only in scenes that
  carry no evidence about it).

Inherent limits: an object the human cared about but never had to treat differently from the default
(the default already avoids it, or another relevant object was always the better choice in its scenes)
leaves no trace in the demonstrations; the model then calls it irrelevant. And when the demonstrated
deviation is the same whatever the relevant set (a detour that avoids every object at once), the
demonstrations cannot single out objects at all: those objects come out ``undetermined``.
``docs/results/relevant_objects.md`` measures the first on the shipped suites; the second is what the Drake
place_mug demonstrations were until its simulated human kept the mug low instead of raising it over the table.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from gift.core.data import DemonstrationPair, FeatureSpec
from gift.core.errors import ValidationError

#: Acting and passing roles (see the module docstring).
MODES = ("acting", "passing")
#: Largest number of observed objects whose relevant sets are enumerated exhaustively (2**n subsets).
MAX_OBJECTS = 16
#: The cut on the posterior probability of relevance.
CUT = 0.5
#: Gauss-Legendre nodes for integrating the outlier rate over [0, 1].
_QUAD_NODES = 48
#: Activities closer than this (feature units) are equal: float noise, not motion.
_TOL = 1e-9


@attrs.frozen
class ObjectEvidence:
    """What the demonstrations show of one training object.

    ``scenes`` / ``pairs``: scenes and demonstration pairs it was in. Acting roles: ``chosen``, pairs in
    which the human acted on it beyond the default (fractional when tied). Passing roles: ``avoided`` /
    ``approached``, scenes in which every preferred trajectory stayed further from / came closer to it than
    every default trajectory.
    """

    scenes: int = 0
    pairs: int = 0
    chosen: float = 0.0
    avoided: int = 0
    approached: int = 0


@attrs.frozen
class RelevantObjects:
    """The training objects the demonstrations single out (:func:`infer_relevant_objects`).

    - ``relevant``: inferred relevant names, in training-object order;
    - ``scores``: per observed object, the posterior probability that it is relevant, in [0, 1];
    - ``cut``: the posterior above which an object is relevant; ``rule``: how the cut and the modes were
      decided, and how much of the data was informative, in words;
    - ``unobserved``: training objects in no demonstration (no evidence; not in ``scores``);
    - ``undetermined``: observed objects whose posterior stayed at the prior 1/2 (no evidence either way);
    - ``evidence``: per training object, an :class:`ObjectEvidence`;
    - ``modes``: per role ``"kind:reference"``, ``"acting"`` or ``"passing"``;
    - ``informative``: scenes (per role) whose demonstrations carry evidence, of ``scenes`` in all.
    """

    relevant: tuple[str, ...] = attrs.field(converter=tuple)
    scores: Mapping[str, float] = attrs.field(converter=dict)
    cut: float
    rule: str
    unobserved: tuple[str, ...] = attrs.field(converter=tuple, factory=tuple)
    undetermined: tuple[str, ...] = attrs.field(converter=tuple, factory=tuple)
    evidence: Mapping[str, ObjectEvidence] = attrs.field(converter=dict, factory=dict)
    modes: Mapping[str, str] = attrs.field(converter=dict, factory=dict)
    informative: int = 0
    scenes: int = 0

    @scores.validator
    def _check_scores(self, attribute, value):
        for k, v in value.items():
            if not 0.0 <= v <= 1.0:
                raise ValidationError(f"RelevantObjects.scores[{k!r}] must be in [0, 1], got {v}")

    @property
    def irrelevant(self) -> tuple[str, ...]:
        """Observed objects that are neither relevant nor undetermined."""
        skip = set(self.relevant) | set(self.undetermined)
        return tuple(o for o in self.scores if o not in skip)

    @property
    def separates(self) -> bool:
        """Whether the demonstrations split the observed objects into relevant and irrelevant ones."""
        return bool(self.relevant) and bool(self.irrelevant)

    def to_dict(self) -> dict:
        """A JSON-able summary (for results files): everything but the per-object evidence counts in full."""
        return {"relevant": list(self.relevant), "scores": {k: float(v) for k, v in self.scores.items()},
                "cut": self.cut, "rule": self.rule, "unobserved": list(self.unobserved),
                "undetermined": list(self.undetermined), "modes": dict(self.modes),
                "informative": self.informative, "scenes": self.scenes,
                "evidence": {k: attrs.asdict(v) for k, v in self.evidence.items()}}


# ----------------------------------------------------------------------------- evidence of one scene


@attrs.frozen
class _Unit:
    """One scene's evidence for one role: ``present`` objects, ``counts`` ``[n]`` of the human's choices, and
    (passing) the ``approached`` objects and, per object ``[n]``, the pairs that ``avoided`` it of the
    ``trials`` that could have (see :func:`pair_avoidance`); indices are positions in the observed-object
    list."""

    present: tuple[int, ...]
    counts: np.ndarray
    approached: tuple[int, ...] = ()
    avoided: np.ndarray | None = None
    trials: np.ndarray | None = None


def _role_key(spec: FeatureSpec) -> str:
    kind, ref = spec.role
    return f"{kind}:{ref}" if ref is not None else kind


def _scene_key(pair: DemonstrationPair, index: int):
    """Pairs of one scene share this key; without a scene every pair is its own unit.

    Only the scene's identity and object names are read, never its ``relevant`` field.
    """
    s = pair.scene
    if s is None:
        return ("pair", index)
    return (s.task, s.object_names, s.seed, np.asarray(s.positions).tobytes())


def _activity(values: np.ndarray, mode: str) -> np.ndarray:
    """``values`` ``[n, T, k]`` -> activity ``[n, k]`` (total variation or summed closeness)."""
    if mode == "acting":
        return np.abs(np.diff(values, axis=1)).sum(axis=1)
    return values.sum(axis=1)


def acting_choices(pref: np.ndarray, default: np.ndarray) -> np.ndarray:
    """Acting role: per pair of one scene, the weight of each object as the human's choice.

    ``pref`` ``[n, k]``, ``default`` ``[n, k]``: activities of the ``k`` objects present, pair by pair. An
    untouched object's activity is exactly 0, so what a trajectory acts on is exact. A pair's choice is the
    object its preferred trajectory acted on most among those no default trajectory of the scene acts on
    (split on ties). A pair that acts on none of those did what the default does: its choice is its
    default's own object, provided the human chose differently in some other pair of the scene (if the
    human never does, the scene carries no evidence). A pair acting on every object singles out none.
    Returns ``[n, k]``, one unit per informative pair.
    """
    fresh = pref * (default.max(axis=0) <= _TOL)[None, :]
    out = np.zeros_like(pref)
    same = []
    for i, row in enumerate(fresh):
        if (pref[i] > _TOL).all():
            continue
        if row.max() > _TOL:
            top = row >= row.max() - _TOL
            out[i, top] = 1.0 / top.sum()
        else:
            same.append(i)
    if same and out.any():
        for i in same:
            target = default[i] > _TOL
            if target.any() and not target.all():
                out[i, target] = 1.0 / target.sum()
    return out


def passing_choices(pref: np.ndarray, default: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Passing role: which objects one scene's preferred trajectories avoided, approached, and chose.

    ``pref`` ``[n_p, k]``, ``default`` ``[n_d, k]``: summed closeness of the ``k`` objects present. An object
    is *avoided* (*approached*) when every preferred trajectory stayed further from (came closer to) it than
    every default trajectory. Returns ``(avoided [k], approached [k], choices [n_p, k])``: per pair, one unit
    on the avoided object whose closeness it cut by the largest fraction of the default's (split on ties).
    All three are empty (False / 0) when nothing or every object was avoided: such a deviation singles out
    none.
    """
    avoided = pref.max(axis=0) < default.min(axis=0) - _TOL
    approached = pref.min(axis=0) > default.max(axis=0) + _TOL
    choices = np.zeros_like(pref)
    if not avoided.any() or avoided.all():
        return np.zeros_like(avoided), np.zeros_like(approached), choices
    mean_d = default.mean(axis=0)
    cut = np.where(avoided, (mean_d - pref) / np.where(mean_d > _TOL, mean_d, 1.0), -np.inf)
    for i, row in enumerate(cut):
        top = row >= row.max() - _TOL
        choices[i, top] = 1.0 / top.sum()
    return avoided, approached, choices


def pair_avoidance(pref: np.ndarray, default: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Passing role: how often each object was avoided, pair by pair.

    ``pref`` ``[n_p, k]``, ``default`` ``[n_d, k]`` as in :func:`passing_choices`. A pair avoided an object
    when its preferred trajectory stayed further from it than every default trajectory of the scene. An
    object the defaults never come near (summed closeness 0) cannot be avoided and counts no trial.
    Returns ``(avoided [k], trials [k])``: pairs that avoided each object, pairs that could have.
    """
    reachable = default.min(axis=0) > _TOL
    hit = (pref < default.min(axis=0)[None, :] - _TOL) & reachable[None, :]
    return hit.sum(axis=0).astype(float), np.where(reachable, float(len(pref)), 0.0)


# ----------------------------------------------------------------------------- likelihood over relevant sets


#: log Γ, elementwise over arrays (math.lgamma; the core does not depend on scipy).
_lgamma = np.vectorize(math.lgamma, otypes=[float])


def _lbeta(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return _lgamma(a) + _lgamma(b) - _lgamma(a + b)


def _log_two_rates(a: int, b: int, c: int, d: int) -> float:
    """log ∫∫_{p>q} 2 p^a (1-p)^b q^c (1-q)^d dq dp: ``a`` avoidances and ``b`` non-avoidances of relevant
    objects at rate p, ``c`` and ``d`` of irrelevant ones at rate q <= p (flat prior on the ordered pair).

    Exact, as a sum of positive terms: ∫_0^p q^c (1-q)^d dq = B(c+1, d+1) Σ_{j>c}^{N} C(N, j) p^j (1-p)^(N-j)
    with N = c + d + 1, and each term integrates against p^a (1-p)^b to a beta function.
    """
    n = c + d + 1
    j = np.arange(c + 1, n + 1, dtype=float)
    log_binom = math.lgamma(n + 1.0) - _lgamma(j + 1.0) - _lgamma(n - j + 1.0)
    terms = log_binom + _lbeta(a + j + 1.0, b + n - j + 1.0)
    return math.log(2.0) + float(_lbeta(np.array(c + 1.0), np.array(d + 1.0))) + float(np.logaddexp.reduce(terms))


def _avoidance_loglik(u: _Unit, bits: np.ndarray) -> np.ndarray | None:
    """log P(which pairs avoided which objects | R) ``[M]`` of one passing scene, or None without trials.

    Every relevant object the defaults pass is avoided at one rate p, every irrelevant one (incidentally,
    e.g. beside a relevant one) at a rate q <= p; p and q are integrated out. A second relevant object that
    is never the pair's main choice still shows here.
    """
    if u.trials is None or not u.trials.any():
        return None
    av = u.avoided.astype(int)
    no = (u.trials - u.avoided).astype(int)
    stats = np.stack([bits @ av, bits @ no, (~bits) @ av, (~bits) @ no], axis=1)    # [M, 4]
    keys, inverse = np.unique(stats, axis=0, return_inverse=True)
    values = np.array([_log_two_rates(*map(int, k)) for k in keys])
    return values[np.ravel(inverse)]


def _log_dirmult(counts: np.ndarray, k: np.ndarray) -> np.ndarray:
    """log Dirichlet(1)-multinomial probability of a choice sequence with these nonzero ``counts`` over ``k``
    categories (vectorised in ``k``; no multinomial coefficient: the sequence is observed in order)."""
    return _lgamma(k) - _lgamma(counts.sum() + k) + float(sum(math.lgamma(c + 1.0) for c in counts))


def _unit_loglik(u: _Unit, bits: np.ndarray) -> tuple[np.ndarray, float] | None:
    """``(log P(evidence | R, explained) [M], log P(evidence | outlier))`` of one scene, or None if it is
    uninformative. ``bits`` ``[M, n]``: membership of each object in each candidate set R.

    Explained: every choice is in R (and, passing, R holds no approached object); the choices among the
    objects of R present follow a Dirichlet(1)-multinomial. Outlier: the same over all objects present.
    """
    chosen = np.flatnonzero(u.counts > 0)
    if chosen.size == 0:
        return None
    present = np.zeros(bits.shape[1], dtype=bool)
    present[list(u.present)] = True
    c = u.counts[chosen]
    k_in = bits[:, present].sum(axis=1)
    explained = bits[:, chosen].all(axis=1)
    if u.approached:
        explained &= ~bits[:, list(u.approached)].any(axis=1)
    log_b = np.full(len(bits), -np.inf)
    log_b[explained] = _log_dirmult(c, k_in[explained].astype(float))
    return log_b, float(_log_dirmult(c, np.array([float(present.sum())]))[0])


def _posterior(units: Sequence[_Unit], n_objects: int) -> tuple[np.ndarray, int]:
    """Posterior P(object relevant) ``[n_objects]`` (flat priors; module docstring) and the number of
    informative units."""
    masks = np.arange(1 << n_objects, dtype=np.int64)
    bits = ((masks[:, None] >> np.arange(n_objects)) & 1).astype(bool)          # [M, n]
    nodes, weights = np.polynomial.legendre.leggauss(_QUAD_NODES)
    eps = (nodes + 1.0) / 2.0
    log_w = np.log(weights / 2.0)
    total = np.zeros((len(masks), _QUAD_NODES))                                  # log Π_u mixture(ε)
    informative = 0
    for u in units:
        ll = _unit_loglik(u, bits)
        if ll is None:
            continue
        informative += 1
        log_b, log_a = ll
        with np.errstate(divide="ignore"):
            total += np.logaddexp(np.log1p(-eps)[None, :] + log_b[:, None], np.log(eps)[None, :] + log_a)
        av = _avoidance_loglik(u, bits)
        if av is not None:
            total += av[:, None]
    log_l = np.logaddexp.reduce(total + log_w[None, :], axis=1)                  # [M]
    post = np.exp(log_l - np.logaddexp.reduce(log_l))
    return np.clip(post @ bits, 0.0, 1.0), informative


# ----------------------------------------------------------------------------- the function


def _check(pairs: list, train_objects) -> list[str]:
    if isinstance(train_objects, str) or not train_objects or \
            any(not isinstance(n, str) or not n.strip() for n in train_objects):
        raise ValidationError(f"infer_relevant_objects: train_objects must be a non-empty list of names, "
                              f"got {train_objects!r}")
    names = list(train_objects)
    if len(set(names)) != len(names):
        raise ValidationError(f"infer_relevant_objects: duplicate training objects in {names}")
    if not pairs:
        raise ValidationError("infer_relevant_objects: no demonstration pairs")
    for i, p in enumerate(pairs):
        if not isinstance(p, DemonstrationPair):
            raise ValidationError(f"infer_relevant_objects: pair {i} is a {type(p).__name__}, "
                                  f"not a DemonstrationPair")
        if p.preferred.names != pairs[0].preferred.names:
            raise ValidationError(f"infer_relevant_objects: pair {i} has other feature columns than pair 0 "
                                  f"({list(p.preferred.names)} vs {list(pairs[0].preferred.names)})")
    return names


def infer_relevant_objects(pairs: Sequence[DemonstrationPair], train_objects: Sequence[str]) -> RelevantObjects:
    """Which of ``train_objects`` the human treated specially in ``pairs`` (see the module docstring).

    ``pairs``: preferred-vs-default demonstration pairs from one or several scenes; pairs of one scene share
    their ``scene`` (read only for its identity and object names; without scenes, each pair is its own scene
    and an object is present where one of its columns is nonzero). ``train_objects``: the intent's training
    object names; an object's columns are the features whose ``subject`` is its name (other columns are
    ignored). No LM, no labels: a suite's ``relevant_train`` is never needed.

    Returns a :class:`RelevantObjects`. Raises :class:`~gift.core.errors.ValidationError` for no pairs, no or
    duplicate training objects, pairs with different feature columns, or more than :data:`MAX_OBJECTS`
    observed objects.
    """
    pairs = list(pairs)
    names = _check(pairs, train_objects)
    index = {n: j for j, n in enumerate(names)}
    roles: dict[str, dict[int, int]] = {}                                        # role -> object -> column
    for col, spec in enumerate(pairs[0].preferred.specs):
        if spec.semantic and spec.subject in index:
            roles.setdefault(_role_key(spec), {})[index[spec.subject]] = col
    columns = {j for cols in roles.values() for j in cols}

    groups: dict[object, list[int]] = {}
    for i, p in enumerate(pairs):
        groups.setdefault(_scene_key(p, i), []).append(i)
    scenes: list[tuple[list[int], np.ndarray]] = []                              # (pair indices, present [n])
    for members in groups.values():
        present = np.zeros(len(names), dtype=bool)
        scene = pairs[members[0]].scene
        if scene is not None:
            present[[index[n] for n in scene.object_names if n in index]] = True
        else:
            for cols in roles.values():
                for j, col in cols.items():
                    present[j] |= any(np.any(pairs[i].preferred.values[:, col] != 0) or
                                      np.any(pairs[i].default.values[:, col] != 0) for i in members)
        present &= np.isin(np.arange(len(names)), list(columns))
        scenes.append((members, present))

    observed = [j for j in range(len(names)) if any(pr[j] for _, pr in scenes)]
    if len(observed) > MAX_OBJECTS:
        raise ValidationError(f"infer_relevant_objects: {len(observed)} observed objects; the exhaustive model "
                              f"handles at most {MAX_OBJECTS}")
    local = {j: k for k, j in enumerate(observed)}
    ev = {n: {"scenes": 0, "pairs": 0, "chosen": 0.0, "avoided": 0, "approached": 0} for n in names}
    for members, present in scenes:
        for j in np.flatnonzero(present):
            ev[names[j]]["scenes"] += 1
            ev[names[j]]["pairs"] += len(members)

    modes: dict[str, str] = {}
    units: list[_Unit] = []
    for role, cols in roles.items():
        objs = sorted(cols)
        moving = []
        for members, present in scenes:                                          # 1. mode, from the defaults
            here = [cols[j] for j in objs if present[j]]
            if here:
                d = np.stack([pairs[i].default.values[:, here] for i in members])
                moving.append((np.ptp(d, axis=1) > _TOL).ravel())
        flat = np.concatenate(moving) if moving else np.zeros(0, dtype=bool)
        mode = modes[role] = "passing" if flat.size and flat.mean() > 0.5 else "acting"
        for members, present in scenes:                                          # 2-3. evidence per scene
            objs_here = [j for j in objs if present[j]]
            if not objs_here:
                continue
            cols_here = [cols[j] for j in objs_here]
            ap = _activity(np.stack([pairs[i].preferred.values[:, cols_here] for i in members]), mode)
            ad = _activity(np.stack([pairs[i].default.values[:, cols_here] for i in members]), mode)
            at = tuple(local[j] for j in objs_here)
            counts = np.zeros(len(observed))
            approached: tuple[int, ...] = ()
            hits = trials = None
            if mode == "acting":
                w = acting_choices(ap, ad).sum(axis=0)
            else:
                avoided, near, choices = passing_choices(ap, ad)
                w = choices.sum(axis=0)
                approached = tuple(k for k, b in zip(at, near) if b)
                hits, trials = np.zeros(len(observed)), np.zeros(len(observed))
                hits[list(at)], trials[list(at)] = pair_avoidance(ap, ad)
                for j, a, b in zip(objs_here, avoided, near):
                    ev[names[j]]["avoided"] += int(a)
                    ev[names[j]]["approached"] += int(b)
            counts[list(at)] = w
            for j, c in zip(objs_here, w):
                ev[names[j]]["chosen"] += float(c)
            units.append(_Unit(at, counts, approached, hits, trials))

    post, informative = _posterior(units, len(observed)) if observed else (np.zeros(0), 0)
    scores = {names[j]: float(post[k]) for k, j in enumerate(observed)}
    undetermined = tuple(n for n, s in scores.items() if abs(s - 0.5) < 1e-9)
    relevant = tuple(n for n in names if scores.get(n, 0.0) > CUT and n not in undetermined)
    rule = (f"posterior P(relevant | demonstrations) under a per-scene choice model with scene outliers (flat "
            f"priors over relevant sets and the outlier rate; passing roles also count every object each pair "
            f"avoided, relevant ones at a rate at least the others'); relevant = posterior > {CUT}, the fewest "
            f"expected misclassified objects. Roles: " + ", ".join(f"{r} {m}" for r, m in modes.items()) +
            f". {informative} of {len(units)} scene-role units are informative.")
    if not informative:
        rule += " No scene's demonstrations single out an object: nothing is inferred."
    return RelevantObjects(relevant=relevant, scores=scores, cut=CUT, rule=rule,
                           unobserved=tuple(n for j, n in enumerate(names) if j not in local),
                           undetermined=undetermined,
                           evidence={n: ObjectEvidence(**e) for n, e in ev.items()}, modes=modes,
                           informative=informative, scenes=len(units))
