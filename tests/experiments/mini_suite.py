"""The reduced suite of the experiment tests: the ``valuables`` intent of gift-paper with 8 of its test
objects. Shared by test_reproduce.py and test_viewing_browser.py, whose runs then ask the LM the same
questions (the second is served by the session's LM cache when both run)."""

from __future__ import annotations

import yaml

import gift

N_TEST = 8


def mini_suite(path):
    """The `valuables` intent of gift-paper with 8 of its test objects (4 relevant, 4 not, confounds first)."""
    suite = gift.load_suite("gift-paper")
    spec = suite.intent("valuables")
    rel = [t for t in spec.test if t.relevant][: N_TEST // 2]
    irr = sorted((t for t in spec.test if not t.relevant), key=lambda t: not t.confounds)[: N_TEST // 2]
    names = list(spec.train_objects) + [t.object for t in rel + irr]
    doc = {"suite": "mini-valuables",
           "objects": {n: {"description": suite.objects[n].description,
                           "appearance": {"shape": suite.objects[n].appearance.shape,
                                          "size": list(suite.objects[n].appearance.size),
                                          "color": list(suite.objects[n].appearance.color)}} for n in names},
           "intents": [{"id": "valuables", "task": spec.task, "text": spec.text,
                        "train_objects": list(spec.train_objects), "relevant_train": list(spec.relevant_train),
                        "test": [{"object": t.object, "relevant": t.relevant, "confounds": list(t.confounds)}
                                 for t in rel + irr]}]}
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path
