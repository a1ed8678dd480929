"""Alignment F1 and win rate against the number of questions per intent, for each query policy (issue 20).

    .venv/bin/python scripts/query_curves.py \\
        [--suites gift-paper,gift-dev,tests/kernels/data/lm_dev_suite.yaml] [--intent-sources ground-truth,inferred] \\
        [--robot jaco] [--kernel gift-prob] [--random-seeds 10] [--stages out/query_curves] \\
        [--out docs/results/queries.md]

For each suite, intent source and intent, the chain of ``gift reproduce`` runs once up to the kernel's scores
(same seeds and sizes as the committed reproduce runs; finished stages are kept in ``--stages`` and the LM's
answers in the LM cache, so a rerun with an unchanged recipe makes no LM call), with the RQ1 test scenes and
the reward learned from the demonstrations. Then every policy asks 0, 1, 2, 4, 8 questions per intent,
offline, answered from the suite's labels (``gift_experiments.query_curves``). Writes ``--out`` (Markdown),
``<out dir>/queries/<intent source>.png`` and ``<out dir>/queries/curves.json`` (every number, with the
commit, the LM and its model file's hash, the suites' hashes and the options that made them).
"""

from __future__ import annotations

import argparse
import json
import logging
import shlex
import sys
import time
from pathlib import Path

import attrs

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SUITES = ("gift-paper", "gift-dev", "tests/kernels/data/lm_dev_suite.yaml")
log = logging.getLogger("query_curves")


def _rel(path: Path) -> str:
    path = path.resolve()
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def _fmt(v, digits: int = 3) -> str:
    return "–" if v is None else f"{v:.{digits}f}"


def run(args: argparse.Namespace) -> dict:
    import gift
    from gift.core.errors import GiftError
    from gift.core.provenance import code_version, git_commit
    from gift.study.chain import StudyConfig, lm_inputs
    from gift.study.components import components_for
    from gift.study.stages import StageCache
    from gift.study.sweeps import suite_provenance, versions
    from gift_experiments import query_curves as qc

    out: dict = {"kernel": args.kernel,
                 "command": "python scripts/query_curves.py " + " ".join(shlex.quote(a) for a in sys.argv[1:]),
                 "git": git_commit(), "code_version": code_version(), "versions": versions(), "runs": {},
                 "suites": {}, "failures": []}
    t_all = time.perf_counter()
    comp = None
    for suite_name in args.suites:
        suite = gift.load_suite(suite_name)
        out["suites"][suite.name] = suite_provenance(suite)
        for source in args.intent_sources:
            cfg = StudyConfig(suite=suite_name, robot=args.robot, kernels=(args.kernel,), intent_source=source,
                              thresholds=("train-calibrated", "non-oracle"), sanity_reps=0, rq3=False, lm=args.lm)
            comp = components_for(cfg.lm, cfg.defaults)
            cache = StageCache(args.stages)
            data = []
            for spec in suite.intents:
                t0 = time.perf_counter()
                try:
                    d = qc.prepare(cfg, suite, spec, cache, comp)
                except GiftError as e:  # one intent that cannot run must not lose the others
                    out["failures"].append(f"{suite.name}/{source}/{spec.id}: {type(e).__name__}: {e}")
                    log.warning("%s/%s/%s failed: %s", suite.name, source, spec.id, e)
                    continue
                data.append(d)
                log.info("%s / %s / %s ready in %.0fs%s", suite.name, source, spec.id, time.perf_counter() - t0,
                         f" ({d.note})" if d.note else "")
            if not data:
                continue
            sim = qc.simulate(data, random_seeds=args.random_seeds, grid=args.grid, policies=args.policies,
                              rescore=args.rescore, move=args.move, choose=args.choose,
                              rescore_when=args.rescore_when)
            if args.rescore:  # the same sessions with answers that only re-threshold, for the comparison
                sim["without_rescore"] = qc.simulate(data, random_seeds=args.random_seeds, grid=args.grid,
                                                     policies=args.policies, bands=(), move=args.move,
                                                     rescore=False, choose=args.choose)["curves"]
            else:  # the first cut rule tried (widest gap), for the record
                sim["widest"] = qc.simulate(data, random_seeds=args.random_seeds, grid=args.grid,
                                            policies=args.policies, bands=(), move="widest", rescore=False,
                                            choose=args.choose)["curves"]
            sim.update({"suite": suite.name, "intent_source": source, "robot": args.robot, "kernel": args.kernel,
                        "config": attrs.asdict(cfg), "target": qc.target_check(sim),
                        "intents": {d.intent: {"intent_text": d.intent_text, "relevant": list(d.relevant),
                                               "n_test": len(d.labels), "n_relevant": sum(d.labels.values()),
                                               "note": d.note, "cut": d.scores.threshold("train-calibrated")[0]}
                                    for d in data}})
            out["runs"][f"{suite.name} | {source}"] = sim
    out["lm"] = lm_inputs(comp) if comp is not None and comp.lm_built else None
    out["random_seeds"] = args.random_seeds
    out["rescore"] = bool(args.rescore)
    out["move"] = args.move
    out["choose"] = args.choose
    out["rescore_when"] = args.rescore_when
    out["seconds"] = round(time.perf_counter() - t_all, 1)
    return out


