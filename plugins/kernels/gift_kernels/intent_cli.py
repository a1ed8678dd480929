"""``gift infer-intent``: Calls 1 and 2 on a saved file of demonstration pairs.

The file is JSON (written by :func:`save_demonstrations`)::

    {"format": 1, "task_context": "...", "objects": ["paintbrush", ...],     # both optional
     "pairs": [{"features": [{"name": ..., "description": ..., "subject": ..., "reference": ..., "kind": ...}],
                "preferred": [[...F values...] x T], "default": [[...] x T]}, ...]}
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path

import attrs

from gift.core.data import DemonstrationPair, FeatureSpec, FeatureTrace
from gift.core.errors import GiftError, ValidationError

FORMAT = 1


def save_demonstrations(path: str | Path, pairs: Sequence[DemonstrationPair], *, task_context: str = "",
                        objects: Sequence[str] = ()) -> Path:
    """Write demonstration pairs as JSON (feature specs + ``[T, F]`` values of both traces)."""
    doc = {"format": FORMAT, "task_context": task_context, "objects": list(objects), "pairs": [
        {"features": [attrs.asdict(s) for s in p.preferred.specs], "preferred": p.preferred.values.tolist(),
         "default": p.default.values.tolist()} for p in pairs]}
    p = Path(path)
    p.write_text(json.dumps(doc))
    return p


def load_demonstrations(path: str | Path) -> tuple[list[DemonstrationPair], str, list[str]]:
    """``(pairs, task_context, objects)`` from a file :func:`save_demonstrations` wrote; errors name the pair."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except OSError as e:
        raise GiftError(f"cannot read demonstrations file {p}: {e.strerror}") from None
    except json.JSONDecodeError as e:
        raise GiftError(f"demonstrations file {p} is not valid JSON: {e}") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("pairs"), list) or not doc["pairs"]:
        raise GiftError(f"demonstrations file {p}: expected an object with a non-empty list 'pairs'")
    if doc.get("format", FORMAT) != FORMAT:
        raise GiftError(f"demonstrations file {p}: format {doc.get('format')!r}, expected {FORMAT}")
    pairs = []
    for k, raw in enumerate(doc["pairs"]):
        try:
            specs = tuple(FeatureSpec(**f) for f in raw["features"])
            pairs.append(DemonstrationPair(FeatureTrace(specs, raw["preferred"]), FeatureTrace(specs, raw["default"])))
        except (KeyError, TypeError, ValueError, ValidationError) as e:
            raise GiftError(f"demonstrations file {p}, pair {k}: {type(e).__name__}: {e}") from None
    return pairs, str(doc.get("task_context", "")), [str(o) for o in doc.get("objects", [])]


def configure_infer_intent(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("demonstrations", help="JSON file of demonstration pairs (see gift_kernels.intent_cli)")
    parser.add_argument("--estimator", default="lm-contrastive", help="registered intent estimator")
    parser.add_argument("--lm", default=None, help="LM backend (default: the embedded model)")
    parser.add_argument("--task-context", default=None, help="one sentence about the task (overrides the file's)")
    parser.add_argument("--objects", nargs="*", default=None, help="object names for the semantic axes")
    parser.add_argument("--json", action="store_true", help="machine-readable output")


def run_infer_intent(args: argparse.Namespace) -> int:
    import gift

    pairs, context, objects = load_demonstrations(args.demonstrations)
    options = {"lm": args.lm} if args.lm else {}
    estimator = gift.get_intent_estimator(args.estimator, **options)
    intent = estimator.estimate(pairs, task_context=args.task_context if args.task_context is not None else context,
                                objects=args.objects if args.objects is not None else objects)
    if args.json:
        print(json.dumps(intent.to_dict(), indent=1))
        return 0
    print(f"intent: {intent.text}")
    for k, m in enumerate(intent.motivations, 1):
        print(f"  {k}. {m.text}\n     features: {', '.join(m.features) or '-'}")
    for a in intent.axes:
        print(f"  axis: {a.question}  ->  {', '.join(a.objects) or '-'}")
    return 0
