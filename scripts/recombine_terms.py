"""Re-score saved gift-prob runs under other ways of combining its two terms, without the LM.

A ``gift evaluate-alignment --out`` result keeps, per intent, gift-prob's LM term (the log-odds, or with the
ladder the mixed z-scores) for every test and held-out training object. The MiniLM term is cheap to recompute.
This rebuilds each scene's relevance with the kernel's own code (``GiftProbKernel._embed_scores`` and
``_combine``) under each variant of the options that act *after* the LM (``embed_text``, ``weight``,
``weighting``, ``embed_reference``, ``standardize``, ``combine``, ``veto``), places the train-calibrated cut with
the core (``AlignmentScores.with_relevance``), and prints pooled F1 (train-calibrated and oracle cut), AUC and how many
distractors named like the goal's class (``lang`` confounds) were aligned.

The variant ``default`` is the run's own options, identified by reproducing its saved decisions to 1e-5 (the script
stops when none does: the file was made by other code, or its terms are not the kernel's); the other variants are
applied on top of it.

    python scripts/recombine_terms.py docs/results/data/front_half/gift-dev6-inferred.json \
        --variant embed_text=description --variant weight=0.25 --out table.md

``--queries 0,1,2,4`` adds F1 after that many questions per intent (``--policy``, default ``uncertainty``),
answered from the suite's labels on the re-scored scenes (issue 20's measurement, without the LM).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from oracle_gap import f1, pick_kernel  # noqa: E402  (this directory's script)

from gift.core.alignment import AlignmentScores, oracle_cut  # noqa: E402
from gift.core.metrics import binary_metrics, roc_auc  # noqa: E402
from gift.study.sweeps import recorded_suite  # noqa: E402

AFTER_LM = {"embed_text": str, "weight": float, "weighting": str, "embed_reference": str, "standardize": str,
            "combine": str, "veto": str}


def parse_variant(text: str) -> tuple[str, dict]:
    """``"key=value,key=value"`` (or ``"default"``) -> ``(label, kwargs)`` of options that act after the LM."""
    if text == "default":
        return text, {}
    out = {}
    for part in text.split(","):
        key, sep, value = part.partition("=")
        if not sep or key not in AFTER_LM:
            raise SystemExit(f"--variant {text!r}: each part is key=value with key one of {sorted(AFTER_LM)} "
                             f"(options that act after the LM), got {part!r}")
        out[key] = AFTER_LM[key](value)
    return text, out


def base_options(kernel_name: str) -> dict:
    """The options of a kernel spec ``"gift-prob:a=b,c=d"`` that this script can rebuild (others are LM-side)."""
    opts = {}
    for part in filter(None, kernel_name.partition(":")[2].split(",")):
        key, _, value = part.partition("=")
        if key in AFTER_LM:
            opts[key] = AFTER_LM[key](value)
    return opts


def _relevance(opts: dict, lo: np.ndarray, test: list, train: list, rel: np.ndarray) -> np.ndarray:
    """gift-prob's relevance ``[n_test + n_train]`` from its LM term ``lo`` under the after-LM options ``opts``."""
    from gift_kernels.lm_kernels import GiftProbKernel, _sigmoid

    k = GiftProbKernel(**opts)
    if k.combine == "none":
        return _sigmoid(lo)
    emb = np.concatenate([k._embed_scores(test, train, rel, False), k._embed_scores(train, train, rel, True)])
    return _sigmoid(k._combine(lo, emb, rel, len(test))[0])


#: What "gift-prob" has meant after the LM: the current defaults; before ``embed_reference`` became ``"prototype"``
#: (2026-12-07, docs/results/front_half.md, section 44) ``"contrastive"``; before the default of ``embed_text``
#: became ``"description"`` (section 19) also ``"name+description"``. A run's options are identified by
#: reproducing its saved decisions.
RUN_DEFAULTS = ({}, {"embed_reference": "contrastive"},
                {"embed_reference": "contrastive", "embed_text": "name+description"})


