"""In ``--intent-source inferred`` nothing from a suite's ``relevant_train`` reaches an estimator, a kernel, a
threshold or a prompt (issue 16): the same study on a copy of the suite whose ``relevant_train`` lists the
wrong training objects gives the same results, bit for bit. Ground-truth mode, the control, reads the labels,
so there the corrupted copy changes the results.

Real components: the Drake plant simulates the human, the embedded model infers the intent and answers
gift-prob's questions, MiniLM scores the language kernel. Reduced sizes (two training scenes of three
demonstrations). The simulated human does read the labels (they say what it demonstrates), so the
demonstrations are made once from the true suite and saved; both inferred runs load them
(``StudyConfig.demonstrations``), as a user's own demonstrations would be. The second run asks the LM
nothing new: identical prompts are answered by the LM cache, which is itself evidence that no prompt changed.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from gift.study.chain import StudyConfig

pytestmark = [pytest.mark.slow, pytest.mark.drake]

SUITE = Path(__file__).parents[1] / "executor" / "data" / "sweep_suite.yaml"
INTENT = "art_supplies"  # relevant_train: paintbrush, sketchbook
WRONG = ["magazine", "textbook"]
SIZES = StudyConfig(train_scenes=2, demos_per_scene=3, alternatives_per_scene=8, sanity_pairs=2)
#: fields that name the suite file or time the run, not results
VOLATILE = {"seconds", "manifest", "suite_path", "suite", "suite_sha256", "started", "finished"}


def corrupted_copy(tmp_path: Path) -> Path:
    data = yaml.safe_load(SUITE.read_text(encoding="utf-8"))
    spec = next(i for i in data["intents"] if i["id"] == INTENT)
    assert set(WRONG) <= set(spec["train_objects"]) and not set(WRONG) & set(spec["relevant_train"])
    spec["relevant_train"] = WRONG
    path = tmp_path / "sweep_suite_wrong_labels.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def without(value, keys):
    if isinstance(value, dict):
        return {k: without(v, keys) for k, v in value.items() if k not in keys}
    if isinstance(value, list):
        return [without(v, keys) for v in value]
    return value


def run(suite: Path, kernels: list[str], source: str, tmp_path: Path, tag: str, demos: Path | None = None) -> dict:
    import attrs

    from gift.study.sweeps import evaluate_alignment

    cfg = attrs.evolve(SIZES, demonstrations=str(demos) if demos else None)
    return evaluate_alignment(str(suite), kernels, intent_source=source, intents=[INTENT], executor="serial",
                              config=cfg, stages=tmp_path / f"stages-{tag}")


def saved_demonstrations(tmp_path: Path) -> Path:
    """The training set of INTENT simulated from the true suite (Drake), saved as a user's demonstrations."""
    import attrs

    import gift
    from gift.study.chain import get_training, intent_seeds
    from gift.study.components import Components
    from gift.study.scenes import save_training_set

    suite = gift.load_suite(str(SUITE))
    cfg = attrs.evolve(SIZES, suite=str(SUITE))
    ts = get_training(Components(None, cfg.defaults), cfg, suite, suite.intent(INTENT),
                      intent_seeds(cfg, INTENT)["train"])
    save_training_set(tmp_path / "demos" / INTENT, ts)
    return tmp_path / "demos"


def test_inferred_mode_never_reads_the_suites_relevant_training_objects(tmp_path):
    wrong, demos = corrupted_copy(tmp_path), saved_demonstrations(tmp_path)
    kernels = ["gift-prob", "language"]
    a = run(SUITE, kernels, "inferred", tmp_path, "a", demos)
    b = run(wrong, kernels, "inferred", tmp_path, "b", demos)
    for k in kernels:
        assert INTENT in a["kernels"][k]["intents"], a["kernels"][k].get("errors")
    rec = a["kernels"]["gift-prob"]["intents"][INTENT]
    # the kernel saw the objects the demonstrations single out, and named a category from them
    assert rec["relevant"]["source"] == "demonstrations", rec["relevant"]
    assert set(rec["relevant"]["names"]) == {"paintbrush", "sketchbook"}, rec["relevant"]
    assert rec["details"]["category"]
    assert json.dumps(without(a["kernels"], VOLATILE), sort_keys=True) == \
        json.dumps(without(b["kernels"], VOLATILE), sort_keys=True)
    usage = b["manifest"]["lm"]["usage"]
    assert usage["requests"] > 0 and usage["misses"] == 0, usage  # every prompt of the second run was asked before


def test_ground_truth_mode_reads_them_so_the_corruption_is_visible_there(tmp_path):
    wrong = corrupted_copy(tmp_path)
    a = run(SUITE, ["language"], "ground-truth", tmp_path, "a")["kernels"]["language"]["intents"][INTENT]
    b = run(wrong, ["language"], "ground-truth", tmp_path, "b")["kernels"]["language"]["intents"][INTENT]
    assert a["relevant"]["names"] == ["paintbrush", "sketchbook"] and b["relevant"]["names"] == WRONG
    assert json.dumps(without(a, VOLATILE), sort_keys=True) != json.dumps(without(b, VOLATILE), sort_keys=True)
