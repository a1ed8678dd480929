import numpy as np
import pytest

from gift.core.data import (
    DISTRACTOR, Alignment, Appearance, DemonstrationPair, FeatureBatch, FeatureSpec, FeatureTrace, Intent,
    Message, Motivation, ObjectSpec, Scene, Trajectory, TrajectoryBatch, as_messages, proximity_feature, slug,
)
from gift.core.errors import ValidationError


def test_object_spec_defaults_and_validation():
    o = ObjectSpec("coffee mug", "a ceramic cup with a handle")
    assert o.appearance == Appearance()
    assert o.slug == "coffee_mug"
    with pytest.raises(ValidationError, match="name"):
        ObjectSpec("  ")
    with pytest.raises(ValidationError, match="shape"):
        Appearance(shape="cone")
    with pytest.raises(ValidationError, match="cylinder needs 2"):
        Appearance(shape="cylinder", size=(0.1, 0.1, 0.1))
    with pytest.raises(ValidationError, match="color"):
        Appearance(color=(2, 0, 0))
    with pytest.raises(ValidationError, match="metres"):
        Appearance(size=(0, 1, 1))
    with pytest.raises(Exception):
        o.name = "x"  # frozen


def test_scene_validation():
    objs = (ObjectSpec("a"), ObjectSpec("b"))
    s = Scene("pack_backpack", objs, relevant={"a"}, positions=np.zeros((2, 3)), seed=3)
    assert s.object_names == ("a", "b")
    with pytest.raises(ValidationError, match="duplicate"):
        Scene("pack_backpack", (ObjectSpec("a"), ObjectSpec("a")))
    with pytest.raises(ValidationError, match="not in the scene"):
        Scene("pack_backpack", objs, relevant={"c"})
    with pytest.raises(ValidationError, match="positions"):
        Scene("pack_backpack", objs, positions=np.zeros((3, 3)))


def test_trajectory_batch_shapes_and_indexing():
    n, t = 4, 61
    b = TrajectoryBatch(np.zeros((n, t, 7)), np.zeros((n, t, 3)), np.zeros((n, t, 2, 3)), ["a", "b"],
                        landmark_positions=np.zeros((n, t, 1, 3)), landmark_names=["backpack"])
    assert len(b) == 4 and b.n_steps == 61
    assert len(b[1:3]) == 2 and len(b[0]) == 1
    assert not b.joint_positions.flags.writeable
    with pytest.raises(ValidationError, match="ee_positions"):
        TrajectoryBatch(np.zeros((n, t, 7)), np.zeros((n, t, 2)), np.zeros((n, t, 2, 3)), ["a", "b"])
    with pytest.raises(ValidationError, match="object_positions"):
        TrajectoryBatch(np.zeros((n, t, 7)), np.zeros((n, t, 3)), np.zeros((n, t, 3, 3)), ["a", "b"])
    with pytest.raises(ValidationError, match="duplicate"):
        TrajectoryBatch(np.zeros((n, t, 7)), np.zeros((n, t, 3)), np.zeros((n, t, 2, 3)), ["a", "a"])
    one = Trajectory(np.zeros((t, 7)), np.zeros((t, 3)), np.zeros((t, 2, 3)), ["a", "b"])
    assert len(one) == 1


def test_features_reindex_trace_text_and_pairs():
    specs = (proximity_feature("paintbrush", "backpack"), FeatureSpec("ee_height", "height", kind="ee_height"))
    vals = np.arange(2 * 3 * 2, dtype=float).reshape(2, 3, 2)
    fb = FeatureBatch(specs, vals)
    assert fb.names == ("paintbrush_proximity_to_backpack", "ee_height")
    other = (proximity_feature("banana", "backpack"),) + specs
    r = fb.reindex(other)
    assert r.values.shape == (2, 3, 3)
    assert np.all(r.values[..., 0] == 0) and np.array_equal(r.values[..., 1:], vals)
    text = fb.trace(0).to_text()
    assert text.splitlines()[0] == "Timestep 0: paintbrush_proximity_to_backpack: 0.00, ee_height: 1.00"
    with pytest.raises(ValidationError):
        FeatureBatch(specs, np.zeros((2, 3, 3)))
    with pytest.raises(ValidationError, match="duplicate"):
        FeatureBatch(specs + specs[:1], np.zeros((2, 3, 3)))
    pair = DemonstrationPair(fb.trace(0), fb.trace(1))
    assert pair.preferred.names == pair.default.names
    with pytest.raises(ValidationError):
        DemonstrationPair(fb.trace(0), FeatureTrace(specs[:1], np.zeros((3, 1))))
    assert FeatureBatch.concat([fb, fb]).values.shape == (4, 3, 2)


def test_proximity_feature_subject_and_slug():
    f = proximity_feature("mug", "laptop", subject="laptop")
    assert f.name == "mug_proximity_to_laptop" and f.subject == "laptop" and f.reference == "mug"
    assert slug("MacBook Pro!") == "macbook_pro"
    with pytest.raises(ValidationError):
        proximity_feature("mug", "laptop", subject="cup")


def test_intent_alignment_and_error_bound():
    intent = Intent("pack art supplies", motivations=[Motivation("m1", ["a", "b"]), Motivation("m2", ["b", "c"])])
    assert intent.relevant_features == ("a", "b", "c")
    with pytest.raises(ValidationError):
        Motivation("m", "a_feature")  # a bare string is not a list
    al = Alignment({"clay": "paintbrush", "toothbrush": DISTRACTOR}, {"clay": 0.8, "toothbrush": 0.1})
    assert al.target("clay") == "paintbrush" and al.target("unknown") == DISTRACTOR
    assert al.relevant(["paintbrush"]) == {"clay": True, "toothbrush": False}
    # L * sum_t (1 - K): 61 states, K = 0.8 on the aligned object, distractor dropped
    assert al.error_bound(lipschitz=2.0, n_steps=61) == pytest.approx(2.0 * 61 * 0.2)
    with pytest.raises(ValidationError, match=r"\[0, 1\]"):
        Alignment({"clay": "paintbrush"}, {"clay": 1.5})
    with pytest.raises(ValidationError, match="does not map"):
        Alignment({"clay": "paintbrush"}, {"pencil": 0.5})


def test_messages():
    assert as_messages("hi") == (Message("user", "hi"),)
    assert as_messages([{"role": "system", "content": "s"}])[0].role == "system"
    with pytest.raises(ValueError):
        Message("robot", "x")


def test_a_messages_cut_hint_stays_within_its_content_and_out_of_what_a_model_is_sent():
    m = Message("user", "Is a kettle one of the tools?", cut=21)
    assert m.content[: m.cut] == "Is a kettle one of th" and m.to_dict() == {"role": "user", "content": m.content}
    assert Message("user", "x").cut == 0 and m != Message("user", m.content)
    assert as_messages([{"role": "user", "content": "abc", "cut": 2}])[0].cut == 2
    with pytest.raises(ValueError, match="cut 9 is outside the content's 3 characters"):
        Message("user", "abc", cut=9)
    with pytest.raises(ValueError, match="outside"):
        Message("user", "abc", cut=-1)
