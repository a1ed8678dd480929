"""Probe (issue 16, not built in): a logistic calibration of gift-prob's two terms fitted on inferred dev intents.

Reads the front-half runs (``docs/results/data/front_half/*.json``, ``gift evaluate-alignment --kernels
gift-prob``): per object the LM log-odds and the MiniLM term gift-prob recorded (``details["terms"]``).
Fits one logistic model on the pooled test and training objects of the ``--fit`` runs (standardised
features, a weak Gaussian prior), then scores every run two ways, cut at 1/2: ``pooled`` (that model
alone) and ``pooled+intent`` (updated per intent with its relevant training objects: a MAP fit under the
pooled model as prior, as ``calibration="pooled"`` does). Prints the pooled F1 per run; compare with the
default's train-calibrated F1 in docs/results/front_half.md. Offline, no LM, no MiniLM.

    .venv/bin/python scripts/inferred_calibration_probe.py [--fit gift-dev-inferred lm-dev-inferred]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from gift.core.metrics import binary_metrics
from gift.study.sweeps import recorded_suite

sys.path.insert(0, str(Path(__file__).resolve().parent))
from gift_prob_study import fit_logistic

DATA = Path(__file__).resolve().parents[1] / "docs" / "results" / "data" / "front_half"
RUNS = ("gift-dev-inferred", "gift-dev-ground-truth", "lm-dev-inferred", "lm-dev-ground-truth",
        "gift-paper-inferred", "gift-paper-ground-truth")


def load(name: str) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Per intent: test features ``[n, 2]``, training features ``[m, 2]``, test labels, relevant training mask."""
    res = json.loads((DATA / f"{name}.json").read_text())
    suite = recorded_suite(res, f"{name}.json")
    out = []
    for iid, rec in res["kernels"]["gift-prob"]["intents"].items():
        t = rec["details"]["terms"]
        out.append((np.c_[t["lm"]["test"], t["language"]["test"]], np.c_[t["lm"]["train"], t["language"]["train"]],
                    np.array([x.relevant for x in suite.intent(iid).test]),
                    np.array(rec["scores"]["loo_labels"], dtype=bool)))
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fit", nargs="+", default=["gift-dev-inferred"], choices=RUNS)
    args = p.parse_args(argv)
    runs = {name: load(name) for name in RUNS}
    X = np.vstack([np.vstack([a, b]) for name in args.fit for a, b, _, _ in runs[name]])
    Y = np.concatenate([np.r_[y, rel] for name in args.fit for _, _, y, rel in runs[name]]).astype(float)
    mu, sd = X.mean(axis=0), X.std(axis=0)
    w0 = fit_logistic((X - mu) / sd, Y, prior_sd=10.0)
    print(f"fitted on {', '.join(args.fit)}: coefficients (LM, MiniLM, intercept) {np.round(w0, 2).tolist()}")
    print("| run | pooled | pooled+intent |\n|---|---|---|")
    for name, rows in runs.items():
        f1 = {}
        for update in (False, True):
            preds, truth = [], []
            for xt, xr, y, rel in rows:
                w = w0
                if update and rel.any() and (~rel).any():
                    w = fit_logistic((xr - mu) / sd, rel.astype(float), prior_mean=w0, prior_sd=1.0)
                z = np.c_[(xt - mu) / sd, np.ones(len(xt))] @ w
                preds.append(z >= 0.0)
                truth.append(y)
            f1[update] = binary_metrics(np.concatenate(preds), np.concatenate(truth)).f1
        print(f"| {name} | {f1[False]:.3f} | {f1[True]:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
