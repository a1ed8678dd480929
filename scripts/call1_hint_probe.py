"""Dev-suite probe (gift-dev only): does Call 1 write better goals when it is told which training objects the
demonstrations single out (inferred from the demonstrations, never from the suite)? Compares, per intent, the
default Call 1 with one whose task context adds that evidence; gift-prob (default) scores the test objects
under each goal. Prints the goals, the intent cosine to the true text, AUC and F1 with the train-calibrated cut.

Run: .venv/bin/python scripts/call1_hint_probe.py gift-dev
"""

from __future__ import annotations

import json
import sys

import numpy as np

import gift
from gift.core.alignment import best_separating_cut
from gift.core.demonstrations import infer_relevant_objects
from gift.core.metrics import binary_metrics, roc_auc
from gift.study.chain import StudyConfig, get_training, intent_seeds
from gift.study.components import Components, build


def hint(relevant, others, mode: str) -> str:
    verb = "kept clear of" if mode == "passing" else "acted on"
    return (f" In the demonstrations the person {verb} these objects: {', '.join(relevant)}; "
            f"and treated these like the default robot: {', '.join(others) or 'none'}.")


def main(suite_name: str) -> int:
    from gift_kernels.language import LanguageKernel

    suite = gift.load_suite(suite_name)
    cfg = StudyConfig(suite=suite_name, intent_source="inferred", sanity_reps=0)
    comp = Components(None, cfg.defaults)
    kernel = gift.get_kernel("gift-prob", lm=comp.lm)
    rows, pooled = [], {"default": ([], []), "hint": ([], [])}
    for spec in suite.intents:
        training = get_training(comp, cfg, suite, spec, intent_seeds(cfg, spec.id)["train"])
        est_rel = infer_relevant_objects(training.pairs(), spec.train_objects)
        rel = list(est_rel.relevant)
        others = [o for o in spec.train_objects if o not in rel]
        mode = "passing" if any(m == "passing" for m in est_rel.modes.values()) else "acting"
        task = comp.task(spec.task)
        estimator = build("intent_estimator", cfg.estimator, lm=comp.lm,
                          defaults={"seed": 0, "temperature": 0.0, "axes": False})
        test, train = suite.specs(spec.test_objects), suite.specs(spec.train_objects)
        labels = np.array([t.relevant for t in spec.test])
        for variant, ctx in (("default", task.context()), ("hint", task.context() + hint(rel, others, mode))):
            intent = estimator.estimate(training.pairs()[: cfg.sanity_pairs], task_context=ctx,
                                        objects=spec.train_objects)
            rs = kernel.score(test, train, intent, rel)
            mask = np.array([o.name in rel for o in train])
            cut = best_separating_cut(rs.train_loo[mask], rs.train_loo[~mask]) if mask.any() and (~mask).any() else 0.5
            pred = rs.relevance >= cut
            pooled[variant][0].append(pred)
            pooled[variant][1].append(labels)
            cos = float(LanguageKernel.text_cosine([intent.text], spec.text)[0])
            row = {"intent": spec.id, "variant": variant, "goal": intent.text, "category": rs.details.get("category"),
                   "cosine": round(cos, 3), "auc": round(roc_auc(rs.relevance, labels), 3),
                   "f1": round(binary_metrics(pred, labels).f1, 3)}
            rows.append(row)
            print(json.dumps(row), flush=True)
    for variant, (p, y) in pooled.items():
        r = [x for x in rows if x["variant"] == variant]
        print(variant, "pooled F1", round(binary_metrics(np.concatenate(p), np.concatenate(y)).f1, 3),
              "AUC", round(float(np.mean([x["auc"] for x in r])), 3),
              "cosine", round(float(np.mean([x["cosine"] for x in r])), 3))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1] if len(sys.argv) > 1 else "gift-dev"))
