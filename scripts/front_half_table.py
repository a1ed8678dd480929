"""Per-intent Markdown tables of the front half from ``gift evaluate-alignment --out`` results (issue 16).

For each result file: per intent, the relevant training objects the run used (and whether they match the
suite's), the intent text, its MiniLM cosine to the suite's true text (the paper's sanity check; inferred
runs only), gift-prob's category, its F1 with the train-calibrated and the oracle cut and its AUC, and the
best label-free surface baseline's train-calibrated F1; then the pooled rows per kernel.

    python scripts/front_half_table.py out/r16b/gift-paper-inferred.json out/r16b/gift-paper-ground-truth.json

With ``--pool``: one table of every kernel's F1 pooled over all the files' intents together (true positives,
false positives and false negatives summed over every test object), per cut, and each file's commit.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gift.study.sweeps import recorded_suite

TC, OR = "train-calibrated", "oracle"


def table(path: str, extra: Sequence[str] = ()) -> str:
    """``extra``: results of the same suite and intent source whose other kernels join the table."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, str(path))
    kernels = dict(res["kernels"])
    for e in extra:
        more = json.loads(Path(e).read_text(encoding="utf-8"))
        if (more["suite"], more["intent_source"]) != (res["suite"], res["intent_source"]):
            raise SystemExit(f"{e}: another suite or intent source than {path}")
        kernels.update({k: v for k, v in more["kernels"].items() if not k.startswith("gift-prob")})
    gp = next(k for k in kernels if k.startswith("gift-prob"))
    base = [k for k in kernels if not k.startswith(("gift", "lm-"))]
    inferred = res["intent_source"] == "inferred"
    cos = {}
    if inferred:
        from gift_kernels.language import LanguageKernel

        for iid, rec in kernels[gp]["intents"].items():
            cos[iid] = float(LanguageKernel.text_cosine([rec["intent_text"]], suite.intent(iid).text)[0])
    lines = [f"`{res['suite']}`, {res['intent_source']} intents ({Path(path).name}):", "",
             "| intent | relevant training objects used | intent text | cosine to the true text | category | "
             "gift-prob F1 (oracle cut) | AUC | best baseline F1 |", "|---|---|---|---|---|---|---|---|"]
    wins = 0
    for iid, rec in kernels[gp]["intents"].items():
        spec = suite.intent(iid)
        used = rec["relevant"]["names"]
        ok = "" if set(used) == set(spec.relevant_train) else f" (suite: {', '.join(spec.relevant_train)})"
        f1 = rec["metrics"][TC]["all"]["f1"]
        best = max((kernels[b]["intents"][iid]["metrics"][TC]["all"]["f1"], b) for b in base
                   if iid in kernels[b]["intents"])
        wins += f1 > best[0]
        text = rec["intent_text"] if inferred else "(true)"
        cosine = f"{cos[iid]:.2f}" if inferred else "–"
        category = (rec.get("details") or {}).get("category", "")
        lines.append(f"| `{iid}` | {', '.join(used)}{ok} | {text} | {cosine} | {category} | "
                     f"{f1:.2f} ({rec['metrics'][OR]['all']['f1']:.2f}) | {rec['metrics'][TC]['all']['auc']:.2f} | "
                     f"{best[0]:.2f} ({best[1]}) |")
    lines += ["", f"gift-prob above the best baseline on {wins} of {len(kernels[gp]['intents'])} intents"
              + (f"; mean cosine to the true text {np.mean(list(cos.values())):.2f}" if cos else "") + ".", "",
              "| kernel | F1 train-calibrated | F1 oracle cut | AUC (mean over intents) |", "|---|---|---|---|"]
    for k, v in kernels.items():
        o = v["overall"]
        auc = np.nanmean([r["metrics"][TC]["all"]["auc"] if r["metrics"][TC]["all"]["auc"] is not None else np.nan
                          for r in v["intents"].values()])
        lines.append(f"| {k} | {o[TC]['all']['f1']:.3f} | {o[OR]['all']['f1']:.3f} | {auc:.3f} |")
    return "\n".join(lines)


def pooled(paths: Sequence[str]) -> str:
    """Markdown: per kernel present in every file, F1 with each cut pooled over all the files' intents, from the
    ``overall`` counts of ``all`` (so each test object counts once, whatever its suite)."""
    runs = [json.loads(Path(p).read_text(encoding="utf-8")) for p in paths]
    kernels = [k for k in runs[0]["kernels"] if all(k in r["kernels"] for r in runs)]
    lines = ["| kernel | " + " | ".join(f"F1 {c} (pooled)" for c in (TC, OR)) + " | intents |",
             "|---|" + "---|" * 3]
    for k in kernels:
        cells = []
        for cut in (TC, OR):
            tp = fp = fn = 0
            for r in runs:
                a = r["kernels"][k]["overall"][cut]["all"]
                tp, fp, fn = tp + a["tp"], fp + a["fp"], fn + a["fn"]
            cells.append(f"{2 * tp / (2 * tp + fp + fn):.3f}" if tp else "0.000")
        n = sum(len(r["kernels"][k]["intents"]) for r in runs)
        lines.append(f"| {k} | " + " | ".join(cells) + f" | {n} |")
    lines.append("")
    lines += [f"- `{Path(p).name}`: {r['suite']}, {r['intent_source']}, commit "
              f"`{r['manifest']['git']['commit'][:7]}`{' (dirty)' if r['manifest']['git']['dirty'] else ''}"
              for p, r in zip(paths, runs)]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="+")
    p.add_argument("--with", dest="extra", nargs="*", default=[],
                   help="results of the same suite and intent source whose baseline kernels join the table")
    p.add_argument("--pool", action="store_true", help="one table of F1 pooled over all the files' intents")
    args = p.parse_args(argv)
    print(pooled(args.results) if args.pool else "\n\n".join(table(r, args.extra) for r in args.results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
