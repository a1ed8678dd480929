"""Features and their text, object renders, datasets on disk, and the plugin listing."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from sim_drake_catalog import FAMILIES, RELEVANT

import gift
from gift.core.alignment import align_features
from gift.core.data import Alignment, Appearance, ObjectSpec
from gift.core.errors import GiftError
from gift.tasks import EE_FEATURES
from gift_sim_drake.datasets import generate_or_load, load_dataset, save_dataset
from gift_sim_drake.features import compute_features, trace_text

pytestmark = pytest.mark.drake


@pytest.fixture(scope="module")
def pack_batch(simulators, objects):
    sim = simulators["drake-franka"]
    scene = sim.make_scene("pack_backpack", objects, RELEVANT, seed=3)
    return sim.generate(scene, "random", 30, seed=2)


@pytest.mark.parametrize("family", FAMILIES)
def test_feature_columns_are_the_task_specs(simulators, objects, family):
    sim = simulators["drake-jaco"]
    b = sim.generate(sim.make_scene(family, objects, RELEVANT, seed=1), "preferred", 5, seed=0)
    f = sim.features(b, family)
    assert f.specs == gift.get_task(family).feature_specs(b.object_names)
    assert f.values.shape == (5, 61, len(objects) + len(EE_FEATURES))
    assert f.values.min() >= 0.0 and f.values.max() <= 1.0
    assert all(s.description for s in f.specs)
    speed = f.values[..., f.names.index("ee_speed")]
    assert (speed[:, 0] == 0).all() and speed[:, 1:].max() > 0.2


def test_proximity_is_one_when_close_and_zero_when_absent(pack_batch):
    f = compute_features(pack_batch, "pack_backpack")
    i = pack_batch.meta["acted_on"].index(pack_batch.meta["acted_on"][0])
    col = f.names.index(f"{gift.core.data.slug(pack_batch.meta['acted_on'][i])}_proximity_to_backpack")
    assert f.values[i, -1, col] > 0.95 and f.values[i, 0, col] < 0.1
    # an absent object (NaN position) has proximity 0, the other columns are unchanged
    absent = pack_batch.object_positions.copy()
    absent[:, :, 1] = np.nan
    g = compute_features(attrs_evolve(pack_batch, object_positions=absent), "pack_backpack")
    assert (g.values[..., 1] == 0).all()
    np.testing.assert_array_equal(np.delete(g.values, 1, axis=2), np.delete(f.values, 1, axis=2))


def attrs_evolve(batch, **kw):
    import attrs

    return attrs.evolve(batch, **kw)


def test_alignment_is_a_renaming_without_new_simulation(pack_batch):
    """Aligned features equal the features of the same motion with the objects renamed to their targets."""
    f = compute_features(pack_batch, "pack_backpack")
    mapping = {"paintbrush": "crayon", "sketchbook": "notebook", "banana": "distractor", "coffee mug": "cup"}
    train_specs = gift.get_task("pack_backpack").feature_specs(["crayon", "notebook", "cup", "apple"])
    aligned = align_features(f, Alignment(mapping), train_specs)
    renamed = attrs_evolve(pack_batch, object_names=tuple(mapping[n] if mapping[n] != "distractor" else "apple"
                                                          for n in pack_batch.object_names))
    direct = compute_features(renamed, "pack_backpack").reindex(train_specs)
    apple = aligned.names.index("apple_proximity_to_backpack")
    np.testing.assert_array_equal(aligned.values[..., apple], 0.0)  # the distractor is dropped
    keep = [j for j in range(len(train_specs)) if j != apple]
    np.testing.assert_array_equal(aligned.values[..., keep], direct.values[..., keep])


def test_trace_text_lists_descriptions_and_every_step(pack_batch):
    f = compute_features(pack_batch, "pack_backpack")
    text = trace_text(f, 0)
    assert "paintbrush_proximity_to_backpack: closeness of the paintbrush to the backpack" in text
    assert "ee_speed: distance the end effector moved" in text
    steps = [ln for ln in text.splitlines() if ln.startswith("Timestep")]
    assert len(steps) == 61 and steps[-1].startswith("Timestep 60: paintbrush_proximity_to_backpack: ")
    assert len(trace_text(f, 0, every=10).splitlines()) < 20
    with pytest.raises(GiftError, match="out of range"):
        trace_text(f, 99)


def test_unknown_feature_kind_is_a_clear_error(pack_batch):
    from gift.core.data import FeatureSpec
    from gift.core.interfaces import Task

    class Odd(Task):
        name = "odd"

        def feature_specs(self, objects):
            return (FeatureSpec("wobble", "how much it wobbles", kind="wobble"),)

        def ground_truth_reward(self, features, relevant):
            return np.zeros(len(features))

    with pytest.raises(GiftError, match="kind 'wobble'"):
        compute_features(pack_batch, Odd())


@pytest.mark.slow
def test_renders_distinguish_appearances(simulators, tmp_path, monkeypatch):
    monkeypatch.setenv("GIFT_CACHE_DIR", str(tmp_path))
    sim = simulators["drake-franka"]
    red = ObjectSpec("red mug", appearance=Appearance("cylinder", (0.04, 0.1), (0.8, 0.1, 0.1)))
    blue = ObjectSpec("blue mug", appearance=Appearance("cylinder", (0.04, 0.1), (0.1, 0.1, 0.8)))
    book = ObjectSpec("book", appearance=Appearance("box", (0.2, 0.15, 0.03), (0.8, 0.1, 0.1)))
    imgs = {o.name: sim.render_object(o, size=64) for o in (red, blue, book)}
    for im in imgs.values():
        assert im.shape == (3, 64, 64, 3) and im.dtype == np.uint8
        assert (im.reshape(3, -1, 3).std(axis=1) > 5).all()  # something is in every view
        assert not np.array_equal(im[0], im[2])  # three different viewpoints
    names = list(imgs)
    for a in range(3):
        for b in range(a + 1, 3):
            assert np.abs(imgs[names[a]].astype(int) - imgs[names[b]].astype(int)).mean() > 2.0
    red_px = imgs["red mug"][0].reshape(-1, 3).astype(int)
    assert ((red_px[:, 0] - red_px[:, 2]) > 60).sum() > 50  # red really is red
    cached = list((tmp_path / "renders").glob("*.npz"))
    assert len(cached) == 3
    again = sim.render_object(ObjectSpec("another name", appearance=red.appearance), size=64)
    assert np.array_equal(again, imgs["red mug"]) and len(list((tmp_path / "renders").glob("*.npz"))) == 3


def test_dataset_roundtrip_and_cache(simulators, objects, tmp_path, pack_batch):
    sim = simulators["drake-franka"]
    f = sim.features(pack_batch, "pack_backpack")
    stem = save_dataset(tmp_path / "d", pack_batch, f, meta={"note": "x"})
    b2, f2, meta = load_dataset(stem.with_suffix(".npz"))
    assert meta == {"note": "x"}
    for name in ("joint_positions", "ee_positions", "object_positions", "landmark_positions"):
        assert np.array_equal(getattr(b2, name), getattr(pack_batch, name))
    assert b2.object_names == pack_batch.object_names and b2.meta["acted_on"] == pack_batch.meta["acted_on"]
    assert f2.specs == f.specs and np.array_equal(f2.values, f.values)

    kw = dict(scene_seed=4, generator="preferred", n=6, seed=1, cache_dir=tmp_path / "cache")
    b3, f3 = generate_or_load(sim, "store_drawer", objects, RELEVANT, **kw)
    files = sorted((tmp_path / "cache").iterdir())
    assert [p.suffix for p in files] == [".json", ".npz"]
    info = json.loads(files[0].read_text())
    assert info["meta"]["generator"] == "preferred" and info["trajectory_meta"]["robot"] == "franka"
    mtime = files[1].stat().st_mtime_ns
    b4, f4 = generate_or_load(sim, "store_drawer", objects, RELEVANT, **kw)
    assert files[1].stat().st_mtime_ns == mtime  # loaded, not regenerated
    assert np.array_equal(b4.joint_positions, b3.joint_positions) and np.array_equal(f4.values, f3.values)
    with pytest.raises(GiftError, match="does not exist"):
        load_dataset(tmp_path / "missing")


def test_gift_plugins_lists_simulators_and_families():
    out = subprocess.run([sys.executable, "-m", "gift.cli", "plugins", "--json"], capture_output=True, text=True,
                         check=True)
    comps = json.loads(out.stdout)["components"]
    sims = {c["name"]: c for c in comps if c["kind"] == "simulator"}
    assert {"drake-franka", "drake-jaco"} <= set(sims)
    assert sims["drake-jaco"]["distribution"] == "gift-sim-drake"
    assert set(FAMILIES) <= {c["name"] for c in comps if c["kind"] == "task"}
