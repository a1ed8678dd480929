"""What ``gift view`` replays of a study run, in Drake's Meshcat (:mod:`gift_sim_drake.viewer`).

Two views per intent of a ``gift demo`` / ``gift reproduce`` output folder:

- ``demos``: the first training scene of the run with its demonstration pairs (a preferred demonstration,
  then the intent-blind default one, as the LM saw them in Call 1);
- ``test``: the first RQ1 test scene, its objects marked by their alignment under one kernel (a disc per
  object, coloured by the training object it maps to, grey for a distractor), and the best- and
  worst-scored of the scene's test trajectories under the aligned reward R_θ(f_ω(ξ')).

Scenes and trajectories are regenerated from ``results.json`` (configuration, suite, the seeds derived from
the intent id) by the functions of :mod:`gift.study` that made them: the simulator is deterministic, so
they are the ones the run used; in the process that just ran the study Drake's IK cache makes this take
a second or two. The reward is refitted on the run's training set (MaxEnt IRL, deterministic). The
alignment is the run's record in ``results["alignment"]``.

:func:`export_views` writes ``out/views/<intent>_<view>.html`` (self-contained Meshcat pages) and
``out/views/index.json`` (what was written, or why a view failed); ``gift demo`` and ``gift reproduce``
call it after ``write_report``.
"""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

import gift
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch
from gift.core.errors import GiftError

log = logging.getLogger(__name__)

VIEWS = ("demos", "test")
#: Kernel whose alignment the test view shows when none is asked for (the first present).
KERNEL_PREFERENCE = ("gift-prob", "gift", "lm-no-intent", "language", "vision")
#: Marker colours: one per training object an object maps to (in order of first use); grey for a distractor.
PALETTE = ((0.17, 0.63, 0.17), (0.12, 0.47, 0.71), (0.58, 0.40, 0.74), (1.0, 0.5, 0.05), (0.09, 0.75, 0.81),
           (0.89, 0.47, 0.76), (0.74, 0.74, 0.13), (0.55, 0.34, 0.29))
DISTRACTOR_RGB = (0.3, 0.3, 0.3)


# ----------------------------------------------------------------------------- reading a run


def run_config(results: Mapping[str, Any]):
    """The :class:`~gift.study.chain.StudyConfig` of a results dictionary (unknown keys dropped)."""
    from gift.study.chain import StudyConfig

    cfg = results.get("config") or {}
    if not cfg:
        raise GiftError("results.json has no 'config' section: cannot regenerate the run's scenes")
    names = {f.name for f in attrs.fields(StudyConfig)}
    return StudyConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in cfg.items() if k in names})


def main_threshold(results: Mapping[str, Any]) -> str | None:
    ths = (results.get("config") or {}).get("thresholds") or []
    return ths[0] if ths else None


def load_alignments(results: Mapping[str, Any], out: Path | None, intent: str) -> dict[str, dict[str, dict]]:
    """``{kernel: {threshold: {"cut", "note", "mapping", "scores", "objects"?, "fallbacks"?, "relevant_train"?}}}``
    of one intent: from ``results["alignment"]`` (the study's records), else, for runs made before it,
    from the old stage cache ``out/stages/<config key>/align-<intent>-<kernel>.json`` (empty when neither)."""
    found: dict[str, dict[str, dict]] = {}
    for kernel, rec in (((results.get("alignment") or {}).get(intent)) or {}).items():
        if not isinstance(rec, Mapping) or not isinstance(rec.get("thresholds"), Mapping):
            continue
        shared = {k: rec[k] for k in ("objects", "fallbacks", "relevant_train", "details") if k in rec}
        found[kernel] = {th: {**shared, **block} for th, block in rec["thresholds"].items()}
    key = (results.get("manifest") or {}).get("config_key")
    if out is not None and key:
        stages = Path(out) / "stages" / key
        for kernel in (results.get("config") or {}).get("kernels") or []:
            path = stages / f"align-{intent}-{kernel}.json"
            if kernel not in found and path.is_file():
                try:
                    found[kernel] = json.loads(path.read_text())
                except ValueError as e:
                    log.warning("unreadable stage file %s: %s", path, e)
    return found


def relevant_training(results: Mapping[str, Any], intent: str, spec=None) -> tuple[str, ...] | None:
    """The training objects the run treated as relevant (inferred from the demonstrations, or the suite's)."""
    rel = ((results.get("relevant") or {}).get(intent) or {}).get("names")
    if rel is not None:
        return tuple(rel)
    return tuple(spec.relevant_train) if spec is not None else None


