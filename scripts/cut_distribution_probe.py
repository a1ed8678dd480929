"""Probe (front_half.md, section 12): place gift-prob's cut from the distribution of one intent's own scores
(Otsu's threshold) instead of at the scale's boundary 1/2.

Offline on the saved decision scores of ``gift evaluate-alignment`` runs (test objects) and the training
objects' leave-one-out scores; no label is read to place a cut. Prints the pooled F1 (subset "all") with the
cut at 1/2 (the default), C1 Otsu on the test and training scores, C2 the mean of C1 and 1/2, C3 Otsu on the
test scores alone, and the cut each run recorded.

    python scripts/cut_distribution_probe.py docs/results/data/front_half/rungs-both-gift-dev-inferred.json
"""

from __future__ import annotations

import argparse
import json
import logging
from collections.abc import Callable
from pathlib import Path

import numpy as np

from gift.core.metrics import binary_metrics
from gift.study.sweeps import recorded_suite

log = logging.getLogger("cut_distribution_probe")


def otsu(values: np.ndarray) -> float:
    """The cut between two sorted neighbours that maximises the between-class variance of ``values`` ``[n]``."""
    v = np.sort(np.asarray(values, dtype=float))
    best, best_var = 0.5, -1.0
    for i in range(1, v.size):
        lo, hi = v[:i], v[i:]
        var = (i / v.size) * (1 - i / v.size) * (lo.mean() - hi.mean()) ** 2
        if var > best_var:
            best, best_var = float((v[i - 1] + v[i]) / 2), var
    return best


RULES: dict[str, Callable[[np.ndarray, np.ndarray], float] | None] = {
    "boundary": lambda test, train: 0.5,
    "C1": lambda test, train: otsu(np.r_[test, train]),
    "C2": lambda test, train: (otsu(np.r_[test, train]) + 0.5) / 2,
    "C3": lambda test, train: otsu(test),
    "recorded": None,
}


def probe(path: str) -> dict[str, float]:
    """Pooled F1 of the run's gift-prob kernel under each rule of :data:`RULES`."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, str(path))
    by_id = {s.id: s for s in suite.intents}
    names = [k for k in res["kernels"] if k.split(":")[0] == "gift-prob"]
    if len(names) != 1:
        raise SystemExit(f"{path}: expected one gift-prob kernel (any options), found {sorted(res['kernels'])}")
    out = {}
    for rule, cut_of in RULES.items():
        predicted, labels = [], []
        for intent_id, rec in res["kernels"][names[0]]["intents"].items():
            spec = by_id[intent_id]
            test = np.array([rec["objects"][t.object]["decision"] for t in spec.test])
            train = np.asarray(rec["scores"]["loo_scores"] or [], dtype=float)
            cut = rec["thresholds"]["train-calibrated"]["cut"] if cut_of is None else cut_of(test, train)
            predicted.append(test >= cut)
            labels.append(np.array([t.relevant for t in spec.test]))
        out[rule] = round(binary_metrics(np.concatenate(predicted), np.concatenate(labels)).f1, 3)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="+", help="gift evaluate-alignment --out files with a gift-prob kernel")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    for path in args.results:
        log.info("%s %s", Path(path).name, probe(path))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
