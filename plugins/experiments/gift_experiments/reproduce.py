"""The paper's experiments, end to end, on registered components.

Stages (each cached under ``out/stages/`` so a killed run resumes; trajectories and LM answers are also
cached by their own plugins):

1. ``train``    R_θ by MaxEnt IRL from preferred demonstrations vs default/random alternatives in
                ``train_scenes`` training scenes per intent.
2. ``intent``   ω̂ = J(D_H, D_¬H) from ``sanity_pairs`` demonstration pairs; the sanity check repeats it
                ``sanity_reps`` times and compares with the ground truth by MiniLM cosine (vs a generic intent).
3. ``rq1``      win rate of R̃_θ(ξ'|ω) = R_θ(f_ω(ξ')) per kernel on test scenes of unseen objects.
4. ``rq2``      alignment F1 / FP / FN per kernel, threshold and subset; the language-vs-vision scatter.
5. ``rq3``      Boltzmann distribution over four candidates, each acting on a different held-out object.

Every stage of one intent is one :class:`IntentJob` (:func:`run_intent`, seeds derived from the intent id),
so :func:`run` runs the intents on any executor of :mod:`gift.core.executor` (``serial``, ``local``, ``ray``)
and merges their slices of the results in intent order: the results do not depend on the executor.
"""

from __future__ import annotations

import functools
import hashlib
import json
import platform
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from importlib import metadata
from pathlib import Path
from typing import Any

import attrs
import numpy as np

import gift
from gift.core.data import DISTRACTOR, Alignment, DemonstrationPair, FeatureBatch, Intent, Scene
from gift.core.errors import GiftError, PlacementError
from gift.core.executor import ExecutionError, Executor, using_executor
from gift.core.metrics import boltzmann, mean_se, pairwise_win_rate, sample_pairs
from gift.core.suite import IntentSpec, Suite
from gift_experiments.report import json_default

GENERIC_INTENT = "The human prefers to move objects around the table."
ALL_KERNELS = ("vision", "language", "lm-no-intent", "gift", "gift-prob")
#: The reference row: alignment from the suite's labels (an upper bound on what any kernel can give).
ORACLE = "oracle-labels"


@attrs.frozen
class ReproduceConfig:
    suite: str = "gift-paper"
    robot: str = "jaco"
    pairs: int = 250
    seeds: int = 3
    samples: int = 10
    lm: str | None = None
    kernels: tuple[str, ...] = ALL_KERNELS
    reward: str = "maxent-linear"
    intents: tuple[str, ...] = ()  # empty: every intent of the suite
    intent_source: str = "inferred"  # or "ground-truth"
    thresholds: tuple[str, ...] = ("train-calibrated", "non-oracle", "oracle")
    train_scenes: int = 4
    demos_per_scene: int = 6
    alternatives_per_scene: int = 24
    test_objects_per_scene: int = 4
    trajectories_per_generator: int = 20
    sanity_reps: int = 10
    sanity_pairs: int = 3
    rq3: bool = True
    rq3_robot: str = "franka"

    def key(self) -> str:
        return hashlib.sha256(json.dumps(attrs.asdict(self), sort_keys=True).encode()).hexdigest()[:12]


class Progress:
    """tqdm progress bars for long stages (silent when not on a terminal unless forced)."""

    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled

    def __call__(self, iterable, desc: str, total: int | None = None):
        if not self.enabled:
            return iterable
        from tqdm.auto import tqdm

        return tqdm(iterable, desc=desc, total=total, leave=False, file=sys.stderr)


class StageCache:
    """JSON results per (stage, key) under ``root``: finished stages are not recomputed."""

    def __init__(self, root: Path, config_key: str) -> None:
        self.root = root / "stages" / config_key
        self.root.mkdir(parents=True, exist_ok=True)

    def get_or_compute(self, name: str, fn: Callable[[], Any]) -> Any:
        path = self.root / f"{name}.json"
        if path.exists():
            return json.loads(path.read_text())
        value = fn()
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(value, default=json_default))
        tmp.replace(path)
        return value


def _seed(*parts: Any) -> int:
    return int.from_bytes(hashlib.sha256(repr(parts).encode()).digest()[:4], "little")


# ----------------------------------------------------------------------------- components


