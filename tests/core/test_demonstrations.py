"""The relevant training objects inferred from demonstrations (:mod:`gift.core.demonstrations`), on synthetic
feature traces: the two modes, the outlier scenes, the cut and the edge cases. No simulator: the traces are
built here the way a simulator's features look (a constant column for an untouched object; a ramp for an
object moved to a fixed reference; a bump while a moving reference passes an object). The real Drake
families are covered in ``tests/experiments/test_relevant_objects.py``.
"""

from __future__ import annotations

import attrs
import numpy as np
import pytest

from gift.core.data import DemonstrationPair, FeatureTrace, ObjectSpec, Scene, proximity_feature
from gift.core.demonstrations import CUT, RelevantObjects, infer_relevant_objects
from gift.core.errors import ValidationError
from gift.tasks import EE_FEATURES

T = 21
OBJECTS = ("ruby", "opal", "brick", "cork", "nail", "rope")
RELEVANT = ("ruby", "opal")


def acting_specs(objects=OBJECTS):
    return tuple(proximity_feature(o, "box", subject=o) for o in objects) + EE_FEATURES


def passing_specs(objects=OBJECTS):
    return tuple(proximity_feature("cart", o, subject=o) for o in objects) + EE_FEATURES


def scene(names, seed, relevant=()):
    """A scene holding ``names``; ``relevant`` is the ground-truth field the inference must never read."""
    return Scene("test_family", tuple(ObjectSpec(n) for n in names), frozenset(relevant), seed=seed)


