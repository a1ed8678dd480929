"""Probe (issue 20, not built): would the human's answers help more if they re-named the category ladder?

For each inferred intent of a saved ``gift evaluate-alignment`` run of the default ``gift-prob`` (with the
ladder), the two test objects nearest the kernel's cut are "asked" (answered from the suite's labels). The
ladder is then named again from the demonstrated objects plus the objects answered "yes" (and the
left-alone ones plus those answered "no"), every test object is asked about the new rungs, and the LM term
is rebuilt: the mean of the z-scored log-odds under the goal's category and the new rungs. Printed per
intent and pooled: the LM-only AUC over the *unasked* test objects, before and after, and the rungs.

This costs one ladder call and three yes/no questions per test object per intent on the embedded model.

    python scripts/answers_rename_ladder_probe.py docs/results/data/front_half/ladder-boundary-gift-dev-inferred.json
"""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

import numpy as np

from gift.core.data import Intent
from gift.core.metrics import roc_auc
from gift.study.sweeps import recorded_suite

log = logging.getLogger("answers_rename_ladder_probe")


def zscore(v: np.ndarray) -> np.ndarray:
    sd = v.std()
    return (v - v.mean()) / sd if sd > 1e-9 else v - v.mean()


def probe(path: str, kernel, questions: int = 2) -> list[dict]:
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, str(path))
    rows = []
    for intent_id, rec in res["kernels"]["gift-prob"]["intents"].items():
        ladder = rec["details"].get("ladder")
        if not ladder:
            continue
        s = rec["scores"]
        test, train = list(s["test"]), list(s["train"])
        n = len(test)
        truth = set(suite.intent(intent_id).relevant_test)
        labels = np.array([t in truth for t in test])
        cut = float(rec["thresholds"]["train-calibrated"]["cut"]) if "train-calibrated" in rec["thresholds"] else 0.5
        decision = np.asarray(s["decision"], dtype=float)
        asked = list(np.argsort(np.abs(decision - cut))[:questions])
        rel = np.asarray(s["relevant_mask"], dtype=bool)
        handled = [t for t, r in zip(train, rel) if r] + [test[i] for i in asked if labels[i]]
        alone = [t for t, r in zip(train, rel) if not r] + [test[i] for i in asked if not labels[i]]
        rungs = kernel.ladder(handled, alone)
        goal = np.asarray(ladder["goal"], dtype=float)[:n]
        old = np.mean([zscore(goal)] + [zscore(np.asarray(t["test"], dtype=float)) for t in ladder["terms"]], axis=0)
        intent = Intent(text=rec["intent_text"], source="inferred")
        objs = suite.specs(test)
        new_terms = [kernel.log_odds(objs, intent, [r] * n) for r in rungs]
        new = np.mean([zscore(goal)] + [zscore(v) for v in new_terms], axis=0) if new_terms else old
        keep = np.ones(n, dtype=bool)
        keep[asked] = False
        row = {"suite": suite.name, "intent": intent_id, "asked": [test[i] for i in asked],
               "answers": [bool(labels[i]) for i in asked], "old_rungs": ladder["categories"], "new_rungs": list(rungs),
               "auc_before": roc_auc(old[keep], labels[keep]), "auc_after": roc_auc(new[keep], labels[keep])}
        log.info("%s / %s: asked %s -> %s; rungs %s -> %s; LM-only AUC on the unasked %.3f -> %.3f", suite.name,
                 intent_id, row["asked"], row["answers"], row["old_rungs"], row["new_rungs"], row["auc_before"],
                 row["auc_after"])
        rows.append(row)
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="+")
    p.add_argument("--questions", type=int, default=2)
    p.add_argument("--out", default=None, help="JSON file for every row")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    from gift_kernels.lm_kernels import GiftProbKernel

    kernel = GiftProbKernel()
    rows = []
    for path in args.results:
        got = probe(path, kernel, args.questions)
        rows += got
        log.info("%s: mean LM-only AUC on the unasked objects %.3f -> %.3f (%d intents)", Path(path).name,
                 np.mean([r["auc_before"] for r in got]), np.mean([r["auc_after"] for r in got]), len(got))
    if args.out:
        Path(args.out).write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
