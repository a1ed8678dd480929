"""Probe (issue 20, not built in): do answers help more as exemplars of gift-prob's MiniLM term than as cut evidence?

For each intent of ``gift evaluate-alignment --kernels gift-prob`` results (the front-half runs in
``docs/results/data/front_half/``), the uncertainty policy asks k questions (the unanswered test object
nearest the cut), answered from the suite's labels.

- ``cut-only``: the kernel's scores stay; answers join the evidence of the train-calibrated cut (the
  widest-gap best separating cut of the leave-one-out training scores and the answered objects, averaged
  with 1/2 as gift-prob's prior cut); answered objects are fixed to their answer. This is close to, not
  the same as, gift's rule (``gift.core.queries``: the best cut *nearest* the cut without answers), so its
  numbers differ a little from docs/results/queries.md; both arms use the same rule, which is what the
  comparison needs.
- ``exemplars``: also re-ranks. A "yes" joins the relevant exemplars and a "no" the others in the
  contrastive MiniLM term (largest cosine to a relevant exemplar minus largest cosine to another), the
  reliability weights are re-estimated with the answered objects as evidence and both terms re-z-scored;
  the LM log-odds are kept (no LM call).

Offline (MiniLM only). Prints the pooled F1 per results file for k = 0, 2, 4. The k = 0 column recombines
the saved terms and can differ slightly from the kernel's own run.

    .venv/bin/python scripts/answer_exemplars_probe.py [RESULTS.json ...]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
from gift_kernels.lm_kernels import _sigmoid, _zscore, separation_weight

import gift
from gift.core.alignment import best_separating_cut
from gift.core.metrics import binary_metrics
from gift.study.sweeps import recorded_suite

DATA = Path(__file__).resolve().parents[1] / "docs" / "results" / "data" / "front_half"
FILES = ("gift-dev-inferred", "lm-dev-inferred", "gift-dev-ground-truth", "lm-dev-ground-truth",
         "gift-paper-inferred", "gift-paper-ground-truth")
PRIOR_CUT, PRIOR_WEIGHT = 0.5, 0.5


def rescore(lo: np.ndarray, sim: np.ndarray, pos: list[int], neg: list[int], evidence: list[int],
            labels: np.ndarray) -> np.ndarray:
    """Decision scores ``[N]`` of test + training objects: the LM log-odds ``lo`` ``[N]`` and the contrastive
    MiniLM term of the exemplar indices ``pos`` / ``neg`` (``sim`` ``[N, N]`` cosines; an object is never its own
    exemplar), z-scored and weighted by how well each separates ``labels`` at the ``evidence`` indices."""
    emb = np.zeros(len(lo))
    for i in range(len(lo)):
        p, q = [j for j in pos if j != i], [j for j in neg if j != i]
        emb[i] = (sim[i, p].max() if p else 0.0) - (sim[i, q].max() if q else 0.0)
    terms = {"lm": _zscore(lo), "language": _zscore(emb)}
    w = {t: 0.5 * separation_weight(v[evidence], labels) for t, v in terms.items()}
    if any(math.isnan(v) for v in w.values()) or sum(w.values()) <= 0:
        w = {"lm": 0.5, "language": 0.5}
    s = sum(w[t] / sum(w.values()) * terms[t] for t in terms)
    return _sigmoid(s)


def pooled_f1(path: Path, k: int, mode: str, language) -> float:
    res = json.loads(path.read_text())
    suite = recorded_suite(res, str(path))
    preds, truth = [], []
    for iid, rec in res["kernels"]["gift-prob"]["intents"].items():
        spec, sc, terms = suite.intent(iid), rec["scores"], rec["details"]["terms"]
        n, m = len(sc["test"]), len(sc["train"])
        objs = suite.specs(list(sc["test"]) + list(sc["train"]))
        sim = np.asarray(language.similarity(objs, objs), dtype=float)
        lo = np.r_[terms["lm"]["test"], terms["lm"]["train"]]
        y = np.array([t.relevant for t in spec.test])
        rel = np.array(sc["loo_labels"], dtype=bool)
        lonely = rel & (rel.sum() < 2)  # a relevant training object with no relevant partner: no LOO evidence
        answered: dict[int, bool] = {}
        for step in range(k + 1):
            evidence = [n + j for j in range(m) if not lonely[j]] + list(answered)
            labels = np.r_[rel[~lonely], list(answered.values())].astype(bool)
            if mode == "exemplars":
                pos = [n + j for j in range(m) if rel[j]] + [i for i, a in answered.items() if a]
                neg = [n + j for j in range(m) if not rel[j]] + [i for i, a in answered.items() if not a]
                d = rescore(lo, sim, pos, neg, evidence, labels)
            else:
                d = np.r_[sc["decision"], sc["loo_scores"]]
            p = d[[i for i, lab in zip(evidence, labels) if lab]]
            q = d[[i for i, lab in zip(evidence, labels) if not lab]]
            loo = best_separating_cut(p, q) if p.size and q.size else PRIOR_CUT
            cut = PRIOR_WEIGHT * PRIOR_CUT + (1 - PRIOR_WEIGHT) * loo
            unasked = [i for i in range(n) if i not in answered]
            if step == k or not unasked:
                break
            ask = min(unasked, key=lambda i: abs(d[i] - cut))
            answered[ask] = bool(y[ask])
        pred = d[:n] >= cut
        for i, a in answered.items():
            pred[i] = a
        preds.append(pred)
        truth.append(y)
    return binary_metrics(np.concatenate(preds), np.concatenate(truth)).f1


def main(argv: list[str]) -> int:
    paths = [Path(a) for a in argv] or [DATA / f"{f}.json" for f in FILES]
    language = gift.get_kernel("language", use_descriptions=True)
    print("| results | k | cut-only | exemplars |\n|---|---|---|---|")
    for path in paths:
        for k in (0, 2, 4):
            print(f"| {path.stem} | {k} | {pooled_f1(path, k, 'cut', language):.3f} | "
                  f"{pooled_f1(path, k, 'exemplars', language):.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
