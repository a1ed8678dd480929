"""Offline study of gift-prob's front half and cut, from ``gift evaluate-alignment`` results.

Input: JSON results of ``gift evaluate-alignment --kernels gift-prob:candidates=all:candidate_terms=true,...``
(one file per suite and intent source). Each intent's record holds, for every candidate goal (the intent's
text, its other motivations, the objects alone), the LM log-odds of the training objects (leave-one-out
categories) and of the test objects, and the MiniLM term. This script recombines them offline, with no LM
call, under several recipes and cut rules, and prints AUC and F1 per suite:

- candidate choice: ``text`` (the intent's own text), ``verified`` (the kernel's verifier: best leave-one-out
  AUC on the training objects, then margin), ``objects`` (the objects alone), ``best-test`` (the candidate
  with the best test AUC: an upper bound that reads test labels);
- combination: the kernel's (z-scores pooled over the intent's objects, reliability-weighted);
- cut: ``loo`` (the train-calibrated cut: best separation of the leave-one-out training scores), ``oracle``
  (best F1 on the test labels: an upper bound), ``pooled`` (a logistic calibration of the two terms fitted
  on other suites' test objects, cut at 1/2), ``pooled+intent`` (that calibration as a prior, updated with
  the intent's leave-one-out training objects; cut at 1/2).

    python scripts/gift_prob_study.py --fit out/r16/gift-dev-*.json out/r16/lm_dev_suite-*.json \\
        --report out/r16/gift-paper-*.json

``--fit`` files choose and fit; ``--report`` files are only scored (the held-apart suites).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from gift.core.alignment import best_separating_cut, oracle_cut
from gift.core.metrics import binary_metrics, roc_auc
from gift.study.sweeps import recorded_suite

KERNEL_PREFIX = "gift-prob"


def _zscore(x: np.ndarray) -> np.ndarray:
    sd = x.std()
    return (x - x.mean()) / sd if sd > 1e-9 else x - x.mean()


def load_rows(paths: Sequence[str]) -> list[dict[str, Any]]:
    """One row per (file, intent): labels, relevant training mask and every candidate's terms."""
    rows = []
    for path in paths:
        res = json.loads(Path(path).read_text())
        suite = recorded_suite(res, str(path))
        kname = next((k for k in res["kernels"] if k.startswith(KERNEL_PREFIX)), None)
        if kname is None:
            continue
        for iid, rec in res["kernels"][kname]["intents"].items():
            spec = suite.intent(iid)
            det = rec.get("details") or {}
            if "candidates" not in det:
                continue
            rel_names = set(rec["relevant"]["names"])
            rows.append({"file": Path(path).name, "suite": res["suite"], "source": res["intent_source"],
                         "intent": iid, "task": spec.task, "labels": np.array([t.relevant for t in spec.test]),
                         "rel": np.array([o in rel_names for o in spec.train_objects]),
                         "true_rel": np.array([o in spec.relevant_train for o in spec.train_objects]),
                         "train_names": list(spec.train_objects),
                         "language_test": np.array(det["terms"]["language"]["test"]),
                         "language_train": np.array(det["terms"]["language"]["train"]),
                         "candidates": det["candidates"]})
    return rows


def candidate(row: dict, rule: str) -> dict:
    cands = row["candidates"]
    if rule == "text":
        return cands[0]
    if rule == "verified":
        return next(c for c in cands if c["chosen"])
    if rule == "objects":
        return next((c for c in cands if c["goal"] is None), cands[0])
    if rule == "mean":  # every candidate's log-odds, z-scored over the intent's objects, averaged
        zs = [_zscore(np.concatenate([c["lm_test"], c["lm_train"]])) for c in cands]
        z, n = np.mean(zs, axis=0), len(cands[0]["lm_test"])
        return {"goal": "mean", "category": " | ".join(c["category"] for c in cands), "lm_test": z[:n],
                "lm_train": z[n:], "chosen": False}
    if rule == "agree":  # the first goal that names no training object the demonstrations left alone
        left = [o.lower() for o, r in zip(row["train_names"], row["rel"]) if not r]
        ok = [c for c in cands if c["goal"] is None or not any(o in c["goal"].lower() for o in left)]
        return ok[0] if ok else cands[-1]
    if rule == "best-test":
        return max(cands, key=lambda c: roc_auc(c["lm_test"], row["labels"]))
    raise ValueError(rule)


def combined(row: dict, cand: dict) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's combination: pooled z-scores, reliability-weighted (test scores, training scores)."""
    lo = np.concatenate([cand["lm_test"], cand["lm_train"]])
    emb = np.concatenate([row["language_test"], row["language_train"]])
    n = len(cand["lm_test"])
    terms = {"lm": _zscore(lo), "language": _zscore(emb)}
    w = {}
    for t, v in terms.items():
        auc = roc_auc(v[n:], row["rel"]) if row["rel"].any() and (~row["rel"]).any() else float("nan")
        w[t] = 0.5 * (max(auc - 0.5, 0.0) if not math.isnan(auc) else float("nan"))
    if any(math.isnan(v) for v in w.values()) or sum(w.values()) <= 0:
        w = {"lm": 0.5, "language": 0.5}
    z = sum(w[t] / sum(w.values()) * terms[t] for t in terms)
    return z[:n], z[n:]


