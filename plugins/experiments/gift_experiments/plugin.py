"""Entry point of gift-experiments: the commands ``gift reproduce``, ``gift demo``, ``gift view``, ``gift report``."""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path

from gift.core.executor import add_executor_argument, executor_from_args
from gift.plugins.hookspecs import hookimpl


def _configure_reproduce(p: argparse.ArgumentParser) -> None:
    from gift_experiments.reproduce import ALL_KERNELS

    p.add_argument("--suite", default="gift-paper", help="registered suite name or suite file")
    p.add_argument("--robot", default="jaco", choices=["jaco", "franka"])
    p.add_argument("--pairs", type=int, default=250, help="trajectory pairs per test scene")
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--samples", type=int, default=10, help="LM samples per alignment (gift, lm-no-intent)")
    p.add_argument("--lm", default=None, help="LM to use (default: the embedded model)")
    p.add_argument("--kernels", default=",".join(ALL_KERNELS), help="comma-separated kernel names")
    p.add_argument("--reward", default="maxent-linear", choices=["maxent-linear", "maxent-neural"])
    p.add_argument("--intents", default="", help="comma-separated intent ids (default: all)")
    p.add_argument("--intent-source", default="inferred", choices=["inferred", "ground-truth"])
    p.add_argument("--thresholds", default="train-calibrated,non-oracle,oracle")
    p.add_argument("--train-scenes", type=int, default=4)
    p.add_argument("--sanity-reps", type=int, default=10)
    p.add_argument("--trajectories", type=int, default=20, help="test trajectories per generator and scene")
    p.add_argument("--no-rq3", action="store_true")
    p.add_argument("--out", default="out/reproduce", help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_executor_argument(p)  # one item per intent; the executor does not change the results


def _config_from_args(args: argparse.Namespace):
    from gift_experiments.reproduce import ReproduceConfig

    split = lambda s: tuple(x.strip() for x in s.split(",") if x.strip())  # noqa: E731
    return ReproduceConfig(suite=args.suite, robot=args.robot, pairs=args.pairs, seeds=args.seeds,
                           samples=args.samples, lm=args.lm, kernels=split(args.kernels), reward=args.reward,
                           intents=split(args.intents), intent_source=args.intent_source,
                           thresholds=split(args.thresholds), train_scenes=args.train_scenes,
                           sanity_reps=args.sanity_reps, trajectories_per_generator=args.trajectories,
                           rq3=not args.no_rq3)


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def run_reproduce(args: argparse.Namespace) -> int:
    from gift_experiments.html_report import write_html_report
    from gift_experiments.lm_calls import recording
    from gift_experiments.report import write_report
    from gift_experiments.reproduce import Progress, run
    from gift_experiments.views import export_views

    cfg = _config_from_args(args)
    out = Path(args.out)
    t0 = time.perf_counter()
    # local workers print their log lines themselves; out/lm_calls.jsonl records the LM calls for report.html
    with recording(out, args.lm), executor_from_args(args) as executor:
        results = run(cfg, out, Progress(enabled=not args.quiet), log=_log, executor=executor,
                      echo=not executor.in_process and executor.live_stderr)
    results["timing"]["total"] = time.perf_counter() - t0
    argv = sys.argv[sys.argv.index("reproduce"):] if "reproduce" in sys.argv else ["reproduce"]
    command = "gift " + " ".join(shlex.quote(a) for a in argv)
    path = write_report(results, out, command=command)
    export_views(results, out)  # views/<intent>_{demos,test}.html: Meshcat replays of the first two intents
    html = write_html_report(results, out, command=command)
    print(f"report: {path}\nreport.html: {html}")
    return 0


def _configure_demo(p: argparse.ArgumentParser) -> None:
    p.add_argument("--intent", default="art_supplies", help="intent id of the gift-paper suite")
    p.add_argument("--lm", default=None, help="LM to use (default: the embedded model)")
    p.add_argument("--kernels", default="vision,language,gift-prob",
                   help="comma-separated kernels (add gift,lm-no-intent for the binary Call-3 kernels: slow on CPU)")
    p.add_argument("--out", default="out/demo")
    p.add_argument("--quiet", action="store_true")


def run_demo(args: argparse.Namespace) -> int:
    from gift_experiments.demo import demo
    from gift_experiments.lm_calls import recording

    kernels = tuple(k.strip() for k in args.kernels.split(",") if k.strip())
    with recording(Path(args.out), args.lm):  # out/lm_calls.jsonl: the LM calls shown in report.html
        return demo(intent=args.intent, lm=args.lm, out=Path(args.out), progress=not args.quiet, kernels=kernels)


def _configure_view(p: argparse.ArgumentParser) -> None:
    from gift_experiments.views import VIEWS

    p.add_argument("out", nargs="?", default="out/demo", help="output folder of gift demo / gift reproduce")
    p.add_argument("--intent", default=None, help="intent id (default: the run's first)")
    p.add_argument("--show", default="test", choices=VIEWS,
                   help="demos: a training scene's demonstration pairs; test: a test scene coloured by alignment "
                        "with the best- and worst-scored trajectories under the aligned reward")
    p.add_argument("--kernel", default=None, help="kernel whose alignment to show (default: gift-prob if it ran)")
    p.add_argument("--pairs", type=int, default=2, help="demonstration pairs to replay (--show demos)")
    p.add_argument("--export", default=None, metavar="FILE.html",
                   help="write a self-contained HTML page (no server, no network) instead of serving live")
    p.add_argument("--port", type=int, default=None, help="live mode: Meshcat port (default: the first free from 7000)")
    p.add_argument("--seconds", type=float, default=None, help="live mode: stop after this long (default: Ctrl-C)")


def run_view(args: argparse.Namespace) -> int:
    from gift_experiments.views import view_command

    return view_command(Path(args.out), intent=args.intent, show=args.show, kernel=args.kernel, pairs=args.pairs,
                        export=Path(args.export) if args.export else None, port=args.port, seconds=args.seconds)


def _configure_report(p: argparse.ArgumentParser) -> None:
    p.add_argument("out", nargs="?", default="out/demo", help="output folder of gift demo / gift reproduce")
    p.add_argument("--no-render", action="store_true",
                   help="use only the object thumbnails already in OUT/renders (no Drake)")
    p.add_argument("--views", action="store_true", help="also (re)write the Meshcat replays in OUT/views")


def run_report(args: argparse.Namespace) -> int:
    import json

    from gift_experiments.html_report import regenerate

    out = Path(args.out)
    if args.views:
        from gift_experiments.views import export_views

        for e in export_views(json.loads((out / "results.json").read_text()), out):
            print(f"{e['intent']}/{e['view']}: {e.get('file') or e.get('error')}")
    print(f"report.html: {regenerate(out, render=not args.no_render)}")
    return 0


@hookimpl
def gift_register_commands(register):
    register("reproduce", run_reproduce, help="run the paper's experiments and write a report with figures",
             configure=_configure_reproduce)
    register("demo", run_demo, help="one intent, small sizes, embedded LM: a table of win rate and F1 per kernel",
             configure=_configure_demo)
    register("view", run_view, help="replay a run's demonstrations or test trajectories in Drake's Meshcat "
             "(live, or --export FILE.html)", configure=_configure_view)
    register("report", run_report, help="write report.html of a gift demo / gift reproduce output folder again",
             configure=_configure_report)
