"""Does the gap between the named and the unnamed yes/no question point at wrong decisions? (issue 20 probe)

    .venv/bin/python scripts/name_gap_probe.py docs/results/data/front_half/gift-dev13-inferred.json \\
        docs/results/data/front_half/gift-dev15-inferred.json

With ``ask_text="both"`` ``gift-prob`` asks every yes/no question twice, with the object's name and description
and with its description alone, and averages the log-odds. A distractor *named* like the class should get "yes"
from the first and "no" from the second; if so, the gap (named minus unnamed log-odds, averaged over the
categories the kernel kept, by their check weights) would be a query policy's cue. For each saved
``evaluate-alignment`` JSON (its ``gift-prob`` decisions, cut, categories and inferred intents) this asks the same
questions again (answered from the LM cache when they were asked before; else by the LM) and counts, per intent,
how many of the first k objects each ranking would ask about were decided wrong. Logs the counts; nothing is
written.
"""

from __future__ import annotations

import argparse
import json
import logging
from collections import defaultdict

import numpy as np

log = logging.getLogger("name_gap_probe")


def rows_of(path: str, kernel) -> list[dict]:
    import gift
    from gift_kernels import prompts

    d = json.loads(open(path, encoding="utf-8").read())
    suite = gift.load_suite(d["suite"])
    specs = {s.id: s for s in suite.intents}
    out = []
    for iid, it in d["kernels"]["gift-prob"]["intents"].items():
        spec = specs[iid]
        labels = {t.object: t.relevant for t in spec.test}
        det = it["details"]
        lad = det.get("ladder") or {}
        cats = [det.get("category")] + list(lad.get("categories") or [])
        w = np.asarray((lad.get("check") or {}).get("weights") or [1.0] * len(cats), dtype=float)
        if w.size != len(cats) or w.sum() <= 0:
            w = np.ones(len(cats))
        goal = it["intent_text"]
        cut = float(it["thresholds"]["train-calibrated"]["cut"])
        for o in suite.specs(spec.test_objects):
            lo = {text: np.array([kernel._ask(prompts.relevance_messages(o, goal, kernel.template,
                                                                          kernel.use_descriptions, c, text))
                                  for c in cats]) for text in prompts.OBJECT_TEXT}
            gap = float(np.sum(w * (lo["name+description"] - lo["description"])) / w.sum())
            decision = float(it["objects"][o.name]["decision"])
            out.append({"suite": d["suite"], "intent": iid, "object": o.name, "relevant": bool(labels[o.name]),
                        "predicted": decision >= cut, "distance": abs(decision - cut), "gap": gap})
    return out


def wrong_among_first(rows: list[dict], key, k: int) -> tuple[int, int]:
    """``(wrong, asked)``: per intent the ``k`` objects with the smallest ``key``, how many were decided wrong."""
    by = defaultdict(list)
    for r in rows:
        by[(r["suite"], r["intent"])].append(r)
    chosen = [r for rs in by.values() for r in sorted(rs, key=key)[:k]]
    return sum(r["predicted"] != r["relevant"] for r in chosen), len(chosen)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+", help="saved evaluate-alignment JSON files with a gift-prob kernel")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    from gift.study.components import Components

    kernel = Components().kernel("gift-prob")
    rows = [r for path in args.runs for r in rows_of(path, kernel)]
    log.info("%d test objects, %d decided wrong", len(rows), sum(r["predicted"] != r["relevant"] for r in rows))
    rankings = {"nearest the cut (uncertainty)": lambda r: r["distance"],
                "largest gap against the decision": lambda r: -(r["gap"] if r["predicted"] else -r["gap"]),
                "largest |gap|": lambda r: -abs(r["gap"])}
    for name, key in rankings.items():
        log.info("%-36s first 1: %d of %d wrong; first 2: %d of %d wrong", name, *wrong_among_first(rows, key, 1),
                 *wrong_among_first(rows, key, 2))
    for pred, rel, label in ((True, False, "false positives"), (True, True, "true positives"),
                             (False, True, "false negatives"), (False, False, "true negatives")):
        g = [r["gap"] for r in rows if r["predicted"] == pred and r["relevant"] == rel]
        log.info("mean gap of the %-15s %6.2f (%d objects)", label, float(np.mean(g)) if g else float("nan"), len(g))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
