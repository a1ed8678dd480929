"""Probe (front_half.md, section 10): weight the ladder's categories by how well each separates the inferred
relevant training objects (leave-one-out AUC - 1/2, as gift-prob weights its terms) instead of averaging them.

Offline on the saved scores of ``gift evaluate-alignment --kernels gift-prob`` runs with the ladder; prints the
mean over intents of the LM-only test AUC: the goal's category alone, the plain mean (the kernel's), the
reliability-weighted mean, and the mean of the categories with a weight above 0.

    python scripts/ladder_rung_weights_probe.py docs/results/data/front_half/ladder-boundary-gift-dev-inferred.json
"""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

import numpy as np

from gift.core.metrics import roc_auc
from gift.study.sweeps import recorded_suite

log = logging.getLogger("ladder_rung_weights_probe")


def zscore(v: np.ndarray) -> np.ndarray:
    sd = v.std()
    return (v - v.mean()) / sd if sd > 1e-9 else v - v.mean()


def probe(path: str) -> dict[str, float]:
    """Mean over the run's intents of each rule's LM-only test AUC."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, str(path))
    out: dict[str, list[float]] = {"goal": [], "mean": [], "weighted": [], "kept": []}
    names = [k for k in res["kernels"] if k.split(":")[0] == "gift-prob"]
    if len(names) != 1:
        raise SystemExit(f"{path}: expected one gift-prob kernel (any options), found {sorted(res['kernels'])}")
    for intent_id, rec in res["kernels"][names[0]]["intents"].items():
        ladder = rec["details"].get("ladder")
        if not ladder:
            continue
        scores = rec["scores"]
        n = len(scores["test"])
        truth = set(suite.intent(intent_id).relevant_test)
        labels = [t in truth for t in scores["test"]]
        relevant = np.asarray(scores["relevant_mask"], dtype=bool)
        # [4, n_test + n_train] z-scored log-odds: the goal's category, then the rungs (training objects
        # leave-one-out, as the kernel stores them)
        views = [zscore(np.asarray(ladder["goal"], dtype=float))]
        views += [zscore(np.asarray(t["test"] + t["train"], dtype=float)) for t in ladder["terms"]]
        weights = np.array([max(roc_auc(v[n:], relevant) - 0.5, 0.0) if relevant.any() and (~relevant).any()
                            else 0.0 for v in views])
        mean = np.mean(views, axis=0)
        weighted = np.tensordot(weights, views, axes=1) / weights.sum() if weights.sum() > 0 else mean
        kept = np.mean([v for v, w in zip(views, weights) if w > 0] or views, axis=0)
        for key, v in (("goal", views[0]), ("mean", mean), ("weighted", weighted), ("kept", kept)):
            out[key].append(roc_auc(v[:n], labels))
    return {k: round(float(np.mean(v)), 3) for k, v in out.items()}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="+", help="gift evaluate-alignment --out files of gift-prob with the ladder")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    for path in args.results:
        log.info("%s %s", Path(path).name, probe(path))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