def features(row: dict, cand: dict, part: str) -> np.ndarray:
    """``[n, 2]``: LM log-odds and MiniLM term of the test (``part="test"``) or training objects."""
    return np.stack([np.asarray(cand[f"lm_{part}"], float), row[f"language_{part}"]], axis=1)


def fit_logistic(X: np.ndarray, y: np.ndarray, prior_mean: np.ndarray | None = None, prior_sd: float = 1e3,
                 iters: int = 200) -> np.ndarray:
    """MAP logistic regression ``[w_1, w_2, b]`` with a Gaussian prior (Newton's method)."""
    Xb = np.hstack([X, np.ones((len(X), 1))])
    m = np.zeros(Xb.shape[1]) if prior_mean is None else np.asarray(prior_mean, float)
    w = m.copy()
    lam = 1.0 / prior_sd ** 2
    for _ in range(iters):
        p = 1.0 / (1.0 + np.exp(-(Xb @ w)))
        g = Xb.T @ (p - y) + lam * (w - m)
        H = Xb.T @ (Xb * (p * (1 - p))[:, None]) + lam * np.eye(len(w))
        step = np.linalg.solve(H, g)
        w -= step
        if np.abs(step).max() < 1e-8:
            break
    return w


def evaluate(rows: list[dict], rule: str, cut: str, pooled: np.ndarray | None = None, scale=None,
             prior_sd: float = 1.0) -> dict[str, Any]:
    preds, labels, aucs, per = [], [], [], {}
    for row in rows:
        cand = candidate(row, rule)
        y = row["labels"]
        if cut in ("pooled", "pooled+intent"):
            mu, sd = scale
            Xt = (features(row, cand, "test") - mu) / sd
            w = pooled
            if cut == "pooled+intent" and row["rel"].any() and (~row["rel"]).any():
                Xtr = (features(row, cand, "train") - mu) / sd
                w = fit_logistic(Xtr, row["rel"].astype(float), prior_mean=pooled, prior_sd=prior_sd)
            s = 1.0 / (1.0 + np.exp(-(np.hstack([Xt, np.ones((len(Xt), 1))]) @ w)))
            c = 0.5
        else:
            s, s_train = combined(row, cand)
            if cut == "oracle":
                c = oracle_cut(s, y)
            else:
                pos, neg = s_train[row["rel"]], s_train[~row["rel"]]
                c = best_separating_cut(pos, neg) if pos.size and neg.size else float(np.median(s))
        p = s >= c
        preds.append(p)
        labels.append(y)
        auc = roc_auc(s, y)
        aucs.append(auc)
        per[f"{row['suite']}/{row['source']}/{row['intent']}"] = {"auc": auc, "f1": binary_metrics(p, y).f1,
                                                                  "category": cand["category"]}
    m = binary_metrics(np.concatenate(preds), np.concatenate(labels))
    return {"f1": m.f1, "precision": m.precision, "recall": m.recall, "auc": float(np.nanmean(aucs)), "per": per}


def pooled_fit(rows: list[dict], rule: str) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
    X = np.vstack([features(r, candidate(r, rule), "test") for r in rows])
    y = np.concatenate([r["labels"] for r in rows]).astype(float)
    mu, sd = X.mean(axis=0), X.std(axis=0)
    return fit_logistic((X - mu) / sd, y, prior_sd=10.0), (mu, sd)


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fit", nargs="+", required=True, help="results the recipes are chosen and fitted on")
    p.add_argument("--report", nargs="*", default=[], help="results only scored")
    p.add_argument("--per-intent", action="store_true")
    args = p.parse_args(argv)
    fit_rows = load_rows(args.fit)
    report_rows = load_rows(args.report)
    out = []
    for rule in ("text", "verified", "objects", "mean", "agree", "best-test"):
        pooled, scale = pooled_fit(fit_rows, rule)
        for cut in ("loo", "oracle", "pooled", "pooled+intent"):
            for name, rows in (("fit", fit_rows), ("report", report_rows)):
                for source in sorted({r["source"] for r in rows}):
                    sub = [r for r in rows if r["source"] == source]
                    if not sub:
                        continue
                    res = evaluate(sub, rule, cut, pooled, scale)
                    out.append((name, source, rule, cut, res))
    print("| set | intents | candidate | cut | AUC | F1 | P | R |\n|---|---|---|---|---|---|---|---|")
    for name, source, rule, cut, res in out:
        print(f"| {name} | {source} | {rule} | {cut} | {res['auc']:.3f} | {res['f1']:.3f} | {res['precision']:.2f} | "
              f"{res['recall']:.2f} |")
    if args.per_intent:
        for name, source, rule, cut, res in out:
            if cut == "loo":
                for k, v in res["per"].items():
                    print(f"{name} {rule} {k}: AUC {v['auc']:.2f} F1 {v['f1']:.2f} [{v['category']}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