def pick_kernel(alignments: Mapping[str, Any], kernel: str | None = None) -> str:
    from gift.study.components import parse_spec

    if kernel is not None:
        if kernel not in alignments:
            raise GiftError(f"no alignment of kernel {kernel!r} in this run; it has {sorted(alignments) or 'none'}")
        return kernel
    by_name = {parse_spec(k)[0]: k for k in sorted(alignments, reverse=True)}
    for k in KERNEL_PREFERENCE:
        if k in by_name:
            return by_name[k]
    if alignments:
        return sorted(alignments)[0]
    raise GiftError("this run recorded no alignment (no kernel finished, or results.json predates them)")


@attrs.frozen
class IntentViews:
    """The regenerated material of one intent: scenes, trajectories, reward, alignment.

    ``preferred`` / ``default``: the demonstrations of the first training scene (None when the run used
    saved demonstrations, which hold features only); ``test``: the preferred, default and random
    trajectories of the first RQ1 test scene with ``aligned_score`` ``[N]`` (R_θ(f_ω(ξ'))) and
    ``true_reward`` ``[N]`` (the task's ground truth for the scene's relevant objects)."""

    intent: str
    robot: str
    train_scene: Any
    preferred: Any
    default: Any
    test_scene: Any
    test: Any
    aligned_score: np.ndarray
    true_reward: np.ndarray
    kernel: str | None
    alignment: Alignment | None
    relevant_test: frozenset[str]
    relevant_train: tuple[str, ...]
    simulator: Any = None  # the simulator that generated the trajectories (replays them too)


def _concat(batches):
    from gift.core.data import TrajectoryBatch

    first = batches[0]
    return TrajectoryBatch(np.concatenate([b.joint_positions for b in batches]),
                           np.concatenate([b.ee_positions for b in batches]),
                           np.concatenate([b.object_positions for b in batches]), first.object_names,
                           landmark_positions=np.concatenate([b.landmark_positions for b in batches]),
                           landmark_names=first.landmark_names,
                           meta={"acted_on": sum((list(b.meta.get("acted_on", [])) for b in batches), []),
                                 "action_labels": sum((list(b.meta.get("action_labels", [])) for b in batches), []),
                                 "generator": sum(([b.meta.get("generator", "")] * len(b) for b in batches), [])})


def intent_views(results: Mapping[str, Any], out: Path | None, intent: str, kernel: str | None = None,
                 components=None) -> IntentViews:
    """Regenerate one intent's first training scene (with its demonstrations) and first RQ1 test scene (with
    its trajectories scored by the reward aligned under ``kernel``; default: :data:`KERNEL_PREFERENCE`),
    as :mod:`gift.study.chain` made them (same seeds, same generators)."""
    from gift.study.chain import ORACLE, get_training, intent_seeds, oracle_alignment, simulator_name
    from gift.study.components import Components
    from gift.study.scenes import stable_seed, test_scene

    cfg = run_config(results)
    suite = gift.load_suite(cfg.suite)
    spec = suite.intent(intent)
    comp = components or Components(cfg.lm, cfg.defaults)
    sim = comp.simulator(simulator_name(cfg.robot))
    task = comp.task(spec.task)
    seeds = intent_seeds(cfg, spec.id)
    training = get_training(comp, cfg, suite, spec, seeds["train"])
    reward = comp.reward(cfg.reward).fit(training.demonstrations, training.alternatives)
    train_scene, preferred, default = training.scenes[0], None, None
    if not cfg.demonstrations:  # the first training scene's demonstrations, as scenes.training_set drew them
        preferred = sim.generate(train_scene, "preferred", cfg.demos_per_scene, stable_seed("p", spec.id, 0))
        default = sim.generate(train_scene, "default", cfg.demos_per_scene, stable_seed("d", spec.id, 0))
    seed = seeds["rq1"][0]  # the first RQ1 test scene and its trajectories, as chain.win_rates drew them
    scene = test_scene(sim, suite, spec, cfg.test_objects_per_scene, seed)
    specs = task.feature_specs(scene.object_names)
    batches = []
    for g in ("preferred", "default", "random"):
        b = sim.generate(scene, g, cfg.trajectories_per_generator, stable_seed(seed, g))
        batches.append(attrs.evolve(b, meta={**b.meta, "generator": g}))
    test = _concat(batches)
    feats = FeatureBatch.concat([sim.features(b, spec.task).reindex(specs) for b in batches])
    truth = np.asarray(task.ground_truth_reward(feats, sorted(scene.relevant)), dtype=float)
    alignments = load_alignments(results, out, intent)
    th = main_threshold(results)
    if alignments:
        name = pick_kernel(alignments, kernel)
        block = alignments[name].get(th) or next(iter(alignments[name].values()))
        alignment = Alignment(block["mapping"], block.get("scores", {}), block.get("cut"), kernel=name)
    elif kernel is not None:
        raise GiftError(f"no alignment of kernel {kernel!r} in this run")
    else:
        alignment, name = oracle_alignment(spec), ORACLE
    score = np.asarray(reward.score_aligned(feats, alignment), dtype=float)
    return IntentViews(intent, cfg.robot, train_scene, preferred, default, scene, test, score, truth, name,
                       alignment, frozenset(t.object for t in spec.test if t.relevant),
                       relevant_training(results, intent, spec) or (), sim)


