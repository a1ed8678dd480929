"""Query curves: alignment F1 and win rate against the number of questions per intent, per query policy.

The expensive part runs once per intent (:func:`prepare`): exactly the chain of ``gift reproduce`` up to the
kernel's alignment (the same seeds, the same stage cache, so the answers of the LM are reused), plus the
RQ1 test scenes and the reward learned from the demonstrations. Everything after is offline
(:func:`simulate`): each policy asks k = 0, 1, 2, 4, 8 questions per intent, answered from the suite's
labels (the simulated human), and the scene is re-scored from the kernel's scores
(:mod:`gift.core.queries`); F1 is pooled over the suite's test objects (train-calibrated cut after the
answers) and the win rate is the mean over intents of the RQ1 win rate of the re-scored alignment.
``random`` is averaged over several seeds. :func:`figure` draws the curves from the saved JSON (for
reports: ``figure(json.load(open("curves.json"))["runs"], path)``).
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from gift.core.alignment import AlignmentScores
from gift.core.metrics import binary_metrics, mean_se, pairwise_win_rate
from gift.core.queries import (DEFAULT_CHOOSE, DEFAULT_MOVE, DEFAULT_RESCORE_WHEN, Answer, QueryProblem, QueryState,
                               asking, labels_answerer, resolve)

log = logging.getLogger("gift.query_curves")

K_GRID = (0, 1, 2, 4, 8)
POLICIES = ("uncertainty", "disagreement", "error-bound")
BASELINE = "random"
BANDS = (0.02, 0.05, 0.1)
THRESHOLD = "train-calibrated"


@attrs.frozen(eq=False)
class IntentData:
    """One intent, ready for offline sessions: the kernel's ``scores``, the labels of its test objects, and
    (None when the scenes could not be built) the RQ1 ``scenes`` ``[(features, truth, pairs)]`` and ``reward``."""

    intent: str
    scores: AlignmentScores
    labels: Mapping[str, bool]
    scenes: Sequence[tuple[Any, np.ndarray, np.ndarray]] | None = None
    reward: Any = None
    intent_text: str = ""
    relevant: tuple[str, ...] = ()
    note: str = ""
    #: The kernel's re-scoring with answers (rule 5 of :mod:`gift.core.queries`), None when it has none.
    rescore: Any = None


def prepare(cfg: Any, suite: Any, spec: Any, cache: Any, comp: Any) -> IntentData:
    """The chain of ``gift reproduce`` for one intent up to ``cfg.kernels[0]``'s alignment (stage-cached),
    the RQ1 scenes and the reward. A scene the simulator cannot build (objects that do not fit, an action out
    of reach) leaves the win rate out, with a ``note``; in inferred mode the demonstrations are needed."""
    from gift.core.data import Intent
    from gift.core.errors import GiftError
    from gift.core.queries import kernel_rescorer
    from gift.study.chain import (align_stage, get_training, intent_seeds, intent_stage, relevant_training,
                                  rq1_scenes)
    from gift.study.progress import Progress

    seeds = intent_seeds(cfg, spec.id)
    note = ""
    try:  # the simulator may fail to place or reach a scene (a GiftError naming it)
        training = get_training(comp, cfg, suite, spec, seeds["train"])
    except GiftError as e:
        if cfg.intent_source == "inferred":
            raise
        training, note = None, f"no demonstrations ({e}): no win rate"
    relevant = relevant_training(cfg, spec, training)
    if cfg.intent_source == "inferred":
        inferred = intent_stage(comp, cfg, suite, spec, training, relevant, cache, log.info, Progress(False))
        intent = Intent.from_dict(inferred["main"])
    else:
        intent = Intent(text=spec.text, source="ground-truth")
    rec = align_stage(comp, cfg, suite, spec, cfg.kernels[0], intent, relevant, cfg.thresholds, cache)
    scores = AlignmentScores.from_dict(rec["scores"])
    scenes = reward = None
    if training is not None:
        try:
            scenes = rq1_scenes(comp, cfg, suite, spec, seeds["rq1"], Progress(False))
            reward = comp.reward(cfg.reward).fit(training.demonstrations, training.alternatives)
        except GiftError as e:
            scenes, note = None, f"test scenes: {e}: no win rate"
    labels = {t.object: t.relevant for t in spec.test}

    def again(answers: Mapping[str, bool]) -> AlignmentScores | None:
        """Re-scoring with answers (rule 5); the kernel (and its LM) is built only when a session re-scores."""
        kernel = comp.kernel(cfg.kernels[0])
        rescore = kernel_rescorer(kernel, suite.specs(spec.test_objects), suite.specs(spec.train_objects),
                                  intent if getattr(kernel, "uses_intent", False) else None,
                                  relevant_train=tuple(relevant.names), need=tuple(cfg.thresholds))
        return None if rescore is None else rescore(answers)

    return IntentData(spec.id, scores, labels, scenes, reward, intent.text, tuple(relevant.names), note, again)


def session(data: IntentData, policy: str, seed: int = 0, band: float = 0.0,
            grid: Sequence[int] = K_GRID, move: str = DEFAULT_MOVE, rescore: bool = True,
            choose: str = DEFAULT_CHOOSE, rescore_when: str = DEFAULT_RESCORE_WHEN) -> list[QueryState]:
    """The states after k questions for each k of ``grid`` (the last state when every object was asked);
    ``rescore``: the kernel scores the scene again with the answers when it can (rule 5, the default as in
    :func:`gift.core.queries.align_with_queries`; ``gift-prob`` weighs them as evidence, no LM call); False:
    answers only re-threshold."""
    trajectories = [f for f, _, _ in data.scenes] if data.scenes else []
    problem = QueryProblem.of(data.scores, THRESHOLD, trajectories=trajectories, abstain=band, move=move,
                              rescore=data.rescore if rescore else None, choose=choose, rescore_when=rescore_when)
    states = list(asking(problem, policy, labels_answerer(data.labels), max(grid), seed=seed))
    return [states[min(k, len(states) - 1)] for k in grid]


def outcome(data: IntentData, state: QueryState) -> dict[str, Any]:
    """Counts, F1 and (with scenes) the mean RQ1 win rate of one state; ``decided``: F1 without abstained objects."""
    y = np.array([data.labels[t] for t in state.test])
    m = binary_metrics(state.predicted, y)
    keep = ~np.isin(state.test, state.abstained)
    out = {"tp": m.tp, "fp": m.fp, "tn": m.tn, "fn": m.fn, "f1": m.f1, "asked": len(state.answers),
           "abstained": len(state.abstained), "f1_decided": binary_metrics(state.predicted[keep], y[keep]).f1,
           "win": None}
    if data.scenes and data.reward is not None:
        out["win"] = float(np.mean([pairwise_win_rate(data.reward.score_aligned(f, state.alignment), truth, pairs)
                                    for f, truth, pairs in data.scenes]))
    return out


def _aggregate(per_intent: Mapping[str, dict[str, Any]]) -> dict[str, Any]:
    """Pooled F1 (counts summed over intents), mean per-intent F1, mean win rate over intents with scenes."""
    tp, fp, fn = (sum(o[k] for o in per_intent.values()) for k in ("tp", "fp", "fn"))
    wins = [o["win"] for o in per_intent.values() if o["win"] is not None]
    return {"f1": 2 * tp / (2 * tp + fp + fn) if tp + fp + fn else 0.0,
            "f1_mean_intent": float(np.mean([o["f1"] for o in per_intent.values()])),
            "f1_decided_mean_intent": float(np.mean([o["f1_decided"] for o in per_intent.values()])),
            "win": float(np.mean(wins)) if wins else None,
            "asked": float(np.mean([o["asked"] for o in per_intent.values()])),
            "abstained": int(sum(o["abstained"] for o in per_intent.values()))}


def best_questions(data: IntentData, k: int = 2, move: str = DEFAULT_MOVE,
                   choose: str = DEFAULT_CHOOSE) -> tuple[QueryState, dict[str, Any]]:
    """The ceiling of any policy: the ``k`` questions, chosen with the labels among all sets of ``k`` test
    objects, after whose answers (rules 1-3 of :mod:`gift.core.queries`, no re-scoring) the scene has the fewest
    wrong decisions (fp + fn; ties: more tp, then the first set in scene order). Per intent no policy gets fewer
    wrong decisions with ``k`` questions; pooled F1 is not separable over intents, so it is the ceiling of F1 up to
    that. Returns the state and its :func:`outcome`."""
    problem = QueryProblem.of(data.scores, THRESHOLD, move=move, choose=choose)
    y = np.array([data.labels[t] for t in problem.test])
    best, best_value = None, None
    for chosen in itertools.combinations(problem.test, min(k, len(problem.test))):
        state = resolve(problem, [Answer(o, bool(data.labels[o])) for o in chosen])
        m = binary_metrics(state.predicted, y)
        value = (-(m.fp + m.fn), m.tp)
        if best_value is None or value > best_value:
            best, best_value = state, value
    return best, outcome(data, best)


def simulate(data: Sequence[IntentData], *, random_seeds: int = 10, grid: Sequence[int] = K_GRID,
             bands: Sequence[float] = BANDS, move: str = DEFAULT_MOVE, rescore: bool = True,
             policies: Sequence[str] = POLICIES, choose: str = DEFAULT_CHOOSE,
             rescore_when: str = DEFAULT_RESCORE_WHEN) -> dict[str, Any]:
    """Every policy (and ``random`` over ``random_seeds`` seeds) at every k of ``grid`` on one suite; abstention
    at k = 0 for each band; ``move``: how answers move the cut (:data:`gift.core.queries.MOVES`); ``rescore``:
    the kernel scores each scene again with the answers where it can (rule 5); ``policies``: the policies run; ``choose``:
    which intent candidate decides after answers (rule 3, :data:`gift.core.queries.CHOOSE`); ``rescore_when``: when
    answers re-score (:data:`gift.core.queries.RESCORE_WHEN`). Returns
    ``{"grid", "curves": {policy: {...}}, "per_intent", "abstention", "bound", "rescored_intents"}``; ``bound``:
    the best 2 questions per intent chosen with the labels (:func:`best_questions`, the ceiling of any policy when
    answers only re-threshold), None when some session re-scored its scene or without 2 in the grid;
    ``rescored_intents``: the intents where some session's scene was scored again with answers (none with
    ``rescore=False`` or a kernel that cannot re-score)."""
    curves: dict[str, Any] = {}
    per_intent: dict[str, Any] = {}
    rescored: set[str] = set()  # intents where some session's scene was actually scored again (rule 5)
    for policy in tuple(policies) + (BASELINE,):
        seeds = range(random_seeds) if policy == BASELINE else (0,)
        runs = []  # per seed: [per k: aggregate]
        by_intent: dict[str, list] = {d.intent: [] for d in data}
        for seed in seeds:
            outcomes = {}
            for d in data:
                states = session(d, policy, seed, grid=grid, move=move, rescore=rescore, choose=choose,
                                 rescore_when=rescore_when)
                if any(st.rescored for st in states):
                    rescored.add(d.intent)
                outcomes[d.intent] = [outcome(d, st) for st in states]
            runs.append([_aggregate({i: o[k] for i, o in outcomes.items()}) for k in range(len(grid))])
            for i, o in outcomes.items():
                by_intent[i].append(o)
        curve: dict[str, Any] = {}
        for key in ("f1", "f1_mean_intent", "win", "asked"):
            vals = np.array([[r[k][key] if r[k][key] is not None else np.nan for k in range(len(grid))]
                             for r in runs], dtype=float)
            curve[key] = [None if np.isnan(v) else float(v) for v in np.nanmean(vals, axis=0)] \
                if not np.all(np.isnan(vals)) else [None] * len(grid)
            if len(runs) > 1:
                curve[key + "_se"] = [float(mean_se(vals[:, k])[1]) if not np.any(np.isnan(vals[:, k])) else None
                                      for k in range(len(grid))]
        curves[policy] = curve
        per_intent[policy] = {i: {"f1": [float(np.mean([o[k]["f1"] for o in runs_i])) for k in range(len(grid))],
                                  "win": [None if runs_i[0][k]["win"] is None else
                                          float(np.mean([o[k]["win"] for o in runs_i])) for k in range(len(grid))]}
                              for i, runs_i in by_intent.items()}
    for policy in policies:  # which objects each deterministic policy asked about, in order, per intent
        for d in data:
            last = session(d, policy, 0, grid=(max(grid),), move=move, rescore=rescore, choose=choose,
                           rescore_when=rescore_when)[0]
            per_intent[policy][d.intent]["asked"] = [a.object for a in last.answers]
    bound = None
    if 2 in grid and not rescored:  # what any policy could reach with 2 questions (answers only re-threshold)
        found = {d.intent: best_questions(d, 2, move, choose) for d in data}
        bound = {"k": 2, **_aggregate({i: o for i, (_, o) in found.items()}),
                 "asked": {i: [a.object for a in st.answers] for i, (st, _) in found.items()}}
    abstention = {}
    for band in bands:
        outs = {d.intent: outcome(d, session(d, policies[0], 0, band, grid=(0,), move=move, choose=choose)[0])
                for d in data}
        abstention[str(band)] = _aggregate(outs)
    return {"grid": list(grid), "curves": curves, "per_intent": per_intent, "abstention": abstention,
            "bound": bound, "rescored_intents": [d.intent for d in data if d.intent in rescored]}


def ran_policies(curves: Mapping[str, Any]) -> tuple[str, ...]:
    """The policies (not ``random``) a run's ``curves`` hold: those of :data:`POLICIES` in that order, then any
    other (a run may ask with a subset, ``--policies``)."""
    return tuple(p for p in POLICIES if p in curves) + tuple(p for p in curves if p not in POLICIES + (BASELINE,))


def queries_to_reach(grid: Sequence[int], values: Sequence[float | None], target: float) -> float | None:
    """The number of questions at which a curve first reaches ``target`` (linear between grid points);
    None when it does not within the grid."""
    prev_k, prev_v = None, None
    for k, v in zip(grid, values):
        if v is None:
            return None
        if v >= target - 1e-9:
            if prev_k is None or v == prev_v:
                return float(k)
            return float(prev_k + (k - prev_k) * (target - prev_v) / (v - prev_v))
        prev_k, prev_v = k, v
    return None


def target_check(sim: Mapping[str, Any], at: Sequence[int] = (1, 2, 4)) -> dict[str, Any]:
    """The best policy (highest pooled F1 at 2 questions) against random: for each k in ``at`` the F1 it
    reaches and the number of questions random needs to reach it."""
    grid = sim["grid"]
    k2 = grid.index(2)
    run = list(ran_policies(sim["curves"]))
    best = max(run, key=lambda p: (sim["curves"][p]["f1"][k2], -run.index(p)))
    rows = []
    for k in (k for k in at if k in grid):
        f1 = sim["curves"][best]["f1"][grid.index(k)]
        rand = queries_to_reach(grid, sim["curves"][BASELINE]["f1"], f1)
        rows.append({"k": k, "f1": f1, "random_needs": rand,
                     "ratio": (k / rand) if rand else None})
    return {"best": best, "rows": rows}


def figure(runs: Mapping[str, Mapping[str, Any]], path: Path, title: str = "") -> Path:
    """Two rows (pooled F1, mean win rate) x one column per run (``{label: simulate(...)}``): a line per
    policy, random as its mean over seeds with ± 1 SE."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(runs)
    fig, axes = plt.subplots(2, len(labels), figsize=(4.2 * len(labels), 6.4), squeeze=False, sharex=True)
    styles = {"uncertainty": ("tab:blue", "o"), "disagreement": ("tab:orange", "s"),
              "error-bound": ("tab:green", "^"), BASELINE: ("tab:gray", "x")}
    for c, label in enumerate(labels):
        sim = runs[label]
        grid = sim["grid"]
        for r, (key, name) in enumerate((("f1", "alignment F1 (pooled)"), ("win", "win rate (mean over intents)"))):
            ax = axes[r][c]
            for policy in ran_policies(sim["curves"]) + (BASELINE,):
                vals = sim["curves"][policy][key]
                if all(v is None for v in vals):
                    continue
                y = np.array([np.nan if v is None else v for v in vals], dtype=float)
                color, marker = styles.get(policy, ("tab:purple", "d"))
                ax.plot(grid, y, marker=marker, color=color, label=policy, linestyle="--" if policy == BASELINE else "-")
                se = sim["curves"][policy].get(key + "_se")
                if se:
                    s = np.array([np.nan if v is None else v for v in se], dtype=float)
                    ax.fill_between(grid, y - s, y + s, color=color, alpha=0.2, linewidth=0)
            ax.set_xticks(grid)
            ax.grid(alpha=0.3)
            if r == 0:
                ax.set_title(label, fontsize=9)
            if r == 1:
                ax.set_xlabel("questions per intent")
            if c == 0:
                ax.set_ylabel(name)
    axes[0][0].legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