def acting_trace(specs, present, acted, rng):
    """Untouched objects keep a constant small closeness; the acted-on one ramps to 1 (moved to the box)."""
    values = np.zeros((T, len(specs)))
    for j, s in enumerate(specs):
        if s.subject in present:
            values[:, j] = rng.uniform(0.01, 0.1)
            if s.subject == acted:
                values[T // 2:, j] = np.linspace(values[0, j], 1.0, T - T // 2)
    values[:, -2:] = rng.uniform(0, 1, size=(T, 2))  # ee columns: not semantic, ignored
    return FeatureTrace(specs, values)


def passing_trace(specs, present, amplitude, rng, noise=0.02):
    """A moving reference passes every present object: a bump of height ``amplitude[o]`` (+ noise)."""
    t = np.linspace(0, 1, T)
    values = np.zeros((T, len(specs)))
    for j, s in enumerate(specs):
        if s.subject in present:
            centre = 0.2 + 0.6 * (present.index(s.subject) + 0.5) / len(present)
            a = max(amplitude[s.subject] + rng.normal(0, noise), 0.0)
            values[:, j] = a * np.exp(-((t - centre) / 0.1) ** 2)
    return FeatureTrace(specs, values)


def acting_pairs(layouts, relevant=RELEVANT, n=6, seed=0, unreachable=(), specs=None):
    """Pairs of a pack-like family: the default acts on the first irrelevant object of each layout, the
    human on a random relevant one present (on random others in the layouts listed in ``unreachable``)."""
    rng = np.random.default_rng(seed)
    specs = specs or acting_specs()
    pairs = []
    for k, names in enumerate(layouts):
        sc = scene(names, k, [o for o in names if o in relevant])
        nominal = next((o for o in names if o not in relevant), names[0])
        rel_here = [o for o in names if o in relevant]
        options = [o for o in names if o not in relevant and o != nominal] if k in unreachable else rel_here
        for _ in range(n):
            pref = acting_trace(specs, names, rng.choice(options) if options else nominal, rng)
            pairs.append(DemonstrationPair(pref, acting_trace(specs, names, nominal, rng), sc))
    return pairs


LAYOUTS = [("ruby", "brick", "cork", "nail"), ("opal", "ruby", "rope", "brick"), ("cork", "opal", "nail", "rope"),
           ("ruby", "rope", "cork", "opal")]


def test_acting_relevant_objects_are_the_ones_the_human_acts_on():
    res = infer_relevant_objects(acting_pairs(LAYOUTS), OBJECTS)
    assert isinstance(res, RelevantObjects)
    assert res.relevant == RELEVANT and res.separates
    assert res.modes == {"proximity:box": "acting"}
    assert all(res.scores[o] > 0.95 for o in RELEVANT)
    assert all(res.scores[o] < 0.05 for o in OBJECTS if o not in RELEVANT)
    assert res.unobserved == () and res.undetermined == ()
    assert res.evidence["ruby"].chosen > 0 and res.evidence["brick"].chosen == 0
    assert res.informative == res.scenes == len(LAYOUTS)


def test_a_scene_whose_relevant_object_the_human_could_not_reach_is_an_outlier():
    """In the third layout the human acts on irrelevant objects (as when Drake cannot reach the relevant
    one): the outlier component absorbs it instead of calling those objects relevant."""
    layouts = LAYOUTS + [("opal", "cork", "nail", "rope")]
    res = infer_relevant_objects(acting_pairs(layouts, unreachable=(4,)), OBJECTS)
    assert res.relevant == RELEVANT
    assert max(res.scores[o] for o in OBJECTS if o not in RELEVANT) < CUT


def test_the_scenes_ground_truth_field_is_never_read():
    pairs = acting_pairs(LAYOUTS)
    corrupted = [attrs.evolve(p, scene=attrs.evolve(p.scene, relevant=frozenset(p.scene.object_names[-1:])))
                 for p in pairs]
    a, b = infer_relevant_objects(pairs, OBJECTS), infer_relevant_objects(corrupted, OBJECTS)
    assert a.relevant == b.relevant and a.scores == b.scores


def test_a_second_relevant_object_avoided_beside_the_first_is_relevant():
    """Passing family: wherever ruby is, the human steers by ruby, so opal beside it is never a pair's choice.
    Kept further from opal in every pair too, opal is relevant (the pairs' avoidances, module docstring step
    4); passed as close as the default beside ruby, it is not, and no irrelevant object rises with it."""
    specs = passing_specs()
    layouts = [("ruby", "opal", "brick", "cork"), ("ruby", "opal", "nail", "rope"), ("ruby", "cork", "rope", "brick"),
               ("opal", "brick", "nail", "rope")]

    def infer(opal_beside_ruby: float):
        rng = np.random.default_rng(0)
        pairs = []
        for k, names in enumerate(layouts):
            base = {o: 1.0 for o in names}
            steered = ({**base, "ruby": 0.4, **({"opal": opal_beside_ruby} if "opal" in names else {})}
                       if "ruby" in names else {**base, "opal": 0.7})
            for _ in range(6 if "ruby" in names else 2):
                pairs.append(DemonstrationPair(passing_trace(specs, list(names), steered, rng),
                                               passing_trace(specs, list(names), base, rng), scene(names, k)))
        return infer_relevant_objects(pairs, OBJECTS)

    both, one = infer(0.8), infer(1.0)
    assert both.modes == one.modes == {"proximity:cart": "passing"}
    assert both.evidence["opal"].chosen <= 2 < both.evidence["ruby"].chosen
    assert both.relevant == ("ruby", "opal") and both.scores["opal"] > 0.95
    assert one.relevant == ("ruby",) and one.scores["opal"] < 0.05
    for res in (both, one):
        assert max(res.scores[o] for o in OBJECTS if o not in RELEVANT) < 0.05


def test_the_cut_is_one_half_of_the_posterior():
    res = infer_relevant_objects(acting_pairs(LAYOUTS[:2], n=2, seed=3), OBJECTS)
    assert res.cut == CUT == 0.5
    assert set(res.relevant) == {o for o, s in res.scores.items() if s > CUT} - set(res.undetermined)
    assert all(0.0 <= s <= 1.0 for s in res.scores.values())
    assert "posterior" in res.rule and "acting" in res.rule


def test_more_demonstrations_sharpen_the_posterior():
    few = infer_relevant_objects(acting_pairs(LAYOUTS[:2], n=1, seed=1), OBJECTS)
    many = infer_relevant_objects(acting_pairs(LAYOUTS[:2], n=6, seed=1), OBJECTS)
    assert many.scores["ruby"] >= few.scores["ruby"]
    assert many.scores["brick"] <= few.scores["brick"]


def test_all_relevant_when_the_human_acts_on_every_object_without_preference():
    res = infer_relevant_objects(acting_pairs(LAYOUTS, relevant=OBJECTS), OBJECTS)
    assert res.relevant == OBJECTS and not res.separates


def test_nothing_relevant_when_the_human_does_what_the_default_does():
    rng = np.random.default_rng(0)
    specs = acting_specs()
    pairs = []
    for k, names in enumerate(LAYOUTS):
        for _ in range(3):
            same = acting_trace(specs, names, names[0], rng)
            pairs.append(DemonstrationPair(same, same, scene(names, k)))
    res = infer_relevant_objects(pairs, OBJECTS)
    assert res.relevant == () and set(res.undetermined) == set(OBJECTS)
    assert res.informative == 0 and "nothing is inferred" in res.rule


def test_an_object_in_no_scene_is_unobserved_not_irrelevant():
    layouts = [tuple(o for o in names if o != "rope") for names in LAYOUTS]
    res = infer_relevant_objects(acting_pairs(layouts), OBJECTS)
    assert res.unobserved == ("rope",) and "rope" not in res.scores
    assert res.relevant == RELEVANT and "rope" not in res.irrelevant


def test_without_scenes_presence_comes_from_the_columns():
    pairs = [attrs.evolve(p, scene=None) for p in acting_pairs(LAYOUTS)]
    res = infer_relevant_objects(pairs, OBJECTS)
    assert res.relevant == RELEVANT
    assert res.scenes == len(pairs)  # every pair is its own scene


def passing_pairs(layouts, amp_default=0.6, amp_pref=None, n=6, seed=0):
    """A mug-like family: the default passes every object at ``amp_default``; the human's detour lowers the
    closeness of the objects in ``amp_pref`` (object -> amplitude) and keeps the others at the default's."""
    rng = np.random.default_rng(seed)
    specs = passing_specs()
    pairs = []
    for k, names in enumerate(layouts):
        names = list(names)
        default = {o: amp_default for o in names}
        pref = {o: amp_pref.get(o, amp_default) for o in names}
        for _ in range(n):
            pairs.append(DemonstrationPair(passing_trace(specs, names, pref, rng),
                                           passing_trace(specs, names, default, rng), scene(names, k)))
    return pairs


def test_passing_relevant_objects_are_the_ones_the_human_steers_around():
    detour = {"ruby": 0.1, "opal": 0.15, "brick": 0.95}  # around the gems, closer to the brick
    res = infer_relevant_objects(passing_pairs(LAYOUTS, amp_pref=detour), OBJECTS)
    assert res.modes == {"proximity:cart": "passing"}
    assert res.relevant == RELEVANT
    assert res.evidence["brick"].approached > 0 and res.evidence["ruby"].avoided > 0
    assert res.scores["brick"] < 0.05


def test_a_detour_that_avoids_every_object_singles_out_none():
    everything = {o: 0.1 for o in OBJECTS}
    res = infer_relevant_objects(passing_pairs(LAYOUTS, amp_pref=everything), OBJECTS)
    assert res.relevant == () and set(res.undetermined) == set(OBJECTS) and not res.separates
    assert res.informative == 0


def test_passing_noise_alone_singles_out_nothing():
    res = infer_relevant_objects(passing_pairs(LAYOUTS, amp_pref={}), OBJECTS)
    assert res.relevant == () and res.informative == 0


@pytest.mark.parametrize("pairs,names,match", [
    ([], OBJECTS, "no demonstration pairs"),
    (None, [], "non-empty list"),
    (None, "ruby", "non-empty list"),
    (None, ["ruby", "ruby"], "duplicate"),
    (["not a pair"], OBJECTS, "not a DemonstrationPair"),
])
def test_bad_input_is_a_clear_error(pairs, names, match):
    pairs = acting_pairs(LAYOUTS[:1], n=1) if pairs is None else pairs
    with pytest.raises(ValidationError, match=match):
        infer_relevant_objects(pairs, names)


def test_pairs_with_different_columns_are_rejected():
    a = acting_pairs(LAYOUTS[:1], n=1)
    b = acting_pairs(LAYOUTS[:1], n=1, specs=acting_specs(OBJECTS[:5]))
    with pytest.raises(ValidationError, match="other feature columns"):
        infer_relevant_objects(a + b, OBJECTS)


def test_scenes_without_a_relevant_object_carry_no_evidence():
    """Twelve objects, scenes of five drawn at random: where no relevant object is present the human does
    what the default does, and such scenes neither promote nor demote their objects."""
    objs = tuple(f"thing{i}" for i in range(12))
    rng = np.random.default_rng(0)
    layouts = [tuple(str(o) for o in rng.choice(objs[:-1], 5, replace=False)) for _ in range(10)]
    layouts.append(("thing11", "thing5", "thing6", "thing7", "thing8"))  # thing11 is only here
    res = infer_relevant_objects(acting_pairs(layouts, relevant=objs[:3], specs=acting_specs(objs)), objs)
    assert res.relevant == objs[:3]
    assert res.undetermined == ("thing11",) and res.unobserved == ()


def test_more_objects_than_the_exhaustive_model_handles_is_a_clear_error():
    from gift.core.demonstrations import MAX_OBJECTS

    objs = tuple(f"thing{i}" for i in range(MAX_OBJECTS + 1))
    layouts = [objs[i:i + 5] for i in range(0, len(objs) - 4, 4)] + [objs[-5:]]
    with pytest.raises(ValidationError, match=f"at most {MAX_OBJECTS}"):
        infer_relevant_objects(acting_pairs(layouts, relevant=objs[:2], n=1, specs=acting_specs(objs)), objs)


@pytest.mark.parametrize("a,b,c,d", [(0, 0, 0, 0), (5, 0, 1, 7), (0, 6, 6, 0), (12, 3, 2, 20)])
def test_the_two_rate_integral_is_exact(a, b, c, d):
    """``_log_two_rates``: 2 ∫∫_{p>q} p^a (1-p)^b q^c (1-q)^d against a fine midpoint grid."""
    from gift.core.demonstrations import _log_two_rates

    g = (np.arange(4000) + 0.5) / 4000
    p, q = np.meshgrid(g, g, indexing="ij")
    grid = 2 * np.sum(np.where(p > q, p ** a * (1 - p) ** b * q ** c * (1 - q) ** d, 0.0)) / g.size ** 2
    assert _log_two_rates(a, b, c, d) == pytest.approx(np.log(grid), abs=2e-3)


def test_pair_avoidance_counts_pairs_and_skips_objects_the_defaults_never_pass():
    from gift.core.demonstrations import pair_avoidance

    default = np.array([[1.0, 1.0, 0.0], [1.1, 0.9, 0.0]])
    pref = np.array([[0.5, 0.95, 0.0], [0.6, 0.8, 0.0], [1.2, 0.85, 0.0]])
    avoided, trials = pair_avoidance(pref, default)
    assert avoided.tolist() == [2.0, 2.0, 0.0] and trials.tolist() == [3.0, 3.0, 0.0]
