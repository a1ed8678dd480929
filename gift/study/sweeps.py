"""Studies over many intents (and kernels) on an executor: what ``gift reproduce``, ``gift demo`` and
``gift evaluate-alignment`` run.

- :func:`run_study`: one :class:`~gift.study.chain.IntentJob` per intent (the whole chain of
  :func:`~gift.study.chain.run_intent`); the slices come back in intent order and are merged, so the
  results do not depend on the executor. The manifest records what made them.
- :func:`evaluate_alignment`: alignment only. One item per (kernel, intent) (:func:`align_item`); with
  inferred intents each intent's front half (demonstrations, relevant training objects, ω̂) runs first
  as its own item (:func:`front_item`), once for all kernels.

Every item is a picklable module-level call that carries its seeds (the executors' contract).
"""

from __future__ import annotations

import functools
import logging
import os
import platform
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from importlib import metadata
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from gift.core.alignment import THRESHOLDS
from gift.core.data import Intent
from gift.core.errors import GiftError
from gift.core.executor import ExecutionError, Executor, using_executor
from gift.core.metrics import pooled_alignment_metrics
from gift.core.provenance import code_version, file_sha256, git_commit
from gift.core.queries import DEFAULT_CHOOSE, DEFAULT_MOVE
from gift.core.suite import Suite, load_suite
from gift.study.chain import (
    INTENT_SOURCES,
    REPORT_SUBSETS,
    SECTIONS,
    IntentJob,
    RelevantTraining,
    StudyConfig,
    add_usage,
    alignment_record,
    get_training,
    intent_seeds,
    intent_stage,
    query_stage,
    query_threshold,
    relevant_training,
    rescorer,
    run_intent,
    score_intent,
    subset_masks,
)
from gift.study.components import check_spec, components_for
from gift.study.progress import Progress
from gift.study.stages import StageCache

log = logging.getLogger("gift.study")


def _echo_logger() -> logging.Logger:
    """A logger that reaches stderr in a pool worker (which inherits no logging configuration)."""
    logger = logging.getLogger("gift.study.worker")
    if not logger.handlers:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(message)s"))
        logger.addHandler(handler)
        logger.setLevel(os.environ.get("GIFT_LOG_LEVEL", "INFO"))
        logger.propagate = False
    return logger


# ============================================================================= provenance


def suite_provenance(suite: Suite) -> dict[str, Any]:
    """The suite's name, file and the SHA-256 of the file's bytes."""
    out: dict[str, Any] = {"name": suite.name, "path": suite.path}
    if suite.path and Path(suite.path).is_file():
        out["sha256"] = file_sha256(suite.path)
    return out


def recorded_suite(result: Mapping[str, Any], where: str = "result") -> Suite:
    """The suite a result (of ``evaluate-alignment`` or ``reproduce``) was scored on: the first of its recorded
    file (when that exists here) and the suite of its name whose bytes hash to the sha256 the result's manifest
    recorded (without a recorded hash, the first). A GiftError naming ``where`` when none does: the labels read
    would not be the ones the run was scored on."""
    rec = (result.get("manifest") or {}).get("suite") or {}
    paths = [result.get("suite_path"), rec.get("path"), (result.get("config") or {}).get("suite")]
    candidates = list(dict.fromkeys(p for p in paths if p and Path(p).is_file()))
    name = result.get("suite") or rec.get("name")
    if name:
        candidates.append(name)
    if not candidates:
        raise GiftError(f"{where}: records no suite (no suite_path, manifest suite or config suite)")
    seen = []
    for c in candidates:
        try:
            suite = load_suite(c)
        except GiftError as e:
            seen.append(f"{c}: {e}")
            continue
        digest = file_sha256(suite.path) if suite.path else None
        if not rec.get("sha256") or rec["sha256"] == digest:
            return suite
        seen.append(f"{suite.path}: sha256 {str(digest)[:12]}")
    raise GiftError(f"{where}: suite {name!r} has changed since the run (recorded sha256 "
                    f"{str(rec.get('sha256'))[:12]}; here {'; '.join(seen)}): its labels may not be the ones the run "
                    "was scored on")


