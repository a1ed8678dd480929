"""``gift align``: align test objects to training objects with one kernel (``gift infer-intent``: intent_cli)."""

from __future__ import annotations

import argparse
import difflib
import logging
from collections.abc import Mapping, Sequence

from gift.core import serialization
from gift.core.alignment import THRESHOLDS, score_alignment
from gift.core.data import DISTRACTOR, Intent, ObjectSpec
from gift.core.errors import GiftError

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
    p.add_argument("--allow-unknown", action="store_true",
                   help="accept object names that no catalog has (they get no description and the default "
                        "appearance, a grey 8 cm cube; the output lists them). Default: an error")
    p.add_argument("--lm", default=None, help="LM backend for LM kernels (default: the embedded model)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


def lookup_objects(names: Sequence[str], suite: str | None = None
                   ) -> tuple[tuple[ObjectSpec, ...], list[str], dict[str, Mapping[str, ObjectSpec]]]:
    """``(specs, missing, catalogs)``: the catalog entry of each name (from ``suite``'s catalog, else the first
    registered suite's that has it), the names no catalog has (given a bare spec), and the catalogs searched."""
    from gift.core.suite import load_suite
    from gift.plugins.manager import get_manager

    catalogs: dict[str, Mapping[str, ObjectSpec]] = {}
    if suite is not None:
        loaded = load_suite(suite)
        catalogs[loaded.path or suite] = loaded.objects
    else:
        for name in sorted(get_manager().suites()):
            try:
                catalogs[name] = load_suite(name).objects
            except GiftError:
                continue
    specs, missing = [], []
    for n in names:
        found = next((c[n] for c in catalogs.values() if n in c), None)
        if found is None:
            missing.append(n)
            found = ObjectSpec(name=n)
        specs.append(found)
    return tuple(specs), missing, catalogs


def catalog_objects(names: Sequence[str], suite: str | None = None, *, allow_unknown: bool = False
                    ) -> tuple[ObjectSpec, ...]:
    """ObjectSpecs for names (see :func:`lookup_objects`).

    A name that no catalog has is a :class:`GiftError` naming it, with close matches: a bare name would
    silently be a grey cube without a description. ``allow_unknown=True`` gives it that bare spec instead.
    """
    specs, missing, catalogs = lookup_objects(names, suite)
    if missing and not allow_unknown:
        raise unknown_objects_error(missing, catalogs, suite)
    return specs


def unknown_objects_error(missing: Sequence[str], catalogs: Mapping[str, Mapping[str, ObjectSpec]],
                          suite: str | None) -> GiftError:
    known = sorted({k for c in catalogs.values() for k in c})
    hints = []
    for n in missing:
        close = difflib.get_close_matches(n, known, n=3)
        hints.append(f"{n!r} (did you mean {', '.join(map(repr, close))}?)" if close else repr(n))
    where = (f"the catalog of suite {next(iter(catalogs))}" if suite is not None else
             f"the catalog of any registered suite ({', '.join(catalogs) or 'none'})")
    many = len(missing) > 1
    return GiftError(f"unknown object{'s' if many else ''} {', '.join(hints)}: not in {where}. Add "
                     f"{'them' if many else 'it'} to a suite file and pass --suite FILE, or pass --allow-unknown "
                     f"to use bare names (no description, the default appearance: a grey 8 cm cube)")


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
    stray = sorted(set(args.relevant) - set(args.train))
    if stray:
        raise GiftError(f"--relevant {stray}: not among the --train objects {list(args.train)}")
    train, missing_train, catalogs = lookup_objects(args.train, args.suite)
    test, missing_test, _ = lookup_objects(args.test, args.suite)
    unknown = missing_train + missing_test
    if unknown and not args.allow_unknown:
        raise unknown_objects_error(unknown, catalogs, args.suite)
    if unknown:
        logging.getLogger("gift").warning(
            "gift align: warning: %d object(s) in no catalog, aligned as bare names without a description and "
            "with the default appearance (a grey 8 cm cube): %s", len(unknown), ", ".join(unknown))
    name, _ = parse_spec(args.kernel)
    kernel = build("kernel", args.kernel, lm=args.lm)
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
           "unknown_objects": {"names": unknown, "note": "in no catalog: no description, default appearance "
                                                         "(grey 8 cm cube)"} if unknown else None,
           "similarity": {"test": list(scores.test), "train": list(scores.train),
                          "K": [[round(float(v), 6) for v in row] for row in scores.K]}}
    if args.json:
        print(serialization.dumps(out, indent=2))
        return 0
    print(f"kernel {args.kernel}, threshold {cut:.3f} ({note})")
    width = max(len(o.name) for o in test)
    for r in rows:
        flag = "" if r["relevant"] is None else ("  [relevant]" if r["relevant"] else "")
        print(f"  {r['object']:<{width}} -> {r['target']:<20} K={r['score']:.3f}{flag}")
    print(f"alignment error bound per state (L=1): {out['error_bound_per_state']:.3f}")
    return 0
