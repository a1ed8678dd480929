"""``gift align``: align test objects to training objects with one kernel (``gift infer-intent``: intent_cli).

``gift align --ask N`` asks the human on the terminal about up to N test objects ("is it part of the
goal?", :mod:`gift.core.queries`) and re-scores the scene with the answers. Answers are saved (``--answers
FILE``, default ``<gift cache>/answers.json``) under a key made of the intent text, the training objects
and the relevant training objects, one entry per test object: a rerun uses them and asks only about
objects not answered yet, until N objects of the scene are answered.
"""

from __future__ import annotations

import argparse
import difflib
import json
import logging
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

from gift.cli import add_answer_arguments, check_answer_arguments
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
    p.add_argument("--threshold", default=None,
                   help="non-oracle (default; train-calibrated with --ask) | train-calibrated | a number in [0, 1]")
    p.add_argument("--suite", default=None, help="look object descriptions/appearances up in this suite "
                                                 "(default: every registered suite's catalog)")
    p.add_argument("--allow-unknown", action="store_true",
                   help="accept object names that no catalog has (they get no description and the default "
                        "appearance, a grey 8 cm cube; the output lists them). Default: an error")
    p.add_argument("--lm", default=None, help="LM backend for LM kernels (default: the embedded model)")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--ask", type=int, default=0, metavar="N",
                   help="ask on the terminal about up to N test objects (saved answers count; a rerun does not ask "
                        "again) and re-score with the answers")
    add_answer_arguments(p)
    p.add_argument("--answers", default=None, metavar="FILE",
                   help="where --ask saves and finds answers (default: answers.json in the gift cache directory)")


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
    if args.ask < 0:
        raise GiftError(f"--ask must be >= 0, got {args.ask}")
    check_answer_arguments(args)
    threshold: str | float = args.threshold or ("train-calibrated" if args.ask else "non-oracle")
    if threshold not in THRESHOLDS:
        try:
            threshold = float(threshold)
        except ValueError:
            raise GiftError(f"--threshold must be one of non-oracle, train-calibrated or a number, "
                            f"got {args.threshold!r}") from None
        if not 0.0 <= threshold <= 1.0:
            raise GiftError(f"--threshold must be in [0, 1], got {threshold}")
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
    state = None
    if args.ask or args.abstain:
        from gift.core.queries import kernel_rescorer

        again = kernel_rescorer(kernel, test, train, intent, relevant_train=tuple(args.relevant),
                                need=need) if args.rescore else None
        state = _ask_on_terminal(args, scores, test, threshold, again)
        cut, note, alignment = state.cut, state.note, state.alignment
    else:
        cut, note = scores.threshold(threshold)
        alignment = scores.alignment(cut)
    rel = set(args.relevant)
    rows = []
    for i, o in enumerate(test):
        target = alignment.target(o.name)
        row = {"object": o.name, "target": target, "score": alignment.scores[o.name],
               "decision": float(scores.decision[i]),
               "relevant": (target != DISTRACTOR and target in rel) if rel else None}
        if state is not None:
            a = state.answer_of(o.name)
            row["answer"] = None if a is None else a.to_dict()
            row["abstained"] = o.name in state.abstained
        rows.append(row)
    out = {"kernel": args.kernel, "intent": args.intent, "threshold": cut, "threshold_rule": note,
           "error_bound_per_state": alignment.error_bound(), "alignment": rows,
           "unknown_objects": {"names": unknown, "note": "in no catalog: no description, default appearance "
                                                         "(grey 8 cm cube)"} if unknown else None,
           "similarity": {"test": list(scores.test), "train": list(scores.train),
                          "K": [[round(float(v), 6) for v in row] for row in scores.K]}}
    if state is not None:
        out["queries"] = {"policy": args.policy, "ask": args.ask, "abstain": args.abstain,
                          "answers_file": str(_answers_path(args)), **state.to_dict()}
    if args.json:
        print(serialization.dumps(out, indent=2))
        return 0
    print(f"kernel {args.kernel}, threshold {cut:.3f} ({note})")
    width = max(len(o.name) for o in test)
    for r in rows:
        flag = "" if r["relevant"] is None else ("  [relevant]" if r["relevant"] else "")
        if r.get("answer") is not None:
            flag += "  [answered: " + _answer_text(r["answer"]) + "]"
        if r.get("abstained"):
            flag += "  [abstained: held out like a distractor]"
        print(f"  {r['object']:<{width}} -> {r['target']:<20} K={r['score']:.3f}{flag}")
    if state is not None:
        print(f"answers used: {len(state.answers)} (saved in {_answers_path(args)}); "
              f"abstained: {len(state.abstained)}")
    print(f"alignment error bound per state (L=1): {out['error_bound_per_state']:.3f}")
    return 0