class Components:
    """The registered components a run uses, built once."""

    def __init__(self, cfg: ReproduceConfig) -> None:
        self.cfg = cfg
        self._sims: dict[str, Any] = {}
        self._kernels: dict[str, Any] = {}
        self._lm = None
        self.alignment = gift.get_alignment_operator("argmax-threshold")

    def simulator(self, robot: str):
        if robot not in self._sims:
            self._sims[robot] = gift.get_simulator(gift.robot_simulator(robot))
        return self._sims[robot]

    @property
    def lm(self):
        if self._lm is None:
            from gift_llm import resolve_lm

            self._lm = resolve_lm(self.cfg.lm)
        return self._lm

    def kernel(self, name: str):
        if name not in self._kernels:
            opts: dict[str, Any] = {}
            if name in ("gift", "lm-no-intent", "gift-prob"):
                opts["lm"] = self.lm
            if name in ("gift", "lm-no-intent"):
                opts["samples"] = self.cfg.samples
            self._kernels[name] = gift.get_kernel(name, **opts)
        return self._kernels[name]

    def estimator(self, seed: int = 0, temperature: float = 0.0, axes: bool | None = None):
        # Call 2 (semantic axes) only feeds the binary `gift` kernel's prompt; skip it when no kernel reads it
        return gift.get_intent_estimator("lm-contrastive", lm=self.lm, seed=seed, temperature=temperature,
                                         axes=("gift" in self.cfg.kernels) if axes is None else axes)


# ----------------------------------------------------------------------------- data generation


def _features(sim, batch, task: str, specs) -> FeatureBatch:
    return sim.features(batch, task).reindex(specs)


def training_data(comp: Components, suite: Suite, spec: IntentSpec, robot: str,
                  seeds: Sequence[int] | None = None):
    """Preferred demonstrations and alternatives over the intent's training objects, plus demo pairs.

    ``seeds``: one per training scene (default ``_seed("train", spec.id, k)``, see :func:`intent_seeds`).
    """
    sim = comp.simulator(robot)
    task = gift.get_task(spec.task)
    specs = task.feature_specs(spec.train_objects)
    rel = list(spec.relevant_train)
    irr = [o for o in spec.train_objects if o not in rel]
    if seeds is None:
        seeds = [_seed("train", spec.id, k) for k in range(comp.cfg.train_scenes)]
    demos, alts, pairs = [], [], []
    for k, seed in enumerate(seeds):
        # each training scene holds a random subset of the training objects (several configurations)
        scene = _placed_scene(sim, suite, spec.task, rel, irr, comp.cfg.test_objects_per_scene, seed)
        pref = _features(sim, sim.generate(scene, "preferred", comp.cfg.demos_per_scene, _seed("p", spec.id, k)),
                         spec.task, specs)
        default = _features(sim, sim.generate(scene, "default", comp.cfg.demos_per_scene, _seed("d", spec.id, k)),
                            spec.task, specs)
        rand = _features(sim, sim.generate(scene, "random", comp.cfg.alternatives_per_scene, _seed("r", spec.id, k)),
                         spec.task, specs)
        demos.append(pref)
        alts += [default, rand]
        pairs += [DemonstrationPair(pref.trace(i), default.trace(i), scene) for i in range(len(pref))]
    return FeatureBatch.concat(demos), FeatureBatch.concat(alts), pairs, specs


def _pick(rel: Sequence[str], irr: Sequence[str], n: int, rng: np.random.Generator) -> list[str]:
    """``n`` names (fewer if there are not enough), at least one relevant and one irrelevant when both exist."""
    n = min(n, len(rel) + len(irr))
    lo = 1 if rel and irr else (n if rel else 0)
    hi = min(len(rel), n - (1 if irr else 0))
    k_rel = int(rng.integers(lo, max(lo, hi) + 1)) if rel else 0
    k_rel = min(k_rel, len(rel))
    names = list(rng.choice(rel, k_rel, replace=False)) if k_rel else []
    names += list(rng.choice(irr, min(n - k_rel, len(irr)), replace=False)) if irr and n > k_rel else []
    rng.shuffle(names)
    return [str(x) for x in names]


