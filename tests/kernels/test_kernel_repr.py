"""A kernel's ``repr`` is what result files record as the kernel as built (``configuration``): it must name every
option of the constructor, so a run made with another default can be told apart from the file alone."""

from __future__ import annotations

import inspect

import pytest
from gift_kernels.language import LanguageKernel
from gift_kernels.lm_kernels import GiftProbKernel, MappingKernel, NoIntentMappingKernel

import gift


@pytest.mark.parametrize("cls", [GiftProbKernel, MappingKernel, NoIntentMappingKernel, LanguageKernel])
def test_the_repr_names_every_constructor_option(cls):
    text = repr(cls())  # no LM is built until a question is asked
    options = [p for p in inspect.signature(cls.__init__).parameters if p not in ("self", "lm")]
    assert [p for p in options if f"{p}=" not in text] == []


def test_a_spec_option_shows_in_the_repr_of_the_kernel_built_from_it():
    k = gift.get_kernel("gift-prob", embed_text="name+description", weight=0.25)
    assert "embed_text='name+description'" in repr(k) and "weight=0.25" in repr(k)
    assert "embed_text='description'" in repr(gift.get_kernel("gift-prob"))
