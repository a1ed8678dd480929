"""Pytest fixtures and contract checks for gift plugin authors (a pytest plugin, like pytest's own).

Installing gift registers this module through the ``pytest11`` entry point, so every test suite in an
environment with gift sees these fixtures without importing anything:

- ``gift_plugin_manager``: a freshly loaded :class:`~gift.plugins.manager.GiftPluginManager` (the process-wide
  one is forgotten before and after the test, so entry points installed just now are discovered).
- ``tiny_suite``: a three-intent :class:`~gift.core.suite.Suite` parsed from :data:`TINY_SUITE`.
- ``tiny_objects``: ``(train, test, intent)`` of the suite's first intent: ObjectSpecs and a ground-truth Intent.
- ``kernel_contract``: :func:`check_kernel_contract`, to call on any kernel instance.
- ``reward_contract``: :func:`check_reward_contract`, to call on any unfitted reward model.

The checks are plain functions too, for use outside pytest.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from gift.core.data import FeatureBatch, FeatureSpec, Intent, ObjectSpec, proximity_feature
from gift.core.interfaces import RewardModel, SimilarityKernel
from gift.core.suite import Suite, parse_suite
from gift.plugins.manager import GiftPluginManager, get_manager, reset_manager

#: A small suite in the suite-file format (see docs/suites.md): three intents of two task families.
TINY_SUITE: dict = {
    "suite": "tiny",
    "description": "three small intents for plugin tests",
    "objects": {
        "paintbrush": {"description": "a brush for painting art on paper",
                       "appearance": {"shape": "cylinder", "size": [0.01, 0.2], "color": [0.8, 0.6, 0.2]}},
        "sketchbook": {"description": "a book of blank paper pages for drawing art",
                       "appearance": {"shape": "box", "size": [0.2, 0.15, 0.02], "color": [0.9, 0.9, 0.85]}},
        "banana": {"description": "a yellow fruit to eat",
                   "appearance": {"shape": "cylinder", "size": [0.02, 0.18], "color": [0.95, 0.85, 0.2]}},
        "coffee mug": {"description": "a ceramic cup for hot drinks",
                       "appearance": {"shape": "cylinder", "size": [0.04, 0.1], "color": [0.9, 0.9, 0.9]}},
        "molding clay": {"description": "soft clay for sculpting art",
                         "appearance": {"shape": "box", "size": [0.08, 0.08, 0.04], "color": [0.8, 0.3, 0.2]}},
        "toothbrush": {"description": "a small brush for cleaning teeth",
                       "appearance": {"shape": "cylinder", "size": [0.01, 0.18], "color": [0.2, 0.6, 0.9]}},
        "laptop": {"description": "a portable computer with a keyboard and screen",
                   "appearance": {"shape": "box", "size": [0.33, 0.23, 0.02], "color": [0.3, 0.3, 0.3]}},
        "tablet": {"description": "a flat touchscreen computer",
                   "appearance": {"shape": "box", "size": [0.25, 0.17, 0.01], "color": [0.1, 0.1, 0.1]}},
        "apple": {"description": "a round red fruit to eat",
                  "appearance": {"shape": "sphere", "size": [0.04], "color": [0.8, 0.1, 0.1]}},
        "notebook": {"description": "paper pages bound together for notes",
                     "appearance": {"shape": "box", "size": [0.21, 0.15, 0.02], "color": [0.3, 0.5, 0.8]}},
    },
    "intents": [
        {"id": "art_supplies", "task": "pack_backpack", "text": "pack the art supplies",
         "train_objects": ["paintbrush", "sketchbook", "banana", "coffee mug"],
         "relevant_train": ["paintbrush", "sketchbook"],
         "test": [{"object": "molding clay", "relevant": True},
                  {"object": "toothbrush", "relevant": False, "confounds": ["lang", "vis"]},
                  {"object": "apple", "relevant": False}]},
        {"id": "electronics", "task": "place_mug", "text": "keep the coffee away from electronics",
         "train_objects": ["laptop", "notebook", "banana"],
         "relevant_train": ["laptop"],
         "test": [{"object": "tablet", "relevant": True},
                  {"object": "sketchbook", "relevant": False, "confounds": ["vis"]}]},
        {"id": "food", "task": "store_drawer", "text": "store the food",
         "train_objects": ["banana", "coffee mug", "notebook"],
         "relevant_train": ["banana"],
         "test": [{"object": "apple", "relevant": True},
                  {"object": "laptop", "relevant": False}]},
    ],
}


def tiny_suite_object(known_tasks: Sequence[str] | None = None) -> Suite:
    """:data:`TINY_SUITE` parsed by the strict suite loader."""
    return parse_suite(TINY_SUITE, path="<gift.testing.TINY_SUITE>", known_tasks=known_tasks)


def check_kernel_contract(kernel: SimilarityKernel, train: Sequence[ObjectSpec] | None = None,
                          test: Sequence[ObjectSpec] | None = None, intent: Intent | None = None) -> np.ndarray:
    """Assert what every :class:`SimilarityKernel` promises; return K of ``test`` × ``train``.

    - it is a SimilarityKernel with a non-empty ``name`` and a bool ``uses_intent``;
    - ``similarity`` returns a finite float array ``[n_test, n_train]`` with values in [0, 1];
    - the same call twice gives the same matrix (deterministic);
    - an empty test or training list gives an empty ``[0, n_train]`` / ``[n_test, 0]`` array, not an error;
    - rows do not depend on which other test objects share the call (batching is an implementation detail);
    - if ``uses_intent`` is False, passing an intent changes nothing.
    """
    suite = tiny_suite_object()
    spec = suite.intents[0]
    train = tuple(train) if train is not None else suite.specs(spec.train_objects)
    test = tuple(test) if test is not None else suite.specs(spec.test_objects)
    intent = intent if intent is not None else Intent(spec.text, source="ground-truth")
    assert isinstance(kernel, SimilarityKernel), f"{kernel!r} is not a gift SimilarityKernel"
    assert isinstance(getattr(kernel, "name", None), str) and kernel.name.strip(), "kernel.name must be set"
    assert isinstance(kernel.uses_intent, bool), "kernel.uses_intent must be a bool"

    k = np.asarray(kernel.similarity(test, train, intent))
    assert k.shape == (len(test), len(train)), f"{kernel.name}: K must be [n_test, n_train], got {k.shape}"
    assert np.issubdtype(k.dtype, np.floating), f"{kernel.name}: K must be a float array, got {k.dtype}"
    assert np.all(np.isfinite(k)), f"{kernel.name}: K has non-finite values"
    assert k.min() >= 0.0 and k.max() <= 1.0, f"{kernel.name}: K must be in [0, 1], got [{k.min()}, {k.max()}]"
    again = np.asarray(kernel.similarity(test, train, intent))
    np.testing.assert_array_equal(k, again, err_msg=f"{kernel.name}: K is not deterministic")
    for row in range(len(test)):
        single = np.asarray(kernel.similarity(test[row:row + 1], train, intent))
        np.testing.assert_allclose(single[0], k[row], atol=1e-6,
                                   err_msg=f"{kernel.name}: row of {test[row].name!r} depends on the batch")
    assert np.asarray(kernel.similarity((), train, intent)).shape == (0, len(train)), \
        f"{kernel.name}: no test objects must give a [0, n_train] array"
    assert np.asarray(kernel.similarity(test, (), intent)).shape == (len(test), 0), \
        f"{kernel.name}: no training objects must give a [n_test, 0] array"
    if not kernel.uses_intent:
        np.testing.assert_allclose(np.asarray(kernel.similarity(test, train, None)), k, atol=1e-9,
                                   err_msg=f"{kernel.name}: uses_intent is False but the intent changes K")
    return k


def toy_feature_batches(seed: int = 0, n: int = 24, t: int = 11
                        ) -> tuple[FeatureBatch, FeatureBatch, tuple[FeatureSpec, ...]]:
    """Demonstrations and alternatives ``[n, t, 3]`` where demonstrations bring ``a`` and not ``b`` to a box.

    Returns ``(demonstrations, alternatives, specs)``; columns ``a_proximity_to_box``,
    ``b_proximity_to_box`` and ``ee_height``.
    """
    rng = np.random.default_rng(seed)
    specs = (proximity_feature("a", "box"), proximity_feature("b", "box"),
             FeatureSpec("ee_height", "height of the end effector", kind="ee_height"))
    ramp = np.linspace(0.0, 1.0, t)[None, :]
    demo = np.stack([ramp * rng.uniform(0.8, 1.0, (n, 1)), ramp * rng.uniform(0.0, 0.2, (n, 1)),
                     rng.uniform(0.2, 0.4, (n, t))], axis=-1)
    alt = np.stack([ramp * rng.uniform(0.0, 1.0, (n, 1)), ramp * rng.uniform(0.0, 1.0, (n, 1)),
                    rng.uniform(0.2, 0.4, (n, t))], axis=-1)
    return FeatureBatch(specs, demo), FeatureBatch(specs, alt), specs


def check_reward_contract(model: RewardModel, tmp_dir) -> np.ndarray:
    """Assert what every :class:`RewardModel` promises on :func:`toy_feature_batches`; return the scores.

    ``fit`` returns the model; ``score`` gives finite ``[N]`` and ranks demonstrations above alternatives
    on average; columns are matched by name (a permuted batch scores the same); ``save``/``load``
    round-trips the scores.
    """
    demo, alt, specs = toy_feature_batches()
    assert model.fit(demo, alt) is model, "fit must return the model itself"
    assert tuple(s.name for s in model.feature_specs) == tuple(s.name for s in specs)
    s_demo, s_alt = np.asarray(model.score(demo)), np.asarray(model.score(alt))
    assert s_demo.shape == (len(demo),) and np.all(np.isfinite(s_demo)), "score must be finite [N]"
    assert s_demo.mean() > s_alt.mean(), "the learned reward must prefer the demonstrations"
    permuted = demo.reindex(tuple(reversed(specs)))
    np.testing.assert_allclose(model.score(permuted), s_demo, atol=1e-9,
                               err_msg="score must match columns by name, not position")
    path = f"{tmp_dir}/reward.json"
    model.save(path)
    np.testing.assert_allclose(type(model).load(path).score(demo), s_demo, atol=1e-9)
    return s_demo


# ----------------------------------------------------------------------------- fixtures


@pytest.fixture
def gift_plugin_manager() -> GiftPluginManager:
    """A freshly loaded plugin manager (entry points are discovered again; forgotten after the test)."""
    reset_manager()
    yield get_manager()
    reset_manager()


@pytest.fixture
def tiny_suite() -> Suite:
    """:data:`TINY_SUITE` as a :class:`~gift.core.suite.Suite`."""
    return tiny_suite_object()


@pytest.fixture
def tiny_objects(tiny_suite) -> tuple[tuple[ObjectSpec, ...], tuple[ObjectSpec, ...], Intent]:
    """``(train, test, intent)`` of the tiny suite's ``art_supplies`` intent."""
    spec = tiny_suite.intents[0]
    return tiny_suite.specs(spec.train_objects), tiny_suite.specs(spec.test_objects), \
        Intent(spec.text, source="ground-truth")


@pytest.fixture
def kernel_contract():
    """:func:`check_kernel_contract`: call it with a kernel instance (and optionally objects, intent)."""
    return check_kernel_contract


@pytest.fixture
def reward_contract(tmp_path):
    """``check(model)``: :func:`check_reward_contract` with a temporary directory for save/load."""
    return lambda model: check_reward_contract(model, tmp_path)
