"""``gift align``: align test objects to training objects with one kernel (``gift infer-intent``: intent_cli)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence

from gift.core.data import DISTRACTOR, Intent, ObjectSpec
from gift.core.errors import GiftError
from gift.core.alignment import THRESHOLDS, score_alignment

# ----------------------------------------------------------------------------- gift align


def configure_align(p: argparse.ArgumentParser) -> None:
    p.add_argument("--train", nargs="+", required=True, metavar="OBJECT", help="training object names")
    p.add_argument("--test", nargs="+", required=True, metavar="OBJECT", help="test object names")
    p.add_argument("--intent", default=None, metavar="TEXT", help="the intent, e.g. 'pack art supplies'")
    p.add_argument("--relevant", nargs="+", default=(), metavar="OBJECT",
                   help="training objects relevant under the intent (needed by train-calibrated)")
    p.add_argument("--kernel", required=True, help="registered kernel, optionally name:key=value (see gift plugins)")
    p.add_argument("--threshold", default="non-oracle",
                   help="non-oracle (default) | train-calibrated | a number in [0, 1]")
    p.add_argument("--suite", default=None, help="look object descriptions/appearances up in this suite "
                                                 "(default: every registered suite's catalog)")
    p.add_argument("--lm", default=None, help="LM backend for LM kernels (default: the embedded model)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


def catalog_objects(names: Sequence[str], suite: str | None = None) -> tuple[ObjectSpec, ...]:
    """ObjectSpecs for names: from ``suite``'s catalog, else any registered suite's; unknown names get a bare spec."""
    from gift.core.suite import load_suite
    from gift.plugins.manager import get_manager

    catalogs = []
    if suite is not None:
        catalogs.append(load_suite(suite).objects)
    else:
        for name in sorted(get_manager().suites()):
            try:
                catalogs.append(load_suite(name).objects)
            except GiftError:
                continue
    out = []
    for n in names:
        found = next((c[n] for c in catalogs if n in c), None)
        out.append(found if found is not None else ObjectSpec(name=n))
    return tuple(out)


def run_align(args: argparse.Namespace) -> int:
    from gift.study.components import build, parse_spec

    clash = sorted(set(args.train) & set(args.test))
    if clash:
        raise GiftError(f"objects {clash} are both training and test objects")
    if args.threshold == "oracle":
        raise GiftError("gift align has no test labels, so no oracle threshold; use non-oracle, "
                        "train-calibrated or a number")
    threshold: str | float = args.threshold
    if threshold not in THRESHOLDS:
        try:
            threshold = float(threshold)
        except ValueError:
            raise GiftError(f"--threshold must be one of non-oracle, train-calibrated or a number, "
                            f"got {args.threshold!r}") from None
    name, _ = parse_spec(args.kernel)
    kernel = build("kernel", args.kernel, lm=args.lm)
    train = catalog_objects(args.train, args.suite)
    test = catalog_objects(args.test, args.suite)
    intent = Intent(text=args.intent, source="given") if args.intent else None
    if getattr(kernel, "uses_intent", False) and intent is None:
        raise GiftError(f"kernel {name!r} reads the intent: pass --intent TEXT")
    need = ("non-oracle", "train-calibrated") if threshold == "train-calibrated" else (
        ("non-oracle",) if threshold == "non-oracle" else ())
    scores = score_alignment(kernel, test, train, intent, relevant_train=tuple(args.relevant), need=need)
    cut, note = scores.threshold(threshold)
    alignment = scores.alignment(cut)
    rel = set(args.relevant)
    rows = []
    for i, o in enumerate(test):
        target = alignment.target(o.name)
        rows.append({"object": o.name, "target": target, "score": alignment.scores[o.name],
                     "decision": float(scores.decision[i]),
                     "relevant": (target != DISTRACTOR and target in rel) if rel else None})
    out = {"kernel": args.kernel, "intent": args.intent, "threshold": cut, "threshold_rule": note,
           "error_bound_per_state": alignment.error_bound(), "alignment": rows,
           "similarity": {"test": list(scores.test), "train": list(scores.train),
                          "K": [[round(float(v), 6) for v in row] for row in scores.K]}}
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"kernel {args.kernel}, threshold {cut:.3f} ({note})")
    width = max(len(o.name) for o in test)
    for r in rows:
        flag = "" if r["relevant"] is None else ("  [relevant]" if r["relevant"] else "")
        print(f"  {r['object']:<{width}} -> {r['target']:<20} K={r['score']:.3f}{flag}")
    print(f"alignment error bound per state (L=1): {out['error_bound_per_state']:.3f}")
    return 0
