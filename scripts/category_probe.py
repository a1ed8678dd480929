"""Run: .venv/bin/python scripts/category_probe.py gift-dev

Dev-suite probe (gift-dev only): which category few-shot examples and which category source hold up when the
goal text is object-bound (as Call 1 of the 1.5B model often writes it)? LM-only test AUC per intent."""
import json, sys
import numpy as np
import gift
from gift.core.data import Intent
from gift.core.metrics import roc_auc
from gift_kernels import prompts
from gift_kernels.lm_kernels import GiftProbKernel
from gift_llm import get_default_lm

OLD = (("put the aquarium supplies on the shelf", ("aquarium net", "fish food flakes"), ("tripod", "kettle"), "aquarium supplies"),
       ("get the car cleaning things ready", ("car wax tin", "windshield squeegee"), ("toaster", "desk lamp"), "car cleaning things"),
       ("keep the toddler away from anything with small parts", ("bag of marbles", "box of push pins"), ("beach ball", "floor cushion"), "things with small parts"),
       ("get ready for the party", ("party hat", "confetti cannon"), ("tire gauge", "bath mat"), "party supplies"))
NEW = prompts.CATEGORY_EXAMPLES_WITH_OBJECTS
VERB = {"place_mug": "carry the mug around the {x}", "sweep_spill": "sweep the {x} away from the spill",
        "pack_backpack": "pick up the {x} and put it into the backpack", "store_drawer": "put the {x} in the drawer"}
lm = get_default_lm()
suite = gift.load_suite(sys.argv[1] if len(sys.argv) > 1 else "gift-dev")
rows = []
for spec in suite.intents:
    test = suite.specs(spec.test_objects)
    labels = [t.relevant for t in spec.test]
    handled = list(spec.relevant_train)
    alone = [t for t in spec.train_objects if t not in handled]
    goals = {"true": spec.text, **{f"bound{i}": VERB[spec.task].format(x=x) for i, x in enumerate(handled[:2])}}
    for exname, ex in (("old", OLD), ("new", NEW)):
        prompts.CATEGORY_EXAMPLES_WITH_OBJECTS = ex
        k = GiftProbKernel(lm=lm, combine="none")
        variants = [(g, goals[g], True) for g in goals] + [("objects", None, True)]
        for gname, goal, _ in variants:
            cat = k.category(goal, handled, alone)
            qtext = goal or cat
            lo = k.log_odds(test, Intent(text=qtext, source="inferred"), [cat] * len(test))
            auc = roc_auc(lo, labels)
            rows.append(dict(intent=spec.id, examples=exname, goal=gname, category=cat, auc=auc))
            print(json.dumps(rows[-1]), flush=True)
json.dump(rows, open(f"out/category_probe-{suite.name}.json", "w"), indent=1)
for exname in ("old", "new"):
    for g in ("true", "bound0", "bound1", "objects"):
        a = [r["auc"] for r in rows if r["examples"] == exname and r["goal"] == g]
        print(exname, g, round(float(np.mean(a)), 3))
