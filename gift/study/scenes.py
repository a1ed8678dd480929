"""Scenes and demonstrations of a study: which objects share a table, and what the human showed there.

- :func:`pick_objects` / :func:`place_scene`: a random subset of objects (at least one relevant and one
  irrelevant when both exist) laid out by the simulator; a pick that does not fit on the table is
  replaced by the next pick of the same generator (deterministic), up to ``attempts`` picks.
- :class:`TrainingSet` / :func:`training_set`: the training scenes of one intent with the preferred
  (human) and default (nominal controller) demonstrations and random alternatives, as feature batches
  over the intent's training columns. It is what the reward is learned from and what the intent and the
  relevant training objects are inferred from. :func:`save_training_set` / :func:`load_training_set`
  store one (a user can bring their own demonstrations in this format).
- :func:`test_scene`: a scene of unseen test objects.

Seeds: every scene and trajectory seed derives from the intent id (:func:`stable_seed`), so a scene is
the same in every process and on every executor.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from gift.core.data import DemonstrationPair, FeatureBatch, FeatureSpec, Scene
from gift.core.errors import GiftError, PlacementError
from gift.core.suite import IntentSpec, Suite

FORMAT = 1


def stable_seed(*parts: Any) -> int:
    """A 32-bit seed from ``parts`` (their repr), the same in every process."""
    return int.from_bytes(hashlib.sha256(repr(parts).encode()).digest()[:4], "little")


def pick_objects(rel: Sequence[str], irr: Sequence[str], n: int, rng: np.random.Generator) -> list[str]:
    """``n`` names (fewer if there are not enough), at least one relevant and one irrelevant when both exist."""
    n = min(n, len(rel) + len(irr))
    lo = 1 if rel and irr else (n if rel else 0)
    hi = min(len(rel), n - (1 if irr else 0))
    k_rel = int(rng.integers(lo, max(lo, hi) + 1)) if rel else 0
    k_rel = min(k_rel, len(rel))
    names = list(rng.choice(rel, k_rel, replace=False)) if k_rel else []
    names += list(rng.choice(irr, min(n - k_rel, len(irr)), replace=False)) if irr and n > k_rel else []
    rng.shuffle(names)
    return [str(x) for x in names]


def place_scene(sim: Any, suite: Suite, task: str, rel: Sequence[str], irr: Sequence[str], n: int, seed: int,
                attempts: int = 20) -> Scene:
    """A scene of ``n`` objects picked by :func:`pick_objects` from ``seed``; when they do not fit on the
    table, the next pick of the same generator, up to ``attempts`` picks (then :class:`PlacementError`)."""
    rng = np.random.default_rng(seed)
    last: Exception | None = None
    for _ in range(attempts):
        names = pick_objects(rel, irr, n, rng)
        try:
            return sim.make_scene(task, suite.specs(names), [x for x in names if x in rel], seed=seed)
        except PlacementError as e:
            last = e
    raise PlacementError(f"{attempts} random picks of {n} objects for a {task} scene (seed {seed}) did not fit "
                         f"on the table; last: {last}")


@attrs.frozen
class TrainingSet:
    """The training scenes of one intent and what was demonstrated in them.

    Per scene k: ``preferred[k]`` ``[n_demos, T, F]`` (the human's demonstrations), ``default[k]``
    ``[n_demos, T, F]`` (the nominal controller in the same scene) and ``random[k]`` ``[n_alt, T, F]``;
    every batch uses the intent's training columns ``specs`` (a column of an object absent from a scene
    is 0). ``objects``: the training objects the set covers.
    """

    task: str
    objects: tuple[str, ...]
    specs: tuple[FeatureSpec, ...]
    scenes: tuple[Scene, ...]
    preferred: tuple[FeatureBatch, ...]
    default: tuple[FeatureBatch, ...]
    random: tuple[FeatureBatch, ...]

    def __attrs_post_init__(self) -> None:
        n = len(self.scenes)
        if not n or not (len(self.preferred) == len(self.default) == len(self.random) == n):
            raise GiftError(f"TrainingSet: {n} scenes need as many preferred, default and random batches "
                            f"(got {len(self.preferred)}, {len(self.default)}, {len(self.random)})")

    @property
    def demonstrations(self) -> FeatureBatch:
        """Every preferred trajectory: ``[N, T, F]``."""
        return FeatureBatch.concat(list(self.preferred))

    @property
    def alternatives(self) -> FeatureBatch:
        """The alternatives MaxEnt IRL contrasts the demonstrations with (default and random): ``[M, T, F]``."""
        return FeatureBatch.concat([b for pair in zip(self.default, self.random) for b in pair])

    def pairs(self) -> list[DemonstrationPair]:
        """Preferred vs default trajectory pairs, scene by scene (the evidence of the intent)."""
        out = []
        for scene, pref, dflt in zip(self.scenes, self.preferred, self.default):
            out += [DemonstrationPair(pref.trace(i), dflt.trace(i), scene) for i in range(min(len(pref), len(dflt)))]
        return out


def training_set(sim: Any, task: Any, suite: Suite, spec: IntentSpec, *, seeds: Sequence[int], demos: int,
                 alternatives: int, objects_per_scene: int) -> TrainingSet:
    """Simulate the human of ``spec`` in one training scene per seed.

    Each scene holds a random subset of the training objects (:func:`place_scene`); the human's
    relevance (``spec.relevant_train``) drives only the preferred generator, as a person's goal would.
    """
    specs = tuple(task.feature_specs(spec.train_objects))
    rel = list(spec.relevant_train)
    irr = [o for o in spec.train_objects if o not in rel]
    scenes, pref, dflt, rand = [], [], [], []
    for k, seed in enumerate(seeds):
        scene = place_scene(sim, suite, spec.task, rel, irr, objects_per_scene, seed)
        scenes.append(scene)
        for out, gen, n, tag in ((pref, "preferred", demos, "p"), (dflt, "default", demos, "d"),
                                 (rand, "random", alternatives, "r")):
            batch = sim.generate(scene, gen, n, stable_seed(tag, spec.id, k))
            out.append(sim.features(batch, spec.task).reindex(specs))
    return TrainingSet(spec.task, tuple(spec.train_objects), specs, tuple(scenes), tuple(pref), tuple(dflt),
                       tuple(rand))


def test_scene(sim: Any, suite: Suite, spec: IntentSpec, n_objects: int, seed: int) -> Scene:
    """A randomised scene of unseen test objects with at least one relevant and one irrelevant object."""
    rel = [t.object for t in spec.test if t.relevant]
    irr = [t.object for t in spec.test if not t.relevant]
    if not rel or not irr:
        raise GiftError(f"intent {spec.id!r} needs relevant and irrelevant test objects")
    return place_scene(sim, suite, spec.task, rel, irr, n_objects, seed)


test_scene.__test__ = False  # not a pytest test


# ----------------------------------------------------------------------------- files


def save_training_set(path: str | Path, ts: TrainingSet) -> Path:
    """Write ``ts`` as ``<stem>.npz`` (feature arrays) + ``<stem>.json`` (specs, scenes); returns the stem.

    Scenes are stored by object names and positions; the objects' descriptions and appearances come
    from the suite when the set is loaded.
    """
    stem = Path(path)
    stem = stem.with_suffix("") if stem.suffix in (".npz", ".json") else stem
    stem.parent.mkdir(parents=True, exist_ok=True)
    arrays = {}
    for name in ("preferred", "default", "random"):
        for k, b in enumerate(getattr(ts, name)):
            arrays[f"{name}_{k}"] = b.values
    info = {"format": FORMAT, "task": ts.task, "objects": list(ts.objects),
            "specs": [attrs.asdict(s) for s in ts.specs],
            "scenes": [{"objects": list(s.object_names), "positions": s.positions.tolist(),
                        "landmarks": {k: list(map(float, v)) for k, v in s.landmarks.items()}, "seed": s.seed}
                       for s in ts.scenes]}
    tmp = stem.with_name(stem.name + ".tmp.npz")
    np.savez_compressed(tmp, **arrays)
    tmp.replace(stem.with_suffix(".npz"))
    tmp_json = stem.with_name(stem.name + ".tmp.json")
    tmp_json.write_text(json.dumps(info), encoding="utf-8")
    tmp_json.replace(stem.with_suffix(".json"))
    return stem


def load_training_set(path: str | Path, suite: Suite) -> TrainingSet:
    """Read what :func:`save_training_set` wrote; object specs come from ``suite``'s catalog.

    Scenes carry no relevance: a loaded set says only what was demonstrated, not why.
    """
    stem = Path(path)
    stem = stem.with_suffix("") if stem.suffix in (".npz", ".json") else stem
    js, npz = stem.with_suffix(".json"), stem.with_suffix(".npz")
    try:
        info = json.loads(js.read_text(encoding="utf-8"))
        with np.load(npz) as f:
            arrays = {k: f[k] for k in f.files}
    except (OSError, ValueError) as e:
        raise GiftError(f"cannot read the demonstrations {stem} (.json + .npz): {e}") from None
    if info.get("format") != FORMAT:
        raise GiftError(f"demonstrations {js}: format {info.get('format')!r}, expected {FORMAT}")
    specs = tuple(FeatureSpec(**s) for s in info["specs"])
    scenes = tuple(Scene(info["task"], suite.specs(s["objects"]), positions=np.asarray(s["positions"]),
                         landmarks={k: tuple(v) for k, v in s["landmarks"].items()}, seed=int(s["seed"]))
                   for s in info["scenes"])
    batches = {name: tuple(FeatureBatch(specs, arrays[f"{name}_{k}"]) for k in range(len(scenes)))
               for name in ("preferred", "default", "random")}
    return TrainingSet(info["task"], tuple(info["objects"]), specs, scenes, **batches)
