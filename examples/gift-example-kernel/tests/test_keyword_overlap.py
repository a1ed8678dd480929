"""Tests of the example kernel, written with the fixtures gift exports for plugin authors (gift.testing)."""

import numpy as np
import pytest

import gift
from gift.core.data import Intent, ObjectSpec
from gift.core.errors import ValidationError
from gift_example_kernel import KeywordOverlapKernel, keywords


def test_kernel_meets_the_gift_kernel_contract(kernel_contract, tiny_objects):
    train, test, intent = tiny_objects
    k = kernel_contract(KeywordOverlapKernel(), train, test, intent)
    assert k.shape == (len(test), len(train))


def test_plugin_is_discovered_through_its_entry_point(gift_plugin_manager):
    component = gift_plugin_manager.get("kernel", "keyword-overlap")
    assert component.distribution == "gift-example-kernel"
    assert isinstance(gift.get_kernel("keyword-overlap", intent_weight=1.0), KeywordOverlapKernel)


def test_intent_keywords_raise_the_similarity_of_role_sharing_objects(tiny_objects):
    train, test, intent = tiny_objects
    kernel = KeywordOverlapKernel(intent_weight=4.0)
    clay, brush = test.index(next(o for o in test if o.name == "molding clay")), 0
    with_intent = kernel.similarity(test, train, intent)[clay, brush]
    without = kernel.similarity(test, train, None)[clay, brush]
    assert with_intent > without > 0.0  # both mention "art"; the intent "pack the art supplies" stresses it


def test_aligns_by_name_through_the_registered_alignment_operator(gift_plugin_manager, tiny_objects):
    pytest.importorskip("gift_kernels")
    train, test, intent = tiny_objects
    pipe = gift.GiftPipeline(kernel="keyword-overlap", alignment=gift.get_alignment_operator("argmax-threshold",
                                                                                             threshold=0.2))
    alignment = pipe.align(test, train, intent, relevant_train=("paintbrush", "sketchbook"))
    assert alignment.mapping["molding clay"] == "paintbrush"
    assert alignment.mapping["apple"] == "banana"  # both "fruit to eat"
    assert alignment.mapping["toothbrush"] == gift.DISTRACTOR


def test_keywords_drop_stopwords_and_plurals():
    assert keywords("The Markers for painting, and a CUP") == {"marker", "painting", "cup"}
    assert keywords("glass") == {"glass"}


def test_objects_without_keywords_have_zero_similarity():
    k = KeywordOverlapKernel().similarity([ObjectSpec("a")], [ObjectSpec("the")], Intent("anything"))
    np.testing.assert_array_equal(k, [[0.0]])


def test_negative_intent_weight_is_rejected_with_the_value():
    with pytest.raises(ValidationError, match="intent_weight.*-1"):
        KeywordOverlapKernel(intent_weight=-1)