def test_scene(comp: Components, suite: Suite, spec: IntentSpec, robot: str, seed: int,
               n_objects: int | None = None) -> Scene:
    """A randomised test scene of unseen objects with at least one relevant and one irrelevant object."""
    rel = [t.object for t in spec.test if t.relevant]
    irr = [t.object for t in spec.test if not t.relevant]
    if not rel or not irr:
        raise GiftError(f"intent {spec.id!r} needs relevant and irrelevant test objects")
    return _placed_scene(comp.simulator(robot), suite, spec.task, rel, irr,
                         n_objects or comp.cfg.test_objects_per_scene, seed)


def _placed_scene(sim, suite: Suite, task: str, rel: Sequence[str], irr: Sequence[str], n: int, seed: int,
                  attempts: int = 20) -> Scene:
    """A scene of ``n`` objects picked by :func:`_pick` from ``seed``; when they do not fit on the table,
    the next pick of the same generator (deterministic), up to ``attempts`` picks."""
    rng = np.random.default_rng(seed)
    for attempt in range(attempts):
        names = _pick(rel, irr, n, rng)
        try:
            return sim.make_scene(task, suite.specs(names), [x for x in names if x in rel], seed=seed)
        except PlacementError as e:
            last = e
    raise PlacementError(f"{attempts} random picks of {n} objects for a {task} scene (seed {seed}) did not fit "
                         f"on the table; last: {last}")


# ----------------------------------------------------------------------------- intents


def infer_intent(comp: Components, spec: IntentSpec, pairs: Sequence[DemonstrationPair], seed: int = 0,
                 temperature: float = 0.0, axes: bool | None = None) -> Intent:
    """Calls 1 (and 2 when ``axes``; default: when a kernel reads the axes) on the first ``sanity_pairs`` pairs."""
    task = gift.get_task(spec.task)
    est = comp.estimator(seed=seed, temperature=temperature, axes=axes)
    return est.estimate(list(pairs)[: comp.cfg.sanity_pairs], task_context=task.context(),
                        objects=spec.train_objects)


def text_cosine(a: Sequence[str], b: str) -> np.ndarray:
    """MiniLM cosine of each sentence in ``a`` with ``b`` (raw cosine in [-1, 1])."""
    from gift_kernels.language import embed_texts

    emb = embed_texts(list(a) + [b])  # unit-norm rows
    return emb[:-1] @ emb[-1]


# ----------------------------------------------------------------------------- alignment


def oracle_alignment(spec: IntentSpec) -> Alignment:
    target = spec.relevant_train[0] if spec.relevant_train else DISTRACTOR
    mapping = {t.object: (target if t.relevant else DISTRACTOR) for t in spec.test}
    return Alignment(mapping, {k: 1.0 if v != DISTRACTOR else 0.0 for k, v in mapping.items()}, kernel=ORACLE)


def align_kernel(comp: Components, suite: Suite, spec: IntentSpec, kernel_name: str, intent: Intent | None,
                 thresholds: Sequence[str]) -> dict[str, dict]:
    """Run one kernel once on the intent's test objects; per threshold: the alignment and its metrics.

    Returns ``{threshold: {"cut", "note", "fallbacks", "mapping", "scores", "metrics": {subset: {...}}}}``;
    ``fallbacks`` lists the kernel's LM answers that were completed by default (see ``MappingKernel``).
    """
    from gift_kernels.evaluation import score_intent

    kernel = comp.kernel(kernel_name)
    n_fallbacks = len(getattr(kernel, "fallbacks", ()))
    scores, cuts, metrics = score_intent(kernel, suite, spec, intent if kernel.uses_intent else None, thresholds)
    fallbacks = list(getattr(kernel, "fallbacks", ()))[n_fallbacks:]  # LM answers completed by default
    out = {}
    for th in thresholds:
        cut, note = cuts[th]
        al = scores.alignment(cut)
        out[th] = {"cut": cut, "note": note, "fallbacks": fallbacks, "mapping": dict(al.mapping),
                   "scores": dict(al.scores), "metrics": metrics[th]}
    return out


# ----------------------------------------------------------------------------- the run


