"""language: real all-MiniLM-L6-v2 embeddings (loaded once per process), on names and on descriptions."""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.data import ObjectSpec
from gift_kernels import language
from gift_kernels.embedding_cache import EmbeddingCache

pytestmark = pytest.mark.slow

OBJ = {n: ObjectSpec(n, d) for n, d in [
    ("paintbrush", "a brush with soft bristles for applying paint"),
    ("toothbrush", "a small brush for cleaning teeth"),
    ("banana", "a ripe yellow fruit"),
    ("apple", "a round red fruit"),
    ("watercolor set", "a tin of small cakes of watercolor paint"),
]}


@pytest.fixture(scope="module")
def kernel():
    return gift.get_kernel("language")


def test_names_kernel_is_cosine_in_unit_interval_and_follows_surface_similarity(kernel):
    test = [OBJ["toothbrush"], OBJ["apple"]]
    train = [OBJ["paintbrush"], OBJ["banana"]]
    K = kernel.similarity(test, train)
    assert K.shape == (2, 2) and (K >= 0).all() and (K <= 1).all()
    assert K[0, 0] > K[0, 1]        # toothbrush ~ paintbrush by name (the paper's language confound)
    assert K[1, 1] > K[1, 0]        # apple ~ banana
    self_sim = kernel.similarity([OBJ["banana"]], [OBJ["banana"]])
    assert self_sim[0, 0] == pytest.approx(1.0, abs=1e-5)
    emb = language.embed_texts(["toothbrush", "paintbrush"])
    assert emb.shape == (2, 384)
    assert K[0, 0] == pytest.approx((1 + float(emb[0] @ emb[1])) / 2, abs=1e-5)


def test_descriptions_change_what_is_embedded(kernel):
    desc = gift.get_kernel("language", use_descriptions=True)
    assert language.object_text(OBJ["banana"], True) == "banana: a ripe yellow fruit"
    assert language.object_text(ObjectSpec("widget"), True) == "widget"  # no description: the name
    test, train = [OBJ["watercolor set"]], [OBJ["paintbrush"], OBJ["banana"]]
    Kn, Kd = kernel.similarity(test, train), desc.similarity(test, train)
    assert not np.allclose(Kn, Kd)
    assert Kd[0, 0] > Kd[0, 1]  # both about paint once described
    with pytest.raises(gift.GiftError, match="use_descriptions"):
        gift.get_kernel("language", use_descriptions="yes")


def test_descriptions_alone_leave_the_name_out():
    alone = gift.get_kernel("language", use_descriptions=True, names=False)
    assert language.object_text(OBJ["banana"], True, names=False) == "a ripe yellow fruit"
    assert language.object_text(ObjectSpec("widget"), True, names=False) == "widget"  # no description: the name
    # two things named alike but described apart: the description alone tells them apart, the name pulls them together
    grater = ObjectSpec("cheese grater", "a four-sided steel box with rasps for shredding")
    cheddar = ObjectSpec("wedge of cheddar", "a firm crumbly orange block made from cow's milk")
    both = gift.get_kernel("language", use_descriptions=True)
    assert alone.similarity([grater], [cheddar])[0, 0] < both.similarity([grater], [cheddar])[0, 0]
    same = [ObjectSpec("thing one", "a round red fruit"), ObjectSpec("other name", "a round red fruit")]
    assert alone.similarity(same[:1], same[1:])[0, 0] == pytest.approx(1.0, abs=1e-5)
    with pytest.raises(gift.GiftError, match="names=False embeds the descriptions alone"):
        gift.get_kernel("language", names=False)
    # gift-prob's MiniLM term reads the descriptions alone (embed_text="description", the default)
    from gift_kernels.lm_kernels import GiftProbKernel
    assert GiftProbKernel().language.names is False
    assert GiftProbKernel(embed_text="name+description").language.names is True


def test_embeddings_are_cached_on_disk(tmp_path, monkeypatch):
    monkeypatch.setenv("GIFT_CACHE_DIR", str(tmp_path))
    cache = EmbeddingCache("test-model")
    calls = []

    def compute(texts):
        calls.append(list(texts))
        return language.load_minilm().encode(texts, normalize_embeddings=True)

    a = cache.embed(["mug", "laptop", "mug"], compute)
    assert calls == [["mug", "laptop"]] and a.shape == (3, 384) and np.array_equal(a[0], a[2])
    assert len(list((tmp_path / "embeddings" / "test-model").glob("*.npy"))) == 2
    again = EmbeddingCache("test-model").embed(["laptop", "mug"], compute)  # a new process would do this
    assert len(calls) == 1 and np.allclose(again, a[[1, 0]])
