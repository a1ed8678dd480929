"""Probe (front_half.md, section 28): three re-weightings of what gift-prob already computed, offline on saved runs.

Each saved ``gift evaluate-alignment`` run with gift-prob's ladder and ``check="fit"`` holds, per intent, the raw
log-odds of every checked category (``details.ladder``: the goal's category and each rung, test objects and the
training objects' leave-one-out scores), the check's in-sample AUCs, the MiniLM term and the decisions. This script
first recomputes the kernel's own decisions from them (it stops when one differs by more than 1e-6: the
recomputation is then not the kernel's) and then scores, with the train-calibrated cut the run used:

- ``size``: the categories the check keeps, weighed by the size principle of Bayesian concept learning, each by
  ``size ** -n`` (``n``: the demonstrated objects; ``size``: the category's share of the scene's test objects the
  LM says yes to, hard ``P(yes) > 1/2`` or soft mean ``P(yes)``; at least ``1 / n_test``), or the smallest alone;
- ``offset``: the cut moved by a fixed amount on the combined z-scale (one number for every intent);
- ``combine``: the LM and MiniLM terms combined otherwise than by the reliability-weighted mean;
- ``lm veto``: the default combination, but an object whose z-scored LM term is below a level is left out whatever
  the MiniLM term says (front_half.md, section 42: the look-alike distractors get in on the MiniLM term).

Prints pooled train-calibrated F1 per run for every variant, the mean, and wins / losses against the saved runs;
``--kinds`` prints instead, per run, how many test objects of each kind (members, distractors named like members,
ones that look like members, the others) the saved decisions let in and how many each term alone puts above its
scene's mean.

    python scripts/offline_recombine_probe.py [RUN.json:KERNEL ...]   # default: the used suites' latest runs
    python scripts/offline_recombine_probe.py --kinds gift-dev23-inferred.json:gift-prob
"""

from __future__ import annotations

import argparse
import json
import logging
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from gift.core.metrics import roc_auc
from gift.study.sweeps import recorded_suite

log = logging.getLogger("offline_recombine_probe")
ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "docs" / "results" / "data" / "front_half"
#: The latest saved inferred run of each suite a front-half or query choice was made on (gift-paper excluded),
#: with check="fit" and the ladder, and the kernel's name in it.
DEFAULT_RUNS = (
    "check-fit-gift-dev-inferred.json:gift-prob:check=fit", "check-fit-gift-dev2-inferred.json:gift-prob:check=fit",
    "gift-dev3-inferred.json:gift-prob:check=fit", "gift-dev5-inferred.json:gift-prob",
    "gift-dev6-inferred.json:gift-prob", "gift-dev7-inferred.json:gift-prob",
    "gift-dev8-inferred.json:gift-prob:ask_text=both", "check-margin-gift-dev9-inferred.json:gift-prob",
    "check-margin-gift-dev10-inferred.json:gift-prob", "check-margin-gift-dev11-inferred.json:gift-prob",
    "check-margin-gift-dev12-inferred.json:gift-prob", "check-margin-gift-dev13-inferred.json:gift-prob",
    "check-margin-lm-dev-inferred.json:gift-prob")


def zscore(v: np.ndarray) -> np.ndarray:
    sd = v.std()
    return (v - v.mean()) / sd if sd > 1e-9 else v - v.mean()


def sigmoid(v: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-v))


def reliability(t: np.ndarray, rel: np.ndarray, n_test: int) -> float:
    auc = roc_auc(t[n_test:], rel)
    return float("nan") if math.isnan(auc) else max(auc - 0.5, 0.0)


def combine_mean(lm: np.ndarray, emb: np.ndarray, rel: np.ndarray, n_test: int) -> np.ndarray:
    """gift-prob's combination: z-scores weighed by ``max(AUC - 1/2, 0)`` on the training objects (1/2 each when
    that is undefined or all zero)."""
    terms = [zscore(lm), zscore(emb)]
    w = [reliability(t, rel, n_test) * 0.5 for t in terms]
    if any(math.isnan(x) for x in w) or sum(w) <= 0:
        w = [0.5, 0.5]
    return (w[0] * terms[0] + w[1] * terms[1]) / sum(w)


