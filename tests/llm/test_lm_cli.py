"""``gift plugins`` and ``gift lm ...`` as a user runs them (separate processes, the real embedded model)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

GIFT = [str(Path(sys.executable).with_name("gift"))]


def _gift(*args, env=None, timeout=600):
    p = subprocess.run(GIFT + list(args), capture_output=True, text=True, timeout=timeout,
                       env={**os.environ, **(env or {})})
    assert p.returncode == 0, p.stderr[-3000:]
    return p.stdout


def test_gift_plugins_lists_the_lm_backends():
    out = json.loads(_gift("plugins", "--json", "--all"))
    by_kind = {(c["kind"], c["name"]): c for c in out["components"]}
    for name in ("llamacpp", "litellm", "transformers", "replay"):
        assert by_kind[("lm_backend", name)]["distribution"] == "gift-llm"
    assert ("command", "lm") in by_kind


@pytest.mark.slow
@pytest.mark.lm
def test_gift_lm_ask_answers_from_the_embedded_default_and_caches_across_processes(cache_root):
    env = {"GIFT_CACHE_DIR": str(cache_root)}
    q = "What is the capital of France? Reply with one word."
    first = json.loads(_gift("lm", "ask", q, "--json", "--max-tokens", "5", env=env))
    assert "paris" in first["text"].lower() and first["lm"].startswith("llamacpp:qwen2.5-coder-1.5b")
    assert first["stats"]["calls"] == 1 and first["stats"]["misses"] == 1
    second = json.loads(_gift("lm", "ask", q, "--json", "--max-tokens", "5", env=env))
    assert second["text"] == first["text"] and second["stats"]["calls"] == 0 and second["stats"]["hits"] == 1
    stats = json.loads(_gift("lm", "cache-stats", "--json", env=env))
    assert stats["entries"] == 1 and stats["path"].startswith(str(cache_root))
    assert _gift("lm", "install", env=env).strip().endswith("qwen2.5-coder-1.5b-instruct-q4_k_m.gguf")


def test_gift_lm_reports_errors_cleanly(tmp_path):
    p = subprocess.run(GIFT + ["lm", "ask", "hi", "--lm", "nosuchbackend:model"], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 1 and "unknown LM 'nosuchbackend:model'" in p.stderr and "Traceback" not in p.stderr
    p = subprocess.run(GIFT + ["lm", "ask", "hi", "--lm", f"replay:{tmp_path / 'missing.jsonl'}"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 1 and "does not exist" in p.stderr
