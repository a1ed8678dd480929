"""Entry point of gift-experiments: the study commands ``gift reproduce``, ``gift demo`` and
``gift evaluate-alignment``, thin callers of :mod:`gift.study`; ``gift view`` and ``gift report`` show a run."""

from __future__ import annotations

import argparse
import json
import logging
import shlex
import sys
import time
from pathlib import Path

from gift.cli import add_answer_arguments, check_answer_arguments
from gift.core.errors import GiftError
from gift.core.executor import add_executor_argument, executor_from_args
from gift.plugins.hookspecs import hookimpl

log = logging.getLogger("gift")


def _names(kind: str) -> list[str]:
    from gift.plugins.manager import get_manager

    return get_manager().names(kind)


def _split(s: str) -> tuple[str, ...]:
    return tuple(x.strip() for x in s.split(",") if x.strip())


def robot_choices() -> list[str]:
    """Registered robots that some simulator plugin builds a simulator for (the choices of ``--robot``)."""
    from gift.plugins.manager import get_manager

    manager = get_manager()
    return [r for r in manager.names("robot") if manager.simulators_for_robot(r)]


def _add_robot_argument(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--robot", default="jaco", choices=robot_choices(),
                   help=f"{what}: a registered robot (gift plugins lists them; default: %(default)s)")


def check_kernels(specs: tuple[str, ...]) -> tuple[str, ...]:
    """The kernel specs, or a GiftError naming the unknown ones and the registered kernels."""
    from gift.study.components import parse_spec

    if not specs:
        raise GiftError("--kernels is empty")
    known = _names("kernel")
    bad = [k for k in specs if parse_spec(k)[0] not in known]
    if bad:
        raise GiftError(f"unknown kernel(s) {bad}; registered kernels: {', '.join(known)}")
    return specs


def add_query_arguments(p: argparse.ArgumentParser) -> None:
    """``--queries N`` and :func:`gift.cli.add_answer_arguments`: questions the simulated human (the suite's labels)
    answers."""
    p.add_argument("--queries", type=int, default=0, metavar="N",
                   help="per intent and kernel, ask the simulated human (the suite's labels) N questions "
                        "'is this object part of the goal?' and re-score (default 0); adds a row per kernel")
    add_answer_arguments(p)


def _check_queries(args: argparse.Namespace) -> None:
    if args.queries < 0:
        raise GiftError(f"--queries must be >= 0, got {args.queries}")
    check_answer_arguments(args)


def _configure_reproduce(p: argparse.ArgumentParser) -> None:
    from gift.study.chain import ALL_KERNELS

    p.add_argument("--suite", default="gift-paper", help="registered suite name or suite file")
    _add_robot_argument(p, "robot of the training and test scenes")
    p.add_argument("--pairs", type=int, default=250, help="trajectory pairs per test scene")
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--samples", type=int, default=10, help="LM samples per alignment (gift, lm-no-intent)")
    p.add_argument("--lm", default=None, help="LM to use (default: the embedded model)")
    p.add_argument("--kernels", default=",".join(ALL_KERNELS),
                   help=f"comma-separated kernel specs (registered kernels: {', '.join(_names('kernel'))})")
    p.add_argument("--reward", default="maxent-linear", choices=_names("reward_model"),
                   help="a registered reward model (default: %(default)s)")
    p.add_argument("--intents", default="", help="comma-separated intent ids (default: all)")
    p.add_argument("--intent-source", default="inferred", choices=["inferred", "ground-truth"])
    p.add_argument("--thresholds", default="train-calibrated,non-oracle,oracle")
    p.add_argument("--train-scenes", type=int, default=4)
    p.add_argument("--sanity-reps", type=int, default=10)
    p.add_argument("--trajectories", type=int, default=20, help="test trajectories per generator and scene")
    p.add_argument("--no-rq3", action="store_true")
    p.add_argument("--demonstrations", default=None, metavar="DIR",
                   help="saved training sets (<intent>.npz/.json) to use instead of simulating the human")
    add_query_arguments(p)
    p.add_argument("--out", default="out/reproduce", help="output directory")
    add_executor_argument(p)  # one item per intent; the executor does not change the results