# ----------------------------------------------------------------------------- gift align --ask


def _answers_path(args: argparse.Namespace) -> Path:
    if args.answers:
        return Path(args.answers)
    from gift.core.provenance import cache_dir

    return cache_dir() / "answers.json"


def answers_key(intent: str | None, train: Sequence[str], relevant: Sequence[str]) -> str:
    """The key saved answers are filed under: the intent text, the training and the relevant objects."""
    from gift.study.stages import digest

    return digest({"intent": intent, "train": sorted(train), "relevant": sorted(relevant)})


def load_answers(path: Path, key: str) -> dict[str, dict]:
    """``{test object: answer dict}`` saved under ``key`` in ``path`` ({} when there is none)."""
    if not path.exists():
        return {}
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        return dict(doc["scenes"].get(key, {}).get("answers", {}))
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
        raise GiftError(f"cannot read the saved answers {path}: {type(e).__name__}: {e}; move it aside or pass "
                        f"--answers FILE") from None


def save_answer(path: Path, key: str, context: dict, answer) -> None:
    """Add one answer under ``key`` (atomically; other scenes' answers are kept)."""
    doc = {"format": 1, "scenes": {}}
    if path.exists():
        doc = json.loads(path.read_text(encoding="utf-8"))
    entry = doc["scenes"].setdefault(key, {**context, "answers": {}})
    entry["answers"][answer.object] = {"relevant": answer.relevant, "plays": answer.plays}
    path.parent.mkdir(parents=True, exist_ok=True)
    serialization.write_json(path, doc, indent=2)


def _answer_text(a: dict) -> str:
    if a["relevant"] is None:
        return "don't know"
    return ("yes" if a["relevant"] else "no") + (f", plays {a['plays']}" if a.get("plays") else "")


def _ask_on_terminal(args: argparse.Namespace, scores, test: Sequence[ObjectSpec], threshold, rescore=None):
    """Ask on stderr/stdin until ``args.ask`` objects of the scene are answered; every answer is saved.
    ``rescore``: the kernel's re-scoring with answers (:func:`gift.core.queries.kernel_rescorer`), or None."""
    from gift.core.queries import Answer, QueryProblem, ask, parse_reply

    path = _answers_path(args)
    key = answers_key(args.intent, args.train, args.relevant)
    context = {"intent": args.intent, "train": sorted(args.train), "relevant": sorted(args.relevant)}
    saved = load_answers(path, key)
    known = [Answer(name, d.get("relevant"), d.get("plays")) for name, d in saved.items() if name in scores.test]
    new = max(0, args.ask - len(known))
    descriptions = {o.name: o.description for o in test}
    goal = f'the goal "{args.intent}"' if args.intent else "the goal"
    count = {"asked": 0}

    def answer(name: str):
        count["asked"] += 1
        desc = f" ({descriptions[name]})" if descriptions.get(name) else ""
        err = sys.stderr
        err.write(f"\nquestion {count['asked']} of {new} ({args.policy}): is \"{name}\"{desc} part of {goal}?\n"
                  f"  answer y (yes), n (no), ? (don't know), or the training object it plays: "
                  f"{', '.join(scores.train)}\n")
        while True:
            err.write("> ")
            err.flush()
            line = sys.stdin.readline()
            if not line:
                raise GiftError(f"no answer on stdin for {name!r}; the {count['asked'] - 1} answer(s) given so far "
                                f"are saved in {path}")
            try:
                a = parse_reply(name, line.strip(), scores)
            except GiftError as e:
                err.write(f"  not understood: {e}\n")
                continue
            save_answer(path, key, context, a)
            return a

    if known:
        sys.stderr.write(f"using {len(known)} saved answer(s) from {path}\n")
    problem = QueryProblem.of(scores, threshold, abstain=args.abstain, rescore=rescore)
    return ask(problem, args.policy, answer, new, answers=known)
