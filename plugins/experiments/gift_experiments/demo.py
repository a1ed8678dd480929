"""``gift demo``: one intent of the gift-paper suite with small sizes, the whole chain, a short table."""

from __future__ import annotations

import time
from pathlib import Path

from gift.study.chain import ORACLE, StudyConfig
from gift_experiments.report import KERNEL_ORDER

#: Small sizes. The binary Call-3 kernels (``gift``, ``lm-no-intent``) are left out by default: on the embedded
#: 1.5B model one Call 3 over ~25 objects takes minutes on 2 cores; add them with ``--kernels``.
DEMO = dict(suite="gift-paper", pairs=100, seeds=2, samples=3, train_scenes=2, sanity_reps=0,
            trajectories_per_generator=10, thresholds=("train-calibrated",), rq3=False)
DEMO_KERNELS = ("vision", "language", "gift-prob")


def demo(intent: str = "art_supplies", lm: str | None = None, out: Path = Path("out/demo"), robot: str = "jaco",
         kernels: tuple[str, ...] = DEMO_KERNELS) -> int:
    from gift_experiments.plugin import run_study_command

    cfg = StudyConfig(intents=(intent,), lm=lm, robot=robot, kernels=tuple(kernels), **DEMO)
    t0 = time.perf_counter()
    results = run_study_command(cfg, out, f"gift demo --intent {intent} --robot {robot}")
    elapsed = time.perf_counter() - t0
    intent_text = results["intents"][intent]["text"]
    relevant = results["relevant"][intent]
    print(f"intent {intent!r}: inferred -> {intent_text!r}")
    print(f"relevant training objects ({relevant['source']}): {', '.join(relevant['names'])}")
    rq1, rq2 = results["rq1"][intent], results["rq2"].get(intent, {})
    rows = [k for k in KERNEL_ORDER if k in rq1] + [k for k in rq1 if k not in KERNEL_ORDER and k != ORACLE] + [ORACLE]
    width = max(16, *(len(k) for k in rows))  # kernel specs with options are longer than the names
    print(f"{'kernel':<{width}} {'win rate':>9} {'F1':>6}")
    for k in rows:
        f1 = rq2.get(k, {}).get("train-calibrated", {}).get("all", {}).get("f1")
        print(f"{k:<{width}} {rq1[k]['mean']:>9.3f} {'' if f1 is None else f'{f1:.3f}':>6}")
    print(f"({elapsed:.0f} s; report.html, report.md, figures and replays in {out})")
    return 0