def intent_seeds(cfg: ReproduceConfig, intent_id: str) -> dict[str, tuple[int, ...]]:
    """The scene seeds of one intent, all derived from its id: ``train`` (one per training scene), ``rq1``
    and ``rq3`` (one per seed of the test scenes). Trajectory seeds derive from these and the generator."""
    return {"train": tuple(_seed("train", intent_id, k) for k in range(cfg.train_scenes)),
            "rq1": tuple(_seed("rq1", intent_id, s) for s in range(cfg.seeds)),
            "rq3": tuple(_seed("rq3", intent_id, s) for s in range(cfg.seeds))}


@attrs.frozen(repr=False)
class IntentJob:
    """One intent of a run, the unit of work of :func:`run` (picklable; run by :func:`run_intent`).

    ``suite``: the loaded suite (so workers need not resolve ``cfg.suite``); ``out``: absolute output
    directory (stage caches in ``out/stages/<cfg.key()>/``); ``seeds``: :func:`intent_seeds`.
    """

    cfg: ReproduceConfig
    suite: Suite
    out: str
    intent_id: str
    seeds: Mapping[str, tuple[int, ...]]

    def __repr__(self) -> str:
        return f"IntentJob({self.intent_id!r}, config {self.cfg.key()}, out={self.out!r})"


#: The per-intent slices of the results dictionary, merged in intent order.
SECTIONS = ("sanity", "rq1", "rq2", "scatter", "rq3", "intents")
#: Per worker process: the components of each config (simulators, kernels, LM), reused across intents.
_WORKER_COMPONENTS: dict[ReproduceConfig, Components] = {}


