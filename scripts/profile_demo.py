"""Profile a cold ``gift demo``: where the time goes, with every LM call's prompt and answer tokens.

Every gift cache (LM answers, embeddings, renders, trajectory datasets) starts empty in a temporary
``GIFT_CACHE_DIR``; only the assembled embedded model is linked in (no 1 GB copy, no re-hash). The run
goes through the real ``gift demo`` command in this process, with timers wrapped around the functions
that do the work (Drake scenes, trajectories and IK, renders, EfficientNet and MiniLM, llama.cpp), and
prints a Markdown table (also written as JSON next to the demo's report).

Usage::

    .venv/bin/python scripts/profile_demo.py [--out DIR] [--cache DIR] [--pyinstrument] [-- DEMO ARGS...]

``--cache DIR`` reuses (or fills) that cache directory instead of a fresh one: run twice with the same
directory for a warm profile. ``--pyinstrument`` also writes a pyinstrument call tree (if installed).
Times are wall-clock seconds of this process; nested timers (IK inside trajectory generation, renders
inside the vision kernel) are reported inclusively.
"""

from __future__ import annotations

import argparse
import collections
import functools
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROWS: dict[str, list[float]] = collections.defaultdict(list)
CPU: dict[str, list[float]] = collections.defaultdict(list)  #: process CPU seconds (all threads) per row
LM_CALLS: list[dict] = []


def _timed(label: str, fn):
    @functools.wraps(fn)
    def wrapper(*a, **kw):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            return fn(*a, **kw)
        finally:
            ROWS[label].append(time.perf_counter() - t0)
            CPU[label].append(time.process_time() - c0)

    return wrapper


def _patch(obj, name: str, label: str) -> None:
    setattr(obj, name, _timed(label, getattr(obj, name)))


def _lm_kind(messages) -> str:
    """What an LM call is, from its system prompt (the prompts live in gift_kernels.prompts)."""
    from gift.core.data import as_messages
    from gift_kernels import prompts

    msgs = as_messages(messages)
    system = msgs[0].content if msgs and msgs[0].role == "system" else ""
    repair = sum(m.role == "assistant" for m in msgs)
    for text, kind in ((prompts.INTENT_SYSTEM, "Call 1 (motivations)"), (prompts.AXES_SYSTEM, "Call 2 (axes)"),
                       (prompts.CATEGORY_SYSTEM, "gift-prob category"),
                       (prompts.RELEVANCE_SYSTEM, "gift-prob yes/no"), (prompts.MAP_SYSTEM, "Call 3 (mapping)")):
        if system == text:
            if kind.startswith(("Call 1", "Call 2")) and repair:
                return f"{kind} repair {repair}"
            return kind
    return "other"


def _instrument() -> None:
    from gift_llm.backends import llamacpp

    orig_complete = llamacpp.LlamaCppLM.complete
    orig_choices = llamacpp.LlamaCppLM.choice_probabilities

    def complete(self, messages, **kw):
        t0, c0 = time.perf_counter(), time.process_time()
        out = orig_complete(self, messages, **kw)
        dt, cpu = time.perf_counter() - t0, time.process_time() - c0
        LM_CALLS.append({"kind": _lm_kind(messages), "method": "complete", "prompt_tokens": out.usage.prompt_tokens,
                         "reused_tokens": self.last_reused_tokens, "answer_tokens": out.usage.completion_tokens, "seconds": dt,
                         "cpu_s": cpu, "threads": self.last_threads, "json": kw.get("json_schema") is not None})
        return out

    def choice_probabilities(self, messages, choices):
        t0, c0 = time.perf_counter(), time.process_time()
        out = orig_choices(self, messages, choices)
        dt, cpu = time.perf_counter() - t0, time.process_time() - c0
        LM_CALLS.append({"kind": _lm_kind(messages), "method": "choice_probabilities",
                         "prompt_tokens": len(self._prompt_tokens(messages)), "reused_tokens": self.last_reused_tokens,
                         "answer_tokens": 0, "seconds": dt, "cpu_s": cpu,
                         "threads": self.last_threads, "json": False})
        return out

    llamacpp.LlamaCppLM.complete = complete
    llamacpp.LlamaCppLM.choice_probabilities = choice_probabilities
    _patch(llamacpp, "load_llama", "LM: load the GGUF")

    from gift_sim_drake import kinematics, motion, render, simulator

    _patch(simulator.DrakeSimulator, "make_scene", "Drake: make_scene (placement)")
    _patch(simulator.DrakeSimulator, "generate", "Drake: generate trajectories")
    _patch(simulator.DrakeSimulator, "features", "Drake: features")
    _patch(motion.MotionPlanner, "prepare", "  of which: MotionPlanner.prepare (IK per scene)")
    _patch(kinematics.ArmKinematics, "solve_pointing_down", "  of which: IK solves")
    _patch(render, "_draw", "Drake: render an object (3 views, uncached)")

    from gift_kernels import language, vision

    _patch(vision, "load_efficientnet", "vision: load EfficientNet-Lite0")
    _patch(vision, "image_features", "vision: EfficientNet forward")
    _patch(vision.VisionKernel, "render", "vision: renders (cache lookups included)")
    _patch(language, "load_minilm", "language: load MiniLM")
    _patch(language, "embed_texts", "language: embed_texts (cache lookups included)")