def _check_choices(args: argparse.Namespace) -> None:
    rewards = _names("reward_model")
    if args.reward not in rewards:
        raise GiftError(f"unknown reward model {args.reward!r}; registered: {', '.join(rewards)}")
    from gift.study.chain import simulator_name

    sims = _names("simulator")
    if simulator_name(args.robot) not in sims:
        robots = sorted({s.removeprefix("drake-") for s in sims})
        raise GiftError(f"unknown robot {args.robot!r}; robots with a registered simulator: {', '.join(robots)}")


def _config_from_args(args: argparse.Namespace):
    from gift.study.chain import StudyConfig

    _check_choices(args)
    _check_queries(args)
    return StudyConfig(suite=args.suite, robot=args.robot, pairs=args.pairs, seeds=args.seeds, samples=args.samples,
                       lm=args.lm, kernels=check_kernels(_split(args.kernels)), reward=args.reward,
                       intents=_split(args.intents), intent_source=args.intent_source,
                       thresholds=_split(args.thresholds), train_scenes=args.train_scenes,
                       sanity_reps=args.sanity_reps, trajectories_per_generator=args.trajectories,
                       rq3=not args.no_rq3, demonstrations=args.demonstrations, queries=args.queries,
                       query_policy=args.policy, abstain=args.abstain, query_rescore=args.rescore)


def run_study_command(cfg, out: Path, command: str, executor=None) -> dict:
    """Run a study into ``out`` (resuming from its stage caches), write results.json, report.md, figures,
    the Meshcat replays of the first intents (``views/``) and report.html; the LM calls of the run are
    recorded in ``out/lm_calls.jsonl`` (:mod:`gift_experiments.lm_calls`)."""
    from gift.study.progress import Progress
    from gift.study.sweeps import previous_runs, run_study
    from gift_experiments.html_report import write_html_report
    from gift_experiments.lm_calls import recording
    from gift_experiments.report import write_report
    from gift_experiments.views import export_views

    t0 = time.perf_counter()
    echo = executor is not None and not executor.in_process and executor.live_stderr
    with recording(out, cfg.lm):
        results = run_study(cfg, out, Progress(), log_line=log.info, executor=executor, echo=echo,
                            previous=previous_runs(out / "results.json"))
    results["timing"]["total"] = time.perf_counter() - t0
    write_report(results, out, command=command)
    export_views(results, out)  # views/<intent>_{demos,test}.html: Meshcat replays of the first two intents
    write_html_report(results, out, command=command)
    return results


def run_reproduce(args: argparse.Namespace) -> int:
    cfg = _config_from_args(args)
    out = Path(args.out)
    argv = sys.argv[sys.argv.index("reproduce"):] if "reproduce" in sys.argv else ["reproduce"]
    with executor_from_args(args) as executor:  # local workers print their intents' log lines themselves
        run_study_command(cfg, out, "gift " + " ".join(shlex.quote(a) for a in argv), executor)
    print(f"report: {out / 'report.md'} (and {out / 'report.html'})")
    return 0


def _configure_demo(p: argparse.ArgumentParser) -> None:
    p.add_argument("--intent", default="art_supplies", help="intent id of the gift-paper suite")
    _add_robot_argument(p, "robot of the scenes")
    p.add_argument("--lm", default=None, help="LM to use (default: the embedded model)")
    p.add_argument("--kernels", default="vision,language,gift-prob",
                   help="comma-separated kernels (add gift,lm-no-intent for the binary Call-3 kernels: slow on CPU)")
    p.add_argument("--out", default="out/demo")


def run_demo(args: argparse.Namespace) -> int:
    from gift_experiments.demo import demo

    _check_choices(argparse.Namespace(reward="maxent-linear", robot=args.robot))
    return demo(intent=args.intent, lm=args.lm, out=Path(args.out), robot=args.robot,
                kernels=check_kernels(_split(args.kernels)))


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
    p.add_argument("--query-curves", default=None, metavar="FILE",
                   help="query curves JSON of scripts/query_curves.py (docs/results/queries/curves.json) to draw in "
                        "the 'Questions asked' section; copied to OUT/query_curves.json for later regenerations")