def _echo(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def run(cfg: ReproduceConfig, out: Path, progress: Progress | None = None, log: Callable[[str], None] = print,
        executor: Executor | str | None = None, echo: bool = False) -> dict:
    """Run every stage; return the results dictionary (see :mod:`gift_experiments.report`).

    One :class:`IntentJob` per intent runs on ``executor`` (an :class:`~gift.core.executor.Executor`, a
    registered name, or None: ``serial``); the slices come back in intent order, so the results are the
    same on every executor. ``serial`` runs the intents one after the other in this process with
    ``progress`` bars and ``log`` lines as they happen. A pool runs them in one ``map``, each worker
    building its own components; ``log`` then gets each intent's lines when the map returns, unless
    ``echo=True`` (for executors with ``live_stderr``, e.g. ``local``), which makes the workers print them
    to stderr as they happen. Executor options do not change results and are not part of ``cfg``.
    """
    progress = progress or Progress()
    suite = gift.load_suite(cfg.suite)
    intents = [suite.intent(i) for i in cfg.intents] if cfg.intents else list(suite.intents)
    StageCache(out, cfg.key())
    jobs = [IntentJob(cfg, suite, str(Path(out).resolve()), spec.id, intent_seeds(cfg, spec.id)) for spec in intents]
    with using_executor(executor) as ex:
        if ex.in_process:
            fn = functools.partial(run_intent, comp=Components(cfg), progress=progress, log=log)
            slices, failure = [], None
            for job in progress(jobs, "intents"):
                try:
                    slices.append(ex.map(fn, [job])[0])
                except ExecutionError as e:
                    failure = e.__cause__ or e
                    break
            if failure is not None:  # in this process: raise what the intent raised, as before executors
                raise failure
        else:
            slices = ex.map(functools.partial(run_intent, echo=echo), jobs, chunksize=1)
            if not echo:
                for part in slices:
                    for line in part["log"]:
                        log(line)
        where = {"name": ex.name, "max_workers": ex.max_workers}
    results: dict[str, Any] = {"config": attrs.asdict(cfg), **{k: {} for k in SECTIONS}}
    timing: dict[str, float] = {}
    for part in slices:
        for k in SECTIONS:
            results[k].update(part[k])
        if part["errors"]:
            results.setdefault("errors", []).extend(part["errors"])
        for stage, sec in part["timing"].items():
            timing[stage] = timing.get(stage, 0.0) + sec
    results["timing"] = timing
    results["manifest"] = manifest(cfg, lm=_merge_lm([part["lm"] for part in slices]))
    results["manifest"]["executor"] = where
    return results


def run_intent(job: IntentJob, *, comp: Components | None = None, progress: Progress | None = None,
               log: Callable[[str], None] | None = None, echo: bool = False) -> dict:
    """The whole run for one intent: training data, reward, intent inference, alignments, RQ1, scatter, RQ3.

    Returns the intent's slice of the results: ``{section: {intent_id: ...}}`` for each of
    :data:`SECTIONS` (empty when the stage did not run), ``errors`` (failed kernels), ``timing``
    (seconds per stage), ``lm`` (identity and this intent's usage counters, or None) and ``log`` (lines
    not yet shown: those that went neither to ``log`` nor, with ``echo``, to stderr).
    ``comp``: default one :class:`Components` per config and worker process.
    """
    cfg, suite = job.cfg, job.suite
    spec = suite.intent(job.intent_id)
    if comp is None:
        if cfg not in _WORKER_COMPONENTS:
            _WORKER_COMPONENTS[cfg] = Components(cfg)
        comp = _WORKER_COMPONENTS[cfg]
    progress = progress or Progress(enabled=False)
    lines: list[str] = []
    say = log or (_echo if echo else lines.append)
    usage_before = _lm_usage(comp)
    cache = StageCache(Path(job.out), cfg.key())
    results: dict[str, Any] = {k: {} for k in SECTIONS}
    errors: list[str] = []
    timing: dict[str, float] = {}

    def timed(stage: str, fn: Callable[[], Any]) -> Any:
        t0 = time.perf_counter()
        value = fn()
        timing[stage] = timing.get(stage, 0.0) + time.perf_counter() - t0
        return value

    say(f"[{spec.id}] training the reward on {cfg.robot}")
    demos, alts, pairs, train_specs = timed("train data", lambda: training_data(comp, suite, spec, cfg.robot,
                                                                                job.seeds["train"]))
    reward = timed("train reward", lambda: gift.get_reward_model(cfg.reward).fit(demos, alts))

    # ---- intent
    needs_intent = any(gift.get_manager().get("kernel", k).factory.uses_intent for k in cfg.kernels)
    if cfg.intent_source == "inferred" and (needs_intent or cfg.sanity_reps):
        def _infer():
            main = infer_intent(comp, spec, pairs, seed=0, temperature=0.0).to_dict()
            reps, rep_errors = [], []
            for r in progress(range(cfg.sanity_reps), f"{spec.id}: intent reps"):
                try:  # the sanity check reads only the text: no Call 2
                    reps.append(infer_intent(comp, spec, pairs, seed=r + 1, temperature=0.7, axes=False).text)
                except GiftError as e:  # a sampled answer that stays invalid after repairs: count it, go on
                    rep_errors.append(f"repetition {r + 1}: {type(e).__name__}: {e}")
                    say(f"[{spec.id}] intent repetition {r + 1} failed: {type(e).__name__}: {e}")
            return {"main": main, "reps": reps, "rep_errors": rep_errors}

        inferred = timed("intent", lambda: cache.get_or_compute(f"intent-{spec.id}", _infer))
        intent = Intent.from_dict(inferred["main"])
        if inferred["reps"]:
            texts = inferred["reps"]
            cos_inf = text_cosine(texts, spec.text)
            cos_gen = text_cosine([GENERIC_INTENT], spec.text)
            results["sanity"][spec.id] = {"inferred": list(mean_se(cos_inf)),
                                          "generic": [float(cos_gen[0]), 0.0], "texts": texts,
                                          "failed": len(inferred.get("rep_errors", []))}
        for err in inferred.get("rep_errors", []):
            errors.append(f"{spec.id}/intent {err}")
    else:
        from gift_kernels.evaluation import ground_truth_intent

        intent = ground_truth_intent(spec)
    results["intents"][spec.id] = intent.to_dict()

    # ---- alignments (once per kernel; independent of the number of trajectories)
    aligned: dict[str, dict[str, tuple[Alignment, dict]]] = {}
    for kname in progress(cfg.kernels, f"{spec.id}: kernels"):
        try:
            d = timed(f"align {kname}", lambda: cache.get_or_compute(
                f"align-{spec.id}-{kname}", lambda: align_kernel(comp, suite, spec, kname, intent, cfg.thresholds)))
        except Exception as e:  # noqa: BLE001 - keep what the other kernels computed
            say(f"[{spec.id}] kernel {kname} failed: {type(e).__name__}: {e}")
            errors.append(f"{spec.id}/{kname}: {type(e).__name__}: {e}")
            continue
        for th, r in d.items():
            aligned.setdefault(kname, {})[th] = (Alignment(r["mapping"], r["scores"], r["cut"], kernel=kname),
                                                 r["metrics"])
            results["rq2"].setdefault(spec.id, {}).setdefault(kname, {})[th] = r["metrics"]
        fallbacks = next(iter(d.values()), {}).get("fallbacks")  # the same for every threshold
        if fallbacks:
            errors.append(f"{spec.id}/{kname}: LM answers completed by default: {'; '.join(fallbacks)}")
    oracle = oracle_alignment(spec)

    # ---- RQ1
    main_th = cfg.thresholds[0]
    per_kernel: dict[str, list[float]] = {}
    for seed in progress(job.seeds["rq1"], f"{spec.id}: RQ1 seeds"):
        scene = test_scene(comp, suite, spec, cfg.robot, seed)
        sim = comp.simulator(cfg.robot)
        task = gift.get_task(spec.task)
        specs = task.feature_specs(scene.object_names)
        feats = FeatureBatch.concat([
            _features(sim, sim.generate(scene, g, cfg.trajectories_per_generator, _seed(seed, g)), spec.task,
                      specs) for g in ("preferred", "default", "random")])
        truth = task.ground_truth_reward(feats, sorted(scene.relevant))
        pairs_idx = sample_pairs(len(feats), cfg.pairs, np.random.default_rng(seed))
        for kname, by_th in list(aligned.items()) + [(ORACLE, {main_th: (oracle, {})})]:
            if main_th not in by_th:
                continue
            pred = reward.score_aligned(feats, by_th[main_th][0])
            per_kernel.setdefault(kname, []).append(pairwise_win_rate(pred, truth, pairs_idx))
    results["rq1"][spec.id] = {k: {"mean": mean_se(v)[0], "se": mean_se(v)[1], "per_seed": v}
                               for k, v in per_kernel.items()}

    # ---- scatter (language vs vision similarity to the first relevant training object)
    if {"language", "vision"} <= set(cfg.kernels) and spec.relevant_train:
        anchor = suite.objects[spec.relevant_train[0]]
        test = suite.specs(spec.test_objects)
        lang = comp.kernel("language").similarity(test, [anchor])[:, 0]
        vis = comp.kernel("vision").similarity(test, [anchor])[:, 0]
        results["scatter"][spec.id] = {"anchor": anchor.name, "points": [
            {"object": o.name, "language": float(a), "vision": float(b), "relevant": t.relevant}
            for o, a, b, t in zip(test, lang, vis, spec.test)]}

    # ---- RQ3 (pack and store, on the second robot)
    if cfg.rq3 and spec.task in ("pack_backpack", "store_drawer"):
        try:
            results["rq3"][spec.id] = timed("rq3", lambda: rq3(comp, suite, spec, reward, aligned, oracle, main_th,
                                                              progress, seeds=job.seeds["rq3"]))
        except PlacementError as e:  # RQ3's four fixed objects may not fit on the table: keep RQ1/RQ2
            say(f"[{spec.id}] RQ3 skipped: {e}")
            errors.append(f"{spec.id}/rq3: {e}")
    say(f"[{spec.id}] done: " + ", ".join(f"{k}={v['mean']:.3f}" for k, v in results["rq1"][spec.id].items()))
    lm = None
    if comp._lm is not None:
        lm = {"identity": comp._lm.identity(), "usage": _usage_delta(usage_before, _lm_usage(comp))}
    return {**results, "errors": errors, "timing": timing, "lm": lm, "log": lines}


def rq3(comp: Components, suite: Suite, spec: IntentSpec, reward, aligned, oracle, threshold: str,
        progress: Progress, seeds: Sequence[int] | None = None) -> dict:
    """Four candidates, each acting on a different held-out object; Boltzmann over aligned rewards.

    ``seeds``: one per base scene (default ``_seed("rq3", spec.id, s)``, see :func:`intent_seeds`).
    """
    sim = comp.simulator(comp.cfg.rq3_robot)
    task = gift.get_task(spec.task)
    rel = [t.object for t in spec.test if t.relevant]
    conf = [t.object for t in spec.test if not t.relevant and t.confounds] or \
        [t.object for t in spec.test if not t.relevant]
    objects = (rel[:1] + conf[:3]) if len(conf) >= 3 else (rel[:2] + conf[:2])
    specs = task.feature_specs(objects)
    probs: dict[str, list[np.ndarray]] = {}
    if seeds is None:
        seeds = [_seed("rq3", spec.id, s) for s in range(comp.cfg.seeds)]
    for seed in progress(seeds, f"{spec.id}: RQ3"):
        base = sim.make_scene(spec.task, suite.specs(objects), [o for o in objects if o in rel], seed=seed)
        feats = FeatureBatch.concat([
            _features(sim, sim.generate(attrs.evolve(base, relevant=frozenset({o})), "preferred", 1,
                                        _seed(seed, o)), spec.task, specs) for o in objects])
        for kname, by_th in list(aligned.items()) + [(ORACLE, {threshold: (oracle, {})})]:
            if threshold in by_th:
                probs.setdefault(kname, []).append(boltzmann(reward.score_aligned(feats, by_th[threshold][0])))
    relevant = [o in rel for o in objects]
    return {k: {"objects": objects, "relevant": relevant, "mean": np.mean(v, axis=0).tolist(),
                "se": (np.std(v, axis=0, ddof=1) / np.sqrt(len(v))).tolist() if len(v) > 1 else [0.0] * len(objects)}
            for k, v in probs.items()}


def _lm_usage(comp: Components) -> dict[str, Any] | None:
    """The public usage counters of ``comp``'s LM (None when it was not built or has no counters)."""
    if comp._lm is None:
        return None
    stats = getattr(comp._lm, "stats", None)
    if stats is None:
        return None
    return {k: v for k, v in (attrs.asdict(stats, recurse=False) if attrs.has(type(stats))
                              else vars(stats)).items() if not k.startswith("_")}


def _add(a: Any, b: Any, sign: int = 1) -> Any:
    """``a + sign * b`` for usage counters; None (no price) counts as nothing, None + None stays None."""
    if a is None and b is None:
        return None
    return (a or 0) + sign * (b or 0)


def _usage_delta(before: dict[str, Any] | None, after: dict[str, Any] | None) -> dict[str, Any] | None:
    """Counters spent between two :func:`_lm_usage` snapshots of one LM."""
    if after is None:
        return None
    before = before or {}
    return {k: (v if k not in before else _add(v, before[k], -1)) for k, v in after.items()}


def _merge_lm(parts: Sequence[dict[str, Any] | None]) -> dict[str, Any] | None:
    """One ``{"identity", "usage"}`` from the intents' (usage counters summed; None when no intent used an LM)."""
    used = [p for p in parts if p is not None]
    if not used:
        return None
    usage: dict[str, Any] | None = None
    for p in used:
        if p.get("usage") is not None:
            usage = dict(p["usage"]) if usage is None else {k: _add(usage.get(k), v) for k, v in p["usage"].items()}
    return {"identity": used[0]["identity"], "usage": usage}


def manifest(cfg: ReproduceConfig, comp: Components | None = None, *, lm: dict[str, Any] | None = None) -> dict:
    """Package versions, seeds, model identity and hash, LM usage and cache hits.

    ``lm``: ``{"identity", "usage"}`` summed over the workers of a run (:func:`run`); without it, read
    from ``comp``'s LM (its counters since it was built).
    """
    versions = {}
    for dist in ("gift", "gift-llm", "gift-kernels", "gift-rewards", "gift-sim-drake", "gift-experiments", "drake",
                 "numpy", "torch", "llama-cpp-python", "litellm", "sentence-transformers"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            pass
    m: dict[str, Any] = {"python": platform.python_version(), "platform": platform.platform(),
                         "versions": versions, "config_key": cfg.key()}
    if lm is None and comp is not None and comp._lm is not None:
        lm = {"identity": comp._lm.identity(), "usage": _lm_usage(comp)}
    if lm is not None:
        m["lm"] = {"identity": lm["identity"]}
        if lm.get("usage") is not None:
            m["lm"]["usage"] = lm["usage"]
        try:
            from gift_llm.embedded import EXPECTED_SHA256

            if cfg.lm is None:
                m["lm"]["sha256"] = EXPECTED_SHA256
        except ImportError:
            pass
    return m
