import numpy as np

from gift.core.alignment import align_features, align_state
from gift.core.data import DISTRACTOR, Alignment, FeatureBatch
from gift.tasks import PackBackpack, PlaceMug

TRAIN = ["paintbrush", "sketchbook", "banana"]


def _batch(task, objects, rng, n=5, t=7):
    specs = task.feature_specs(objects)
    return FeatureBatch(specs, rng.random((n, t, len(specs))))


def test_alignment_renames_semantic_columns_and_keeps_continuous_ones():
    rng = np.random.default_rng(0)
    task = PackBackpack()
    test = _batch(task, ["molding clay", "toothbrush"], rng)
    al = Alignment({"molding clay": "paintbrush", "toothbrush": DISTRACTOR})
    train_specs = task.feature_specs(TRAIN)
    out = align_features(test, al, train_specs)
    assert out.names == tuple(s.name for s in train_specs)
    v = out.values
    assert np.array_equal(v[..., 0], test.values[..., 0])          # clay -> paintbrush column
    assert np.all(v[..., 1] == 0) and np.all(v[..., 2] == 0)       # sketchbook, banana absent
    assert np.array_equal(v[..., -2:], test.values[..., -2:])      # ee_height, ee_speed untouched
    # single state and batch agree
    s = align_state(test.values[2, 3], test.specs, al, train_specs)
    assert np.array_equal(s, v[2, 3])


def test_many_to_one_combines_by_maximum_and_place_mug_subject_is_the_object():
    rng = np.random.default_rng(1)
    task = PlaceMug()
    test = _batch(task, ["tablet", "phone"], rng)
    al = Alignment({"tablet": "laptop", "phone": "laptop"})
    out = align_features(test, al, task.feature_specs(["laptop", "banana"]))
    assert out.names[0] == "mug_proximity_to_laptop"
    assert np.array_equal(out.values[..., 0], np.maximum(test.values[..., 0], test.values[..., 1]))
    assert np.all(out.values[..., 1] == 0)