def merge(results: list[dict]) -> dict:
    """One result from several saved ones (each a ``curves.json``): their runs, suites and failures together;
    the first one's provenance, with every one's command, commit and code version kept under ``parts`` (a result
    that is itself merged contributes its own parts, so a page merged again still names every run's commit).
    Runs of different recipes (kernel, re-scoring, LM model file) are refused."""
    first = results[0]
    keys = ("kernel", "rescore", "random_seeds", "move", "choose", "rescore_when")
    before = {"rescore_when": "always"}  # runs saved before the key existed

    def value(r: dict, k: str):
        return r.get(k, before.get(k))

    for r in results[1:]:
        for k in keys:
            if value(r, k) != value(first, k):
                raise SystemExit(f"cannot merge runs with different {k}: {value(first, k)!r} and {value(r, k)!r}")
        if (r.get("lm") or {}).get("model_sha256") != (first.get("lm") or {}).get("model_sha256"):
            raise SystemExit("cannot merge runs made with different LM model files")
    own = ("command", "git", "code_version", "seconds")
    out = {**first, "runs": {}, "suites": {}, "failures": [], "seconds": 0.0,
           "parts": [p for r in results for p in (r.get("parts") or [{k: r.get(k) for k in own}])]}
    for r in results:
        out["runs"].update(r["runs"])
        out["suites"].update(r["suites"])
        out["failures"] += r.get("failures", [])
        out["seconds"] += r.get("seconds") or 0.0
    out["command"] = " ; ".join(r["command"] for r in results)
    return out


def figure_dir(md: Path) -> str:
    """The directory, next to the page ``md``, of its figures and curves.json: ``queries`` for queries.md,
    else the page's own stem (so a second page never overwrites the first one's figures)."""
    return "queries" if md.stem == "queries" else md.stem


def provenance(result: dict) -> str:
    """Commit and code version of the run, or of each merged part in the order of the commands."""
    def one(r: dict) -> str:
        git = r.get("git") or {}
        return (f"commit `{(git.get('commit') or '?')[:10]}`{' (dirty)' if git.get('dirty') else ''}, code version "
                f"`{(r.get('code_version') or '?')[:12]}`")
    parts = result.get("parts") or []
    if len(parts) < 2:
        return one(result)[0].upper() + one(result)[1:]
    return "Merged from runs at " + "; ".join(f"{one(p)} ({p.get('seconds') or 0:.0f} s)" for p in parts)


#: In an existing page, the text from this line on was written by hand and is kept when the page is regenerated.
KEEP = "<!-- written by hand: kept when scripts/query_curves.py regenerates the page above -->"


