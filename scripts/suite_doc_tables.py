"""Regenerate the gift-paper tables in docs/suites.md from the suite file (run after editing the suite):

    .venv/bin/python scripts/suite_doc_tables.py
"""

import re

import gift
s = gift.load_suite('gift-paper')
omega = {"water_sensitive":"ω1","paper_based":"ω2","art_supplies":"ω3a","reading_material":"ω3b","valuables":"ω4a","electronics":"ω4b"}
summ = ["| intent | paper | task | train (relevant) | test (relevant) | S_R | S_lang | S_vis | S_unk |",
        "|---|---|---|---|---|---|---|---|---|"]
for i in s.intents:
    sz = [len(i.subset(c)) for c in ("R","lang","vis","unk")]
    summ.append(f"| `{i.id}` | {omega[i.id]} | `{i.task}` | {len(i.train_objects)} ({len(i.relevant_train)}) | {len(i.test)} ({len(i.relevant_test)}) | " + " | ".join(str(x) if x else "–" for x in sz) + " |")
tab = []
for i in s.intents:
    tab.append(f"#### `{i.id}` — {omega[i.id]}: *{i.text}* (task `{i.task}`)\n")
    rel = ", ".join(i.relevant_train); irr = ", ".join(o for o in i.train_objects if o not in i.relevant_train)
    tab.append(f"Training objects: **relevant** {rel}; **irrelevant** {irr}.\n")
    tab.append("| test object | relevant | subsets |\n|---|---|---|")
    for t in i.test:
        sub = ", ".join("S_"+c for c in t.confounds) if t.confounds else "S_R"
        tab.append(f"| {t.object} | {'yes' if t.relevant else 'no'} | {sub} |")
    tab.append("")
p = __import__('pathlib').Path(__file__).resolve().parents[1] / 'docs' / 'suites.md'
d=open(p).read()
d=re.sub(r"\| intent \| paper \|.*?\n\n", "\n".join(summ)+"\n\n", d, count=1, flags=re.S)
head, rest = d.split("#### `water_sensitive`",1)
_, tail = rest.split("## Writing your own suite",1)
d = head + "\n".join(tab) + "\n## Writing your own suite" + tail
d = re.sub(r"a catalog of \d+ objects", f"a catalog of {len(s.objects)} objects", d)
open(p,'w').write(d)
