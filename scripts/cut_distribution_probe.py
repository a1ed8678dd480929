"""Probe (front_half.md, section 12): place gift-prob's cut from the distribution of one intent's own scores
(Otsu's threshold) instead of at the scale's boundary 1/2.

Offline on the saved decision scores of ``gift evaluate-alignment`` runs (test objects) and the training
objects' leave-one-out scores; no label is read to place a cut. Prints the pooled F1 (subset "all") with the
cut at 1/2 (the default), C1 Otsu on the test and training scores, C2 the mean of C1 and 1/2, C3 Otsu on the
test scores alone, and the cut each run recorded.

    python scripts/cut_distribution_probe.py docs/results/data/front_half/rungs-both-gift-dev-inferred.json

``--overview`` (front_half.md, section 49) instead takes every run of ``scripts/results_overview.py`` but those of
the ``--skip`` suites (default ``gift-paper``), re-scores each at the current MiniLM reference (``recombine_terms.rescore`` with
``embed_reference="prototype"``, the kernel's own code on the saved LM terms) and prints, per intent source, the
mean over runs of each rule's pooled F1 and on how many runs it beats or loses to 1/2.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
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


def pooled_f1(scenes: list[tuple[np.ndarray, np.ndarray, np.ndarray, float]]) -> dict[str, float]:
    """Pooled F1 under each rule of :data:`RULES` over intents ``(test decisions [n], training leave-one-out
    scores [m], test labels [n], recorded cut)``."""
    out = {}
    for rule, cut_of in RULES.items():
        predicted = [test >= (cut if cut_of is None else cut_of(test, train)) for test, train, _, cut in scenes]
        out[rule] = round(binary_metrics(np.concatenate(predicted), np.concatenate([y for *_, y, _ in scenes])).f1, 3)
    return out


def probe(path: str) -> dict[str, float]:
    """Pooled F1 of the run's gift-prob kernel under each rule of :data:`RULES`."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, str(path))
    by_id = {s.id: s for s in suite.intents}
    names = [k for k in res["kernels"] if k.split(":")[0] == "gift-prob"]
    if len(names) != 1:
        raise SystemExit(f"{path}: expected one gift-prob kernel (any options), found {sorted(res['kernels'])}")
    scenes = []
    for intent_id, rec in res["kernels"][names[0]]["intents"].items():
        spec = by_id[intent_id]
        scenes.append((np.array([rec["objects"][t.object]["decision"] for t in spec.test]),
                       np.asarray(rec["scores"]["loo_scores"] or [], dtype=float),
                       np.array([t.relevant for t in spec.test]), rec["thresholds"]["train-calibrated"]["cut"]))
    return pooled_f1(scenes)


def probe_overview(skip: set[str]) -> dict[str, dict[str, list[float]]]:
    """Per intent source and rule, the pooled F1 of every run of the overview whose suite is not in ``skip``,
    re-scored at ``embed_reference="prototype"`` (the recorded cut there is the re-scored train-calibrated one)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from recombine_terms import rescore
    from results_overview import RUNS

    out: dict[str, dict[str, list[float]]] = {}
    for run in RUNS:
        if run.suite in skip:
            continue
        path = str(Path(__file__).resolve().parent.parent / "docs" / "results" / "data" / run.file)
        per = rescore(path, [("prototype", {"embed_reference": "prototype"})], run.kernel)["prototype"]
        scenes = []
        for view, labels in per["views"].values():
            scenes.append((np.asarray(view.decision, dtype=float), np.asarray(view.loo_scores, dtype=float),
                           np.array([labels[t] for t in view.test]), view.threshold("train-calibrated")[0]))
        f1s = pooled_f1(scenes)
        log.info("%s %s %s", run.suite, run.source, f1s)
        for rule, v in f1s.items():
            out.setdefault(run.source, {}).setdefault(rule, []).append(v)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results", nargs="*", help="gift evaluate-alignment --out files with a gift-prob kernel")
    p.add_argument("--overview", action="store_true",
                   help="every run of scripts/results_overview.py, re-scored at the prototype reference")
    p.add_argument("--skip", default="gift-paper", help="with --overview: suites left out (comma-separated)")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if args.overview:
        for source, rules in probe_overview(set(args.skip.split(","))).items():
            base = np.array(rules["boundary"])
            for rule, v in rules.items():
                a = np.array(v)
                log.info("%s %s: mean %.3f over %d runs, better than 1/2 on %d, worse on %d", source, rule,
                         a.mean(), a.size, int((a > base).sum()), int((a < base).sum()))
    elif not args.results:
        p.error("give result files or --overview")
    for path in args.results:
        log.info("%s %s", Path(path).name, probe(path))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
