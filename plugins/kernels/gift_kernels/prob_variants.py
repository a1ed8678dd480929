"""Measure ``gift-prob`` variants on a suite: AUC and F1 with the train-calibrated threshold.

Usage::

    python -m gift_kernels.prob_variants --suite gift-paper [--lm NAME] [--variants a,b] [--json]
        [--intents-from runs/jaco/results.json]   # the intents a reproduce run inferred

Each variant is a set of :class:`gift_kernels.lm_kernels.GiftProbKernel` options. Per intent the kernel
scores the test objects and, leave-one-out, the training objects in one call; the threshold is the cut
that best separates the relevant training objects from the others
(:func:`gift_kernels.alignment.best_separating_cut`); no test label is used. AUC is per intent (the
scores of different intents are on different scales), then averaged; F1 is pooled over all test objects.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gift.core.data import Intent
from gift.core.errors import GiftError, ValidationError
from gift.core.metrics import binary_metrics, roc_auc
from gift.core.serialization import dumps, finite_values
from gift.core.suite import Suite, load_suite

#: name -> GiftProbKernel options. The first entry is the default of gift-prob.
VARIANTS: dict[str, dict[str, Any]] = {
    "objects-category+minilm-reliable": dict(template="category", category_from="goal+objects",
                                             combine="language", embed_reference="contrastive",
                                             weighting="reliability"),
    "objects-category": dict(template="category", category_from="goal+objects", combine="none"),
    "category+minilm-reliable": dict(template="category", category_from="goal", combine="language",
                                     embed_reference="contrastive", weighting="reliability"),
    "category": dict(template="category", category_from="goal", combine="none"),
    "category+minilm": dict(template="category", category_from="goal", combine="language",
                            embed_reference="contrastive", weighting="equal"),
    "lm+minilm-reliable": dict(template="goal", combine="language", embed_reference="contrastive",
                               weighting="reliability"),
    "lm+minilm-contrastive": dict(template="goal", combine="language", embed_reference="contrastive",
                                  weighting="equal"),
    "lm": dict(template="goal", combine="none"),
    "lm+minilm": dict(template="goal", combine="language", embed_reference="relevant", weighting="equal"),
    "lm-about": dict(template="about", combine="none"),
    "lm-name": dict(template="goal-name", combine="none"),
    "lm+minilm-trainstats": dict(template="goal", combine="language", embed_reference="relevant",
                                 standardize="train", weighting="equal"),
    "lm-about+minilm": dict(template="about", combine="language", weighting="equal"),
    "minilm": dict(template="goal", combine="language", embed_reference="relevant", weight=1.0),
    "minilm-contrastive": dict(template="goal", combine="language", embed_reference="contrastive", weight=1.0),
}


def evaluate_variant(kernel: Any, suite: Suite, intents: Mapping[str, Intent] | None = None) -> dict[str, Any]:
    """AUC / F1 of one relevance kernel on every intent of ``suite`` (ground-truth intents by default)."""
    from gift_kernels.alignment import best_separating_cut
    from gift_kernels.prompts import goal_text

    per_intent, preds, truth = {}, [], []
    for spec in suite.intents:
        intent = (intents or {}).get(spec.id) or Intent(text=spec.text, source="ground-truth")
        test, train = suite.specs(spec.test_objects), suite.specs(spec.train_objects)
        r_test, r_train = kernel.relevance_loo(test, train, intent, spec.relevant_train)
        rel = np.array([n in spec.relevant_train for n in spec.train_objects])
        cut = best_separating_cut(r_train[rel], r_train[~rel])
        labels = np.array([t.relevant for t in spec.test])
        pred = r_test >= cut
        m = binary_metrics(pred, labels)
        per_intent[spec.id] = {"auc": roc_auc(r_test, labels), "f1": m.f1, "cut": cut,
                               "fp": m.fp, "fn": m.fn, "weights": dict(getattr(kernel, "last_weights", {})),
                               "category": getattr(kernel, "categories", {}).get(goal_text(intent.text)),
                               "scores": {o: round(float(s), 3) for o, s in zip(spec.test_objects, r_test)}}
        preds += list(pred)
        truth += list(labels)
    m = binary_metrics(preds, truth)
    aucs = finite_values(v["auc"] for v in per_intent.values())  # one-class intents have no AUC
    return {"auc": float(np.mean(aucs)) if aucs else None, "f1": m.f1, "precision": m.precision, "recall": m.recall,
            "fp": m.fp, "fn": m.fn, "per_intent": per_intent}


def run(suite: str, variants: Sequence[str], lm: Any = None, intents: Mapping[str, Intent] | None = None
        ) -> dict[str, Any]:
    from gift_kernels.lm_kernels import GiftProbKernel

    s = load_suite(suite)
    out = {}
    for name in variants:
        k = GiftProbKernel(lm=lm, **VARIANTS[name])
        t0 = time.monotonic()
        res = evaluate_variant(k, s, intents)
        res["seconds"] = time.monotonic() - t0
        res["lm_calls"] = k.calls
        out[name] = res
    return out


def load_intents(results_json: str | Path) -> dict[str, Intent]:
    """intent id -> the intent a `gift reproduce` run conditioned its kernels on (its ``results.json``)."""
    path = Path(results_json)
    try:
        data = json.loads(path.read_text())
        return {k: Intent.from_dict(v) for k, v in data["intents"].items()}
    except (OSError, json.JSONDecodeError) as e:
        raise GiftError(f"--intents-from {path}: cannot read a results.json ({e})") from e
    except (KeyError, TypeError, AttributeError, ValidationError) as e:
        raise GiftError(f"--intents-from {path}: no 'intents' table of {{id: {{text: ...}}}} in it ({e!r})") from e


def format_table(results: Mapping[str, Mapping[str, Any]]) -> str:
    lines = ["| variant | AUC (mean per intent) | F1 (train-calibrated) | precision | recall | FP | FN |",
             "|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        auc = "n/a" if r["auc"] is None else f"{r['auc']:.3f}"
        lines.append(f"| {name} | {auc} | {r['f1']:.3f} | {r['precision']:.3f} | {r['recall']:.3f} | "
                     f"{r['fp']} | {r['fn']} |")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m gift_kernels.prob_variants", description=__doc__.splitlines()[0])
    p.add_argument("--suite", default="gift-paper")
    p.add_argument("--lm", default=None, help="LM backend name (default: the embedded model)")
    p.add_argument("--variants", default=",".join(VARIANTS), help=f"comma-separated, from {list(VARIANTS)}")
    p.add_argument("--intents-from", default=None, metavar="RESULTS_JSON",
                   help="use the inferred intents of a `gift reproduce` run (its results.json) instead of "
                        "the suite's ground-truth texts")
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    names = [v.strip() for v in args.variants.split(",") if v.strip()]
    bad = [v for v in names if v not in VARIANTS]
    if bad:
        p.error(f"unknown variants {bad}; known: {list(VARIANTS)}")
    intents = load_intents(args.intents_from) if args.intents_from else None
    res = run(args.suite, names, lm=args.lm, intents=intents)
    print(dumps(res, indent=1) if args.json else format_table(res))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
