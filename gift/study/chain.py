"""The chain of one intent: every command that studies GIFT on a suite runs these steps.

::

    suite intent ──► training scenes ──► demonstrations (preferred, default, random)      scenes.py
                                             │
                      relevant training objects: the suite's labels (ground-truth mode)
                                             or inferred from the demonstrations (inferred mode)
                                             │
                      intent ω: the suite's text, or ω̂ = J(D_H, D_¬H) (Calls 1-2)
                                             │
                      R_θ by MaxEnt IRL on demonstrations vs alternatives
                                             │
                      per kernel: K(s, s'|ω) on the test objects -> cut -> f_ω        core/alignment.py
                      (RQ2: precision/recall/F1/AUC per threshold and confound subset)
                      optional: k queries answered by the simulated human, abstention   core/queries.py
                                             │
                      RQ1: win rate of R_θ(f_ω(ξ')) on test scenes;  RQ3: Boltzmann over candidates

In inferred mode nothing from the suite's ``relevant_train`` reaches an estimator, a kernel, a threshold
or a prompt: the relevant training objects come from the demonstrations. The suite's labels are used
only to simulate the human (which objects the preferred demonstrations act on) and to score results.

:func:`run_intent` runs the chain for one :class:`IntentJob`; finished stages (the inferred intent, each
kernel's alignment) are kept in a :class:`~gift.study.stages.StageCache`. :mod:`gift.study.sweeps`
runs jobs over intents on an executor and assembles the results.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import attrs
import numpy as np

from gift.core.alignment import THRESHOLDS, AlignmentScores, score_alignment
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch, Intent
from gift.core.errors import GiftError, PlacementError
from gift.core.metrics import alignment_metrics, boltzmann, mean_se, pairwise_win_rate, sample_pairs
from gift.core.suite import SUBSETS, IntentSpec, Suite
from gift.study.components import Components, accepts, components_for, parse_spec
from gift.study.progress import Progress
from gift.study.scenes import TrainingSet, load_training_set, place_scene, stable_seed, test_scene, training_set
from gift.study.stages import StageCache, digest

log = logging.getLogger("gift.study")

INTENT_SOURCES = ("ground-truth", "inferred")
#: Reported subsets: S_R, S_lang, S_vis, S_unk, and their union (every test object).
REPORT_SUBSETS = SUBSETS + ("all",)
ALL_KERNELS = ("vision", "language", "lm-no-intent", "gift", "gift-prob")
GENERIC_INTENT = "The human prefers to move objects around the table."
#: The reference row of RQ1/RQ3: alignment from the suite's labels (an upper bound for any kernel).
ORACLE = "oracle-labels"


def _positive(inst: Any, attribute: attrs.Attribute, value: int) -> None:
    if not isinstance(value, int) or value < 1:
        raise GiftError(f"study option {attribute.name} must be a positive integer, got {value!r}")


def _non_negative(inst: Any, attribute: attrs.Attribute, value: int) -> None:
    if not isinstance(value, int) or value < 0:
        raise GiftError(f"study option {attribute.name} must be an integer >= 0, got {value!r}")


def _thresholds(inst: Any, attribute: attrs.Attribute, value: tuple) -> None:
    bad = [t for t in value if t not in THRESHOLDS]
    if bad or not value:
        raise GiftError(f"unknown threshold(s) {bad or '(none given)'}; choose from {list(THRESHOLDS)}")


def _band(inst: Any, attribute: attrs.Attribute, value: float) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
        raise GiftError(f"study option {attribute.name} must be a number in [0, 1], got {value!r}")


def _source(inst: Any, attribute: attrs.Attribute, value: str) -> None:
    if value not in INTENT_SOURCES:
        raise GiftError(f"unknown intent source {value!r}; choose from {list(INTENT_SOURCES)}")


@attrs.frozen
class StudyConfig:
    """Everything that decides a study's results (executor options do not, so they are not here).

    Sizes follow the paper's experiments: ``train_scenes`` training scenes per intent with
    ``demos_per_scene`` preferred and default demonstrations and ``alternatives_per_scene`` random ones;
    test scenes of ``test_objects_per_scene`` objects with ``trajectories_per_generator`` trajectories
    per generator, ``pairs`` pairs per scene and ``seeds`` scenes (RQ1); ``samples`` LM samples for the
    kernels that take them; ``sanity_reps`` repeated inferences (temperature 0.7) for the intent cosine.
    ``rq1=False`` stops after the alignments (what ``evaluate-alignment`` needs). ``demonstrations``: a
    directory of saved training sets (``<intent id>.npz/.json``, :func:`gift.study.scenes.save_training_set`)
    to use instead of simulating the human. ``queries``: questions per intent and kernel that the simulated
    human (the suite's labels) answers, chosen by the registered ``query_policy``; ``abstain``: the
    abstention band around the cut (:mod:`gift.core.queries`); with either, each kernel gets a second row
    (:func:`query_label`) in RQ1 and RQ2. ``query_rescore``: a kernel that can use the answers scores the
    scene again with them (rule 5 of :mod:`gift.core.queries`; on by default since 2026-12-04: ``gift-prob``
    weighs them as evidence without LM calls, docs/results/queries.md); off: answers only re-threshold.
    """

    suite: str = "gift-paper"
    robot: str = "jaco"
    pairs: int = attrs.field(default=250, validator=_positive)
    seeds: int = attrs.field(default=3, validator=_positive)
    samples: int = attrs.field(default=10, validator=_positive)
    lm: str | None = None
    kernels: tuple[str, ...] = attrs.field(default=ALL_KERNELS, converter=tuple)
    reward: str = "maxent-linear"
    estimator: str = "lm-contrastive"
    intents: tuple[str, ...] = attrs.field(default=(), converter=tuple)
    intent_source: str = attrs.field(default="inferred", validator=_source)
    thresholds: tuple[str, ...] = attrs.field(default=("train-calibrated", "non-oracle", "oracle"),
                                              converter=tuple, validator=_thresholds)
    train_scenes: int = attrs.field(default=4, validator=_positive)
    demos_per_scene: int = attrs.field(default=6, validator=_positive)
    alternatives_per_scene: int = attrs.field(default=24, validator=_positive)
    test_objects_per_scene: int = attrs.field(default=4, validator=_positive)
    trajectories_per_generator: int = attrs.field(default=20, validator=_positive)
    sanity_reps: int = attrs.field(default=10, validator=_non_negative)
    sanity_pairs: int = attrs.field(default=3, validator=_positive)
    rq1: bool = True
    rq3: bool = True
    rq3_robot: str = "franka"
    demonstrations: str | None = None
    queries: int = attrs.field(default=0, validator=_non_negative)
    query_policy: str = "uncertainty"
    abstain: float = attrs.field(default=0.0, validator=_band)
    query_rescore: bool = True

    def key(self) -> str:
        """A short hash of the configuration (names the run in the manifest)."""
        return digest(attrs.asdict(self), 12)

    @property
    def defaults(self) -> dict[str, Any]:
        """Study-wide options given to every component factory that names them."""
        return {"samples": self.samples}


def simulator_name(robot: str) -> str:
    """The registered simulator of ``robot``: the name itself when it is a simulator, else the one built for
    the registered robot ``robot`` (:func:`gift.robot_simulator`; gift-sim-drake: ``drake-<robot>``)."""
    from gift.plugins.manager import get_manager

    manager = get_manager()
    if robot in manager.names("simulator"):
        return robot
    built = manager.simulators_for_robot(robot) if robot in manager.names("robot") else []
    return built[0] if built else f"drake-{robot}"  # unknown: the simulator lookup's error lists what exists


def intent_seeds(cfg: StudyConfig, intent_id: str) -> dict[str, tuple[int, ...]]:
    """The scene seeds of one intent, all derived from its id: ``train`` (one per training scene), ``rq1``
    and ``rq3`` (one per test scene). Trajectory seeds derive from these and the generator."""
    return {"train": tuple(stable_seed("train", intent_id, k) for k in range(cfg.train_scenes)),
            "rq1": tuple(stable_seed("rq1", intent_id, s) for s in range(cfg.seeds)),
            "rq3": tuple(stable_seed("rq3", intent_id, s) for s in range(cfg.seeds))}


@attrs.frozen(repr=False)
class IntentJob:
    """One intent of a study, the unit of work of the sweeps (picklable; run by :func:`run_intent`).

    ``suite``: the loaded suite (workers need not resolve ``cfg.suite``); ``out``: output directory of the
    stage caches (None: nothing cached); ``seeds``: :func:`intent_seeds`; ``kernels``: the kernels of this
    job (default: the config's).
    """

    cfg: StudyConfig
    suite: Suite
    out: str | None
    intent_id: str
    seeds: Mapping[str, tuple[int, ...]]
    kernels: tuple[str, ...] | None = None

    def __repr__(self) -> str:
        return f"IntentJob({self.intent_id!r}, config {self.cfg.key()}, out={self.out!r})"


# ============================================================================= steps


def intent_inputs(suite: Suite, spec: IntentSpec) -> dict[str, Any]:
    """What the suite says about one intent (its entry and its objects): part of every stage key."""
    names = list(dict.fromkeys(spec.train_objects + spec.test_objects))
    return {"intent": attrs.asdict(spec), "objects": {n: attrs.asdict(suite.objects[n]) for n in names}}


def lm_inputs(comp: Components) -> dict[str, Any]:
    """The resolved LM as a stage input: its identity and, where it has one, the hash of its model file."""
    lm = comp.lm
    prov = lm.provenance() if hasattr(lm, "provenance") else {"identity": lm.identity()}
    return dict(prov)


def get_training(comp: Components, cfg: StudyConfig, suite: Suite, spec: IntentSpec,
                 seeds: Sequence[int]) -> TrainingSet:
    """The intent's training set: loaded from ``cfg.demonstrations`` when given, else simulated."""
    if cfg.demonstrations:
        from pathlib import Path

        return load_training_set(Path(cfg.demonstrations) / spec.id, suite)
    return training_set(comp.simulator(simulator_name(cfg.robot)), comp.task(spec.task), suite, spec,
                        seeds=seeds, demos=cfg.demos_per_scene, alternatives=cfg.alternatives_per_scene,
                        objects_per_scene=cfg.test_objects_per_scene)


@attrs.frozen
class RelevantTraining:
    """The training objects the demonstrations treat as part of the goal, and where that came from."""

    names: tuple[str, ...]
    source: str  # "suite" (ground-truth mode) or "demonstrations"
    details: Mapping[str, Any] = attrs.field(factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"names": list(self.names), "source": self.source, **dict(self.details)}


def relevant_training(cfg: StudyConfig, spec: IntentSpec, training: TrainingSet | None) -> RelevantTraining:
    """Ground-truth mode: the suite's ``relevant_train``. Inferred mode: inferred from the demonstrations
    (:func:`gift.core.demonstrations.infer_relevant_objects`), never from the suite."""
    if cfg.intent_source == "ground-truth":
        return RelevantTraining(tuple(spec.relevant_train), "suite")
    if training is None:
        raise GiftError(f"intent {spec.id!r}: inferring the relevant training objects needs demonstrations")
    from gift.core.demonstrations import infer_relevant_objects

    est = infer_relevant_objects(training.pairs(), spec.train_objects)
    details = est.to_dict()
    details.pop("relevant")
    return RelevantTraining(tuple(est.relevant), "demonstrations", details)


def infer_intent(comp: Components, cfg: StudyConfig, spec: IntentSpec, training: TrainingSet,
                 relevant: RelevantTraining, *, seed: int = 0, temperature: float = 0.0,
                 axes: bool | None = None) -> Intent:
    """ω̂ = J(D_H, D_¬H) from the first ``sanity_pairs`` demonstration pairs (Call 2 only when ``axes``;
    default: when a kernel of the study reads the axes, i.e. ``gift``)."""
    from gift.study.components import build

    if axes is None:
        axes = any(parse_spec(k)[0] == "gift" for k in cfg.kernels)
    est = build("intent_estimator", cfg.estimator, lm=comp.lm,
                defaults={"seed": seed, "temperature": temperature, "axes": axes})
    task = comp.task(spec.task)
    return est.estimate(training.pairs()[: cfg.sanity_pairs], task_context=task.context(),
                        objects=spec.train_objects)


def intent_stage(comp: Components, cfg: StudyConfig, suite: Suite, spec: IntentSpec, training: TrainingSet,
                 relevant: RelevantTraining, cache: StageCache, say: Callable[[str], None],
                 progress: Progress) -> dict[str, Any]:
    """``{"main": intent dict, "reps": [texts], "rep_errors": [...]}`` of the inferred intent (stage-cached)."""
    pairs = training.pairs()[: cfg.sanity_pairs]
    inputs = {"suite": intent_inputs(suite, spec), "estimator": cfg.estimator, "lm": lm_inputs(comp),
              "axes": any(parse_spec(k)[0] == "gift" for k in cfg.kernels), "reps": cfg.sanity_reps,
              "demonstrations": digest([[p.preferred.values, p.default.values, list(p.preferred.names)]
                                        for p in pairs]),
              "relevant": list(relevant.names)}

    def compute() -> dict[str, Any]:
        main = infer_intent(comp, cfg, spec, training, relevant).to_dict()
        reps, rep_errors = [], []
        for r in progress(range(cfg.sanity_reps), f"{spec.id}: intent repetitions"):
            try:  # the sanity check reads only the text: no Call 2
                reps.append(infer_intent(comp, cfg, spec, training, relevant, seed=r + 1, temperature=0.7,
                                         axes=False).text)
            except GiftError as e:  # a sampled answer that stays invalid after repairs: count it, go on
                rep_errors.append(f"repetition {r + 1}: {type(e).__name__}: {e}")
                say(f"[{spec.id}] intent repetition {r + 1} failed: {type(e).__name__}: {e}")
        return {"main": main, "reps": reps, "rep_errors": rep_errors}

    return cache.get_or_compute(spec.id, "intent", inputs, compute)


def test_labels(spec: IntentSpec) -> dict[str, bool]:
    return {t.object: t.relevant for t in spec.test}


def subset_masks(spec: IntentSpec) -> dict[str, np.ndarray]:
    """Membership ``[n_test]`` of each reported subset (S_R, S_lang, S_vis, S_unk, all)."""
    return {sub: (np.ones(len(spec.test), dtype=bool) if sub == "all"
                  else np.array([t.in_subset(sub) for t in spec.test], dtype=bool)) for sub in REPORT_SUBSETS}


def score_intent(kernel: Any, suite: Suite, spec: IntentSpec, intent: Intent | None, relevant_train: Sequence[str],
                 thresholds: Sequence[str]) -> tuple[AlignmentScores, dict[str, tuple[float, str]], dict]:
    """One kernel on one intent's test objects: its scores, the cut of every threshold, metrics per
    threshold and subset (``{threshold: {subset: {...}}}``)."""
    scores = score_alignment(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                             intent if getattr(kernel, "uses_intent", False) else None,
                             relevant_train=tuple(relevant_train), need=tuple(thresholds))
    cuts = {thr: scores.threshold(thr, test_labels(spec)) for thr in thresholds}
    metrics = alignment_metrics(scores.decision, [t.relevant for t in spec.test], subset_masks(spec),
                                {thr: c[0] for thr, c in cuts.items()})
    return scores, cuts, metrics


def alignment_record(scores: AlignmentScores, cuts: Mapping[str, tuple[float, str]], metrics: Mapping,
                     seconds: float, kernel: Any = None) -> dict[str, Any]:
    """The JSON record of one kernel on one intent: per threshold the cut, its note, the mapping and
    metrics; per object its decision score and matched training object; fallbacks and kernel details;
    ``scores`` (:meth:`AlignmentScores.to_dict`, to re-threshold or ask queries without the kernel);
    ``configuration``: ``repr(kernel)``, every option the kernel ran with, defaults included."""
    out: dict[str, Any] = {"configuration": None if kernel is None else repr(kernel),
                           "thresholds": {}, "seconds": round(seconds, 3), "fallbacks": list(scores.fallbacks),
                           "details": dict(scores.details), "relevant_train": list(scores.relevant_train),
                           "objects": {name: {"decision": float(scores.decision[i]),
                                              "match": scores.train[scores.target[i]] if scores.train else None}
                                       for i, name in enumerate(scores.test)},
                           "scores": scores.to_dict()}
    for thr, (cut, note) in cuts.items():
        al = scores.alignment(cut)
        out["thresholds"][thr] = {"cut": cut, "note": note, "mapping": dict(al.mapping), "scores": dict(al.scores),
                                  "metrics": metrics[thr]}
    return out


def align_stage(comp: Components, cfg: StudyConfig, suite: Suite, spec: IntentSpec, kernel_spec: str,
                intent: Intent | None, relevant: RelevantTraining, thresholds: Sequence[str],
                cache: StageCache) -> dict[str, Any]:
    """One kernel on one intent (stage-cached): :func:`alignment_record` of :func:`score_intent`."""
    from gift.plugins.manager import get_manager

    name, options = parse_spec(kernel_spec)
    factory = get_manager().get("kernel", name).factory
    uses_intent = bool(getattr(factory, "uses_intent", False))
    inputs: dict[str, Any] = {"suite": intent_inputs(suite, spec), "kernel": kernel_spec,
                              "defaults": {k: v for k, v in cfg.defaults.items() if accepts(factory, k)},
                              "relevant": list(relevant.names), "thresholds": list(thresholds),
                              "intent": intent.to_dict() if (intent is not None and uses_intent) else None}
    if accepts(factory, "lm") and "lm" not in options:
        inputs["lm"] = lm_inputs(comp)

    def compute() -> dict[str, Any]:
        t0 = time.perf_counter()
        kernel = comp.kernel(kernel_spec)
        scores, cuts, metrics = score_intent(kernel, suite, spec, intent, relevant.names, thresholds)
        return alignment_record(scores, cuts, metrics, time.perf_counter() - t0, kernel)

    return cache.get_or_compute(spec.id, f"align-{kernel_spec}", inputs, compute)


def query_label(kernel_spec: str, cfg: StudyConfig) -> str:
    """The row of a kernel after queries and abstention, e.g. ``gift-prob +2q uncertainty``."""
    label = f"{kernel_spec} +{cfg.queries}q {cfg.query_policy}" if cfg.queries else kernel_spec
    return label + (f" abstain {cfg.abstain:g}" if cfg.abstain else "")


def query_threshold(cfg: StudyConfig) -> str:
    """The threshold queries re-score: ``train-calibrated`` when the study has it (answers move only that
    cut, :mod:`gift.core.queries`), else the study's first."""
    return "train-calibrated" if "train-calibrated" in cfg.thresholds else cfg.thresholds[0]


def query_stage(cfg: StudyConfig, spec: IntentSpec, scores: AlignmentScores,
                trajectories: Sequence[FeatureBatch] = (), rescore: Any = None) -> dict[str, Any]:
    """Up to ``cfg.queries`` questions about the intent's test objects, chosen by ``cfg.query_policy`` and
    answered from the suite's labels (the simulated human), abstaining within ``cfg.abstain`` of the cut
    of :func:`query_threshold`. ``trajectories``: the test scenes' features, for the error bound; ``rescore``:
    the kernel's re-scoring with answers (:func:`rescorer`; used when ``cfg.query_rescore``), None: no kernel
    runs again. Returns :meth:`QueryState.to_dict` with the policy and the
    metrics per subset (``{threshold: {subset: ...}}``)."""
    from gift.core.queries import QueryProblem, ask, labels_answerer

    labels, th = test_labels(spec), query_threshold(cfg)
    problem = QueryProblem.of(scores, th, trajectories=trajectories, abstain=cfg.abstain,
                              test_labels=labels if th == "oracle" else None,
                              rescore=rescore if cfg.query_rescore else None)
    state = ask(problem, cfg.query_policy, labels_answerer(labels), cfg.queries, seed=stable_seed("queries", spec.id))
    metrics = alignment_metrics(state.decision, [t.relevant for t in spec.test], subset_masks(spec), {th: state.cut})
    # the ladder named again with the answers (gift-prob's rescore_with="ladder"); answers weighed as evidence
    # keep the first ladder, so none is reported
    renamed = state.rescored and "evidence" not in state.scores.details
    ladder = (state.scores.details.get("ladder") or {}) if renamed else {}
    return {"policy": cfg.query_policy, "queries": cfg.queries, "abstain": cfg.abstain, "threshold": th,
            **state.to_dict(), "rescored_ladder": list(ladder.get("categories") or []), "metrics": metrics}


def rescorer(cfg: StudyConfig, suite: Suite, spec: IntentSpec, kernel: Any, intent: Intent | None,
             relevant: Sequence[str]) -> Any:
    """The ``rescore`` of :func:`query_stage` for ``kernel`` on the intent's test scene (None when the study
    does not re-score or the kernel cannot use answers: :func:`gift.core.queries.kernel_rescorer`)."""
    from gift.core.queries import kernel_rescorer

    if not cfg.query_rescore:
        return None
    return kernel_rescorer(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                           intent if getattr(kernel, "uses_intent", False) else None,
                           relevant_train=tuple(relevant), need=tuple(cfg.thresholds))


def oracle_alignment(spec: IntentSpec) -> Alignment:
    """Every relevant test object to the first relevant training object, the rest to DISTRACTOR (labels)."""
    target = spec.relevant_train[0] if spec.relevant_train else DISTRACTOR
    mapping = {t.object: (target if t.relevant else DISTRACTOR) for t in spec.test}
    return Alignment(mapping, {k: 1.0 if v != DISTRACTOR else 0.0 for k, v in mapping.items()}, kernel=ORACLE)


def rq1_scenes(comp: Components, cfg: StudyConfig, suite: Suite, spec: IntentSpec, seeds: Sequence[int],
               progress: Progress) -> list[tuple[FeatureBatch, np.ndarray, np.ndarray]]:
    """The RQ1 test scenes of one intent, one per seed: the features ``[N, T, F]`` of its preferred,
    default and random trajectories, the human's reward ``[N]`` and the sampled pairs ``[P, 2]``."""
    sim = comp.simulator(simulator_name(cfg.robot))
    task = comp.task(spec.task)
    out = []
    for seed in progress(seeds, f"{spec.id}: RQ1 seeds"):
        scene = test_scene(sim, suite, spec, cfg.test_objects_per_scene, seed)
        specs = task.feature_specs(scene.object_names)
        feats = FeatureBatch.concat([
            sim.features(sim.generate(scene, g, cfg.trajectories_per_generator, stable_seed(seed, g)),
                         spec.task).reindex(specs) for g in ("preferred", "default", "random")])
        truth = task.ground_truth_reward(feats, sorted(scene.relevant))
        out.append((feats, truth, sample_pairs(len(feats), cfg.pairs, np.random.default_rng(seed))))
    return out


def win_rates(comp: Components, cfg: StudyConfig, suite: Suite, spec: IntentSpec, reward: Any,
              alignments: Mapping[str, Alignment], seeds: Sequence[int], progress: Progress,
              scenes: Sequence[tuple[FeatureBatch, np.ndarray, np.ndarray]] | None = None) -> dict[str, dict]:
    """RQ1: pairwise win rate of R_θ(f_ω(ξ')) against the human's reward on test scenes, per alignment
    (``scenes``: :func:`rq1_scenes`, made here when not given)."""
    if scenes is None:
        scenes = rq1_scenes(comp, cfg, suite, spec, seeds, progress)
    per: dict[str, list[float]] = {}
    for feats, truth, pairs_idx in scenes:
        for kname, al in alignments.items():
            per.setdefault(kname, []).append(pairwise_win_rate(reward.score_aligned(feats, al), truth, pairs_idx))
    return {k: {"mean": mean_se(v)[0], "se": mean_se(v)[1], "per_seed": v} for k, v in per.items()}


def rq3_objects(spec: IntentSpec) -> list[str]:
    """The four held-out objects RQ3 places: one relevant and three confounds (two and two when fewer than three
    confounds; any irrelevant object counts when none is marked as a confound)."""
    rel = [t.object for t in spec.test if t.relevant]
    conf = [t.object for t in spec.test if not t.relevant and t.confounds] or \
        [t.object for t in spec.test if not t.relevant]
    return (rel[:1] + conf[:3]) if len(conf) >= 3 else (rel[:2] + conf[:2])


def rq3(comp: Components, cfg: StudyConfig, suite: Suite, spec: IntentSpec, reward: Any,
        alignments: Mapping[str, Alignment], seeds: Sequence[int], progress: Progress) -> dict:
    """RQ3: four candidates, each acting on a different held-out object; Boltzmann over aligned rewards."""
    sim = comp.simulator(simulator_name(cfg.rq3_robot))
    task = comp.task(spec.task)
    rel = [t.object for t in spec.test if t.relevant]
    objects = rq3_objects(spec)
    specs = task.feature_specs(objects)
    probs: dict[str, list[np.ndarray]] = {}
    for seed in progress(seeds, f"{spec.id}: RQ3"):
        base = sim.make_scene(spec.task, suite.specs(objects), [o for o in objects if o in rel], seed=seed)
        feats = FeatureBatch.concat([
            sim.features(sim.generate(attrs.evolve(base, relevant=frozenset({o})), "preferred", 1,
                                      stable_seed(seed, o)), spec.task).reindex(specs) for o in objects])
        for kname, al in alignments.items():
            probs.setdefault(kname, []).append(boltzmann(reward.score_aligned(feats, al)))
    relevant = [o in rel for o in objects]
    return {k: {"objects": objects, "relevant": relevant, "mean": np.mean(v, axis=0).tolist(),
                "se": (np.std(v, axis=0, ddof=1) / np.sqrt(len(v))).tolist() if len(v) > 1 else [0.0] * len(objects)}
            for k, v in probs.items()}


# ============================================================================= the chain of one intent

#: The per-intent sections of a study's results, merged in intent order by the sweeps.
SECTIONS = ("sanity", "rq1", "rq2", "alignment", "scatter", "rq3", "intents", "relevant")


def run_intent(job: IntentJob, *, comp: Components | None = None, progress: Progress | None = None,
               log_line: Callable[[str], None] | None = None) -> dict:
    """The whole chain for one intent; returns its slice of the results.

    ``{section: {intent_id: ...}}`` for each of :data:`SECTIONS` (empty when a stage did not run),
    ``errors`` (failed kernels and other recorded failures), ``timing`` (seconds per stage), ``lm``
    (provenance and this intent's LM usage, or None) and ``log`` (lines that went nowhere else).
    ``comp``: default one :class:`~gift.study.components.Components` per configuration and process.
    """
    cfg, suite = job.cfg, job.suite
    spec = suite.intent(job.intent_id)
    comp = comp or components_for(cfg.lm, cfg.defaults)
    progress = progress or Progress(enabled=False)
    lines: list[str] = []

    def say(msg: str) -> None:
        log.info(msg)
        (log_line or lines.append)(msg)

    usage_before = _lm_usage(comp)
    cache = StageCache(job.out)
    results: dict[str, Any] = {k: {} for k in SECTIONS}
    errors: list[str] = []
    timing: dict[str, float] = {}
    kernels = job.kernels if job.kernels is not None else cfg.kernels

    def timed(stage: str, fn: Callable[[], Any]) -> Any:
        t0 = time.perf_counter()
        value = fn()
        timing[stage] = timing.get(stage, 0.0) + time.perf_counter() - t0
        return value

    needs_intent = cfg.intent_source == "inferred" and (
        any(getattr(_kernel_factory(k), "uses_intent", False) for k in kernels) or cfg.sanity_reps)
    needs_training = cfg.rq1 or cfg.intent_source == "inferred"
    training = None
    if needs_training:
        say(f"[{spec.id}] training scenes and demonstrations on {cfg.robot}")
        training = timed("train data", lambda: get_training(comp, cfg, suite, spec, job.seeds["train"]))
    relevant = relevant_training(cfg, spec, training)
    results["relevant"][spec.id] = relevant.to_dict()
    reward = None
    if cfg.rq1:
        say(f"[{spec.id}] training the reward ({cfg.reward})")
        reward = timed("train reward", lambda: comp.reward(cfg.reward).fit(training.demonstrations,
                                                                           training.alternatives))

    # ---- intent
    if needs_intent:
        say(f"[{spec.id}] inferring the intent from {min(cfg.sanity_pairs, len(training.pairs()))} demonstration pairs")
        inferred = timed("intent", lambda: intent_stage(comp, cfg, suite, spec, training, relevant, cache, say,
                                                          progress))
        intent = Intent.from_dict(inferred["main"])
        if inferred["reps"]:
            texts = inferred["reps"]
            language = comp.kernel("language")
            cos_inf = language.text_cosine(texts, spec.text)
            cos_gen = language.text_cosine([GENERIC_INTENT], spec.text)
            results["sanity"][spec.id] = {"inferred": list(mean_se(cos_inf)), "generic": [float(cos_gen[0]), 0.0],
                                          "texts": texts, "failed": len(inferred.get("rep_errors", []))}
        for err in inferred.get("rep_errors", []):
            errors.append(f"{spec.id}/intent {err}")
    else:
        intent = Intent(text=spec.text, source="ground-truth")
    results["intents"][spec.id] = intent.to_dict()

    # ---- alignments (once per kernel; independent of the number of trajectories)
    aligned: dict[str, Alignment] = {}
    main_th = cfg.thresholds[0]
    for kspec in progress(kernels, f"{spec.id}: kernels"):
        say(f"[{spec.id}] aligning with {kspec}")
        try:
            rec = timed(f"align {kspec}", lambda: align_stage(comp, cfg, suite, spec, kspec, intent, relevant,
                                                                cfg.thresholds, cache))
        except Exception as e:  # noqa: BLE001 - keep what the other kernels computed
            say(f"[{spec.id}] kernel {kspec} failed: {type(e).__name__}: {e}")
            errors.append(f"{spec.id}/{kspec}: {type(e).__name__}: {e}")
            continue
        results["alignment"].setdefault(spec.id, {})[kspec] = rec
        results["rq2"].setdefault(spec.id, {})[kspec] = {th: r["metrics"] for th, r in rec["thresholds"].items()}
        t = rec["thresholds"][main_th]
        aligned[kspec] = Alignment(t["mapping"], t["scores"], t["cut"], kernel=kspec)
        if rec["fallbacks"]:
            errors.append(f"{spec.id}/{kspec}: LM answers completed by default: {'; '.join(rec['fallbacks'])}")
    scenes = timed("rq1", lambda: rq1_scenes(comp, cfg, suite, spec, job.seeds["rq1"], progress)) if cfg.rq1 else None

    # ---- queries to the simulated human and abstention (no kernel runs again)
    if cfg.queries or cfg.abstain:
        for kspec, rec in list(results["alignment"].get(spec.id, {}).items()):
            label = query_label(kspec, cfg)
            say(f"[{spec.id}] {label}: asking the simulated human")
            # the kernel (and its LM) is built only when the study re-scores with the answers
            again = rescorer(cfg, suite, spec, comp.kernel(kspec), intent, relevant.names) if cfg.query_rescore \
                else None
            q = timed("queries", lambda: query_stage(cfg, spec, AlignmentScores.from_dict(rec["scores"]),
                                                     [f for f, _, _ in scenes or ()], again))
            rec["queries"] = q
            results["rq2"][spec.id][label] = {q["threshold"]: q["metrics"][q["threshold"]]}
            aligned[label] = Alignment(q["mapping"], q["scores"], q["cut"], kernel=label)
    if not cfg.rq1:
        return _slice(results, errors, timing, comp, usage_before, lines)
    aligned[ORACLE] = oracle_alignment(spec)

    # ---- RQ1
    say(f"[{spec.id}] RQ1 win rates on {cfg.seeds} test scenes")
    results["rq1"][spec.id] = timed("rq1", lambda: win_rates(comp, cfg, suite, spec, reward, aligned,
                                                             job.seeds["rq1"], progress, scenes))

    # ---- scatter (language vs vision similarity to the first relevant training object)
    names = {parse_spec(k)[0]: k for k in kernels}
    if {"language", "vision"} <= set(names) and spec.relevant_train:
        anchor = suite.objects[spec.relevant_train[0]]
        test = suite.specs(spec.test_objects)
        lang = comp.kernel(names["language"]).similarity(test, [anchor])[:, 0]
        vis = comp.kernel(names["vision"]).similarity(test, [anchor])[:, 0]
        results["scatter"][spec.id] = {"anchor": anchor.name, "points": [
            {"object": o.name, "language": float(a), "vision": float(b), "relevant": t.relevant}
            for o, a, b, t in zip(test, lang, vis, spec.test)]}

    # ---- RQ3 (pack and store, on the second robot)
    if cfg.rq3 and spec.task in ("pack_backpack", "store_drawer"):
        try:
            results["rq3"][spec.id] = timed("rq3", lambda: rq3(comp, cfg, suite, spec, reward, aligned,
                                                              job.seeds["rq3"], progress))
        except PlacementError as e:  # RQ3's four fixed objects may not fit on the table: keep RQ1/RQ2
            say(f"[{spec.id}] RQ3 skipped: {e}")
            errors.append(f"{spec.id}/rq3: {e}")
    say(f"[{spec.id}] done: " + ", ".join(f"{k}={v['mean']:.3f}" for k, v in results["rq1"][spec.id].items()))
    return _slice(results, errors, timing, comp, usage_before, lines)


def _kernel_factory(spec: str) -> Any:
    from gift.plugins.manager import get_manager

    try:
        return get_manager().get("kernel", parse_spec(spec)[0]).factory
    except GiftError:
        return None


def _slice(results: dict, errors: list[str], timing: dict, comp: Components, usage_before: dict | None,
           lines: list[str]) -> dict:
    lm = None
    if comp.lm_built:
        lm = {**lm_inputs(comp), "usage": _usage_delta(usage_before, _lm_usage(comp))}
    return {**results, "errors": errors, "timing": timing, "lm": lm, "log": lines}


# ----------------------------------------------------------------------------- LM usage


def _lm_usage(comp: Components) -> dict[str, Any] | None:
    """The public usage counters of ``comp``'s LM (None when it was not built or has no counters)."""
    from gift.study.components import _public_counters

    if not comp.lm_built:
        return None
    now = _public_counters(getattr(comp.lm, "stats", None))
    base = getattr(comp, "lm_usage_baseline", None)
    if now is None or not base:
        return now
    # counted since this study resolved the LM (a shared instance may carry earlier calls)
    return {k: (add_usage(v, base[k], -1) if k in base else v) for k, v in now.items()}


def add_usage(a: Any, b: Any, sign: int = 1) -> Any:
    """``a + sign * b`` for usage counters; None (no price) counts as nothing, None + None stays None; mappings of
    counts (answers per build, ``made_by``) add key by key, keys left at 0 dropped."""
    if isinstance(a, Mapping) or isinstance(b, Mapping):
        a, b = dict(a or {}), dict(b or {})
        out = {k: add_usage(a.get(k), b.get(k), sign) for k in list(a) + [k for k in b if k not in a]}
        return {k: v for k, v in out.items() if v}
    if a is None and b is None:
        return None
    return (a or 0) + sign * (b or 0)


def _usage_delta(before: dict[str, Any] | None, after: dict[str, Any] | None) -> dict[str, Any] | None:
    """Counters spent between two :func:`_lm_usage` snapshots of one LM."""
    if after is None:
        return None
    before = before or {}
    return {k: (v if k not in before else add_usage(v, before[k], -1)) for k, v in after.items()}
