"""Dev-suite probe (gift-dev, lm-dev only): can the embedded model place a test object with the training objects
the demonstrations singled out, without any goal text? LM-only test AUC per intent, two question forms.

Run: .venv/bin/python scripts/exemplar_probe.py gift-dev
"""
import json
import math
import sys

import numpy as np

import gift
from gift.core.data import Message
from gift.core.metrics import roc_auc
from gift_llm import get_default_lm

SYSTEM = "You answer questions about everyday objects with a single word."
FORMS = {
    "yes-no": ("A person doing a household task treated some objects specially and left the others alone.\n"
               "Treated specially: {a}.\nLeft alone: {b}.\n"
               "Would they treat a {name}{desc} specially too? Answer yes or no.", ["yes", "no"]),
    "a-b": ("Two groups of objects.\nGroup A: {a}.\nGroup B: {b}.\n"
            "Which group does a {name}{desc} fit better? Answer A or B.", ["A", "B"]),
}


def log_odds(lm, form, a, b, obj):
    text, choices = FORMS[form]
    desc = f" ({obj.description.strip()})" if obj.description.strip() else ""
    msgs = (Message("system", SYSTEM), Message("user", text.format(a=", ".join(a), b=", ".join(b), name=obj.name,
                                                                    desc=desc)))
    p = lm.choice_probabilities(msgs, choices)
    return math.log(max(p.get(choices[0], 0), 1e-12)) - math.log(max(p.get(choices[1], 0), 1e-12))


lm = get_default_lm()
suite = gift.load_suite(sys.argv[1] if len(sys.argv) > 1 else "gift-dev")
out = {}
for spec in suite.intents:
    a = list(spec.relevant_train)
    b = [t for t in spec.train_objects if t not in a]
    test = suite.specs(spec.test_objects)
    labels = [t.relevant for t in spec.test]
    for form in FORMS:
        lo = [log_odds(lm, form, a, b, o) for o in test]
        out.setdefault(form, {})[spec.id] = roc_auc(np.array(lo), labels)
        print(json.dumps({"intent": spec.id, "form": form, "auc": out[form][spec.id],
                          "lo": [round(x, 2) for x in lo]}), flush=True)
for form, d in out.items():
    print(form, round(float(np.mean(list(d.values()))), 3), {k: round(v, 2) for k, v in d.items()})
