"""``gift evaluate-alignment``: how well each kernel aligns the labelled test objects of a suite.

For every kernel, intent and threshold strategy: the kernel is run once per intent
(:func:`gift_kernels.alignment.score_alignment`), each threshold is applied to the same scores, and
precision, recall, F1, AUC, FP and FN are computed on S_R, S_lang, S_vis, S_unk and their union
(``all``), per intent and pooled over intents (``overall``). A kernel that fails is reported with its
error; the others, and the intents that did finish, are kept.

Each (kernel, intent) is an independent :class:`AlignmentItem` run by the module-level
:func:`evaluate_item`, so the sweep runs on any executor of :mod:`gift.core.executor` (``serial``,
``local``, ``ray``) with the same result; pooling over intents happens in the calling process.
"""

from __future__ import annotations

import functools
import inspect
import math
import sys
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import attrs
import numpy as np

from gift.core.data import DemonstrationPair, Intent
from gift.core.errors import GiftError
from gift.core.executor import Executor, using_executor
from gift.core.metrics import binary_metrics, roc_auc
from gift.core.serialization import to_jsonable
from gift.core.suite import SUBSETS, IntentSpec, Suite, load_suite
from gift_kernels.alignment import THRESHOLDS, AlignmentScores, score_alignment

#: Reported subsets: S_R, S_lang, S_vis, S_unk, and their union (every test object).
REPORT_SUBSETS = SUBSETS + ("all",)
INTENT_SOURCES = ("ground-truth", "inferred")


def subset_metrics(decision: np.ndarray, labels: np.ndarray, cut: float) -> dict[str, float]:
    """Counts and rates of ``decision >= cut`` against ``labels``, plus AUC of ``decision``."""
    m = binary_metrics(decision >= cut, labels)
    out: dict[str, float] = {"n": int(labels.size), **m.as_dict()}
    out["auc"] = roc_auc(decision, labels) if labels.size else float("nan")
    return out


def _members(spec: IntentSpec, subset: str) -> np.ndarray:
    if subset == "all":
        return np.ones(len(spec.test), dtype=bool)
    return np.array([t.in_subset(subset) for t in spec.test], dtype=bool)


@attrs.frozen
class IntentResult:
    """One kernel on one intent: its scores, and per threshold the cut, its note and per-subset metrics."""

    intent: str
    scores: AlignmentScores
    thresholds: Mapping[str, tuple[float, str]]
    metrics: Mapping[str, Mapping[str, Mapping[str, float]]]  # threshold -> subset -> metric -> value
    intent_text: str = ""
    seconds: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        return {"intent": self.intent, "intent_text": self.intent_text, "seconds": round(self.seconds, 3),
                "thresholds": {k: {"cut": v[0], "note": v[1]} for k, v in self.thresholds.items()},
                "metrics": _jsonable(self.metrics),
                "objects": {name: {"decision": float(self.scores.decision[i]),
                                   "match": self.scores.train[self.scores.target[i]] if self.scores.train else None}
                            for i, name in enumerate(self.scores.test)}}