# ----------------------------------------------------------------------------- replays


def _acted(batch, i: int) -> tuple[str, str]:
    acted = list(batch.meta.get("acted_on", []))
    labels = list(batch.meta.get("action_labels", []))
    return (acted[i] if i < len(acted) else "?"), (labels[i] if i < len(labels) else "")


def marker_colours(alignment: Alignment, objects: Sequence[str]) -> dict[str, tuple[float, float, float]]:
    """Per object: the colour of the training object it maps to (:data:`PALETTE`, in order of first use),
    or :data:`DISTRACTOR_RGB`."""
    colours: dict[str, tuple[float, float, float]] = {}
    targets: dict[str, tuple[float, float, float]] = {}
    for o in objects:
        t = alignment.target(o)
        if t == DISTRACTOR:
            colours[o] = DISTRACTOR_RGB
        else:
            colours[o] = targets.setdefault(t, PALETTE[len(targets) % len(PALETTE)])
    return colours


def build_replay(views: IntentViews, which: str, simulator=None, meshcat=None, pairs: int = 2):
    """Record one view (``"demos"`` or ``"test"``) into ``meshcat`` (default: a new localhost server)."""
    from gift_sim_drake.viewer import Clip, Marker

    if which not in VIEWS:
        raise GiftError(f"unknown view {which!r}; views: {', '.join(VIEWS)}")
    sim = simulator or views.simulator
    if not callable(getattr(sim, "replay", None)):
        raise GiftError(f"the simulator of robot {views.robot!r} ({type(sim).__name__}) cannot replay trajectories "
                        "(it has no replay method; the Drake simulators have one)")
    if which == "demos":
        if views.preferred is None:
            raise GiftError(f"{views.intent}: the run used saved demonstrations (features only): there are no "
                            "demonstration trajectories to replay; --show test still works")
        scene = views.train_scene
        clips = []
        for i in range(min(pairs, len(views.preferred), len(views.default))):
            obj, label = _acted(views.preferred, i)
            clips.append(Clip(f"pair {i + 1}, preferred demonstration: {label or obj}"
                              f"{' (a relevant object)' if obj in scene.relevant else ''}", views.preferred[i]))
            obj, label = _acted(views.default, i)
            clips.append(Clip(f"pair {i + 1}, default (intent-blind) trajectory: {label or obj}", views.default[i]))
        title = f"{views.intent}: demonstrations in a training scene ({views.robot})"
        notes = (f"Training objects in this scene: {', '.join(scene.object_names)}; the human cares about "
                 f"{', '.join(sorted(scene.relevant)) or 'none of them'}.",)
        return sim.replay(scene, clips, title=title, notes=notes, meshcat=meshcat)
    scene = views.test_scene
    order = np.argsort(-views.aligned_score, kind="stable")
    clips = []
    for tag, i in (("best", int(order[0])), ("worst", int(order[-1]))):
        obj, label = _acted(views.test, i)
        gen = views.test.meta["generator"][i]
        rel = "relevant" if obj in scene.relevant else "not relevant"
        clips.append(Clip(f"{tag} under the aligned reward: {label or obj} ({obj} is {rel}; aligned reward "
                          f"{views.aligned_score[i]:.2f}, true reward {views.true_reward[i]:.2f}, a {gen} trajectory)",
                          views.test[i]))
    colours = marker_colours(views.alignment, scene.object_names)
    markers = []
    for o in scene.object_names:
        target = views.alignment.target(o)
        truth = "relevant" if o in views.relevant_test else "not relevant"
        right = (target != DISTRACTOR and target in views.relevant_train) == (o in views.relevant_test)
        what = f"maps to {target}" if target != DISTRACTOR else "distractor"
        markers.append(Marker(o, colours[o], f"{o}: {what} (truly {truth}{'' if right else '; wrong'})"))
    title = f"{views.intent}: a test scene aligned by {views.kernel} ({views.robot})"
    notes = (f"Discs under the objects: their alignment by {views.kernel} (colour = the training object they map "
             f"to, grey = distractor). The clips are the best- and worst-scored of {len(views.test)} test "
             f"trajectories under the aligned reward.",)
    return sim.replay(scene, clips, markers=markers, title=title, notes=notes, meshcat=meshcat)


