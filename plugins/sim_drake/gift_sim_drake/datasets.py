"""Trajectory datasets on disk: ``<stem>.npz`` (arrays) + ``<stem>.json`` (metadata and feature specs),
and a cached "generate or load" keyed by the configuration (robot, task, objects, relevance, seeds,
generator, n, package version)."""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from gift.core.data import FeatureBatch, FeatureSpec, ObjectSpec, TrajectoryBatch
from gift.core.errors import GiftError
from gift.core.paths import cache_root
from gift.core.serialization import to_jsonable

FORMAT_VERSION = 1
_ARRAYS = ("joint_positions", "ee_positions", "object_positions", "landmark_positions")


def _stem(path: str | os.PathLike) -> Path:
    p = Path(path)
    return p.with_suffix("") if p.suffix in (".npz", ".json") else p


def _jsonable(value):
    return to_jsonable(value)


def save_dataset(path: str | os.PathLike, trajectories: TrajectoryBatch,
                 features: FeatureBatch | None = None, meta: dict | None = None) -> Path:
    """Write ``trajectories`` (and ``features``) to ``<stem>.npz`` + ``<stem>.json``; returns the stem."""
    stem = _stem(path)
    stem.parent.mkdir(parents=True, exist_ok=True)
    arrays = {name: getattr(trajectories, name) for name in _ARRAYS}
    if features is not None:
        if len(features) != len(trajectories):
            raise GiftError(f"save_dataset {stem}: {len(features)} feature rows for {len(trajectories)} trajectories")
        arrays["features"] = features.values
    info = {"format": FORMAT_VERSION, "object_names": list(trajectories.object_names),
            "landmark_names": list(trajectories.landmark_names), "trajectory_meta": _jsonable(dict(trajectories.meta)),
            "meta": _jsonable(meta or {}),
            "feature_specs": None if features is None else [
                {"name": s.name, "description": s.description, "subject": s.subject, "reference": s.reference,
                 "kind": s.kind} for s in features.specs],
            "feature_meta": None if features is None else _jsonable(dict(features.meta))}
    tmp_npz = stem.with_name(stem.name + f".{os.getpid()}.tmp.npz")
    np.savez_compressed(tmp_npz, **arrays)
    tmp_json = stem.with_name(stem.name + f".{os.getpid()}.tmp.json")
    tmp_json.write_text(json.dumps(info, indent=1))
    os.replace(tmp_npz, stem.with_suffix(".npz"))
    os.replace(tmp_json, stem.with_suffix(".json"))
    return stem


def load_dataset(path: str | os.PathLike) -> tuple[TrajectoryBatch, FeatureBatch | None, dict]:
    """Read what :func:`save_dataset` wrote: ``(trajectories, features or None, meta)``."""
    stem = _stem(path)
    npz, js = stem.with_suffix(".npz"), stem.with_suffix(".json")
    for f in (npz, js):
        if not f.exists():
            raise GiftError(f"load_dataset: {f} does not exist (a dataset is a .npz plus a .json with the same stem)")
    try:
        info = json.loads(js.read_text())
    except json.JSONDecodeError as e:
        raise GiftError(f"load_dataset: {js} is not valid JSON: {e}") from None
    if info.get("format") != FORMAT_VERSION:
        raise GiftError(f"load_dataset: {js} has format {info.get('format')!r}, expected {FORMAT_VERSION}")
    with np.load(npz) as f:
        arrays = {k: f[k] for k in f.files}
    missing = [k for k in _ARRAYS if k not in arrays]
    if missing:
        raise GiftError(f"load_dataset: {npz} lacks arrays {missing}")
    batch = TrajectoryBatch(arrays["joint_positions"], arrays["ee_positions"], arrays["object_positions"],
                            info["object_names"], landmark_positions=arrays["landmark_positions"],
                            landmark_names=info["landmark_names"], meta=info["trajectory_meta"])
    features = None
    if info.get("feature_specs") is not None:
        specs = tuple(FeatureSpec(**s) for s in info["feature_specs"])
        features = FeatureBatch(specs, arrays["features"], info.get("feature_meta") or {})
    return batch, features, info["meta"]


def dataset_key(robot: str, task: str, objects: Sequence[ObjectSpec], relevant: Sequence[str], scene_seed: int,
                generator: str, n: int, seed: int, robot_fingerprint: str = "") -> str:
    """A stable hash of everything that determines a generated dataset (``robot_fingerprint``:
    :func:`gift_sim_drake.robots.robot_fingerprint`, so an edited URDF or spec makes a new key)."""
    from importlib.metadata import version

    config = {"robot": robot, "robot_fingerprint": robot_fingerprint, "task": task, "relevant": sorted(relevant), "scene_seed": int(scene_seed),
              "generator": generator, "n": int(n), "seed": int(seed), "format": FORMAT_VERSION,
              "package": version("gift-sim-drake"),
              "objects": [[o.name, o.appearance.shape, list(o.appearance.size), list(o.appearance.color)]
                          for o in objects]}
    return hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:20]


def generate_or_load(simulator, task: str, objects: Sequence[ObjectSpec], relevant: Sequence[str], *,
                     scene_seed: int, generator: str, n: int, seed: int,
                     cache_dir: str | os.PathLike | None = None) -> tuple[TrajectoryBatch, FeatureBatch]:
    """The dataset of this configuration from ``cache_dir`` (default ``$GIFT_CACHE_DIR/datasets``), generated
    (scene, trajectories, features) and saved on first use."""
    from gift_sim_drake.simulator import as_object_specs

    objects = as_object_specs(objects)
    if cache_dir is None:
        cache_dir = cache_root() / "datasets"
    from gift_sim_drake.robots import robot_fingerprint

    key = dataset_key(simulator.robot.name, task, objects, relevant, scene_seed, generator, n, seed,
                      robot_fingerprint(simulator.robot))
    stem = Path(cache_dir) / f"{simulator.name}-{task}-{generator}-{key}"
    if stem.with_suffix(".npz").exists() and stem.with_suffix(".json").exists():
        batch, features, _ = load_dataset(stem)
        if features is not None:
            return batch, features
    scene = simulator.make_scene(task, objects, relevant, scene_seed)
    batch = simulator.generate(scene, generator, n, seed)
    features = simulator.features(batch, task)
    save_dataset(stem, batch, features, meta={"key": key, "simulator": simulator.name, "task": task,
                                              "scene_seed": int(scene_seed), "generator": generator, "n": int(n),
                                              "seed": int(seed), "objects": [o.name for o in objects],
                                              "relevant": sorted(relevant)})
    return batch, features
