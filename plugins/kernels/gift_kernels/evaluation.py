"""``gift evaluate-alignment``: how well each kernel aligns the labelled test objects of a suite.

For every kernel, intent and threshold strategy: the kernel is run once per intent
(:func:`gift_kernels.alignment.score_alignment`), each threshold is applied to the same scores, and
precision, recall, F1, AUC, FP and FN are computed on S_R, S_lang, S_vis, S_unk and their union
(``all``), per intent and pooled over intents (``overall``). A kernel that fails is reported with its
error; the others, and the intents that did finish, are kept.
"""

from __future__ import annotations

import inspect
import math
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import attrs
import numpy as np

from gift.core.data import DemonstrationPair, Intent
from gift.core.errors import GiftError
from gift.core.metrics import binary_metrics, roc_auc
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


def evaluate_kernel(kernel: Any, suite: Suite, *, thresholds: Sequence[str] = THRESHOLDS,
                    intent_for: Callable[[IntentSpec, Suite], Intent] = lambda s, _: ground_truth_intent(s),
                    kernel_name: str | None = None, intents: Sequence[str] | None = None,
                    progress: Callable[[str], None] | None = None,
                    on_intent: Callable[[KernelResult], None] | None = None) -> KernelResult:
    """Evaluate one kernel instance on every intent of ``suite`` (or the ids in ``intents``).

    ``on_intent(partial)`` gets the result so far after every intent (to checkpoint long LM runs).
    """
    name = kernel_name or getattr(kernel, "name", type(kernel).__name__)
    results, errors = [], {}
    specs = [s for s in suite.intents if intents is None or s.id in intents]
    for spec in specs:
        t0 = time.perf_counter()
        try:
            intent = intent_for(spec, suite)
            scores = score_alignment(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                                     intent, relevant_train=spec.relevant_train, need=tuple(thresholds))
            labels = {t.object: t.relevant for t in spec.test}
            y = np.array([t.relevant for t in spec.test], dtype=bool)
            cuts = {thr: scores.threshold(thr, labels) for thr in thresholds}
            metrics = {thr: {sub: subset_metrics(scores.decision[_members(spec, sub)], y[_members(spec, sub)],
                                                 cuts[thr][0])
                             for sub in REPORT_SUBSETS if _members(spec, sub).any()}
                       for thr in thresholds}
        except Exception as e:  # noqa: BLE001 - one failing intent must not lose the others
            errors[spec.id] = f"{type(e).__name__}: {e}"
            if progress:
                progress(f"{name} / {spec.id}: FAILED {type(e).__name__}: {e}")
            if not isinstance(e, GiftError):
                errors[spec.id] += "\n" + traceback.format_exc(limit=4)
            if on_intent:
                on_intent(KernelResult(name, tuple(results), dict(errors), pooled_metrics(suite, results, thresholds)))
            continue
        results.append(IntentResult(spec.id, scores, cuts, metrics, intent.text, time.perf_counter() - t0))
        if progress:
            f1 = " ".join(f"{t}={metrics[t]['all']['f1']:.2f}" for t in thresholds)
            progress(f"{name} / {spec.id}: F1 {f1} ({time.perf_counter() - t0:.1f}s)")
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


def evaluate_alignment(suite: Suite | str, kernels: Sequence[str], *, thresholds: Sequence[str] = THRESHOLDS,
                       intent_source: str = "ground-truth", lm: str | None = None,
                       intents: Sequence[str] | None = None,
                       progress: Callable[[str], None] | None = None,
                       checkpoint: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
    """Evaluate kernels (registered names, optionally ``name:key=value``) on a suite; returns a JSON-able dict.

    ``checkpoint(result_so_far)`` is called after every kernel x intent (e.g. to write a file), so an
    interrupted run keeps what it computed.
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
    if intent_source == "ground-truth":
        intent_for = lambda s, _: ground_truth_intent(s)  # noqa: E731
    else:
        infer = inferred_intent_source(lm=lm)
        cache: dict[str, Intent] = {}

        def intent_for(spec: IntentSpec, s: Suite) -> Intent:  # one inference per intent, shared by kernels
            if spec.id not in cache:
                cache[spec.id] = infer(spec, s)
            return cache[spec.id]

    out: dict[str, Any] = {"suite": suite.name, "suite_path": suite.path, "intent_source": intent_source,
                           "thresholds": list(thresholds), "lm": lm, "kernels": {}}
    for spec in kernels:
        t0 = time.perf_counter()
        try:
            name, options = parse_kernel_spec(spec)
            kernel = _create("kernel", name, lm, **options)
        except Exception as e:  # noqa: BLE001 - report and go on with the other kernels
            out["kernels"][spec] = {"kernel": spec, "errors": {"*": f"{type(e).__name__}: {e}"}, "overall": {},
                                    "intents": {}}
            if progress:
                progress(f"{spec}: FAILED to build: {type(e).__name__}: {e}")
            if checkpoint:
                checkpoint(out)
            continue

        def save(partial: KernelResult, spec: str = spec) -> None:
            out["kernels"][spec] = partial.as_dict()
            if checkpoint:
                checkpoint(out)

        res = evaluate_kernel(kernel, suite, thresholds=thresholds, intent_for=intent_for, kernel_name=spec,
                              intents=intents, progress=progress, on_intent=save)
        d = res.as_dict()
        d["seconds"] = round(time.perf_counter() - t0, 2)
        out["kernels"][spec] = d
        if checkpoint:
            checkpoint(out)
    return out


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
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return None if math.isnan(float(x)) else float(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    return x
