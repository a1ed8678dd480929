"""``scripts/front_half_table.py --pool``: F1 pooled over several result files counts every test object once."""

from __future__ import annotations

import json

import script_module  # this directory: scripts/ files as modules


def load_script():
    return script_module.load_script("front_half_table")


def result(suite: str, counts: dict[str, tuple[int, int, int]], n_intents: int, commit: str) -> dict:
    """A result file's shape as `gift evaluate-alignment --out` writes it; ``counts``: per kernel (tp, fp, fn)."""
    def overall(tp, fp, fn):
        return {cut: {"all": {"tp": tp, "fp": fp, "fn": fn}} for cut in ("train-calibrated", "oracle")}
    return {"suite": suite, "intent_source": "inferred",
            "manifest": {"git": {"commit": commit, "dirty": False}},
            "kernels": {k: {"overall": overall(*c), "intents": [{}] * n_intents} for k, c in counts.items()}}


def test_pooled_f1_sums_the_counts_over_files_and_keeps_only_kernels_every_file_has(tmp_path, capsys):
    a = tmp_path / "a.json"
    b = tmp_path / "b.json"
    a.write_text(json.dumps(result("s1", {"k": (9, 1, 0), "only-a": (1, 0, 0)}, 2, "a" * 40)))
    b.write_text(json.dumps(result("s2", {"k": (1, 0, 9)}, 3, "b" * 40)))
    mod = load_script()
    assert mod.main([str(a), str(b), "--pool"]) == 0
    out = capsys.readouterr().out
    # pooled: tp 10, fp 1, fn 9 -> 20 / 30; the per-file F1s (0.947, 0.182) average to 0.565 instead
    assert "| k | 0.667 | 0.667 | 5 |" in out
    assert "only-a" not in out
    assert "s1, inferred, commit `aaaaaaa`" in out and "s2, inferred, commit `bbbbbbb`" in out