def export_views(results: Mapping[str, Any], out: Path, *, intents: Sequence[str] | None = None,
                 max_intents: int = 2, kernel: str | None = None, components=None) -> list[dict[str, Any]]:
    """Write ``out/views/<intent>_<view>.html`` for the first ``max_intents`` intents (or ``intents``) and
    ``out/views/index.json``. A view that fails is logged and recorded with its error; nothing raises,
    so a finished run keeps its results. Returns the index entries."""
    from gift_sim_drake.viewer import new_meshcat

    out = Path(out)
    folder = out / "views"
    folder.mkdir(parents=True, exist_ok=True)
    chosen = list(intents) if intents is not None else list(results.get("rq1") or results.get("intents") or {})
    chosen = chosen[:max_intents]
    entries: list[dict[str, Any]] = []
    meshcat = None
    for intent in chosen:
        t0 = time.perf_counter()
        try:
            views = intent_views(results, out, intent, kernel=kernel, components=components)
        except Exception as e:  # noqa: BLE001 - a view is a convenience; the run's results are already written
            log.warning("views of %s: %s: %s", intent, type(e).__name__, e)
            entries += [{"intent": intent, "view": v, "error": f"{type(e).__name__}: {e}"} for v in VIEWS]
            continue
        prep = time.perf_counter() - t0
        for which in VIEWS:
            t1 = time.perf_counter()
            entry: dict[str, Any] = {"intent": intent, "view": which}
            try:
                if meshcat is None:
                    meshcat = new_meshcat()
                rep = build_replay(views, which, meshcat=meshcat)
                path = folder / f"{intent}_{which}.html"
                path.write_text(rep.static_html(), encoding="utf-8")
                entry.update(file=f"views/{path.name}", title=rep.title,
                             clips=[s.caption for s in rep.segments], duration_s=rep.duration_s,
                             kernel=views.kernel if which == "test" else None)
            except Exception as e:  # noqa: BLE001
                log.warning("view %s of %s: %s: %s", which, intent, type(e).__name__, e)
                entry["error"] = f"{type(e).__name__}: {e}"
            entry["seconds"] = round(time.perf_counter() - t1 + (prep if which == VIEWS[0] else 0.0), 2)
            entries.append(entry)
    (folder / "index.json").write_text(json.dumps(entries, indent=2))
    return entries


def view_command(out: Path, *, intent: str | None = None, show: str = "test", kernel: str | None = None,
                 pairs: int = 2, export: Path | None = None, port: int | None = None,
                 seconds: float | None = None) -> int:
    """``gift view``: one view of a run, served live on localhost (until Ctrl-C or ``seconds``) or written
    to ``export`` as a self-contained HTML page."""
    from gift_sim_drake.viewer import new_meshcat

    path = Path(out) / "results.json"
    if not path.is_file():
        raise GiftError(f"no results.json in {out}: give the output folder of gift demo or gift reproduce")
    try:
        results = json.loads(path.read_text())
    except ValueError as e:
        raise GiftError(f"{path} is not valid JSON: {e}") from None
    known = list(results.get("rq1") or results.get("intents") or {})
    if not known:
        raise GiftError(f"{path} holds no intent")
    if intent is None:
        intent = known[0]
    elif intent not in known:
        raise GiftError(f"intent {intent!r} is not in {path}; it has {', '.join(known)}")
    views = intent_views(results, Path(out), intent, kernel=kernel)
    meshcat = new_meshcat(port)
    rep = build_replay(views, show, meshcat=meshcat, pairs=pairs)
    if export is not None:
        export = Path(export)
        export.parent.mkdir(parents=True, exist_ok=True)
        export.write_text(rep.static_html(), encoding="utf-8")
        print(f"{rep.title}: {export} ({export.stat().st_size / 1e6:.1f} MB, {rep.duration_s:.0f} s of animation)")
        return 0
    lines = [rep.title, f"Meshcat: {rep.url}  (localhost only; Ctrl-C to stop)"]
    lines += [f"  {s.start_s:5.1f}-{s.end_s:5.1f} s  {s.caption}" for s in rep.segments]
    lines += [f"  marker: {m.caption}" for m in rep.markers]
    print("\n".join(lines), flush=True)
    deadline = None if seconds is None else time.monotonic() + seconds
    try:
        while deadline is None or time.monotonic() < deadline:
            time.sleep(0.2 if deadline is None else max(0.0, min(0.2, deadline - time.monotonic())))
    except KeyboardInterrupt:
        pass
    return 0
