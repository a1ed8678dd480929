"""Run: .venv/bin/python scripts/category_ladder_probe.py gift-dev tests/kernels/data/lm_dev_suite.yaml

Development-suite probe (gift-dev, lm-dev only; gift-paper is not run). Question: when the inferred goal is
weak, do *several* names for what the demonstrated objects share, at different breadths (narrow, middle,
broad), contain a category that ranks the test objects well? If one of them does, two answers from the
human could pick it (queries rule 3); if their average does, no answer is needed.

Inputs per intent come from the committed inferred-intent run (docs/results/data/front_half/<suite>-inferred.json):
the relevant training objects inferred from the demonstrations and Call 1's goal. The suite's labels are
read only to score the test objects (AUC), as in every probe. LM-only test AUC per intent; the current
category's AUC is recomputed the same way for comparison. Prints one JSON line per intent and a summary.

The committed log (docs/results/data/front_half/category_ladder_probe.log) is of the first version, whose
worked examples named two rungs differently ("cleaning supplies", "small loose objects"); they were renamed
when the ladder went into gift-prob (a test keeps every example's words out of the suites' goals), and the
script now asks gift-prob's own prompt (gift_kernels.prompts.ladder_messages).
"""
import json
import sys
from pathlib import Path

import numpy as np
from gift_kernels import prompts, schemas
from gift_kernels.lm_kernels import GiftProbKernel, _zscore
from gift_llm import get_default_lm
from gift_llm.structured import ask_dict

import gift
from gift.core.data import Intent
from gift.core.metrics import roc_auc

LEVELS = prompts.LADDER_LEVELS


def main(suites):
    lm = get_default_lm()
    k = GiftProbKernel(lm=lm, combine="none")
    rows = []
    for name in suites:
        suite = gift.load_suite(name)
        tag = Path(name).stem.replace("_suite", "").replace("_", "-") if name.endswith(".yaml") else name
        saved = json.loads(Path(f"docs/results/data/front_half/{tag}-inferred.json").read_text())["kernels"]["gift-prob"]["intents"]
        for spec in suite.intents:
            rec = saved[spec.id]
            handled = list(rec["relevant"]["names"])
            alone = [t for t in spec.train_objects if t not in handled]
            test = suite.specs(spec.test_objects)
            labels = np.array([t.relevant for t in spec.test])
            intent = Intent(text=rec["intent_text"], source="inferred")
            cur = rec["details"]["category"]
            ans = ask_dict(lm, prompts.ladder_messages(handled, alone), temperature=0.0, max_tokens=80,
                           json_schema=schemas.ladder_schema(LEVELS), required_keys=LEVELS)
            cats = {lv: prompts.parse_category(ans[lv]) or ans[lv] for lv in LEVELS}
            lo = {"current": k.log_odds(test, intent, [cur] * len(test))}
            for lv in LEVELS:
                lo[lv] = k.log_odds(test, intent, [cats[lv]] * len(test))
            lo["mean3"] = np.mean([_zscore(lo[lv]) for lv in LEVELS], axis=0)
            lo["mean4"] = np.mean([_zscore(lo[v]) for v in ("current",) + LEVELS], axis=0)
            row = {"suite": tag, "intent": spec.id, "handled": handled, "current": cur, **cats,
                   **{f"auc_{v}": round(float(roc_auc(s, labels)), 3) for v, s in lo.items()}}
            rows.append(row)
            print(json.dumps(row), flush=True)
    out = Path("out/category_ladder_probe.json")
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(rows, indent=1))
    for tag in sorted({r["suite"] for r in rows}):
        rs = [r for r in rows if r["suite"] == tag]
        keys = [k for k in rs[0] if k.startswith("auc_")]
        summary = {k: round(float(np.mean([r[k] for r in rs])), 3) for k in keys}
        summary["auc_best_level"] = round(float(np.mean([max(r[f"auc_{lv}"] for lv in LEVELS) for r in rs])), 3)
        print(tag, json.dumps(summary))


if __name__ == "__main__":
    main(sys.argv[1:] or ["gift-dev", "tests/kernels/data/lm_dev_suite.yaml"])