def check_keep(aucs: list[float | None]) -> np.ndarray:
    """``check="fit"``: the categories at the best in-sample AUC (1 when one reaches it)."""
    a = np.array([np.nan if x is None else x for x in aucs], dtype=float)
    known = ~np.isnan(a)
    if not known.any():
        return np.ones(len(a))
    top = 1.0 if (a[known] >= 1 - 1e-12).any() else a[known].max()
    return (known & (np.nan_to_num(a, nan=-1.0) >= top - 1e-12)).astype(float)


def size_weights(mode: str) -> Callable[[np.ndarray, np.ndarray, int, int], np.ndarray]:
    """Weights of the kept categories by their size among the test objects (``views`` ``[k, n_test + n_train]``
    raw log-odds); ``mode``: ``hard``/``soft`` (``size ** -n``), ``hard-min``/``soft-min`` (the smallest alone)."""
    def weigh(keep: np.ndarray, views: np.ndarray, n_test: int, n_dem: int) -> np.ndarray:
        test = views[:, :n_test]
        size = sigmoid(test).mean(axis=1) if mode.startswith("soft") else (test > 0).mean(axis=1)
        size = np.clip(size, 1.0 / n_test, 1.0)
        if mode.endswith("min"):
            return keep * (size <= size[keep > 0].min() + 1e-12)
        return keep * size ** (-float(n_dem))
    return weigh


def scored(run: dict, suite, kernel: str, weigh=None, combine=combine_mean,
           offset: float = 0.0) -> tuple[int, int, int]:
    """Pooled (tp, fp, fn) of one run (scored on ``suite``, :func:`recorded_suite`) with the categories weighed by
    ``weigh`` (None: the saved weights), the terms combined by ``combine`` and the cut moved by ``offset`` on the
    z-scale."""
    tp = fp = fn = 0
    for intent_id, rec in run["kernels"][kernel]["intents"].items():
        labels = {t.object: t.relevant for t in suite.intent(intent_id).test}
        test, train = rec["scores"]["test"], rec["scores"]["train"]
        n = len(test)
        rel = np.array([t in set(rec["relevant"]["names"]) for t in train])
        det = rec["details"]
        lm = np.array(det["terms"]["lm"]["test"] + det["terms"]["lm"]["train"], dtype=float)
        lad = det.get("ladder")
        if lad is not None and "check" in lad:
            views = np.array([lad["goal"]] + [t["test"] + t["train"] for t in lad["terms"]], dtype=float)
            w = np.asarray(lad["check"]["weights"], dtype=float)
            if weigh is not None:
                new = weigh(check_keep(lad["check"]["in_sample_auc"]), views, n, int(rel.sum()))
                w = new if new.sum() > 0 else w
            mixed = np.tensordot(w, np.stack([zscore(v) for v in views]), axes=1) / w.sum()
            if weigh is None and not np.allclose(mixed, lm, atol=1e-6):
                raise SystemExit(f"{intent_id}: the saved LM term is not the checked categories' weighted mean")
            lm = mixed
        emb = np.array(det["terms"]["language"]["test"] + det["terms"]["language"]["train"], dtype=float)
        z = combine(lm, emb, rel, n)
        cut = rec["thresholds"]["train-calibrated"]["cut"]
        if weigh is None and combine is combine_mean:
            saved = np.array([rec["objects"][o]["decision"] for o in test])
            if not np.allclose(sigmoid(z[:n]), saved, atol=1e-6):
                raise SystemExit(f"{intent_id}: recomputed decisions differ from the saved ones")
        pred = z[:n] > math.log(cut / (1 - cut)) + offset
        y = np.array([labels[o] for o in test])
        tp += int((pred & y).sum())
        fp += int((pred & ~y).sum())
        fn += int((~pred & y).sum())
    return tp, fp, fn


KINDS = ("member", "named-alike", "look-alike", "other")


def kinds(run: dict, suite, kernel: str) -> dict[str, dict[str, int]]:
    """Per kind of test object (:data:`KINDS`; the suite's ``confounds``: ``lang`` named like a member, ``vis``
    looks like one): ``n``, ``in`` (the saved train-calibrated decision lets it in), ``lm`` and ``minilm`` (that
    term, z-scored over the intent's test and training objects, is above 0)."""
    out = {k: {"n": 0, "in": 0, "lm": 0, "minilm": 0} for k in KINDS}
    for intent_id, rec in run["kernels"][kernel]["intents"].items():
        test = rec["scores"]["test"]
        terms = rec["details"]["terms"]
        z = {t: zscore(np.array(terms[t]["test"] + terms[t]["train"], dtype=float))[: len(test)]
             for t in ("lm", "language")}
        cut = rec["thresholds"]["train-calibrated"]["cut"]
        for t in suite.intent(intent_id).test:
            kind = "member" if t.relevant else ("named-alike" if "lang" in t.confounds else
                                                "look-alike" if "vis" in t.confounds else "other")
            i = test.index(t.object)
            row = out[kind]
            row["n"] += 1
            row["in"] += int(rec["objects"][t.object]["decision"] > cut)
            row["lm"] += int(z["lm"][i] > 0)
            row["minilm"] += int(z["language"][i] > 0)
    return out