@attrs.frozen
class KernelResult:
    kernel: str
    intents: tuple[IntentResult, ...] = ()
    errors: Mapping[str, str] = attrs.field(factory=dict)  # intent id (or "*") -> error text
    overall: Mapping[str, Mapping[str, Mapping[str, float]]] = attrs.field(factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return {"kernel": self.kernel, "errors": dict(self.errors), "overall": _jsonable(self.overall),
                "intents": {r.intent: r.as_dict() for r in self.intents}}


def pooled_metrics(suite: Suite, results: Sequence[IntentResult], thresholds: Sequence[str]
                   ) -> dict[str, dict[str, dict[str, float]]]:
    """Metrics pooled over intents (micro: counts summed), and mean per-intent F1 and AUC."""
    by_id = {s.id: s for s in suite.intents}
    out: dict[str, dict[str, dict[str, float]]] = {}
    for thr in thresholds:
        out[thr] = {}
        for subset in REPORT_SUBSETS:
            preds, labels, f1s, aucs = [], [], [], []
            for r in results:
                spec = by_id[r.intent]
                mask = _members(spec, subset)
                if not mask.any():
                    continue
                y = np.array([t.relevant for t in spec.test], dtype=bool)[mask]
                cut = r.thresholds[thr][0]
                preds.append(r.scores.decision[mask] >= cut)
                labels.append(y)
                f1s.append(r.metrics[thr][subset]["f1"])
                aucs.append(r.metrics[thr][subset]["auc"])
            if not labels:
                continue
            p, y = np.concatenate(preds), np.concatenate(labels)
            m = binary_metrics(p, y)
            finite = [a for a in aucs if not math.isnan(a)]
            out[thr][subset] = {"n": int(y.size), **m.as_dict(), "f1_mean_intent": float(np.mean(f1s)),
                                "auc_mean_intent": float(np.mean(finite)) if finite else float("nan")}
    return out


# ----------------------------------------------------------------------------- intents


def ground_truth_intent(spec: IntentSpec) -> Intent:
    return Intent(text=spec.text, source="ground-truth")


def demonstration_pairs(spec: IntentSpec, suite: Suite, simulator: Any, *, n_pairs: int = 2,
                        seed: int = 0) -> list[DemonstrationPair]:
    """Simulated preferred-vs-default demonstrations in a training scene of ``spec``."""
    scene = simulator.make_scene(spec.task, suite.specs(spec.train_objects), spec.relevant_train, seed)
    pref = simulator.features(simulator.generate(scene, "preferred", n_pairs, seed), spec.task)
    dflt = simulator.features(simulator.generate(scene, "default", n_pairs, seed + 1), spec.task)
    return [DemonstrationPair(pref.trace(i), dflt.trace(i), scene) for i in range(n_pairs)]


def inferred_intent_source(simulator: str = "drake-franka", estimator: str = "lm-contrastive",
                           lm: str | None = None, n_pairs: int = 2, seed: int = 0
                           ) -> Callable[[IntentSpec, Suite], Intent]:
    """The GIFT front half: demonstrations from ``simulator``, then Calls 1 and 2 of ``estimator``."""
    import gift

    state: dict[str, Any] = {}

    def infer(spec: IntentSpec, suite: Suite) -> Intent:
        if "sim" not in state:
            state["sim"] = gift.get_simulator(simulator)
            state["est"] = _create("intent_estimator", estimator, lm)
        pairs = demonstration_pairs(spec, suite, state["sim"], n_pairs=n_pairs, seed=seed)
        task = gift.get_task(spec.task)
        return state["est"].estimate(pairs, task_context=task.context(),
                                     objects=spec.train_objects + spec.test_objects)

    return infer


def _create(kind: str, name: str, lm: str | None, **options: Any) -> Any:
    """Build a registered component, passing ``lm`` only to factories that take it."""
    from gift.plugins.manager import get_manager

    comp = get_manager().get(kind, name)
    if lm is not None:
        try:
            params = inspect.signature(comp.factory).parameters
        except (TypeError, ValueError):
            params = {}
        if "lm" in params or any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
            options["lm"] = lm
    return comp.create(**options)


# ----------------------------------------------------------------------------- evaluation


def score_intent(kernel: Any, suite: Suite, spec: IntentSpec, intent: Intent | None, thresholds: Sequence[str]
                 ) -> tuple[AlignmentScores, dict[str, tuple[float, str]], dict[str, dict[str, dict[str, float]]]]:
    """One kernel on one intent: its scores, the cut of every threshold, and metrics per threshold and subset."""
    scores = score_alignment(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                             intent, relevant_train=spec.relevant_train, need=tuple(thresholds))
    labels = {t.object: t.relevant for t in spec.test}
    y = np.array([t.relevant for t in spec.test], dtype=bool)
    cuts = {thr: scores.threshold(thr, labels) for thr in thresholds}
    metrics = {thr: {sub: subset_metrics(scores.decision[_members(spec, sub)], y[_members(spec, sub)], cuts[thr][0])
                     for sub in REPORT_SUBSETS if _members(spec, sub).any()}
               for thr in thresholds}
    return scores, cuts, metrics


@attrs.frozen
class Failure:
    """Why an intent failed: ``text`` for the result (``"Type: message"``, plus a short traceback when the
    error is not a GiftError) and ``message`` (``"Type: message"``) for the progress line."""

    text: str
    message: str

    @classmethod
    def current(cls, e: BaseException) -> "Failure":
        """The failure of ``e`` (call inside the ``except`` block, for the traceback)."""
        message = f"{type(e).__name__}: {e}"
        text = message if isinstance(e, GiftError) else message + "\n" + traceback.format_exc(limit=4)
        return cls(text, message)


def _done_line(name: str, intent_id: str, metrics: Mapping[str, Any], thresholds: Sequence[str],
               seconds: float) -> str:
    f1 = " ".join(f"{t}={metrics[t]['all']['f1']:.2f}" for t in thresholds)
    return f"{name} / {intent_id}: F1 {f1} ({seconds:.1f}s)"


def _failed_line(name: str, intent_id: str, message: str) -> str:
    return f"{name} / {intent_id}: FAILED {message}"


def evaluate_kernel(kernel: Any, suite: Suite, *, thresholds: Sequence[str] = THRESHOLDS,
                    intent_for: Callable[[IntentSpec, Suite], Intent] = lambda s, _: ground_truth_intent(s),
                    kernel_name: str | None = None, intents: Sequence[str] | None = None,
                    progress: Callable[[str], None] | None = None,
                    on_intent: Callable[[KernelResult], None] | None = None) -> KernelResult:
    """Evaluate one kernel instance on every intent of ``suite`` (or the ids in ``intents``), in this process.

    ``on_intent(partial)`` gets the result so far after every intent (to checkpoint long LM runs).
    """
    name = kernel_name or getattr(kernel, "name", type(kernel).__name__)
    results, errors = [], {}
    specs = [s for s in suite.intents if intents is None or s.id in intents]
    for spec in specs:
        t0 = time.perf_counter()
        try:
            intent = intent_for(spec, suite)
            scores, cuts, metrics = score_intent(kernel, suite, spec, intent, thresholds)
        except Exception as e:  # noqa: BLE001 - one failing intent must not lose the others
            failure = Failure.current(e)
            errors[spec.id] = failure.text
            if progress:
                progress(_failed_line(name, spec.id, failure.message))
            if on_intent:
                on_intent(KernelResult(name, tuple(results), dict(errors), pooled_metrics(suite, results, thresholds)))
            continue
        results.append(IntentResult(spec.id, scores, cuts, metrics, intent.text, time.perf_counter() - t0))
        if progress:
            progress(_done_line(name, spec.id, metrics, thresholds, time.perf_counter() - t0))
        if on_intent:
            on_intent(KernelResult(name, tuple(results), dict(errors), pooled_metrics(suite, results, thresholds)))
    return KernelResult(name, tuple(results), errors, pooled_metrics(suite, results, thresholds))


def parse_kernel_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """``"name"`` or ``"name:key=value:key=value"`` -> (name, options); values true/false/int/float/str."""
    name, *opts = spec.strip().split(":")
    options: dict[str, Any] = {}
    for o in opts:
        if "=" not in o:
            raise GiftError(f"kernel option {o!r} in {spec!r} must look like key=value")
        k, v = o.split("=", 1)
        options[k.strip()] = _value(v.strip())
    if not name:
        raise GiftError(f"empty kernel name in {spec!r}")
    return name, options


def _value(v: str) -> Any:
    if v.lower() in ("true", "false"):
        return v.lower() == "true"
    for cast in (int, float):
        try:
            return cast(v)
        except ValueError:
            pass
    return v


# ----------------------------------------------------------------------------- units of work (picklable)


@attrs.frozen
class IntentItem:
    """Infer the intent of one suite intent (GIFT Calls 1-2 on simulated demonstrations)."""

    suite: Suite
    intent_id: str
    lm: str | None = None


@attrs.frozen
class AlignmentItem:
    """One kernel on one intent: the unit of work of ``evaluate-alignment``, run by :func:`evaluate_item`.

    Carries its whole configuration, so any worker can run it. ``kernel``: spec (``name`` or
    ``name:key=value``); ``intent``: the inferred intent, or None for the suite's ground-truth text.
    """

    suite: Suite
    kernel: str
    intent_id: str
    thresholds: tuple[str, ...]
    lm: str | None = None
    intent: Intent | None = None


@attrs.frozen
class ItemOutcome:
    """What :func:`evaluate_item` sends back: a result, an error of the intent, or an error building the kernel."""

    kernel: str
    intent_id: str
    result: IntentResult | None = None
    error: str | None = None
    build_error: str | None = None
    line: str = ""  # the progress line
    seconds: float = 0.0


#: Per worker process: built kernels by (spec, lm), inferrers by lm (reused by every item of a sweep).
_WORKER_KERNELS: dict[tuple[str, str | None], Any] = {}
_WORKER_INFERRERS: dict[str | None, Callable[[IntentSpec, Suite], Intent]] = {}


def _echo(line: str) -> None:
    print(line, file=sys.stderr, flush=True)


def infer_item(item: IntentItem, *, infer: Callable[[IntentSpec, Suite], Intent] | None = None,
               ) -> tuple[Intent | None, Failure | None]:
    """``(intent, None)``, or ``(None, failure)`` when inference fails. ``infer``: default one
    :func:`inferred_intent_source` per LM and worker process."""
    if infer is None:
        if item.lm not in _WORKER_INFERRERS:
            _WORKER_INFERRERS[item.lm] = inferred_intent_source(lm=item.lm)
        infer = _WORKER_INFERRERS[item.lm]
    try:
        return infer(item.suite.intent(item.intent_id), item.suite), None
    except Exception as e:  # noqa: BLE001 - reported per kernel, like a failing kernel
        return None, Failure.current(e)


def evaluate_item(item: AlignmentItem, *, kernels: dict | None = None, echo: bool = False) -> ItemOutcome:
    """Run one (kernel, intent) item; never raises for a failing kernel or intent (the outcome says why).

    The kernel is built here (through the plugin manager; an LM kernel resolves ``item.lm`` with
    gift_llm's ``resolve_lm``, i.e. the shared SQLite cache) and kept in ``kernels`` (default: a cache per
    worker process). ``echo``: print the progress line to stderr (live progress from pool workers).
    """
    cache = _WORKER_KERNELS if kernels is None else kernels
    t0 = time.perf_counter()
    key = (item.kernel, item.lm)
    try:
        if key not in cache:
            name, options = parse_kernel_spec(item.kernel)
            cache[key] = _create("kernel", name, item.lm, **options)
        kernel = cache[key]
    except Exception as e:  # noqa: BLE001 - the kernel is reported as failed, the others go on
        error = f"{type(e).__name__}: {e}"
        out = ItemOutcome(item.kernel, item.intent_id, build_error=error, line=f"{item.kernel}: FAILED to build: {error}")
    else:
        spec = item.suite.intent(item.intent_id)
        intent = item.intent if item.intent is not None else ground_truth_intent(spec)
        try:
            scores, cuts, metrics = score_intent(kernel, item.suite, spec, intent, item.thresholds)
        except Exception as e:  # noqa: BLE001 - one failing intent must not lose the others
            failure = Failure.current(e)
            out = ItemOutcome(item.kernel, item.intent_id, error=failure.text, seconds=time.perf_counter() - t0,
                              line=_failed_line(item.kernel, spec.id, failure.message))
        else:
            seconds = time.perf_counter() - t0
            res = IntentResult(spec.id, scores, cuts, metrics, intent.text, seconds)
            out = ItemOutcome(item.kernel, item.intent_id, result=res, seconds=seconds,
                              line=_done_line(item.kernel, spec.id, metrics, item.thresholds, seconds))
    if echo:
        _echo(out.line)
    return out


class _Table:
    """Collects outcomes into the result dict in kernel order, with progress lines and checkpoints."""

    def __init__(self, out: dict[str, Any], suite: Suite, thresholds: Sequence[str],
                 progress: Callable[[str], None] | None, checkpoint: Callable[[dict[str, Any]], None] | None,
                 live: bool) -> None:
        self.out, self.suite, self.thresholds = out, suite, list(thresholds)
        self.progress, self.checkpoint, self.live = progress, checkpoint, live
        self.results: list[IntentResult] = []
        self.errors: dict[str, str] = {}

    def _say(self, line: str, shown: bool = False) -> None:
        if self.progress and not shown:
            self.progress(line)

    def _save(self) -> None:
        if self.checkpoint and self.live:
            self.checkpoint(self.out)

    def _partial(self, kernel: str) -> KernelResult:
        return KernelResult(kernel, tuple(self.results), dict(self.errors),
                            pooled_metrics(self.suite, self.results, self.thresholds))

    def build_failed(self, kernel: str, error: str, shown: bool = False) -> None:
        self.out["kernels"][kernel] = {"kernel": kernel, "errors": {"*": error}, "overall": {}, "intents": {}}
        self._say(f"{kernel}: FAILED to build: {error}", shown)
        self._save()

    def start(self) -> None:
        self.results, self.errors = [], {}

    def intent_failed(self, kernel: str, intent_id: str, error: str, line: str, shown: bool = False) -> None:
        self.errors[intent_id] = error
        self._say(line, shown)
        self.out["kernels"][kernel] = self._partial(kernel).as_dict()
        self._save()

    def add(self, o: ItemOutcome, shown: bool = False) -> None:
        if o.result is None:
            self.intent_failed(o.kernel, o.intent_id, o.error or "no result", o.line, shown)
            return
        self.results.append(o.result)
        self._say(o.line, shown)
        self.out["kernels"][o.kernel] = self._partial(o.kernel).as_dict()
        self._save()

    def finish(self, kernel: str, seconds: float) -> None:
        d = self._partial(kernel).as_dict()
        d["seconds"] = round(seconds, 2)
        self.out["kernels"][kernel] = d
        self._save()


def _kernel_spec_error(spec: str) -> str | None:
    """Why a kernel spec cannot be built (bad syntax, unknown name), checked without building it."""
    from gift.plugins.manager import get_manager

    try:
        name, _ = parse_kernel_spec(spec)
        get_manager().get("kernel", name)
    except Exception as e:  # noqa: BLE001 - reported like a failing kernel
        return f"{type(e).__name__}: {e}"
    return None


def evaluate_alignment(suite: Suite | str, kernels: Sequence[str], *, thresholds: Sequence[str] = THRESHOLDS,
                       intent_source: str = "ground-truth", lm: str | None = None,
                       intents: Sequence[str] | None = None,
                       progress: Callable[[str], None] | None = None,
                       checkpoint: Callable[[dict[str, Any]], None] | None = None,
                       executor: Executor | str | None = None, echo: bool = False) -> dict[str, Any]:
    """Evaluate kernels (registered names, optionally ``name:key=value``) on a suite; returns a JSON-able dict.

    The work is one :class:`AlignmentItem` per (kernel, intent), run by :func:`evaluate_item` on
    ``executor`` (an :class:`~gift.core.executor.Executor`, a registered name, or None: ``serial``); with
    ``intent_source="inferred"`` each intent is first inferred once (:class:`IntentItem`). The result is
    the same on every executor. ``serial`` runs the items one after the other in this process, calling
    ``progress(line)`` and ``checkpoint(result_so_far)`` after every kernel x intent (so an interrupted
    run keeps what it computed). A pool runs every item in one ``map``; ``progress`` and ``checkpoint``
    are then called when it returns, except that with ``echo=True`` (for executors with ``live_stderr``,
    e.g. ``local``) the workers print each item's progress line to stderr as soon as it is done (and
    ``progress`` does not repeat it).
    """
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
    thresholds = tuple(thresholds)
    specs = [s for s in suite.intents if intents is None or s.id in intents]
    out: dict[str, Any] = {"suite": suite.name, "suite_path": suite.path, "intent_source": intent_source,
                           "thresholds": list(thresholds), "lm": lm, "kernels": {}}
    with using_executor(executor) as ex:
        table = _Table(out, suite, thresholds, progress, checkpoint, live=ex.in_process)
        if ex.in_process:
            _run_in_process(ex, table, suite, kernels, specs, thresholds, intent_source, lm)
        else:
            _run_pool(ex, table, suite, kernels, specs, thresholds, intent_source, lm, echo)
    return out


def _run_in_process(ex: Executor, table: _Table, suite: Suite, kernels: Sequence[str], specs: Sequence[IntentSpec],
                    thresholds: tuple[str, ...], intent_source: str, lm: str | None) -> None:
    """Kernel by kernel, intent by intent, one ``map`` per item: progress and checkpoints after each."""
    built: dict = {}
    infer = inferred_intent_source(lm=lm) if intent_source == "inferred" else None
    inferred: dict[str, tuple[Intent | None, Failure | None]] = {}  # one inference per intent, shared by kernels
    for kspec in kernels:
        t0 = time.perf_counter()
        error = _kernel_spec_error(kspec)
        if error is not None:
            table.build_failed(kspec, error)
            continue
        table.start()
        failed_build = False
        for spec in specs:
            intent = None
            if infer is not None:
                if spec.id not in inferred:
                    inferred[spec.id] = ex.map(functools.partial(infer_item, infer=infer),
                                               [IntentItem(suite, spec.id, lm)])[0]
                intent, failure = inferred[spec.id]
                if failure is not None:
                    table.intent_failed(kspec, spec.id, failure.text, _failed_line(kspec, spec.id, failure.message))
                    continue
            o = ex.map(functools.partial(evaluate_item, kernels=built),
                       [AlignmentItem(suite, kspec, spec.id, thresholds, lm, intent)])[0]
            if o.build_error is not None:
                table.build_failed(kspec, o.build_error)
                failed_build = True
                break
            table.add(o)
        if not failed_build:
            table.finish(kspec, time.perf_counter() - t0)


def _run_pool(ex: Executor, table: _Table, suite: Suite, kernels: Sequence[str], specs: Sequence[IntentSpec],
              thresholds: tuple[str, ...], intent_source: str, lm: str | None, echo: bool) -> None:
    """Every item in one ``map`` (after one ``map`` of intent inferences); then the table, in kernel order."""
    errors = {k: _kernel_spec_error(k) for k in kernels}
    inferred: dict[str, tuple[Intent | None, Failure | None]] = {s.id: (None, None) for s in specs}
    if intent_source == "inferred" and specs and any(e is None for e in errors.values()):
        done = ex.map(infer_item, [IntentItem(suite, s.id, lm) for s in specs], chunksize=1)
        inferred = dict(zip([s.id for s in specs], done))
    items = [AlignmentItem(suite, k, s.id, thresholds, lm, inferred[s.id][0])
             for k in dict.fromkeys(kernels) if errors[k] is None for s in specs if inferred[s.id][1] is None]
    outcomes = ex.map(functools.partial(evaluate_item, echo=echo), items, chunksize=1) if items else []
    by_item = {(o.kernel, o.intent_id): o for o in outcomes}
    for kspec in kernels:
        if errors[kspec] is not None:
            table.build_failed(kspec, errors[kspec])
            continue
        table.start()
        seconds, failed_build = 0.0, False
        for spec in specs:
            failure = inferred[spec.id][1]
            if failure is not None:
                table.intent_failed(kspec, spec.id, failure.text, _failed_line(kspec, spec.id, failure.message))
                continue
            o = by_item[(kspec, spec.id)]
            if o.build_error is not None:
                table.build_failed(kspec, o.build_error, shown=echo)
                failed_build = True
                break
            table.add(o, shown=echo)
            seconds += o.seconds
        if not failed_build:
            table.finish(kspec, seconds)
    if table.checkpoint:
        table.checkpoint(table.out)


# ----------------------------------------------------------------------------- text report


def format_report(result: Mapping[str, Any], *, per_intent: bool = True, detailed: bool = False) -> str:
    """Markdown tables: per kernel x threshold on the union (P, R, F1, AUC, FP, FN) with F1 and FP/FN per
    subset; then F1 per intent; ``detailed`` adds every metric per subset."""
    thresholds = result["thresholds"]
    subs = [s for s in REPORT_SUBSETS if s != "all"]
    lines = [f"Suite `{result['suite']}`, intent source `{result['intent_source']}`. Union = every test object, "
             f"pooled over intents; AUC = mean over intents.", ""]
    lines += ["| kernel | threshold | P | R | F1 | AUC | FP | FN | " + " | ".join(f"F1 {_subset_label(s)}" for s in subs)
              + " | " + " | ".join(f"FP/FN {_subset_label(s)}" for s in subs) + " |",
              "|---" * (8 + 2 * len(subs)) + "|"]
    for kname, k in result["kernels"].items():
        if not k["overall"]:
            lines.append(f"| {kname} | - | error: {_first_error(k)} |" + " |" * (6 + 2 * len(subs)))
            continue
        for thr in thresholds:
            o = k["overall"].get(thr, {})
            u = o.get("all")
            if u is None:
                continue
            f1s = " | ".join(f"{o[s]['f1']:.2f}" if s in o else "-" for s in subs)
            fpfn = " | ".join(f"{o[s]['fp']}/{o[s]['fn']}" if s in o else "-" for s in subs)
            lines.append(f"| {kname} | {thr} | {u['precision']:.2f} | {u['recall']:.2f} | **{u['f1']:.2f}** | "
                         f"{_f(u['auc_mean_intent'])} | {u['fp']} | {u['fn']} | {f1s} | {fpfn} |")
    if detailed:
        lines += ["", "| kernel | threshold | subset | n | precision | recall | F1 | AUC (mean/intent) | FP | FN |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for kname, k in result["kernels"].items():
            for thr in thresholds:
                for sub in REPORT_SUBSETS:
                    m = k["overall"].get(thr, {}).get(sub)
                    if m is None:
                        continue
                    lines.append(f"| {kname} | {thr} | {_subset_label(sub)} | {m['n']} | {m['precision']:.2f} | "
                                 f"{m['recall']:.2f} | {m['f1']:.2f} | {_f(m['auc_mean_intent'])} | {m['fp']} | "
                                 f"{m['fn']} |")
    if per_intent:
        lines += ["", "Per intent (all its test objects):", "",
                  "| kernel | intent | " + " | ".join(f"F1 {t}" for t in thresholds) + " | AUC |",
                  "|---|---|" + "---|" * (len(thresholds) + 1)]
        for kname, k in result["kernels"].items():
            for iid, r in k["intents"].items():
                m = r["metrics"]
                f1s = " | ".join(f"{m[t]['all']['f1']:.2f}" for t in thresholds)
                lines.append(f"| {kname} | {iid} | {f1s} | {_f(m[thresholds[0]]['all']['auc'])} |")
    errs = [(k, i, e) for k, d in result["kernels"].items() for i, e in d["errors"].items()]
    if errs:
        lines += ["", "Errors:"]
        lines += [f"- {k} / {i}: {e.splitlines()[0]}" for k, i, e in errs]
    return "\n".join(lines)


def _first_error(k: Mapping[str, Any]) -> str:
    return next(iter(k["errors"].values()), "no result").splitlines()[0].replace("|", "/")


def _subset_label(sub: str) -> str:
    return "union" if sub == "all" else f"S_{sub}"


def _f(x: float) -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.2f}"


def _jsonable(x: Any) -> Any:
    return to_jsonable(x, nonfinite="null-nan")
