"""Entry point of gift-experiments: the ``gift reproduce`` and ``gift demo`` commands."""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path

from gift.core.executor import add_executor_argument, executor_from_args
from gift.plugins.hookspecs import hookimpl
from gift.plugins.manager import get_manager


def robot_choices() -> list[str]:
    """Registered robots that some simulator plugin builds a simulator for."""
    manager = get_manager()
    return [r for r in manager.names("robot") if manager.simulators_for_robot(r)]


def kernel_list(text: str) -> tuple[str, ...]:
    """``--kernels``: comma-separated names, each a registered kernel (else a clear argparse error)."""
    names = tuple(k.strip() for k in text.split(",") if k.strip())
    known = get_manager().names("kernel")
    unknown = [k for k in names if k not in known]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"unknown kernel(s) {', '.join(map(repr, unknown))}; registered kernels: "
                                         f"{', '.join(known)}" if unknown else "give at least one kernel")
    return names


def _add_robot_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--robot", default="jaco", choices=robot_choices(),
                   help="a registered robot (gift plugins lists them; default: %(default)s)")


def _configure_reproduce(p: argparse.ArgumentParser) -> None:
    from gift_experiments.reproduce import ALL_KERNELS

    p.add_argument("--suite", default="gift-paper", help="registered suite name or suite file")
    _add_robot_argument(p)
    p.add_argument("--pairs", type=int, default=250, help="trajectory pairs per test scene")
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--samples", type=int, default=10, help="LM samples per alignment (gift, lm-no-intent)")
    p.add_argument("--lm", default=None, help="LM to use (default: the embedded model)")
    p.add_argument("--kernels", default=",".join(ALL_KERNELS), type=kernel_list,
                   help="comma-separated registered kernel names")
    p.add_argument("--reward", default="maxent-linear", choices=get_manager().names("reward_model"),
                   help="a registered reward model (default: %(default)s)")
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
                           samples=args.samples, lm=args.lm, kernels=args.kernels, reward=args.reward,
                           intents=split(args.intents), intent_source=args.intent_source,
                           thresholds=split(args.thresholds), train_scenes=args.train_scenes,
                           sanity_reps=args.sanity_reps, trajectories_per_generator=args.trajectories,
                           rq3=not args.no_rq3)


def _log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def run_reproduce(args: argparse.Namespace) -> int:
    from gift_experiments.report import write_report
    from gift_experiments.reproduce import Progress, run

    cfg = _config_from_args(args)
    out = Path(args.out)
    t0 = time.perf_counter()
    with executor_from_args(args) as executor:  # local workers print their intents' log lines themselves
        results = run(cfg, out, Progress(enabled=not args.quiet), log=_log, executor=executor,
                      echo=not executor.in_process and executor.live_stderr)
    results["timing"]["total"] = time.perf_counter() - t0
    argv = sys.argv[sys.argv.index("reproduce"):] if "reproduce" in sys.argv else ["reproduce"]
    path = write_report(results, out, command="gift " + " ".join(shlex.quote(a) for a in argv))
    print(f"report: {path}")
    return 0


def _configure_demo(p: argparse.ArgumentParser) -> None:
    p.add_argument("--intent", default="art_supplies", help="intent id of the gift-paper suite")
    _add_robot_argument(p)
    p.add_argument("--lm", default=None, help="LM to use (default: the embedded model)")
    p.add_argument("--kernels", default="vision,language,gift-prob", type=kernel_list,
                   help="comma-separated kernels (add gift,lm-no-intent for the binary Call-3 kernels: slow on CPU)")
    p.add_argument("--out", default="out/demo")
    p.add_argument("--quiet", action="store_true")


def run_demo(args: argparse.Namespace) -> int:
    from gift_experiments.demo import demo

    return demo(intent=args.intent, lm=args.lm, out=Path(args.out), progress=not args.quiet, kernels=args.kernels,
                robot=args.robot)


@hookimpl
def gift_register_commands(register):
    register("reproduce", run_reproduce, help="run the paper's experiments and write a report with figures",
             configure=_configure_reproduce)
    register("demo", run_demo, help="one intent, small sizes, embedded LM: a table of win rate and F1 per kernel",
             configure=_configure_demo)