def _link_model(cache: Path) -> None:
    """``cache/models`` holds links to the verified embedded GGUF of the user's cache (and its marker)."""
    from gift_llm import embedded

    src = embedded.install()  # the verified file in the user's cache (GIFT_CACHE_DIR is not yet set)
    dest = cache / "models"
    dest.mkdir(parents=True, exist_ok=True)
    link = dest / src.name
    if not link.exists():
        link.symlink_to(src)
        shutil.copy(src.with_name(src.name + ".verified.json"), dest / (src.name + ".verified.json"))


def table(rows: dict[str, list[float]], calls: list[dict], total: float, cpu: dict[str, list[float]]) -> str:
    out = ["| where | calls | seconds | CPU seconds | share of the run |", "|---|---:|---:|---:|---:|"]
    for label, times in sorted(rows.items(), key=lambda kv: -sum(kv[1])):
        out.append(f"| {label} | {len(times)} | {sum(times):.1f} | {sum(cpu[label]):.1f} | "
                   f"{100 * sum(times) / total:.0f} % |")
    by_kind: dict[str, list[dict]] = collections.defaultdict(list)
    for c in calls:
        by_kind[c["kind"]].append(c)
    out += ["", "| LM call | calls | prompt tokens (sum) | of which reused from the KV cache | answer tokens (sum) "
                "| seconds | CPU seconds | s per call |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for kind, cs in sorted(by_kind.items(), key=lambda kv: -sum(c["seconds"] for c in kv[1])):
        s = sum(c["seconds"] for c in cs)
        out.append(f"| {kind} | {len(cs)} | {sum(c['prompt_tokens'] for c in cs)} | "
                   f"{sum(c['reused_tokens'] for c in cs)} | {sum(c['answer_tokens'] for c in cs)} | {s:.1f} | "
                   f"{sum(c['cpu_s'] for c in cs):.1f} | {s / len(cs):.2f} |")
    lm = sum(c["seconds"] for c in calls)
    out.append(f"| **all LM calls** | {len(calls)} | {sum(c['prompt_tokens'] for c in calls)} | "
               f"{sum(c['reused_tokens'] for c in calls)} | {sum(c['answer_tokens'] for c in calls)} | {lm:.1f} | "
               f"{sum(c['cpu_s'] for c in calls):.1f} | |")
    out.append(f"\nTotal wall time {total:.1f} s; LM calls {lm:.1f} s ({100 * lm / total:.0f} %).")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default=None, help="demo output directory (default: a temporary one)")
    p.add_argument("--cache", default=None, help="GIFT_CACHE_DIR to use (default: a fresh temporary one)")
    p.add_argument("--pyinstrument", action="store_true", help="also write a pyinstrument profile")
    p.add_argument("demo_args", nargs="*", help="extra arguments of `gift demo` (after --)")
    args = p.parse_args(argv)

    cache = Path(args.cache) if args.cache else Path(tempfile.mkdtemp(prefix="gift-profile-cache-"))
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="gift-profile-out-"))
    os.environ.pop("GIFT_LM_CACHE_URL", None)
    _link_model(cache)
    os.environ["GIFT_CACHE_DIR"] = str(cache)
    _instrument()

    profiler = None
    if args.pyinstrument:
        from pyinstrument import Profiler

        profiler = Profiler(interval=0.01)
        profiler.start()
    from gift.cli import main as gift_main

    t0 = time.perf_counter()
    cpu0 = time.process_time()
    code = gift_main(["demo", "--out", str(out), *args.demo_args])
    total, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    if profiler is not None:
        profiler.stop()
        (out / "profile.html").write_text(profiler.output_html())
        (out / "profile.txt").write_text(profiler.output_text(unicode=False, color=False, show_all=False))
    text = table(ROWS, LM_CALLS, total, CPU)
    load = os.getloadavg()
    text += f" Process CPU time {cpu:.1f} s; load average at the end {load[0]:.1f} (1 min), {load[2]:.1f} (15 min)."
    print(text)
    (out / "profile.json").write_text(json.dumps({"total_s": total, "cpu_s": cpu, "rows": ROWS, "cpu": CPU, "lm_calls": LM_CALLS,
                                                  "cache": str(cache), "loadavg": load}, indent=1))
    print(f"profile: {out / 'profile.json'}", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())