def rescore(path: str, variants: list[tuple[str, dict]], kernel: str | None = None) -> dict[str, dict]:
    """Per variant: pooled counts ``tp, fp, fn`` (train-calibrated and oracle), per-intent AUCs and aligned
    ``lang`` distractors, for one result file. ``default`` is the run's own options: the first of
    :data:`RUN_DEFAULTS` (over the options in the kernel's name) that reproduces every saved decision to 1e-5;
    the other variants are applied on top of it."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, path)
    kname = pick_kernel(res, path, kernel)
    intents = res["kernels"][kname]["intents"]
    scenes = []
    for iid, rec in intents.items():
        sc, det = rec["scores"], rec["details"]
        if "terms" not in det:
            raise SystemExit(f"{path}: intent {iid!r} has no saved terms (a run older than the terms record)")
        scores = AlignmentScores.from_dict(sc)
        objs = suite.objects
        test, train = [objs[n] for n in sc["test"]], [objs[n] for n in sc["train"]]
        rel = np.asarray(scores.relevant_mask, dtype=bool)
        items = {t.object: t for t in suite.intent(iid).test}
        y = np.array([items[n].relevant for n in sc["test"]], dtype=bool)
        named = np.array(["lang" in items[n].confounds and not items[n].relevant for n in sc["test"]])
        lo = np.asarray(det["terms"]["lm"]["test"] + det["terms"]["lm"]["train"], dtype=float)
        scenes.append((iid, scores, test, train, rel, y, named, lo, np.asarray(sc["decision"], dtype=float)))
    base, worst = None, []
    for guess in RUN_DEFAULTS:
        opts = {**guess, **base_options(kname)}
        rels = [_relevance(opts, lo, t, tr, rel) for _, _, t, tr, rel, _, _, lo, _ in scenes]
        dev = max((float(np.abs(p[: len(sc[2])] - sc[8]).max(initial=0.0)), sc[0]) for p, sc in zip(rels, scenes))
        if dev[0] <= 1e-5:
            base, base_rel = opts, dict(zip((sc[0] for sc in scenes), rels))
            break
        worst.append(dev)
    if base is None:
        raise SystemExit(f"{path}: no known set of gift-prob options reproduces the saved decisions (largest "
                         f"difference {min(worst)[0]:.2e}, intent {min(worst)[1]!r}); this file was not made by "
                         f"this code's gift-prob")
    out = {label: {"tc": np.zeros(3), "oracle": np.zeros(3), "auc": [], "lang": [0, 0], "options": {**base, **o},
                   "intents": {}, "views": {}} for label, o in variants}
    for iid, scores, test, train, rel, y, named, lo, _ in scenes:
        for label, opts in variants:
            p = base_rel[iid] if not opts else _relevance({**base, **opts}, lo, test, train, rel)
            view = scores.with_relevance(p[: len(test)], p[len(test):])
            pred = view.predicted_relevant(view.threshold("train-calibrated")[0])
            o = out[label]
            o["views"][iid] = (view, dict(zip(view.test, y.tolist())))
            for key, predicted in (("tc", pred), ("oracle", p[: len(test)] >= oracle_cut(p[: len(test)], y))):
                m = binary_metrics(predicted, y)
                o[key] += (m.tp, m.fp, m.fn)
                if key == "tc":
                    o["intents"][iid] = float(m.f1)
            if y.any() and (~y).any():
                o["auc"].append(roc_auc(p[: len(test)], y))
            o["lang"][0] += int((pred & named).sum())
            o["lang"][1] += int(named.sum())
    return out


def after_queries(per: dict[str, dict], variant: str, ks: list[int], policy: str = "uncertainty") -> np.ndarray:
    """Pooled counts ``[len(ks), 3]`` (tp, fp, fn) after ``k`` questions per intent chosen by ``policy`` and
    answered from the suite's labels (``gift.core.queries``, its default rules: answers fix the objects they are
    about, the cut stays), on the re-scored scenes of one variant. ``random`` uses seed 0 only."""
    from gift.core.queries import QueryProblem, asking, labels_answerer

    counts = np.zeros((len(ks), 3))
    for view, labels in per[variant]["views"].values():
        y = np.array([labels[t] for t in view.test], dtype=bool)
        # one session of max(ks) questions: the state after k of them (the last when every object was asked)
        states = list(asking(QueryProblem.of(view, "train-calibrated"), policy, labels_answerer(labels), max(ks),
                             seed=0))
        for i, k in enumerate(ks):
            m = binary_metrics(np.asarray(states[min(k, len(states) - 1)].predicted, dtype=bool), y)
            counts[i] += (m.tp, m.fp, m.fn)
    return counts


def queries_table(rows: dict[str, dict[str, dict]], variants: list[str], ks: list[int], policy: str) -> str:
    """Train-calibrated F1 after k questions per intent, per file and variant, and pooled over the files."""
    lines = ["| file | variant | " + " | ".join(f"{k} q" for k in ks) + " |", "|" + "---|" * (len(ks) + 2)]
    pooled = {v: np.zeros((len(ks), 3)) for v in variants}
    for path, per in rows.items():
        for v in variants:
            c = after_queries(per, v, ks, policy)
            pooled[v] += c
            lines.append(f"| {Path(path).name} | {v} | " + " | ".join(f"{f1(r):.3f}" for r in c) + " |")
    if len(rows) > 1:
        lines += [f"| **pooled** | {v} | " + " | ".join(f"{f1(r):.3f}" for r in pooled[v]) + " |" for v in variants]
    return "\n".join(lines) + (f"\n\nF1 with the train-calibrated cut after k `{policy}` questions per intent, "
                               "answered from the suite's labels (answers fix their objects; the cut stays).\n")


def table(rows: dict[str, dict[str, dict]], variants: list[str]) -> str:
    head = "| file | " + " | ".join(variants) + " |"
    lines = [head, "|" + "---|" * (len(variants) + 1)]
    pooled = {v: {"tc": np.zeros(3), "oracle": np.zeros(3), "lang": [0, 0]} for v in variants}
    for path, per in rows.items():
        cells = []
        for v in variants:
            o = per[v]
            cells.append(f"{f1(o['tc']):.3f} / {f1(o['oracle']):.3f} / {np.mean(o['auc']):.3f} "
                         f"({o['lang'][0]}/{o['lang'][1]})")
            pooled[v]["tc"] += o["tc"]
            pooled[v]["oracle"] += o["oracle"]
            pooled[v]["lang"] = [a + b for a, b in zip(pooled[v]["lang"], o["lang"])]
        lines.append(f"| {Path(path).name} | " + " | ".join(cells) + " |")
    if len(rows) > 1:
        lines.append("| **pooled** | " + " | ".join(
            f"{f1(pooled[v]['tc']):.3f} / {f1(pooled[v]['oracle']):.3f} / - "
            f"({pooled[v]['lang'][0]}/{pooled[v]['lang'][1]})" for v in variants) + " |")
    return "\n".join(lines) + ("\n\nEach cell: train-calibrated F1 / oracle-cut F1 / mean AUC (aligned named-alike "
                               "distractors / all of them), pooled over the file's test objects.\n")


def per_intent_table(path: str, per: dict[str, dict], variants: list[str]) -> str:
    """Train-calibrated F1 per intent and variant, next to the surface kernels' recorded F1 in the same file."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    surface = [k for k in ("language", "vision") if k in res["kernels"]]
    lines = [f"{Path(path).name}", "", "| intent | " + " | ".join(variants + surface) + " |",
             "|" + "---|" * (len(variants) + len(surface) + 1)]
    for iid in per[variants[0]]["intents"]:
        base = [res["kernels"][k]["intents"][iid]["metrics"]["train-calibrated"]["all"]["f1"] for k in surface]
        lines.append(f"| {iid} | " + " | ".join(f"{per[v]['intents'][iid]:.2f}" for v in variants) + " | "
                     + " | ".join(f"{b:.2f}" for b in base) + " |")
    return "\n".join(lines) + "\n\n"


