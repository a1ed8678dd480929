"""Ask instead of guess: active alignment queries and abstention.

When the intent-conditioned kernel is unsure about a test object, gift can ask the human "is this object
part of the goal?" (and, optionally, "which training object does it play?") instead of guessing, and it
can *abstain*: leave an object it is unsure of out of the aligned reward. A scene is scored once
(:func:`gift.core.alignment.score_alignment`); answers re-threshold those scores, and a kernel that can use
them scores the scene again with them (rule 5; without a ``rescore`` nothing here calls a kernel again).

The pieces
----------
- :class:`Answer`: what the human said about one object.
- :class:`QueryProblem`: what stays fixed while asking about one scene: the scene's
  :class:`~gift.core.alignment.AlignmentScores` of each *intent candidate* (one or several, in order of
  preference), the threshold strategy, the scene's test trajectories (optional, for error bounds),
  the Lipschitz constant and the abstention band.
- :func:`resolve` re-scores the scene with a list of answers: a :class:`QueryState` (the chosen
  candidate, the cut, every object's decision, the abstained objects, the alignment f_ω).
- A :class:`~gift.core.interfaces.QueryPolicy` (a plugin of kind ``query_policy``) ranks the objects
  not yet asked; :func:`asking` / :func:`ask` run a session with an ``answer(object) -> bool | str``
  callback; :func:`align_with_queries` does it all from a kernel. :func:`labels_answerer` simulates the
  human from labels (the suite's, in studies).

How answers update the scene (the rule)
---------------------------------------
1. **Answered objects are fixed to their answer.** "Yes" aligns the object to the training object the
   human named, else to the kernel's match (its best *relevant* training object), with K = 1 at the
   match: the human vouched for it, so it adds nothing to the error bound. "No" makes it a distractor.
   Naming a training object the goal does not make relevant aligns the object to it, as not relevant.
   "Don't know" (``None``) fixes nothing, adds no evidence, and the object is not asked again.
2. **Answers do not move the cut** (``move="stay"``, the default since the decision of 2026-12-03 in
   docs/results/queries.md). The cut is the one the strategy gives without answers; answers change only the
   objects they are about (rule 1) and which candidate decides (rule 3). With ``gift-prob``'s default the cut
   is its prior cut, which the training objects' leave-one-out scores do not place either, so evidence of a
   dozen objects at most is not asked to move it. The moves measured before (``move=``, :data:`MOVES`):
   ``"nearest"`` (the default until then): each answered test object joins the leave-one-out evidence of the
   ``train-calibrated`` cut as a positive ("yes", or naming a relevant training object) or a negative ("no",
   or naming another one), and the new cut is, among the cuts with the highest balanced accuracy on that
   evidence, the one nearest the cut without answers (:func:`nearest_best_cut`; candidates lie midway between
   neighbouring scores of the scene's training and test objects); when the training side gives no positive or
   no negative the answers alone place it once they hold both a "yes" and a "no". Its first answer can snap a
   prior cut to the leave-one-out-best one (``gift-paper``, inferred intents: 0.807 -> 0.754 after one
   ``uncertainty`` question). ``"widest"``: the widest-gap midpoint of that evidence, which let one hard
   negative lift the cut past every unasked object up to the lowest relevant training object (on
   ``gift-paper``'s reading_material, two "no" answers turned five relevant books into distractors).
   ``"answers"``: the cut without answers moved only as far as the answers alone require. A ``fixed``,
   ``non-oracle`` or ``oracle`` cut is never moved by answers (only the answered objects change).
3. **The kernel's own intent candidate decides** (``choose="primary"``, the default since 2026-12-03,
   docs/results/queries.md). Other candidates stay views the policies read (``disagreement``). With
   ``choose="answers"`` (the default before) answers choose among the candidates: each one is charged the
   number of answered objects its own decisions (at its cut without answers) got wrong, and the one with the
   fewest mistakes decides, ties going to the earlier one (the first is the kernel's own). One or two answers
   are little evidence against the kernel's own, training-side choice: on ``gift-paper`` one "no" handed
   ``reading_material`` to a candidate with 12 objects wrong instead of 4.
4. **Abstention.** An object not answered (or answered "don't know") whose decision score lies strictly
   within ``abstain`` of the cut, ``|decision - cut| < abstain``, is *flagged* instead of decided: it is
   reported, and its semantic features are held out of scoring exactly as a distractor's are (its
   feature columns are dropped by f_ω, so the aligned reward neither seeks nor avoids it, and it adds 0
   to the error bound). The report counts flagged objects; alignment metrics count a flagged object as
   not aligned (that is what the reward sees), and :meth:`QueryState.to_dict` also lists them.
5. **A kernel that can use answers re-scores the scene with them.** When the problem has a ``rescore``
   callable (:func:`kernel_rescorer`: the kernel implements
   :meth:`~gift.core.interfaces.RelevanceKernel.score_with_answers`), each time the set of answers with a
   "yes" or "no" grows the scene is scored again with them as evidence, and the re-scored scene and the
   views it reports replace every candidate (then rules 3, 2 and 1 apply as above). ``gift-prob`` names its
   category ladder again with the "yes" objects beside the demonstrated ones and the "no" objects beside
   the left-alone ones. Re-scored scenes are kept per set of answers, and a policy's "what if" states
   (:meth:`QueryState.assume`) re-threshold the current scores without re-scoring. With
   ``rescore_when="contradicted"`` (measured, not the default: docs/results/queries.md) the scene is re-scored only
   once some answer contradicts the first candidate's decision without answers.

Intent candidates and terms a kernel reports
--------------------------------------------
A relevance kernel may report other views of the same scene in ``RelevanceScores.details``, each as
``{"relevance": [n_test], "train_loo": [n_train]}`` (values in [0, 1]) or as raw scores ``{"test":
[n_test], "train": [n_train]}`` (any monotone scale; put on the relevance scale by a pooled z-score and a
sigmoid), see :func:`views_from_details`:

- ``details["candidates"]``: other intent candidates (a mapping, or ``gift-prob``'s list of verified
  candidate goals, whose test scores it reports with ``candidate_terms=True`` as ``lm_test`` /
  ``lm_train``, its LM term alone); :meth:`QueryProblem.of` adds them after the kernel's own choice;
- ``details["terms"]``: the terms the kernel combined (``gift-prob``: its LM log-odds and its MiniLM
  term), used by the ``disagreement`` policy when there is a single candidate.

Beliefs and error bounds the policies use
-----------------------------------------
- :func:`belief`: a decision score as a probability of "yes": 1/2 at the cut, linear down to 0 at score
  0 and up to 1 at score 1 (clipped). Answered objects have belief 1 ("yes") or 0 ("no").
- :meth:`QueryState.error_bounds`: the paper's bound L · Σ_t (1 − K) of each test trajectory
  (:func:`~gift.core.alignment.trajectory_error_bounds`) under the state's alignment. Without
  trajectories the scene is taken as one state per test object (each object alone in its own state),
  so the bound is the sum of the aligned objects' ``1 − K``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, ClassVar

import attrs
import numpy as np

from gift.core.alignment import NEVER, THRESHOLDS, AlignmentScores, best_separating_cut, trajectory_error_bounds
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, FeatureSpec, Intent, ObjectSpec
from gift.core.errors import GiftError
from gift.core.interfaces import QueryPolicy, SimilarityKernel

#: Replies a callback or a terminal may give, normalised (lower case, stripped).
YES = ("y", "yes", "true", "1")
NO = ("n", "no", "false", "0", DISTRACTOR)
UNKNOWN = ("?", "dont know", "don't know", "unknown", "skip")

#: Name of the kernel's own intent among the candidates (:meth:`QueryProblem.of`).
PRIMARY = "primary"
#: How answers move the train-calibrated cut (rule 2): ``stay`` (the default: answers never move the cut, they only
#: fix the answered objects), ``nearest`` (the default before), ``widest`` and ``answers`` (measured, dropped).
MOVES = ("stay", "nearest", "widest", "answers")
#: The default of :data:`MOVES` (docs/results/queries.md, "Answers that leave the cut where it was").
DEFAULT_MOVE = "stay"
#: Which intent candidate decides after answers (rule 3): ``primary`` (the default: always the kernel's own; the
#: others stay views for the policies) or ``answers`` (the default before: the one the answers contradict least).
CHOOSE = ("primary", "answers")
#: The default of :data:`CHOOSE` (docs/results/queries.md, "The kernel's own candidate decides").
DEFAULT_CHOOSE = "primary"
#: When a problem with a ``rescore`` scores the scene again (rule 5): ``always`` (the default: each time the set
#: of "yes"/"no" answers grows) or ``contradicted`` (only once some answer contradicts the kernel's own decision
#: without answers; answers that agree with it only fix their objects, rule 1).
RESCORE_WHEN = ("always", "contradicted")
#: The default of :data:`RESCORE_WHEN`.
DEFAULT_RESCORE_WHEN = "always"


# ============================================================================= answers


@attrs.frozen
class Answer:
    """The human's answer about test object ``object``.

    ``relevant``: is it part of the goal (None: the human does not know); ``plays``: the training object
    it plays, when the human said so (its relevance follows from that object's).
    """

    object: str = attrs.field(validator=attrs.validators.instance_of(str))
    relevant: bool | None = attrs.field(default=None)
    plays: str | None = None

    @relevant.validator
    def _check_relevant(self, attribute, value):
        if value is not None and not isinstance(value, (bool, np.bool_)):
            raise GiftError(f"answer about {self.object!r}: relevant must be True, False or None, got {value!r}")

    def __attrs_post_init__(self) -> None:
        if self.plays is not None and self.relevant is None:
            raise GiftError(f"answer about {self.object!r}: naming the training object it plays "
                            f"({self.plays!r}) needs relevant=True or False")

    def to_dict(self) -> dict[str, Any]:
        return {"object": self.object, "relevant": None if self.relevant is None else bool(self.relevant),
                "plays": self.plays}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Answer":
        if not isinstance(d, Mapping) or "object" not in d:
            raise GiftError(f"an answer must be a mapping with an 'object', got {d!r}")
        return cls(str(d["object"]), d.get("relevant"), d.get("plays"))


def _norm(s: str) -> str:
    return " ".join(str(s).replace("_", " ").strip().lower().split())


def _relevant_columns(scores: AlignmentScores) -> np.ndarray | None:
    """``[n_train]`` the relevant training columns, or None when relevance is unknown (every column counts)."""
    if scores.relevant_mask is not None and np.asarray(scores.relevant_mask).any():
        return np.asarray(scores.relevant_mask, dtype=bool)
    if scores.relevant_train:
        return np.array([t in set(scores.relevant_train) for t in scores.train], dtype=bool)
    return None


def parse_reply(name: str, reply: Any, scores: AlignmentScores) -> Answer:
    """An :class:`Answer` about test object ``name`` from a callback's or a terminal's reply.

    ``True``/``False``; ``None`` (don't know); an :class:`Answer`; or a string: ``y``/``yes``,
    ``n``/``no``/``distractor``, ``?``/``skip`` (don't know), or the name of a training object (the
    object plays it; relevant iff that training object is, or when relevance is unknown). Anything else
    raises a :class:`GiftError` that lists what is accepted.
    """
    if name not in scores.test:
        raise GiftError(f"answer about {name!r}, which is not a test object of this scene {list(scores.test)}")
    if isinstance(reply, Answer):
        if reply.object != name:
            raise GiftError(f"asked about {name!r} but the answer is about {reply.object!r}")
        answer = reply
    elif reply is None:
        return Answer(name, None)
    elif isinstance(reply, (bool, np.bool_)):
        return Answer(name, bool(reply))
    elif isinstance(reply, str):
        text = _norm(reply)
        if text in YES:
            return Answer(name, True)
        if text in NO:
            return Answer(name, False)
        if text in UNKNOWN:
            return Answer(name, None)
        match = next((t for t in scores.train if _norm(t) == text), None)
        if match is None:
            raise GiftError(f"answer about {name!r}: {reply!r} is not yes / no / ? nor a training object "
                            f"({', '.join(scores.train)})")
        answer = Answer(name, True, match)
    else:
        raise GiftError(f"answer about {name!r}: expected True/False/None, a string or an Answer, "
                        f"got {type(reply).__name__} {reply!r}")
    if answer.plays is not None:
        if answer.plays not in scores.train:
            raise GiftError(f"answer about {name!r}: {answer.plays!r} is not a training object "
                            f"({', '.join(scores.train)})")
        rel = _relevant_columns(scores)
        relevant = True if rel is None else bool(rel[scores.train.index(answer.plays)])
        answer = Answer(name, relevant, answer.plays)
    return answer


def labels_answerer(labels: Mapping[str, bool]) -> Callable[[str], bool]:
    """A simulated human who answers from ``labels`` (test object -> relevant), e.g. a suite's."""
    def answer(name: str) -> bool:
        if name not in labels:
            raise GiftError(f"the simulated human has no label for {name!r}")
        return bool(labels[name])

    return answer


# ============================================================================= the problem and its state


def _check_strategy(inst: Any, attribute: attrs.Attribute, value: Any) -> None:
    if isinstance(value, bool) or not (isinstance(value, (int, float)) or value in THRESHOLDS):
        raise GiftError(f"unknown threshold {value!r}; use one of {THRESHOLDS} or a number in [0, 1]")
    if isinstance(value, (int, float)) and not 0.0 <= float(value) <= 1.0:
        raise GiftError(f"a fixed alignment threshold must be in [0, 1], got {value}")


def _check_move(inst: Any, attribute: attrs.Attribute, value: str) -> None:
    if value not in MOVES:
        raise GiftError(f"unknown cut move {value!r}; one of {MOVES}")


def _check_choose(inst: Any, attribute: attrs.Attribute, value: str) -> None:
    if value not in CHOOSE:
        raise GiftError(f"unknown candidate choice {value!r}; one of {CHOOSE}")


def _check_rescore_when(inst: Any, attribute: attrs.Attribute, value: str) -> None:
    if value not in RESCORE_WHEN:
        raise GiftError(f"unknown rescore_when {value!r}; one of {RESCORE_WHEN}")


def _check_band(inst: Any, attribute: attrs.Attribute, value: float) -> None:
    if not 0.0 <= float(value) <= 1.0:
        raise GiftError(f"the abstention band must be in [0, 1] (distance to the cut on the decision scale), "
                        f"got {value}")


def _zsigmoid(values: Sequence[float], n_test: int) -> tuple[np.ndarray, np.ndarray]:
    """Raw scores of the test and training objects on the relevance scale: a z-score pooled over both,
    then a sigmoid (as ``gift-prob`` combines its terms)."""
    v = np.asarray(values, dtype=float)
    sd = v.std()
    z = (v - v.mean()) / sd if sd > 1e-9 else v - v.mean()
    r = 1.0 / (1.0 + np.exp(-z))
    return r[:n_test], r[n_test:]


def views_from_details(scores: AlignmentScores, key: str) -> dict[str, AlignmentScores]:
    """The views a relevance kernel reported in ``scores.details[key]`` (``"terms"`` or ``"candidates"``),
    each as the scores of the same scene (:meth:`AlignmentScores.with_relevance`); {} when there are none.

    ``details[key]`` maps names to views, or is a list of views named by their ``name``, ``goal`` or
    ``category`` (entries marked ``"chosen": true`` are the kernel's own scores and are skipped). A view
    gives ``relevance`` / ``train_loo`` in [0, 1], used as they are, or raw scores ``test`` / ``train``
    (``gift-prob``'s candidates: ``lm_test`` / ``lm_train``), put on the relevance scale by
    :func:`_zsigmoid`. Entries without scores of the test objects (e.g. a candidate only verified on the
    training objects) are skipped.
    """
    raw = (scores.details or {}).get(key)
    if not raw:
        return {}
    if isinstance(raw, Mapping):
        entries = [(str(name), view) for name, view in raw.items()]
    elif isinstance(raw, Sequence) and not isinstance(raw, str):
        entries = [(str(v.get("name") or v.get("goal") or v.get("category") or f"{key} {k}") if isinstance(v, Mapping)
                    else f"{key} {k}", v) for k, v in enumerate(raw)]
    else:
        raise GiftError(f"kernel {scores.kernel!r}: details[{key!r}] must be a mapping or a list of views, "
                        f"got {type(raw).__name__}")
    n, m = len(scores.test), len(scores.train)
    out: dict[str, AlignmentScores] = {}
    for name, view in entries:
        if not isinstance(view, Mapping):
            raise GiftError(f"kernel {scores.kernel!r}: details[{key!r}] entry {name!r} is not a mapping")
        if view.get("chosen") is True:
            continue
        if "relevance" in view and "train_loo" in view:
            rel, loo = view["relevance"], view["train_loo"]
        else:
            pair = next(((view[a], view[b]) for a, b in (("test", "train"), ("lm_test", "lm_train"))
                         if a in view and b in view), None)
            if pair is None:
                continue
            if len(pair[0]) != n or len(pair[1]) != m:
                raise GiftError(f"kernel {scores.kernel!r}: details[{key!r}][{name!r}] has {len(pair[0])} test / "
                                f"{len(pair[1])} training scores for {n} / {m} objects")
            rel, loo = _zsigmoid(list(pair[0]) + list(pair[1]), n)
        while name in out:
            name += "'"
        out[name] = scores.with_relevance(rel, loo)
    return out


@attrs.frozen
class QueryProblem:
    """What stays fixed while asking about one scene.

    ``candidates``: name -> :class:`AlignmentScores` of the same scene under each intent candidate, in
    order of preference (at least one); ``strategy``: the threshold strategy (see the module docstring
    for which ones answers move); ``trajectories``: the scene's test trajectories ``[N, T, F]`` (one
    batch per scene; empty: one state per object); ``lipschitz``: L of the error bound; ``abstain``: the
    abstention band on the decision scale (0: never abstain); ``test_labels``: only for the oracle cut;
    ``move``: how answers move the train-calibrated cut (:data:`MOVES`, rule 2); ``rescore``: ``answers
    (object -> bool) -> AlignmentScores | None``, the scene scored again with the answers (rule 5;
    :func:`kernel_rescorer`), None: answers only re-threshold; ``choose``: which candidate decides after
    answers (:data:`CHOOSE`, rule 3); ``rescore_when``: when ``rescore`` is called (:data:`RESCORE_WHEN`, rule 5).
    """

    candidates: Mapping[str, AlignmentScores] = attrs.field(converter=dict)
    strategy: str | float = attrs.field(default="train-calibrated", validator=_check_strategy)
    trajectories: tuple[FeatureBatch, ...] = attrs.field(default=(), converter=tuple)
    lipschitz: float = attrs.field(default=1.0, converter=float)
    abstain: float = attrs.field(default=0.0, converter=float, validator=_check_band)
    test_labels: Mapping[str, bool] | None = None
    move: str = attrs.field(default=DEFAULT_MOVE, validator=_check_move)
    rescore: Callable[[Mapping[str, bool]], AlignmentScores | None] | None = attrs.field(default=None, eq=False)
    choose: str = attrs.field(default=DEFAULT_CHOOSE, validator=_check_choose, kw_only=True)
    rescore_when: str = attrs.field(default=DEFAULT_RESCORE_WHEN, validator=_check_rescore_when, kw_only=True)
    _rescored: dict = attrs.field(factory=dict, init=False, eq=False, repr=False)

    def __attrs_post_init__(self) -> None:
        if not self.candidates:
            raise GiftError("a query problem needs the alignment scores of at least one intent candidate")
        first = next(iter(self.candidates.values()))
        for name, s in self.candidates.items():
            if not isinstance(s, AlignmentScores):
                raise GiftError(f"candidate {name!r}: expected AlignmentScores, got {type(s).__name__}")
            if s.test != first.test or s.train != first.train:
                raise GiftError(f"candidate {name!r} scores another scene: test {list(s.test)} / train "
                                f"{list(s.train)}, expected {list(first.test)} / {list(first.train)}")
        if self.lipschitz < 0:
            raise GiftError(f"the Lipschitz constant must be >= 0, got {self.lipschitz}")
        for b in self.trajectories:
            if not isinstance(b, FeatureBatch):
                raise GiftError(f"trajectories must be FeatureBatch objects, got {type(b).__name__}")

    @classmethod
    def of(cls, scores: AlignmentScores, strategy: str | float = "train-calibrated", *,
           candidates: Mapping[str, AlignmentScores] | None = None, trajectories: Sequence[FeatureBatch] = (),
           lipschitz: float = 1.0, abstain: float = 0.0, test_labels: Mapping[str, bool] | None = None,
           move: str = DEFAULT_MOVE, rescore: Callable[[Mapping[str, bool]], AlignmentScores | None] | None = None,
           choose: str = DEFAULT_CHOOSE, rescore_when: str = DEFAULT_RESCORE_WHEN) -> "QueryProblem":
        """The problem of one scene: ``scores`` (the kernel's own intent, named :data:`PRIMARY`), then
        ``candidates`` (other intents' scores of the same scene), then the candidates the kernel reported
        in ``scores.details["candidates"]``."""
        cands = {PRIMARY: scores}
        for name, s in {**(candidates or {}), **views_from_details(scores, "candidates")}.items():
            if name in cands:
                raise GiftError(f"two intent candidates are named {name!r}")
            cands[name] = s
        return cls(cands, strategy, tuple(trajectories), lipschitz, abstain, test_labels, move, rescore, choose=choose,
                   rescore_when=rescore_when)

    def candidates_for(self, answers: Sequence[Answer]) -> Mapping[str, AlignmentScores]:
        """The candidates that decide a scene with ``answers`` (rule 5): :attr:`candidates`, or, when the
        problem can re-score and some answer is a "yes" or "no", the re-scored scene (as :data:`PRIMARY`)
        and the views it reports (kept per set of answers)."""
        known = tuple(sorted((a.object, bool(a.relevant)) for a in answers if a.relevant is not None))
        if self.rescore is None or not known or (self.rescore_when == "contradicted" and not self.contradicted(known)):
            return self.candidates
        if known not in self._rescored:
            new = self.rescore(dict(known))
            if new is None:
                self._rescored[known] = self.candidates
            else:
                if not isinstance(new, AlignmentScores) or new.test != self.test:
                    raise GiftError(f"re-scoring with answers {dict(known)} gave "
                                    f"{type(new).__name__ if not isinstance(new, AlignmentScores) else list(new.test)}"
                                    f", expected AlignmentScores of the test objects {list(self.test)}")
                self._rescored[known] = {PRIMARY: new, **views_from_details(new, "candidates")}
        return self._rescored[known]

    def wrong_answers(self, scores: AlignmentScores, known: Sequence[tuple[str, bool]]) -> int:
        """How many ``(object, relevant)`` answers contradict ``scores``' own decisions at its cut without answers."""
        cut, _ = answered_cut(scores, self.strategy, (), self.test_labels)
        return sum(bool(scores.decision[self.test.index(o)] >= cut) != bool(r) for o, r in known)

    def contradicted(self, known: Sequence[tuple[str, bool]]) -> bool:
        """Whether some ``(object, relevant)`` answer contradicts the first candidate's decision at its cut
        without answers."""
        return self.wrong_answers(next(iter(self.candidates.values())), known) > 0

    @property
    def test(self) -> tuple[str, ...]:
        return next(iter(self.candidates.values())).test

    @property
    def first(self) -> str:
        return next(iter(self.candidates))


def belief(decision: np.ndarray, cut: float) -> np.ndarray:
    """``[n]`` P("yes") from decision scores: 1/2 at the cut, linear to 0 at score 0 and to 1 at score 1."""
    d = np.asarray(decision, dtype=float)
    c = float(np.clip(cut, 0.0, 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        below = 0.5 * np.clip(d, 0.0, None) / c if c > 0 else np.zeros_like(d)
        above = 0.5 + 0.5 * (d - c) / (1.0 - c) if c < 1 else np.full_like(d, 0.5)
    return np.clip(np.where(d >= c, above, below), 0.0, 1.0)


def nearest_best_cut(positives: Sequence[float], negatives: Sequence[float], anchor: float,
                     scene: Sequence[float]) -> float:
    """Among the cuts with the highest balanced accuracy on ``positives`` / ``negatives`` (either may be empty,
    not both), the one nearest ``anchor`` (``anchor`` itself when it is among them). Candidates: midpoints
    between neighbouring values of the labelled points and the ``scene``'s other scores, points just outside
    their range, the anchor."""
    p, n = np.asarray(positives, dtype=float), np.asarray(negatives, dtype=float)
    if p.size == 0 and n.size == 0:
        raise GiftError("nearest_best_cut needs at least one positive or negative score")
    values = np.unique(np.concatenate([p, n, np.asarray(scene, dtype=float)]))
    cands = np.concatenate([[values[0] - 1e-6], (values[:-1] + values[1:]) / 2, [values[-1] + 1e-6], [anchor]])
    # balanced accuracy over the classes present (one class alone: its accuracy)
    parts = [(p[None, :] >= cands[:, None]).mean(axis=1)] if p.size else []
    parts += [(n[None, :] < cands[:, None]).mean(axis=1)] if n.size else []
    bacc = np.mean(parts, axis=0)
    ok = cands[bacc >= bacc.max() - 1e-12]
    return float(ok[np.argmin(np.abs(ok - anchor))])


def answered_cut(scores: AlignmentScores, strategy: str | float, answers: Sequence[Answer],
                 test_labels: Mapping[str, bool] | None = None, move: str = DEFAULT_MOVE) -> tuple[float, str]:
    """``(cut, note)`` of ``strategy`` after the answers (rule 2 of the module). ``move``: ``"stay"`` (the
    default: the cut without answers), ``"nearest"`` (the default before: the answers as extra labelled points,
    the best cut nearest the one without answers), ``"widest"`` (the widest-gap midpoint of the same evidence)
    or ``"answers"`` (the nearest cut to the one without answers among those that best separate the answers
    alone: the training evidence and any prior cut stay as they were weighed without answers)."""
    if move not in MOVES:
        raise GiftError(f"unknown cut move {move!r}; one of {MOVES}")
    if strategy != "train-calibrated":
        cut, note = scores.threshold(strategy, test_labels)
        known = sum(a.relevant is not None for a in answers)
        return cut, note + (f"; a {strategy} cut is not moved by answers" if known else "")
    index = {n: i for i, n in enumerate(scores.test)}
    yes = [float(scores.decision[index[a.object]]) for a in answers if a.relevant is True]
    no = [float(scores.decision[index[a.object]]) for a in answers if a.relevant is False]
    yes, no = [v for v in yes if v > NEVER], [v for v in no if v > NEVER]
    if not yes and not no:
        return scores.threshold("train-calibrated")
    if move == "stay":  # the cut without answers, whatever they say (rule 1 still fixes the answered objects)
        cut, note = scores.threshold("train-calibrated")
        return cut, f"{note}; not moved by the {len(yes)} yes / {len(no)} no answers (move='stay')"
    if move == "answers":  # the cut without answers already holds the training evidence and the prior
        anchor, note = scores.threshold("train-calibrated")
        scene = scores.decision[scores.decision > NEVER]
        cut = nearest_best_cut(yes, no, anchor, scene)
        return float(np.clip(cut, 0.0, 1.0)), (f"{note}; moved only as far as {len(yes)} yes / {len(no)} no "
                                               f"answers require")
    pos = neg = np.zeros(0)
    if scores.relevant_train and scores.loo_scores is not None:
        usable = scores.loo_scores > NEVER
        pos = scores.loo_scores[usable & scores.loo_labels]
        neg = scores.loo_scores[usable & ~scores.loo_labels]
    P, N = np.concatenate([pos, yes]), np.concatenate([neg, no])
    if P.size and N.size:
        if move == "widest":
            cut = best_separating_cut(P, N)
        else:
            anchor = scores.threshold("train-calibrated")[0]
            scene = np.concatenate([scores.decision, scores.loo_scores if scores.loo_scores is not None else []])
            cut = nearest_best_cut(P, N, anchor, scene[scene > NEVER])
        return float(np.clip(cut, 0.0, 1.0)), (f"leave-one-out over {pos.size} relevant / {neg.size} other "
                                               f"training objects and {len(yes)} yes / {len(no)} no answers"
                                               + (", widest gap" if move == "widest" else ""))
    cut, note = scores.threshold("train-calibrated")
    return cut, note + f"; the {len(yes)} yes / {len(no)} no answers give no second class yet"


def _default_target(scores: AlignmentScores, i: int) -> int:
    """The training column a test object aligns to when the human says "yes" without naming one."""
    rel = _relevant_columns(scores)
    t = int(scores.target[i])
    if rel is None or rel[t]:
        return t
    return int(np.argmax(np.where(rel, scores.K[i], -np.inf)))


@attrs.frozen
class QueryState:
    """One scene re-scored with the answers so far (:func:`resolve`).

    ``chosen``: the intent candidate deciding the unanswered objects; ``cut``/``note``: its cut and how
    it was placed; ``predicted`` ``[n_test]``: aligned to a relevant training object; ``decision``
    ``[n_test]``: the decision scores after the answers (``predicted == decision >= cut``: answered
    "yes" at ``max(1, cut)``, answered "no" and abstained objects at -1); ``abstained``: flagged
    objects; ``alignment``: f_ω after the answers and abstentions; ``mistakes``: per candidate, answered
    objects its decisions had wrong; ``candidates``: the candidates' scores this state was decided from
    (the problem's, or the scene re-scored with the answers, rule 5).
    """

    problem: QueryProblem
    answers: tuple[Answer, ...]
    chosen: str
    cut: float
    note: str
    predicted: np.ndarray = attrs.field(eq=False)
    decision: np.ndarray = attrs.field(eq=False)
    abstained: tuple[str, ...]
    alignment: Alignment
    mistakes: Mapping[str, int] = attrs.field(factory=dict)
    candidates: Mapping[str, AlignmentScores] = attrs.field(factory=dict, eq=False)

    @property
    def scores(self) -> AlignmentScores:
        """The chosen candidate's scores (as the kernel gave them, re-scored with the answers under rule 5,
        before rules 1, 2 and 4)."""
        return (self.candidates or self.problem.candidates)[self.chosen]

    @property
    def rescored(self) -> bool:
        """Whether the scene was re-scored with the answers (rule 5)."""
        return bool(self.candidates) and self.candidates is not self.problem.candidates

    @property
    def test(self) -> tuple[str, ...]:
        return self.problem.test

    @property
    def asked(self) -> np.ndarray:
        """``[n_test]`` bool: answered, including "don't know" (never asked again)."""
        done = {a.object for a in self.answers}
        return np.array([t in done for t in self.test], dtype=bool)

    def answer_of(self, name: str) -> Answer | None:
        return next((a for a in self.answers if a.object == name), None)

    def assume(self, answer: Answer) -> "QueryState":
        """The state with one more answer (what a policy asks itself: what if the human said this?), decided
        from this state's candidates: re-thresholded, not re-scored."""
        return resolve(self.problem, self.answers + (answer,), candidates=self.candidates or None)

    def belief(self) -> np.ndarray:
        """``[n_test]`` P("yes"): 1 / 0 for answered objects, :func:`belief` of the chosen scores otherwise."""
        p = belief(self.scores.decision, self.cut)
        for a in self.answers:
            if a.relevant is not None:
                p[self.test.index(a.object)] = 1.0 if a.relevant else 0.0
        return p

    def view_beliefs(self) -> dict[str, np.ndarray]:
        """P("yes") ``[n_test]`` of each view that may disagree: the intent candidates when there are
        several, else the terms the kernel reported (``details["terms"]``), else none. Each view is
        thresholded by the problem's strategy with the same answers (rule 2)."""
        p = self.problem
        cands = self.candidates or p.candidates
        views = dict(cands) if len(cands) > 1 else views_from_details(self.scores, "terms")
        if len(views) < 2:
            return {}
        return {name: belief(s.decision, answered_cut(s, p.strategy, self.answers, p.test_labels, p.move)[0])
                for name, s in views.items()}

    def error_bounds(self) -> np.ndarray:
        """``[N]`` the error bound of each of the problem's test trajectories under this alignment
        (``[1]`` for the one-state-per-object scene when the problem has no trajectories)."""
        batches = self.problem.trajectories or (_one_state_per_object(self.test),)
        return np.concatenate([trajectory_error_bounds(b, self.alignment, self.problem.lipschitz) for b in batches])

    def error_bound(self) -> float:
        """The summed error bound over the scene's trajectories."""
        return float(self.error_bounds().sum())

    def to_dict(self) -> dict[str, Any]:
        """JSON-able: the answers, the cut and its note, the chosen candidate, flagged objects, f_ω, and the
        rules that made them (``move``, ``choose``)."""
        return {"move": self.problem.move, "choose": self.problem.choose,
                "chosen": self.chosen, "candidates": list(self.candidates or self.problem.candidates),
                "mistakes": dict(self.mistakes), "rescored": self.rescored,
                "cut": self.cut, "note": self.note, "answers": [a.to_dict() for a in self.answers],
                "asked": len(self.answers), "abstained": list(self.abstained), "n_abstained": len(self.abstained),
                "mapping": dict(self.alignment.mapping), "scores": dict(self.alignment.scores),
                "predicted": {t: bool(v) for t, v in zip(self.test, self.predicted)},
                "decision": {t: float(v) for t, v in zip(self.test, self.decision)},
                "error_bound": self.error_bound(),
                "bound_over": "trajectories" if self.problem.trajectories else "one state per object"}


def _one_state_per_object(test: Sequence[str]) -> FeatureBatch:
    specs = tuple(FeatureSpec(name=f"present:{t}", subject=t, kind="present") for t in test)
    return FeatureBatch(specs, np.eye(len(test))[None] if test else np.zeros((1, 0, 0)))


def resolve(problem: QueryProblem, answers: Sequence[Answer] = (), *,
            candidates: Mapping[str, AlignmentScores] | None = None) -> QueryState:
    """Re-score the scene of ``problem`` with ``answers`` (the rules of the module docstring).

    ``candidates``: decide from these scores instead of :meth:`QueryProblem.candidates_for` (no re-scoring;
    what :meth:`QueryState.assume` passes)."""
    answers = tuple(answers)
    test = problem.test
    seen: set[str] = set()
    for a in answers:
        if not isinstance(a, Answer):
            raise GiftError(f"answers must be Answer objects, got {type(a).__name__}")
        if a.object not in test:
            raise GiftError(f"answer about {a.object!r}, which is not a test object of this scene {list(test)}")
        if a.object in seen:
            raise GiftError(f"{a.object!r} was answered twice")
        seen.add(a.object)
    known = [a for a in answers if a.relevant is not None]
    cands = problem.candidates_for(answers) if candidates is None else candidates  # rule 5
    # rule 3: the kernel's own candidate (choose="primary"), or the one whose own decisions got the fewest
    # answered objects wrong (choose="answers"; ties: the earlier); mistakes are counted for reports either way
    mistakes = {}
    for name, s in cands.items():
        mistakes[name] = problem.wrong_answers(s, [(a.object, bool(a.relevant)) for a in known])
    order = list(cands)
    chosen = min(order, key=lambda n: (mistakes[n], order.index(n))) if problem.choose == "answers" else order[0]
    scores = cands[chosen]
    # rule 2: the cut after the answers (the problem's move; by default the cut without answers)
    cut, note = answered_cut(scores, problem.strategy, answers, problem.test_labels, problem.move)
    base = scores.alignment(cut)
    mapping, kscores = dict(base.mapping), dict(base.scores)
    predicted = scores.decision >= cut
    decision = scores.decision.astype(float).copy()
    # rule 1: answered objects are fixed
    for a in known:
        i = test.index(a.object)
        if a.relevant or a.plays is not None:
            j = scores.train.index(a.plays) if a.plays is not None else _default_target(scores, i)
            if scores.train:
                mapping[a.object], kscores[a.object] = scores.train[j], 1.0
        else:
            mapping[a.object] = DISTRACTOR
        predicted[i] = bool(a.relevant)
        decision[i] = max(1.0, cut) if a.relevant else NEVER
    # rule 4: abstention inside the band around the cut
    answered = {a.object for a in known}
    flagged = tuple(t for i, t in enumerate(test) if t not in answered
                    and abs(float(scores.decision[i]) - cut) < problem.abstain)
    for t in flagged:
        i = test.index(t)
        mapping[t] = DISTRACTOR
        predicted[i] = False
        decision[i] = NEVER
    alignment = Alignment(mapping, kscores, threshold=cut, kernel=scores.kernel)
    return QueryState(problem, answers, chosen, cut, note, predicted, decision, flagged, alignment, mistakes,
                      dict(cands) if cands is not problem.candidates else problem.candidates)


# ============================================================================= a session


def _policy(policy: QueryPolicy | str) -> QueryPolicy:
    if isinstance(policy, QueryPolicy):
        return policy
    if isinstance(policy, str):
        from gift.plugins.manager import get_manager

        return get_manager().create("query_policy", policy)
    raise GiftError(f"a query policy must be a registered name or a QueryPolicy, got {type(policy).__name__}")


def asking(problem: QueryProblem, policy: QueryPolicy | str, answer: Callable[[str], Any], n: int, *,
           answers: Sequence[Answer] = (), seed: int = 0) -> Iterator[QueryState]:
    """Ask up to ``n`` questions, one at a time; yields the state before the first and after each answer.

    ``policy``: a :class:`QueryPolicy` or a registered name; ``answer(object name)`` returns the
    human's reply (see :func:`parse_reply`: ``True``/``False``, ``None`` for don't know, or the training
    object it plays); ``answers``: answers already known (saved ones; they do not count against ``n``);
    ``seed``: the session's random generator (random policies). Stops early when every object was asked.
    """
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 0:
        raise GiftError(f"the number of queries must be an integer >= 0, got {n!r}")
    policy = _policy(policy)
    rng = np.random.default_rng(seed)
    state = resolve(problem, answers)
    yield state
    for _ in range(int(n)):
        name = policy.choose(state, rng)
        if name is None:
            return
        state = resolve(problem, state.answers + (parse_reply(name, answer(name), state.scores),))
        yield state


def ask(problem: QueryProblem, policy: QueryPolicy | str, answer: Callable[[str], Any], n: int, *,
        answers: Sequence[Answer] = (), seed: int = 0) -> QueryState:
    """The state after a session of :func:`asking` (up to ``n`` questions)."""
    state = None
    for state in asking(problem, policy, answer, n, answers=answers, seed=seed):
        pass
    return state


def kernel_rescorer(kernel: SimilarityKernel, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                    intent: Intent | None = None, *, relevant_train: Sequence[str] = (),
                    need: Sequence[str] = ("train-calibrated", "non-oracle")
                    ) -> Callable[[Mapping[str, bool]], AlignmentScores | None] | None:
    """The ``rescore`` of a :class:`QueryProblem` (rule 5) for ``kernel`` on this scene, or None when the
    kernel does not implement :meth:`~gift.core.interfaces.RelevanceKernel.score_with_answers` (answers
    then only re-threshold). Each call asks the kernel again (an LM kernel: new LM calls)."""
    from gift.core.alignment import rescore_alignment
    from gift.core.interfaces import RelevanceKernel

    own = getattr(type(kernel), "score_with_answers", None)
    if not isinstance(kernel, RelevanceKernel) or own is RelevanceKernel.score_with_answers:
        return None
    test, train, relevant_train, need = tuple(test), tuple(train), tuple(relevant_train), tuple(need)

    def rescore(answers: Mapping[str, bool]) -> AlignmentScores | None:
        return rescore_alignment(kernel, test, train, intent, relevant_train=relevant_train, answers=answers,
                                 need=need)

    return rescore


def align_with_queries(kernel: SimilarityKernel, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                       intent: Intent | None = None, *, answer: Callable[[str], Any], n: int = 2,
                       policy: QueryPolicy | str = "uncertainty", relevant_train: Sequence[str] = (),
                       threshold: str | float = "train-calibrated", abstain: float = 0.0,
                       trajectories: Sequence[FeatureBatch] = (),
                       candidates: Mapping[str, AlignmentScores] | None = None,
                       answers: Sequence[Answer] = (), seed: int = 0, rescore: bool = True) -> QueryState:
    """Score a scene once with ``kernel``, then ask the human up to ``n`` questions through ``answer``.

    ``rescore``: let the kernel score the scene again with the answers when it can (rule 5; the default since
    2026-12-04, docs/results/queries.md: ``gift-prob`` then weighs the answers as evidence, no LM call); False:
    answers only re-threshold the first scores.

    ``answer(object name) -> bool | str | None`` is the human (see :func:`parse_reply`); the result's
    ``alignment`` is f_ω after the answers, ``abstained`` the flagged objects. Example::

        state = align_with_queries(kernel, test, train, intent, relevant_train=["paintbrush"],
                                   answer=lambda obj: input(f"is {obj} part of the goal? ") == "y")
    """
    from gift.core.alignment import score_alignment

    need = ("train-calibrated", "non-oracle") if threshold == "train-calibrated" else (
        (threshold,) if isinstance(threshold, str) else ())
    scores = score_alignment(kernel, test, train, intent, relevant_train=relevant_train, need=need)
    again = kernel_rescorer(kernel, test, train, intent, relevant_train=relevant_train, need=need) if rescore else None
    problem = QueryProblem.of(scores, threshold, candidates=candidates, trajectories=trajectories, abstain=abstain,
                              rescore=again)
    return ask(problem, policy, answer, n, answers=answers, seed=seed)


# ============================================================================= the built-in policies


class UncertaintyPolicy(QueryPolicy):
    """Ask about the object whose decision score is nearest the cut."""

    name: ClassVar[str] = "uncertainty"

    def priority(self, state: QueryState, rng: np.random.Generator) -> np.ndarray:
        return -np.abs(state.scores.decision - state.cut)


class DisagreementPolicy(QueryPolicy):
    """Ask about the object the views disagree on most: the range of P("yes") over the intent candidates
    (several), else over the kernel's terms (``gift-prob``: LM and MiniLM). Without two views every object
    ties, so it asks the one nearest the cut (as ``uncertainty``)."""

    name: ClassVar[str] = "disagreement"

    def priority(self, state: QueryState, rng: np.random.Generator) -> np.ndarray:
        views = state.view_beliefs()
        if not views:
            return np.zeros(len(state.test))
        b = np.stack(list(views.values()))
        return b.max(axis=0) - b.min(axis=0)


class ErrorBoundPolicy(QueryPolicy):
    """Ask about the object whose answer is expected to lower the summed error bound of the scene's
    trajectories most: ``bound now − (p · bound if "yes" + (1 − p) · bound if "no")``, p its belief, each
    hypothetical answer re-scoring the scene (the cut may move). Without trajectories: one state per object."""

    name: ClassVar[str] = "error-bound"

    def priority(self, state: QueryState, rng: np.random.Generator) -> np.ndarray:
        now = state.error_bound()
        p = state.belief()
        out = np.zeros(len(state.test))
        for i in np.flatnonzero(~state.asked):
            name = state.test[i]
            yes = state.assume(Answer(name, True)).error_bound()
            no = state.assume(Answer(name, False)).error_bound()
            out[i] = now - (p[i] * yes + (1.0 - p[i]) * no)
        return out


class ExpectedErrorPolicy(QueryPolicy):
    """Ask about the object whose answer is expected to leave the fewest wrong decisions in the scene (expected
    error reduction, with the kernel's own beliefs): for each of the ``width`` objects nearest the cut that were
    not asked, the scene is resolved with a "yes" and with a "no" as asking would resolve it (rule 5: a kernel that
    can use answers re-scores the scene, ``gift-prob`` without an LM call), and the expected mistakes left,
    ``Σ_j min(b_j, 1 - b_j)`` over the objects not asked before (``b``: :meth:`QueryState.belief` of the state after
    the answer; the asked object counts 0), are averaged with weights ``p`` and ``1 - p`` (``p``: its belief now).
    Priority: the reduction against now; objects outside the ``width`` nearest rank below every evaluated one.
    Without re-scoring (answers only fix their object and the cut stays) the reduction is the asked object's own
    ``min(p, 1 - p)``, which ranks as ``uncertainty``. Cost: ``2 * width`` resolves per question."""

    name: ClassVar[str] = "expected-error"

    def __init__(self, width: int = 6) -> None:
        if not isinstance(width, (int, np.integer)) or isinstance(width, bool) or width < 1:
            raise GiftError(f"expected-error: width must be an integer >= 1, got {width!r}")
        self.width = int(width)

    def priority(self, state: QueryState, rng: np.random.Generator) -> np.ndarray:
        open_ = ~state.asked

        def mistakes(b: np.ndarray) -> float:  # expected wrong decisions among the objects open now
            return float(np.minimum(b, 1.0 - b)[open_].sum())

        p = state.belief()
        now = mistakes(p)
        dist = np.abs(state.scores.decision - state.cut)
        idx = np.flatnonzero(open_)
        idx = idx[np.lexsort((idx, np.round(dist[idx], 12)))][: self.width]
        out = np.full(len(state.test), -1.0 - len(state.test))  # below any reduction (each is >= -n_test / 2)
        for i in idx:
            yes, no = (mistakes(resolve(state.problem, state.answers + (Answer(state.test[i], said),)).belief())
                       for said in (True, False))
            out[i] = now - (p[i] * yes + (1.0 - p[i]) * no)
        return out


class RandomPolicy(QueryPolicy):
    """Ask about an object drawn uniformly among those not asked yet (the baseline)."""

    name: ClassVar[str] = "random"

    def priority(self, state: QueryState, rng: np.random.Generator) -> np.ndarray:
        return rng.random(len(state.test))


BUILTIN_POLICIES = (UncertaintyPolicy, DisagreementPolicy, ErrorBoundPolicy, ExpectedErrorPolicy, RandomPolicy)