def versions() -> dict[str, str]:
    out = {}
    for dist in ("gift", "gift-llm", "gift-kernels", "gift-rewards", "gift-sim-drake", "gift-experiments", "drake",
                 "numpy", "torch", "llama-cpp-python", "litellm", "sentence-transformers"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            pass
    return out


def merge_lm(parts: Sequence[dict[str, Any] | None]) -> dict[str, Any] | None:
    """One LM provenance with the usage counters of the items summed (None when no item used an LM)."""
    used = [p for p in parts if p is not None]
    if not used:
        return None
    usage: dict[str, Any] | None = None
    for p in used:
        if p.get("usage") is not None:
            usage = dict(p["usage"]) if usage is None else {k: add_usage(usage.get(k), v) for k, v in p["usage"].items()}
    merged = {k: v for k, v in used[0].items() if k != "usage"}
    if usage is not None:
        merged["usage"] = usage
    return merged


def source_at_start() -> dict[str, Any]:
    """The git commit and code version of the code that runs, taken when a run starts (a commit made while
    it runs must not be recorded as what made it)."""
    return {"git": git_commit(), "code_version": code_version()}


def run_record(*, options: Mapping[str, Any], suite: Suite, lm: dict[str, Any] | None,
               executor: Mapping[str, Any], started: float, seconds: float,
               recovered: Sequence[str] = (), source: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """What made one run (or one resume) of a study: code (``source``, from :func:`source_at_start` when the
    run started), environment, suite, LM, options."""
    source = source_at_start() if source is None else source
    rec: dict[str, Any] = {"started": time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(started)),
                           "seconds": round(seconds, 2), "git": source["git"], "code_version": source["code_version"],
                           "python": platform.python_version(), "platform": platform.platform(),
                           "versions": versions(), "suite": suite_provenance(suite), "options": dict(options),
                           "executor": dict(executor)}
    if lm is not None:
        rec["lm"] = lm
    if recovered:
        rec["recovered_stage_files"] = list(recovered)
    return rec


def manifest(runs: Sequence[Mapping[str, Any]], config_key: str) -> dict[str, Any]:
    """The manifest of a results file: the latest run's record at the top level (``lm``, ``git``, ...)
    and every run that contributed (first run and resumes) in ``runs``, oldest first."""
    latest = dict(runs[-1])
    out = {k: latest[k] for k in ("git", "code_version", "python", "platform", "versions", "suite", "executor")
           if k in latest}
    out["config_key"] = config_key
    lm = [r["lm"] for r in runs if r.get("lm")]
    if lm:
        out["lm"] = {**{k: v for k, v in lm[-1].items() if k != "usage"},
                     "usage": merge_lm([{"usage": r.get("usage")} for r in lm]).get("usage") if any(
                         r.get("usage") for r in lm) else None}
        if out["lm"]["usage"] is None:
            del out["lm"]["usage"]
    out["runs"] = list(runs)
    return out


def previous_runs(results_path: Path) -> list[dict[str, Any]]:
    """The run records of an earlier results file at ``results_path`` (empty when there is none)."""
    import json

    try:
        old = json.loads(results_path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    runs = (old.get("manifest") or {}).get("runs") if isinstance(old, dict) else None
    return [r for r in runs if isinstance(r, dict)] if isinstance(runs, list) else []


# ============================================================================= run_study


def run_study(cfg: StudyConfig, out: Path | str | None, progress: Progress | None = None,
              log_line: Callable[[str], None] | None = None, executor: Executor | str | None = None,
              echo: bool = False, previous: Sequence[Mapping[str, Any]] = ()) -> dict:
    """Run the chain on every intent of ``cfg`` and return the results dictionary.

    One :class:`IntentJob` per intent runs on ``executor`` (an :class:`~gift.core.executor.Executor`, a
    registered name, or None: ``serial``). ``serial`` runs the intents one after the other in this
    process with ``progress`` bars and ``log_line`` calls as they happen, and raises what an intent
    raised. A pool runs them in one ``map``; their lines go to ``log_line`` when it returns, unless
    ``echo`` (executors with ``live_stderr``), which makes the workers write them to stderr as they happen.
    ``previous``: run records of earlier runs into the same results (resumes), kept in the manifest.
    """
    progress = progress or Progress()
    started, t0, source = time.time(), time.perf_counter(), source_at_start()
    suite = load_suite(cfg.suite)
    intents = [suite.intent(i) for i in cfg.intents] if cfg.intents else list(suite.intents)
    out_dir = None if out is None else str(Path(out).resolve())
    jobs = [IntentJob(cfg, suite, out_dir, spec.id, intent_seeds(cfg, spec.id)) for spec in intents]
    with using_executor(executor) as ex:
        if ex.in_process:
            comp = components_for(cfg.lm, cfg.defaults)
            fn = functools.partial(run_intent, comp=comp, progress=progress, log_line=log_line)
            slices, failure = [], None
            for job in progress(jobs, "intents"):
                try:
                    slices.append(ex.map(fn, [job])[0])
                except ExecutionError as e:
                    failure = e.__cause__ or e
                    break
            if failure is not None:  # in this process: raise what the intent raised
                raise failure
        else:
            slices = ex.map(functools.partial(_pool_intent, echo=echo), jobs, chunksize=1)
            if not echo and log_line is not None:
                for part in slices:
                    for line in part["log"]:
                        log_line(line)
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
    record = run_record(options=attrs.asdict(cfg), suite=suite, lm=merge_lm([p["lm"] for p in slices]),
                        executor=where, started=started, seconds=time.perf_counter() - t0, source=source,
                        recovered=[f for p in slices for f in p.get("recovered", [])])
    results["manifest"] = manifest([*previous, record], cfg.key())
    return results


def _pool_intent(job: IntentJob, echo: bool = False) -> dict:
    """:func:`run_intent` in a pool worker: lines to stderr as they happen when ``echo``."""
    logger = _echo_logger() if echo else None
    return run_intent(job, log_line=logger.info if logger else None)


# ============================================================================= evaluate_alignment


@attrs.frozen
class FrontHalf:
    """What an intent's front half gives every kernel: the intent and the relevant training objects."""

    intent: Intent
    relevant: RelevantTraining
    lm: dict[str, Any] | None = None


@attrs.frozen
class AlignItem:
    """One kernel on one intent: the unit of work of :func:`evaluate_alignment` (run by :func:`align_item`)."""

    cfg: StudyConfig
    suite: Suite
    kernel: str
    intent_id: str
    front: FrontHalf | None = None  # None: ground truth


@attrs.frozen
class ItemOutcome:
    """What :func:`align_item` sends back: a record, an error of the intent, or an error building the kernel."""

    kernel: str
    intent_id: str
    record: dict | None = None
    error: str | None = None
    build_error: str | None = None
    line: str = ""
    seconds: float = 0.0
    lm: dict[str, Any] | None = None


@attrs.frozen
class Failure:
    """Why an item failed: ``text`` for the result (``"Type: message"``, plus a short traceback when the
    error is not a GiftError) and ``message`` (``"Type: message"``) for the progress line."""

    text: str
    message: str

    @classmethod
    def current(cls, e: BaseException) -> "Failure":
        import traceback

        message = f"{type(e).__name__}: {e}"
        text = message if isinstance(e, GiftError) else message + "\n" + traceback.format_exc(limit=4)
        return cls(text, message)


def front_item(job: IntentJob) -> tuple[FrontHalf | None, Failure | None]:
    """The front half of one intent in inferred mode: demonstrations -> relevant objects -> ω̂."""
    cfg, suite = job.cfg, job.suite
    spec = suite.intent(job.intent_id)
    comp = components_for(cfg.lm, cfg.defaults)
    before = _usage(comp)
    try:
        comp.lm.identity()  # an LM that cannot be built fails before any simulation
        training = get_training(comp, cfg, suite, spec, job.seeds["train"])
        relevant = relevant_training(cfg, spec, training)
        inferred = intent_stage(comp, cfg, suite, spec, training, relevant, StageCache(job.out),
                                lambda m: log.info(m), Progress(False))
        intent = Intent.from_dict(inferred["main"])
    except Exception as e:  # noqa: BLE001 - reported per kernel, like a failing kernel
        return None, Failure.current(e)
    return FrontHalf(intent, relevant, _lm_delta(comp, before)), None


def _usage(comp: Any) -> dict | None:
    from gift.study.chain import _lm_usage

    return _lm_usage(comp)


def _lm_delta(comp: Any, before: dict | None) -> dict | None:
    from gift.study.chain import _lm_usage, _usage_delta, lm_inputs

    if not comp.lm_built:
        return None
    return {**lm_inputs(comp), "usage": _usage_delta(before, _lm_usage(comp))}


def _done_line(kernel: str, intent_id: str, record: Mapping[str, Any], seconds: float) -> str:
    f1 = " ".join(f"{t}={r['metrics']['all']['f1']:.2f}" for t, r in record["thresholds"].items())
    q = record.get("queries")
    if q:
        f1 += (f", after {q['asked']} queries ({q['policy']}) {q['metrics'][q['threshold']]['all']['f1']:.2f}"
               + (f", {q['n_abstained']} abstained" if q["abstain"] else ""))
    return f"{kernel} / {intent_id}: F1 {f1} ({seconds:.1f}s)"


def _failed_line(kernel: str, intent_id: str, message: str) -> str:
    return f"{kernel} / {intent_id}: FAILED {message}"


def align_item(item: AlignItem, *, echo: bool = False) -> ItemOutcome:
    """Run one (kernel, intent) item; never raises for a failing kernel or intent (the outcome says why)."""
    cfg, suite = item.cfg, item.suite
    spec = suite.intent(item.intent_id)
    comp = components_for(cfg.lm, cfg.defaults)
    before = _usage(comp)
    t0 = time.perf_counter()
    try:
        kernel = comp.kernel(item.kernel)
    except Exception as e:  # noqa: BLE001 - the kernel is reported as failed, the others go on
        error = f"{type(e).__name__}: {e}"
        out = ItemOutcome(item.kernel, item.intent_id, build_error=error,
                          line=f"{item.kernel}: FAILED to build: {error}")
    else:
        if item.front is None:
            intent = Intent(text=spec.text, source="ground-truth")
            relevant = relevant_training(attrs.evolve(cfg, intent_source="ground-truth"), spec, None)
        else:
            intent, relevant = item.front.intent, item.front.relevant
        try:
            scores, cuts, metrics = score_intent(kernel, suite, spec, intent, relevant.names, cfg.thresholds)
            # the simulated human answers (no trajectories here: the error bound counts one state per object)
            queried = query_stage(cfg, spec, scores, rescore=rescorer(cfg, suite, spec, kernel, intent,
                                                                      relevant.names)) \
                if cfg.queries or cfg.abstain else None
        except Exception as e:  # noqa: BLE001 - one failing intent must not lose the others
            failure = Failure.current(e)
            out = ItemOutcome(item.kernel, item.intent_id, error=failure.text, seconds=time.perf_counter() - t0,
                              line=_failed_line(item.kernel, spec.id, failure.message))
        else:
            seconds = time.perf_counter() - t0
            record = alignment_record(scores, cuts, metrics, seconds, kernel)
            record.update({"intent": spec.id, "intent_text": intent.text, "relevant": relevant.to_dict()})
            if queried is not None:
                record["queries"] = queried
            out = ItemOutcome(item.kernel, item.intent_id, record=record, seconds=seconds,
                              line=_done_line(item.kernel, spec.id, record, seconds))
    out = attrs.evolve(out, lm=_lm_delta(comp, before))
    if echo:
        _echo_logger().info(out.line)
    return out


def _pooled(suite: Suite, records: Sequence[Mapping[str, Any]], thresholds: Sequence[str]) -> dict:
    by_id = {s.id: s for s in suite.intents}
    rows = []
    for r in records:
        spec = by_id[r["intent"]]
        decision = np.array([r["objects"][t.object]["decision"] for t in spec.test])
        cuts = {thr: r["thresholds"][thr]["cut"] for thr in thresholds}
        metrics = {thr: r["thresholds"][thr]["metrics"] for thr in thresholds}
        rows.append((decision, [t.relevant for t in spec.test], subset_masks(spec), cuts, metrics))
    return pooled_alignment_metrics(rows, thresholds, REPORT_SUBSETS)


def _pooled_queries(suite: Suite, records: Sequence[Mapping[str, Any]]) -> dict:
    """``{subset: metrics}`` after the queries, pooled over the intents as :func:`_pooled` pools the cuts."""
    by_id = {s.id: s for s in suite.intents}
    rows, th = [], None
    for r in records:
        q = r.get("queries")
        if not q:
            continue
        spec, th = by_id[r["intent"]], q["threshold"]
        decision = np.array([q["decision"][t.object] for t in spec.test])
        rows.append((decision, [t.relevant for t in spec.test], subset_masks(spec), {th: q["cut"]}, q["metrics"]))
    return pooled_alignment_metrics(rows, [th], REPORT_SUBSETS)[th] if rows else {}


def _intent_entry(record: Mapping[str, Any]) -> dict[str, Any]:
    out = {"intent": record["intent"], "intent_text": record["intent_text"], "seconds": record["seconds"],
           "relevant": record["relevant"], "details": record["details"], "fallbacks": record["fallbacks"],
           "thresholds": {k: {"cut": v["cut"], "note": v["note"]} for k, v in record["thresholds"].items()},
           "metrics": {k: v["metrics"] for k, v in record["thresholds"].items()}, "objects": record["objects"],
           "scores": record["scores"]}
    if "queries" in record:
        out["queries"] = record["queries"]
    return out


class _Table:
    """Collects outcomes into the result dict in kernel order, with progress lines and checkpoints."""

    def __init__(self, out: dict[str, Any], suite: Suite, thresholds: Sequence[str],
                 progress: Callable[[str], None] | None, checkpoint: Callable[[dict[str, Any]], None] | None,
                 live: bool) -> None:
        self.out, self.suite, self.thresholds = out, suite, list(thresholds)
        self.progress, self.checkpoint, self.live = progress, checkpoint, live
        self.records: list[dict] = []
        self.errors: dict[str, str] = {}

    def _say(self, line: str, shown: bool = False) -> None:
        if self.progress and not shown:
            self.progress(line)

    def _save(self) -> None:
        if self.checkpoint and self.live:
            self.checkpoint(self.out)

    def _partial(self, kernel: str) -> dict:
        configs = list(dict.fromkeys(r.get("configuration") for r in self.records))
        out = {"kernel": kernel, "configuration": configs[0] if len(configs) == 1 else configs,
               "errors": dict(self.errors), "overall": _pooled(self.suite, self.records, self.thresholds),
               "intents": {r["intent"]: _intent_entry(r) for r in self.records}}
        if any("queries" in r for r in self.records):
            out["queries"] = _pooled_queries(self.suite, self.records)
        return out

    def build_failed(self, kernel: str, error: str, shown: bool = False) -> None:
        self.out["kernels"][kernel] = {"kernel": kernel, "errors": {"*": error}, "overall": {}, "intents": {}}
        self._say(f"{kernel}: FAILED to build: {error}", shown)
        self._save()

    def start(self) -> None:
        self.records, self.errors = [], {}

    def intent_failed(self, kernel: str, intent_id: str, error: str, line: str, shown: bool = False) -> None:
        self.errors[intent_id] = error
        self._say(line, shown)
        self.out["kernels"][kernel] = self._partial(kernel)
        self._save()

    def add(self, o: ItemOutcome, shown: bool = False) -> None:
        if o.record is None:
            self.intent_failed(o.kernel, o.intent_id, o.error or "no result", o.line, shown)
            return
        self.records.append(o.record)
        self._say(o.line, shown)
        self.out["kernels"][o.kernel] = self._partial(o.kernel)
        self._save()

    def finish(self, kernel: str, seconds: float) -> None:
        d = self._partial(kernel)
        d["seconds"] = round(seconds, 2)
        self.out["kernels"][kernel] = d
        self._save()


def evaluate_alignment(suite: Suite | str, kernels: Sequence[str], *, thresholds: Sequence[str] = THRESHOLDS,
                       intent_source: str = "ground-truth", lm: str | None = None,
                       intents: Sequence[str] | None = None, robot: str = "jaco",
                       progress: Callable[[str], None] | None = None,
                       checkpoint: Callable[[dict[str, Any]], None] | None = None,
                       executor: Executor | str | None = None, echo: bool = False,
                       stages: str | Path | None = None, config: StudyConfig | None = None,
                       queries: int = 0, query_policy: str = "uncertainty", abstain: float = 0.0,
                       query_rescore: bool = True) -> dict[str, Any]:
    """Evaluate kernels (registered names, optionally ``name:key=value``) on a suite; returns a JSON-able dict.

    The work is one :class:`AlignItem` per (kernel, intent) on ``executor`` (None: ``serial``); with
    ``intent_source="inferred"`` each intent's front half (the demonstrations of ``robot``, the relevant
    training objects inferred from them, ω̂) runs first, once per intent. ``serial`` calls
    ``progress(line)`` and ``checkpoint(result_so_far)`` after every kernel x intent (an interrupted run
    keeps what it computed); a pool calls them when its ``map`` returns (with ``echo``, workers print
    each line to stderr as soon as it is done). ``stages``: a directory for the stage cache of the
    inferred intents. ``config``: the study sizes for the demonstrations (default :class:`StudyConfig`).
    ``queries`` / ``query_policy`` / ``abstain``: questions per kernel and intent answered from the suite's
    labels, and the abstention band (:func:`~gift.study.chain.query_stage`); results under ``queries``;
    ``query_rescore``: the kernel scores the scene again with the answers when it can (rule 5; the default).
    """
    started, t0, source = time.time(), time.perf_counter(), source_at_start()
    if isinstance(suite, str):
        suite = load_suite(suite)
    bad = [t for t in thresholds if t not in THRESHOLDS]
    if bad:
        raise GiftError(f"unknown threshold(s) {bad}; choose from {list(THRESHOLDS)}")
    if intent_source not in INTENT_SOURCES:
        raise GiftError(f"unknown intent source {intent_source!r}; choose from {list(INTENT_SOURCES)}")
    if intents is not None:
        unknown = [i for i in intents if i not in {s.id for s in suite.intents}]
        if unknown:
            raise GiftError(f"suite {suite.name!r} has no intent(s) {unknown}")
    base = config or StudyConfig()
    cfg = attrs.evolve(base, suite=suite.path or suite.name, robot=robot, lm=lm, kernels=tuple(kernels),
                       intents=tuple(intents or ()), intent_source=intent_source, thresholds=tuple(thresholds),
                       rq1=False, rq3=False, sanity_reps=0, queries=queries, query_policy=query_policy,
                       abstain=abstain, query_rescore=query_rescore)
    if queries or abstain:
        check = check_spec("query_policy", query_policy)
        if check is not None:
            raise GiftError(check)
    specs = [s for s in suite.intents if intents is None or s.id in intents]
    out: dict[str, Any] = {"suite": suite.name, "suite_path": suite.path, "intent_source": intent_source,
                           "thresholds": list(thresholds), "lm": lm, "kernels": {}}
    if queries or abstain:
        out["queries"] = {"n": queries, "policy": query_policy, "abstain": abstain, "rescore": query_rescore,
                          "threshold": query_threshold(cfg), "move": DEFAULT_MOVE, "choose": DEFAULT_CHOOSE}
    out_dir = None if stages is None else str(Path(stages).resolve())
    with using_executor(executor) as ex:
        table = _Table(out, suite, thresholds, progress, checkpoint, live=ex.in_process)
        lm_parts = _run_items(ex, table, cfg, suite, kernels, specs, out_dir, echo)
        where = {"name": ex.name, "max_workers": ex.max_workers}
    record = run_record(options=attrs.asdict(cfg), suite=suite, lm=merge_lm(lm_parts), executor=where,
                        started=started, seconds=time.perf_counter() - t0, source=source)
    out["manifest"] = manifest([record], cfg.key())
    if checkpoint:
        checkpoint(out)
    return out


def _run_items(ex: Executor, table: _Table, cfg: StudyConfig, suite: Suite, kernels: Sequence[str],
               specs: Sequence[Any], out_dir: str | None, echo: bool) -> list[dict | None]:
    """Front halves (inferred mode) then (kernel, intent) items: one ``map`` each on a pool, item by item
    (progress and checkpoints after each) in this process."""
    errors = {k: check_spec("kernel", k) for k in kernels}
    fronts: dict[str, tuple[FrontHalf | None, Failure | None]] = {s.id: (None, None) for s in specs}
    lm_parts: list[dict | None] = []
    if cfg.intent_source == "inferred" and specs and any(e is None for e in errors.values()):
        jobs = [IntentJob(cfg, suite, out_dir, s.id, intent_seeds(cfg, s.id)) for s in specs]
        done = ex.map(front_item, jobs, chunksize=1)
        fronts = dict(zip([s.id for s in specs], done))
        lm_parts += [f.lm for f, _ in done if f is not None]
    items = [AlignItem(cfg, suite, k, s.id, fronts[s.id][0])
             for k in dict.fromkeys(kernels) if errors[k] is None for s in specs if fronts[s.id][1] is None]
    # in this process: one item at a time below, so progress and checkpoints follow every item
    outcomes = [] if ex.in_process or not items else ex.map(functools.partial(align_item, echo=echo), items,
                                                               chunksize=1)
    by_item = {(o.kernel, o.intent_id): o for o in outcomes}
    for kspec in kernels:
        if errors[kspec] is not None:
            table.build_failed(kspec, errors[kspec])
            continue
        table.start()
        seconds, failed_build = 0.0, False
        for spec in specs:
            failure = fronts[spec.id][1]
            if failure is not None:
                table.intent_failed(kspec, spec.id, failure.text, _failed_line(kspec, spec.id, failure.message))
                continue
            if ex.in_process:
                o = ex.map(align_item, [AlignItem(cfg, suite, kspec, spec.id, fronts[spec.id][0])])[0]
            else:
                o = by_item[(kspec, spec.id)]
            lm_parts.append(o.lm)
            if o.build_error is not None:
                table.build_failed(kspec, o.build_error, shown=echo and not ex.in_process)
                failed_build = True
                break
            table.add(o, shown=echo and not ex.in_process)
            seconds += o.seconds
        if not failed_build:
            table.finish(kspec, seconds)
    return lm_parts