def provenance(paths: list[str]) -> str:
    """What made the table: this checkout's commit, and per file the run's commit, suite and model file hashes."""
    from gift.core.provenance import git_commit

    here = git_commit() or {}
    lines = [f"Re-scored by `scripts/recombine_terms.py` at commit `{str(here.get('commit', '?'))[:7]}`"
             f"{' (dirty)' if here.get('dirty') else ''}; each file's run:", ""]
    for path in paths:
        m = json.loads(Path(path).read_text(encoding="utf-8")).get("manifest", {})
        git, lm = m.get("git") or {}, m.get("lm") or {}
        lines.append(f"- {Path(path).name}: commit `{str(git.get('commit', '?'))[:7]}`"
                     f"{' (dirty)' if git.get('dirty') else ''}, suite sha256 "
                     f"`{str((m.get('suite') or {}).get('sha256', '?'))[:12]}`, LM `{lm.get('identity', '?')}` "
                     f"(model sha256 `{str(lm.get('model_sha256', '?'))[:12]}`)")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+", help="gift evaluate-alignment --out JSON files with a gift-prob kernel")
    ap.add_argument("--variant", action="append", default=[],
                    help="options acting after the LM, e.g. embed_text=description or weight=0.25,combine=language "
                         "(repeatable; 'default' is always included)")
    ap.add_argument("--kernel", help="comma-separated kernel names; the first one in each file is read "
                                     "(default: the file's first gift-prob* kernel)")
    ap.add_argument("--per-intent", action="store_true",
                    help="also print each file's train-calibrated F1 per intent, with the surface kernels' F1")
    ap.add_argument("--queries", help="comma-separated numbers of questions per intent, e.g. 0,1,2,4: also print "
                                      "F1 after that many questions, per variant (offline, from the saved scores)")
    ap.add_argument("--policy", default="uncertainty", help="query policy of --queries (default: uncertainty)")
    ap.add_argument("--out", help="also write the table (Markdown) here")
    args = ap.parse_args(argv)
    ks: list[int] = []
    if args.queries:
        try:
            ks = [int(k) for k in args.queries.split(",") if k.strip()]
        except ValueError:
            raise SystemExit(f"--queries: comma-separated whole numbers, got {args.queries!r}") from None
        if not ks or min(ks) < 0:
            raise SystemExit(f"--queries: comma-separated whole numbers >= 0, got {args.queries!r}")
    variants = [parse_variant("default")] + [parse_variant(v) for v in args.variant if v != "default"]
    rows = {p: rescore(p, variants, args.kernel) for p in args.files}
    text = table(rows, [label for label, _ in variants])
    if args.per_intent:
        text += "\n" + "".join(per_intent_table(p, per, [label for label, _ in variants]) for p, per in rows.items())
    if args.queries:
        text += "\n" + queries_table(rows, [label for label, _ in variants], ks, args.policy)
    text += "\n" + provenance(args.files)
    sys.stdout.write(text)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