def lm_veto(level: float) -> Callable[[np.ndarray, np.ndarray, np.ndarray, int], np.ndarray]:
    """The default combination, with every object whose z-scored LM term is below ``level`` put below the cut."""
    def combine(lm: np.ndarray, emb: np.ndarray, rel: np.ndarray, n: int) -> np.ndarray:
        z = combine_mean(lm, emb, rel, n)
        return np.where(zscore(lm) < level, -np.inf, z)
    return combine


def f1(c: tuple[int, int, int]) -> float:
    tp, fp, fn = c
    return 2 * tp / (2 * tp + fp + fn) if tp else 0.0


def variants() -> dict[str, dict]:
    out: dict[str, dict] = {"saved": {}}
    for mode in ("hard", "soft", "hard-min", "soft-min"):
        out[f"size-{mode}"] = {"weigh": size_weights(mode)}
    for off in (-0.2, 0.1, 0.2, 0.3, 0.5):
        out[f"offset {off:+.1f}"] = {"offset": off}
    out["lm alone"] = {"combine": lambda lm, emb, rel, n: zscore(lm)}
    out["min of terms"] = {"combine": lambda lm, emb, rel, n: np.minimum(zscore(lm), zscore(emb))}
    out["mean - |diff|/4"] = {"combine": lambda lm, emb, rel, n: combine_mean(lm, emb, rel, n)
                              - 0.25 * np.abs(zscore(lm) - zscore(emb))}
    for level in (-1.0, -0.5, 0.0):
        out[f"lm veto {level:+.1f}"] = {"combine": lm_veto(level)}
    return out


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="*", default=list(DEFAULT_RUNS), help="RUN.json:KERNEL (relative to the data dir)")
    p.add_argument("--kinds", action="store_true", help="count the kinds of test object each run lets in")
    args = p.parse_args(argv)
    if args.kinds:
        counts = {}
        print("| run | " + " | ".join(f"{k}: in / LM / MiniLM above the mean" for k in KINDS) + " |")
        print("|---|" + "---|" * len(KINDS))
        for spec in args.runs:
            path, kernel = spec.split(":", 1)
            run = json.loads((DATA / path if not Path(path).is_absolute() else Path(path)).read_text(encoding="utf-8"))
            counts[path] = c = kinds(run, recorded_suite(run, path), kernel)
            print(f"| {Path(path).name} | " + " | ".join(f"{c[k]['in']} / {c[k]['lm']} / {c[k]['minilm']} of "
                                                          f"{c[k]['n']}" for k in KINDS) + " |")
        return counts
    table: dict[str, dict[str, float]] = {}
    for spec in args.runs:
        path, kernel = spec.split(":", 1)
        run = json.loads((DATA / path if not Path(path).is_absolute() else Path(path)).read_text(encoding="utf-8"))
        suite = recorded_suite(run, path)
        # one row per run (a suite's inferred and true-intent runs are two rows)
        row = f"{run['suite']} {run.get('intent_source', '')}".strip()
        table[row] = {name: f1(scored(run, suite, kernel, **opts)) for name, opts in variants().items()}
    names = list(variants())
    width = max(12, *(len(k) + 1 for k in table))
    print("run".ljust(width) + "".join(n.rjust(17) for n in names))
    for suite, row in table.items():
        print(suite.ljust(width) + "".join(f"{row[n]:17.3f}" for n in names))
    base = np.array([row["saved"] for row in table.values()])
    print("mean".ljust(width) + "".join(f"{np.mean([row[n] for row in table.values()]):17.3f}" for n in names))
    for n in names[1:]:
        v = np.array([row[n] for row in table.values()])
        print(f"{n}: better on {(v > base + 1e-9).sum()}, worse on {(v < base - 1e-9).sum()} of {len(v)} runs")
    return table


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO)
    main()
