"""How much of the gap between the train-calibrated cut and the oracle cut any cut could close (issue 16, target 3).

The oracle cut is chosen per intent with the labels of the very objects it is scored on: an in-sample maximum.
For each ``gift evaluate-alignment --out`` result this prints, pooled over the suite's test objects, the F1 of
one relevance kernel (the first ``gift-prob`` kernel unless ``--kernel``) with

- its train-calibrated cut (label-free, as recorded in the file),
- a *leave-one-out* labelled cut: each test object decided by the F1-best cut of the other test objects of its
  intent and their labels (:func:`gift.core.alignment.leave_one_out_oracle`; every label but its own),
- a *half-split* labelled cut: the F1-best cut on a random half of each intent's test objects applied to the
  other half (mean over ``--splits`` splits; F1 on the held halves, against cut and oracle on the same halves),
- the oracle cut (in sample).

Offline, from the scores saved in the files; no LM or simulator runs.

    python scripts/oracle_gap.py docs/results/data/front_half/gift-dev5-inferred.json --out gap.md
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gift.core.alignment import leave_one_out_oracle, middle_f1_cut, oracle_cut
from gift.core.metrics import binary_metrics
from gift.study.sweeps import recorded_suite


def _counts(predicted: np.ndarray, labels: np.ndarray) -> np.ndarray:
    m = binary_metrics(predicted, labels)
    return np.array([m.tp, m.fp, m.fn])


def f1(c: np.ndarray) -> float:
    """F1 from pooled counts ``[tp, fp, fn]`` (0 without a true positive)."""
    return float(2 * c[0] / (2 * c[0] + c[1] + c[2])) if c[0] else 0.0


def pick_kernel(res: dict, path: str, kernel: str | None = None) -> str:
    """The kernel of a result file to read: the first of ``kernel`` (comma-separated names) that the file holds,
    else (``kernel`` None) its first ``gift-prob*`` kernel; a SystemExit naming the file's kernels otherwise."""
    prefer = [k for k in (kernel or "").split(",") if k]
    names = [k for k in prefer if k in res["kernels"]] or \
        ([] if prefer else [k for k in res["kernels"] if k.split(":")[0] == "gift-prob"])
    if not names:
        raise SystemExit(f"{path}: none of the kernels {prefer or ['gift-prob*']} among {sorted(res['kernels'])}")
    return names[0]


def intents_of(path: str, kernel: str | None = None) -> tuple[dict, str, list[tuple[str, np.ndarray, np.ndarray, float]]]:
    """``kernel``: comma-separated kernel names, the first one in the file is read (None: the first gift-prob*).
    The result file, the kernel read, and per intent ``(id, decision [n_test], labels [n_test], cut)`` with the
    recorded train-calibrated cut."""
    res = json.loads(Path(path).read_text(encoding="utf-8"))
    suite = recorded_suite(res, path)
    name = pick_kernel(res, path, kernel)
    rows = []
    for iid, rec in res["kernels"][name]["intents"].items():
        labels = {t.object: bool(t.relevant) for t in suite.intent(iid).test}
        scores = rec["scores"]
        decision = np.asarray(scores["decision"], dtype=float)
        missing = [t for t in scores["test"] if t not in labels]
        if missing:
            raise SystemExit(f"{path}: intent {iid!r}: test objects {missing} have no label in suite {res['suite']!r}")
        y = np.array([labels[t] for t in scores["test"]], dtype=bool)
        rows.append((iid, decision, y, float(rec["thresholds"]["train-calibrated"]["cut"])))
    return res, name, rows


def gap(rows: Sequence[tuple[str, np.ndarray, np.ndarray, float]], splits: int = 300, seed: int = 0) -> dict:
    """Pooled F1 of the train-calibrated cut, the leave-one-out labelled cut and the oracle cut; and, on random
    held halves, of the train-calibrated cut, the cut chosen on the other half, and the in-sample oracle."""
    tc, loo, orc = np.zeros(3), np.zeros(3), np.zeros(3)
    for _, d, y, cut in rows:
        tc += _counts(d >= cut, y)
        loo += _counts(leave_one_out_oracle(d, y), y)
        orc += _counts(d >= oracle_cut(d, y), y)
    rng = np.random.default_rng(seed)
    halves = np.zeros((splits, 3))
    for r in range(splits):
        h_tc, h_lab, h_or = np.zeros(3), np.zeros(3), np.zeros(3)
        for _, d, y, cut in rows:
            idx = rng.permutation(d.size)
            a, b = idx[: d.size // 2], idx[d.size // 2:]
            h_tc += _counts(d[b] >= cut, y[b])
            h_lab += _counts(d[b] >= middle_f1_cut(d[a], y[a]), y[b])
            h_or += _counts(d[b] >= oracle_cut(d[b], y[b]), y[b])
        halves[r] = (f1(h_tc), f1(h_lab), f1(h_or))
    mean = halves.mean(axis=0)
    return {"train_calibrated": f1(tc), "leave_one_out": f1(loo), "oracle": f1(orc),
            "half_train_calibrated": float(mean[0]), "half_labelled": float(mean[1]), "half_oracle": float(mean[2]),
            "intents": len(rows), "test_objects": int(sum(d.size for _, d, _, _ in rows))}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("results", nargs="+", help="gift evaluate-alignment --out JSON files")
    p.add_argument("--kernel", default=None, help="kernel names in order of preference, comma-separated (default: the first gift-prob*)")
    p.add_argument("--splits", type=int, default=300)
    p.add_argument("--out", default=None, help="also write the Markdown table here")
    args = p.parse_args(argv)
    lines = [("| suite | intents | test objects | train-calibrated | leave-one-out labelled cut | oracle cut | "
             "held half: train-calibrated / cut from the other half / oracle | file (commit) |"),
             "|---|---|---|---|---|---|---|---|"]
    for path in args.results:
        res, kernel, rows = intents_of(path, args.kernel)
        g = gap(rows, args.splits)
        commit = res.get("manifest", {}).get("git", {}).get("commit", "?")[:7]
        lines.append(f"| `{res['suite']}`, {res['intent_source']} (`{kernel}`) | {g['intents']} | {g['test_objects']} "
                     f"| {g['train_calibrated']:.3f} | {g['leave_one_out']:.3f} | {g['oracle']:.3f} | "
                     f"{g['half_train_calibrated']:.3f} / {g['half_labelled']:.3f} / {g['half_oracle']:.3f} | "
                     f"{Path(path).name} (`{commit}`) |")
    text = "\n".join(lines)
    sys.stdout.write(text + "\n")
    if args.out:
        Path(args.out).write_text(text + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