def write(result: dict, md: Path) -> None:
    from gift.core.serialization import write_json
    from gift_experiments import query_curves as qc

    sub = figure_dir(md)
    fig_dir = md.parent / sub
    fig_dir.mkdir(parents=True, exist_ok=True)
    write_json(fig_dir / "curves.json", result, indent=1)
    sources = list(dict.fromkeys(r["intent_source"] for r in result["runs"].values()))
    figures = {}
    for source in sources:
        runs = {r["suite"]: r for r in result["runs"].values() if r["intent_source"] == source}
        figures[source] = qc.figure(runs, fig_dir / f"{source}.png",
                                    title=f"{next(iter(runs.values()))['kernel']}, {source} intents: "
                                          f"F1 and win rate after k questions per intent")
    lm = result.get("lm") or {}
    kernel = result.get("kernel", "gift-prob")
    recipe = ("`gift-prob` with its default recipe at the commit below, the one measured in "
              "[the front half](front_half.md)." if kernel == "gift-prob" else
              f"`{kernel}`: `gift-prob` with these options, otherwise its default recipe at the commit below "
              "(the default is measured in [queries.md](queries.md) and [the front half](front_half.md)).")
    title = ("# Answers that re-score the scene: query curves with rule 5" if result.get("rescore") else
             "# Asking instead of guessing: query policies and abstention")
    lines = [title, "",
             "When the intent-conditioned kernel is unsure, gift can ask the human \"is this object part of the "
             "goal?\" about a few test objects and re-score the scene with the answers, or abstain on an object "
             "(leave it out of the aligned reward). The rules (answered objects are fixed; " + (
                 "the cut stays where it was without answers; " if result.get("move") == "stay" else
                 "answers join the leave-one-out evidence of the train-calibrated cut; ") +
             ("the kernel's own intent candidate decides; " if result.get("choose") == "primary" else
              "answers choose among intent candidates; ") +
             "abstained objects are dropped like distractors) are in `gift.core.queries` "
             "([API](../reference/alignment.md)); `gift align --ask N`, `gift evaluate-alignment --queries N` "
             "and `gift reproduce --queries N` use them ([command line](../cli.md)).", "",
             "This page measures what k questions per intent buy. The kernel runs once per intent; each policy "
             "then asks k = " + ", ".join(map(str, result["runs"][next(iter(result["runs"]))]["grid"])) +
             " questions, answered from the suite's labels (the simulated human). **F1** is pooled over the "
             "suite's test objects with the train-calibrated cut after the answers (answered objects count, "
             "and count right); **win rate** is the RQ1 pairwise win rate of the re-scored alignment, mean over "
             f"the intents whose test scenes fit the table. `random` is the mean over {result['random_seeds']} "
             "seeds (± 1 standard error over seeds in the tables and the figure).", "",
             "!!! note \"Which recipe\"",
             f"    {recipe} Inferred intents: the relevant training objects and the intent "
             "come from the demonstrations alone." + (
                 " **Answers re-score the scene** (rule 5 of `gift.core.queries`, `--rescore`): after each answer "
                 "the kernel scores the scene again with the answers (`gift-prob` by default weighs the answered "
                 "objects as evidence beside the training objects, no LM call; with `rescore_with=ladder` it names "
                 "its category ladder again); each suite's table also gives the same sessions without it."
                 if result.get("rescore") else "") + (
                 " Here a scene is re-scored only once some answer contradicts the kernel's decision without "
                 "answers (`--rescore-when contradicted`); answers that agree only fix their objects."
                 if result.get("rescore") and result.get("rescore_when") == "contradicted" else ""), "",
             "Command:", "", "```", result["command"], "```", "",
             provenance(result) + f", LM `{lm.get('identity', '–')}` (model sha256 "
             f"`{(lm.get('model_sha256') or '–')[:12]}`), {result['seconds']:.0f} s. Suites: " +
             ", ".join(f"`{n}` (sha256 `{(p.get('sha256') or '?')[:12]}`)" for n, p in result["suites"].items()) +
             f". Every number is in [`{sub}/curves.json`]({sub}/curves.json).", ""]
    lines += ["## In short", ""]
    for label, r in result["runs"].items():
        t, grid = r["target"], r["grid"]
        k2 = grid.index(2)
        best, rand = r["curves"][t["best"]], r["curves"][qc.BASELINE]
        row2 = next(x for x in t["rows"] if x["k"] == 2)
        needs = ("more than " + str(grid[-1])) if row2["random_needs"] is None else f"{row2['random_needs']:.1f}"
        lines.append(f"- `{r['suite']}`, {r['intent_source']} intents: pooled F1 {best['f1'][0]:.3f} without "
                     f"questions, {best['f1'][k2]:.3f} after 2 `{t['best']}` questions per intent (random: "
                     f"{rand['f1'][k2]:.3f}); random needs {needs} questions per intent for that F1"
                     + (f" (ratio {row2['ratio']:.2f})" if row2["ratio"] else "") + f". Win rate "
                     f"{_fmt(best['win'][0])} -> {_fmt(best['win'][k2])} (random {_fmt(rand['win'][k2])}).")
        if result.get("rescore") and "rescored_intents" in r and len(r["rescored_intents"]) < len(r["intents"]):
            lines.append(f"  Re-scored with the answers on {len(r['rescored_intents'])} of {len(r['intents'])} "
                         "intents; on the others the kernel gave no re-scoring and answers only re-threshold.")
        if "without_rescore" in r:
            w = r["without_rescore"]
            pols = qc.ran_policies(w)
            wb = max(pols, key=lambda p: w[p]["f1"][k2])
            lines.append(f"  Without re-scoring (answers only re-threshold), the same sessions: best after 2 questions "
                         f"{w[wb]['f1'][k2]:.3f} (`{wb}`), random {w[qc.BASELINE]['f1'][k2]:.3f}; after 1 question "
                         f"best {max(w[p]['f1'][grid.index(1)] for p in pols):.3f} against "
                         f"{max(r['curves'][p]['f1'][grid.index(1)] for p in pols):.3f} with it."
                         if 1 in grid else
                         f"  Without re-scoring: best after 2 questions {w[wb]['f1'][k2]:.3f} (`{wb}`).")
    paper_inferred = [r for r in result["runs"].values()
                      if r["suite"] == "gift-paper" and r["intent_source"] == "inferred"]
    if paper_inferred:
        r = paper_inferred[0]
        k2 = r["grid"].index(2)
        f1 = max(r["curves"][p]["f1"][k2] for p in qc.ran_policies(r["curves"]))
        lines.append(f"- Target 1 (inferred intents, `gift-paper`, at most 2 questions per intent: F1 >= 0.90): "
                     f"{f1:.3f}, {'met' if f1 >= 0.90 else 'not met'}.")
        if r.get("bound"):
            lines.append(f"  The best 2 questions per intent chosen with the labels (the fewest wrong decisions per "
                         f"intent: the ceiling of any policy when answers only re-threshold) reach "
                         f"{r['bound']['f1']:.3f}.")
    else:
        lines.append("- Target 1 (inferred intents, `gift-paper`, at most 2 questions per intent: F1 >= 0.90): not "
                     "measured by this run (it has no `gift-paper` run with inferred intents).")
    lines += ["- Target 2 (the best policy needs at most half the questions random needs for the same F1): the "
              "ratios in each suite's table below; 0.5 or less meets it.",
              *(["- The rule by which answers move the cut was changed once, after the first `gift-paper` run: the "
                 "first rule (the widest-gap midpoint) let one or two hard negatives lift the cut past unasked "
                 "relevant objects (its numbers are in each suite's table below). The dev suites were first run "
                 "with the adopted rule."] if any("widest" in r for r in result["runs"].values())
                and result.get("move", "nearest") == "nearest" else []),
              *([f"- The kernel's own intent candidate decides whatever the answers say (`choose=\"primary\"`, "
                 "rule 3 of `gift.core.queries`)."] if result.get("choose") == "primary" else []),
              *([f"- Answers move the cut by `move=\"{result['move']}\"`"
                 + (" (the default: answers never move the cut" + ("; re-scoring moves the scores)" if result.get("rescore")
                                                                   else ", they only fix the objects they are about)")
                    if result["move"] == "stay" else "")
                 + ("." if any("widest" not in r for r in result["runs"].values()) else
                    "; the first rule tried (the widest-gap midpoint) is in each suite's table below.")]
                if result.get("move", "nearest") != "nearest" else []),
              "- Win rates depend on the simulator's scenes at the commit below: the k = 0 row is `gift reproduce "
              "--kernels gift-prob` at the same commit and sizes.", ""]
    for source in sources:
        lines += [f"## {source.capitalize()} intents", "", f"![query curves, {source} intents]({sub}/{source}.png)", ""]
        for label, r in result["runs"].items():
            if r["intent_source"] != source:
                continue
            grid = r["grid"]
            pols = qc.ran_policies(r["curves"])
            n = sum(i["n_test"] for i in r["intents"].values())
            lines += [f"### `{r['suite']}` ({len(r['intents'])} intents, {n} test objects)", "",
                      "Pooled F1 / mean win rate after k questions per intent:", "",
                      "| policy | " + " | ".join(f"k = {k}" for k in grid) + " |", "|---" * (len(grid) + 1) + "|"]
            for policy in pols + (qc.BASELINE,):
                c = r["curves"][policy]
                cells = []
                for j in range(len(grid)):
                    f1 = _fmt(c["f1"][j]) + (f" ± {c['f1_se'][j]:.3f}" if c.get("f1_se") else "")
                    cells.append(f"{f1} / {_fmt(c['win'][j])}")
                lines.append(f"| {policy}{' (mean of seeds)' if policy == qc.BASELINE else ''} | " +
                             " | ".join(cells) + " |")
            t = r["target"]
            lines += ["", f"Best policy at 2 questions: **{t['best']}**. Questions random needs to reach its F1:", "",
                      "| best policy asks | its F1 | random needs | ratio |", "|---|---|---|---|"]
            for row in t["rows"]:
                lines.append(f"| {row['k']} | {_fmt(row['f1'])} | "
                             f"{'more than ' + str(grid[-1]) if row['random_needs'] is None else _fmt(row['random_needs'], 1)} | "
                             f"{'–' if row['ratio'] is None else _fmt(row['ratio'], 2)} |")
            if r.get("bound"):
                b = r["bound"]
                lines += ["", (f"Ceiling: the best 2 questions per intent, chosen with the labels among all pairs of "
                               f"test objects (the fewest wrong decisions per intent; no policy gets fewer under these "
                               f"rules without re-scoring): pooled F1 {_fmt(b['f1'])}, win rate {_fmt(b['win'])}.")]
            if "widest" in r:
                lines += ["", "The first cut rule tried, the widest-gap midpoint of the evidence (`move=\"widest\"`, "
                          "dropped, see `gift.core.queries`), pooled F1 after k questions:", "",
                          "| policy | " + " | ".join(f"k = {k}" for k in grid) + " |", "|---" * (len(grid) + 1) + "|"]
                for policy in pols + (qc.BASELINE,):
                    lines.append(f"| {policy} | " + " | ".join(_fmt(v) for v in r["widest"][policy]["f1"]) + " |")
            if "without_rescore" in r:
                lines += ["", "The same sessions with answers that only re-threshold the first scores (no re-scoring, "
                          "rule 5 off), pooled F1 / mean win rate after k questions:", "",
                          "| policy | " + " | ".join(f"k = {k}" for k in grid) + " |", "|---" * (len(grid) + 1) + "|"]
                for policy in pols + (qc.BASELINE,):
                    c = r["without_rescore"][policy]
                    lines.append(f"| {policy} | " + " | ".join(f"{_fmt(c['f1'][j])} / {_fmt(c['win'][j])}"
                                                             for j in range(len(grid))) + " |")
            lines += ["", "Abstention at k = 0 (objects within the band of the cut are flagged and dropped like "
                      "distractors; F1 counts them as not aligned, *F1 decided* leaves them out):", "",
                      "| band | flagged objects | F1 (pooled) | F1 decided (mean over intents) | win rate |",
                      "|---|---|---|---|---|",
                      f"| 0 | 0 | {_fmt(r['curves'][pols[0]]['f1'][0])} | "
                      f"{_fmt(r['curves'][pols[0]]['f1_mean_intent'][0])} | "
                      f"{_fmt(r['curves'][pols[0]]['win'][0])} |"]
            for band, a in r["abstention"].items():
                lines.append(f"| {band} | {a['abstained']} | {_fmt(a['f1'])} | {_fmt(a['f1_decided_mean_intent'])} | "
                             f"{_fmt(a['win'])} |")
            lines += ["", "Per intent: F1 at k = 0 and after 2 questions, and the first questions each policy asks:", "",
                      "| intent | relevant / test | F1 k=0 | " + " | ".join(f"{p} k=2" for p in pols) +
                      f" | random k=2 | asked first ({pols[0]}) | note |", "|---" * (6 + len(pols)) + "|"]
            k2 = grid.index(2)
            for i, info in r["intents"].items():
                pi = r["per_intent"]
                lines.append(f"| `{i}` | {info['n_relevant']} / {info['n_test']} | {pi[pols[0]][i]['f1'][0]:.2f} | "
                             + " | ".join(f"{pi[p][i]['f1'][k2]:.2f}" for p in pols)
                             + f" | {pi['random'][i]['f1'][k2]:.2f} | {', '.join(pi[pols[0]][i]['asked'][:2])} | "
                             f"{info['note'] or ''} |")
            lines.append("")
    if result["failures"]:
        lines += ["## Failures", ""] + [f"- {f}" for f in result["failures"]] + [""]
    lines += ["## How to read it", "",
              "- *uncertainty* asks about the object whose decision score is nearest the cut; *disagreement* "
              "about the one `gift-prob`'s LM and MiniLM terms (or, when there are several, the intent "
              "candidates) disagree on most; *error-bound* about the one whose answer is expected to lower the "
              "paper's error bound of the scene's test trajectories most; *random* is the baseline.",
              ("- An answer fixes its object and leaves the cut where it was; the kernel then scores the scene again "
               "with the answers, so objects nobody asked about can move too, in either direction (each table's "
               "\"without re-scoring\" rows: the same sessions where only the objects asked about change)."
               if result.get("move") == "stay" and result.get("rescore") else
               "- An answer fixes its object and, here, leaves the cut where it was: only the objects asked about "
               "change." if result.get("move") == "stay" else
               "- An answer fixes its object and moves the train-calibrated cut, so one answer can also flip "
               "objects that were not asked about, in either direction."),
              "- The issue's targets: with at most 2 questions per intent, inferred-intent F1 of at least 0.90 on "
              "`gift-paper`; the best policy needing at most half the questions random needs for the same F1 "
              "(a ratio of 0.5 or less in the tables above).", ""]
    kept = ""
    if md.exists():  # sections written by hand after the generated page stay (from the marker on)
        old = md.read_text(encoding="utf-8")
        if KEEP in old:
            kept = old[old.index(KEEP):]
    md.write_text("\n".join(lines) + ("\n" + kept if kept else ""), encoding="utf-8")