def run_report(args: argparse.Namespace) -> int:
    from gift_experiments.html_report import regenerate

    out = Path(args.out)
    if args.views:
        from gift_experiments.views import export_views

        path = out / "results.json"
        if not path.is_file():
            raise GiftError(f"no results.json in {out}: give the output folder of gift demo or gift reproduce")
        for e in export_views(json.loads(path.read_text()), out):
            print(f"{e['intent']}/{e['view']}: {e.get('file') or e.get('error')}")
    curves = Path(args.query_curves) if args.query_curves else None
    print(f"report.html: {regenerate(out, render=not args.no_render, query_curves=curves)}")
    return 0


def _configure_evaluate_alignment(p: argparse.ArgumentParser) -> None:
    from gift.core.alignment import THRESHOLDS

    p.add_argument("--suite", required=True, help="registered suite name or a suite YAML file")
    p.add_argument("--kernels", required=True,
                   help="comma-separated kernels, each a registered name optionally with :key=value options, "
                        "e.g. language,language:use_descriptions=true,vision")
    p.add_argument("--intent-source", default="ground-truth", choices=("ground-truth", "inferred"),
                   help="ground-truth intent text and relevant training objects, or both inferred by the GIFT "
                        "front half from simulated demonstrations")
    _add_robot_argument(p, "robot of the demonstrations (inferred intents)")
    p.add_argument("--threshold", default=",".join(THRESHOLDS),
                   help=f"comma-separated threshold strategies (default: all of {','.join(THRESHOLDS)})")
    p.add_argument("--intents", default=None, help="comma-separated intent ids (default: all)")
    p.add_argument("--lm", default=None, help="LM backend for LM kernels and intent inference")
    p.add_argument("--json", action="store_true", help="print the full result as JSON")
    p.add_argument("--out", default=None, metavar="FILE", help="also write the full JSON result to FILE")
    p.add_argument("--detailed", action="store_true", help="also print every metric per subset")
    add_query_arguments(p)
    add_executor_argument(p)  # one item per (kernel, intent); serial checkpoints --out after every item


def run_evaluate_alignment(args: argparse.Namespace) -> int:
    from gift.core.serialization import write_json
    from gift.study.sweeps import evaluate_alignment
    from gift_experiments.report import alignment_report

    kernels = [k.strip() for k in args.kernels.split(",") if k.strip()]
    if not kernels:
        raise GiftError("--kernels is empty")
    thresholds = [t.strip() for t in args.threshold.split(",") if t.strip()]
    intents = [i.strip() for i in args.intents.split(",")] if args.intents else None
    _check_queries(args)

    def write(result: dict) -> None:  # serial: after every kernel x intent, so an interrupted run keeps its numbers
        write_json(Path(args.out), result)

    stages = Path(args.out).with_suffix(".stages") if args.out else None
    with executor_from_args(args) as executor:
        result = evaluate_alignment(args.suite, kernels, thresholds=thresholds, intent_source=args.intent_source,
                                    lm=args.lm, intents=intents, robot=args.robot, progress=log.info,
                                    checkpoint=write if args.out else None, executor=executor,
                                    echo=not executor.in_process and executor.live_stderr, stages=stages,
                                    queries=args.queries, query_policy=args.policy, abstain=args.abstain,
                                    query_rescore=args.rescore)
    if args.json:
        from gift.core.serialization import to_jsonable

        print(json.dumps(to_jsonable(result, nonfinite="null"), indent=2, allow_nan=False))
    else:
        print(alignment_report(result, detailed=args.detailed))
    failed = [k for k, d in result["kernels"].items() if d["errors"]]
    return 1 if len(failed) == len(kernels) else 0


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
    register("evaluate-alignment", run_evaluate_alignment,
             help="precision/recall/F1/AUC/FP/FN of kernels on a suite, per intent and per subset",
             configure=_configure_evaluate_alignment)