def qc_grid() -> tuple[int, ...]:
    from gift_experiments.query_curves import K_GRID

    return K_GRID


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--suites", default=",".join(DEFAULT_SUITES))
    p.add_argument("--intent-sources", default="ground-truth")
    p.add_argument("--robot", default="jaco")
    p.add_argument("--kernel", default="gift-prob")
    p.add_argument("--lm", default=None)
    p.add_argument("--random-seeds", type=int, default=10)
    p.add_argument("--stages", default="out/query_curves", help="stage cache directory (kernel scores, intents)")
    p.add_argument("--out", default="docs/results/queries.md")
    p.add_argument("--grid", default=",".join(map(str, qc_grid())), help="questions per intent, must include 2")
    p.add_argument("--policies", default="uncertainty,disagreement,error-bound", help="besides random")
    from gift.core.queries import CHOOSE, DEFAULT_CHOOSE, DEFAULT_MOVE, DEFAULT_RESCORE_WHEN, MOVES, RESCORE_WHEN

    p.add_argument("--move", default=DEFAULT_MOVE, choices=MOVES,
                   help="how answers move the train-calibrated cut (gift.core.queries.MOVES)")
    p.add_argument("--choose", default=DEFAULT_CHOOSE, choices=CHOOSE,
                   help="which intent candidate decides after answers (rule 3 of gift.core.queries)")
    p.add_argument("--rescore", action=argparse.BooleanOptionalAction, default=True,
                   help="the kernel scores each scene again with the answers where it can (rule 5 of "
                        "gift.core.queries; the default, as everywhere answers are used: gift-prob weighs them as "
                        "evidence, no LM call; the curves without it are kept next to them); --no-rescore: answers "
                        "only re-threshold the first scores")
    p.add_argument("--rescore-when", default=DEFAULT_RESCORE_WHEN, choices=RESCORE_WHEN,
                   help="with --rescore: re-score each time the answers grow (always) or only once some answer "
                        "contradicts the kernel's decision without answers (contradicted; rule 5 of gift.core.queries)")
    p.add_argument("--from-json", nargs="+", default=None, metavar="CURVES_JSON",
                   help="write --out from saved curves.json files (their runs merged, nothing recomputed): one page "
                        "from runs made in separate processes")
    args = p.parse_args(argv)
    if args.from_json:
        logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s", datefmt="%H:%M:%S")
        write(merge([json.loads(Path(f).read_text(encoding="utf-8")) for f in args.from_json]), Path(args.out))
        print(f"wrote {args.out} from {len(args.from_json)} saved run file(s)")
        return 0
    args.grid = tuple(int(k) for k in args.grid.split(","))
    args.policies = tuple(s.strip() for s in args.policies.split(",") if s.strip())
    if 2 not in args.grid or 0 not in args.grid:
        p.error("--grid must include 0 and 2")
    args.suites = [s.strip() for s in args.suites.split(",") if s.strip()]
    args.intent_sources = [s.strip() for s in args.intent_sources.split(",") if s.strip()]
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s", datefmt="%H:%M:%S")
    result = run(args)
    if not result["runs"]:
        log.error("nothing ran: %s", result["failures"])
        return 1
    write(result, Path(args.out))
    print(f"wrote {args.out} and {Path(args.out).parent / figure_dir(Path(args.out))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
