"""vision: real EfficientNet-Lite0 features; on Drake renders when the drake-franka simulator is installed."""

from __future__ import annotations

import numpy as np
import pytest

import gift
from gift.core.data import Appearance, ObjectSpec
from gift_kernels import vision

pytestmark = pytest.mark.slow


def draw(obj: ObjectSpec, size: int = 96) -> np.ndarray:
    """Three views of a flat-coloured silhouette on a light background: ``[3, size, size, 3]`` uint8."""
    a = obj.appearance
    yy, xx = np.mgrid[:size, :size] / size - 0.5
    views = []
    for k in range(3):
        scale = 0.25 + 0.05 * k
        if a.shape == "sphere":
            mask = xx ** 2 + yy ** 2 < scale ** 2
        elif a.shape == "cylinder":
            mask = (np.abs(xx) < scale * 0.4) & (np.abs(yy) < scale * 1.6)
        else:
            mask = (np.abs(xx) < scale) & (np.abs(yy) < scale * 0.8)
        img = np.full((size, size, 3), 235, dtype=np.uint8)
        img[mask] = (np.asarray(a.color) * 255).astype(np.uint8)
        views.append(img)
    return np.stack(views)


def test_efficientnet_features_and_kernel_on_drawn_views():
    red_ball = ObjectSpec("red ball", appearance=Appearance("sphere", (0.04,), (0.9, 0.1, 0.1)))
    apple = ObjectSpec("apple", appearance=Appearance("sphere", (0.045,), (0.85, 0.15, 0.1)))
    blue_box = ObjectSpec("blue box", appearance=Appearance("box", (0.1, 0.1, 0.1), (0.1, 0.2, 0.9)))
    feats = vision.image_features(draw(red_ball))
    assert feats.shape == (3, 1280) and np.isfinite(feats).all()
    k = gift.get_kernel("vision", renderer=draw, renderer_id="test-drawn-96")
    K = k.similarity([apple], [red_ball, blue_box])
    assert K.shape == (1, 2) and (K >= 0).all() and (K <= 1).all()
    assert K[0, 0] > K[0, 1]  # a red sphere looks like a red sphere, not like a blue box
    with pytest.raises(gift.GiftError, match="renderer_id"):
        gift.get_kernel("vision", renderer=draw)
    with pytest.raises(gift.GiftError, match=r"\[B, H, W, 3\]"):
        vision.image_features(np.zeros((2, 8, 8), dtype=np.uint8))


def test_vision_kernel_on_drake_renders(drake_franka):
    sim = drake_franka
    mug = ObjectSpec("coffee mug", appearance=Appearance("cylinder", (0.04, 0.1), (0.9, 0.9, 0.9)))
    cup = ObjectSpec("paper cup", appearance=Appearance("cylinder", (0.035, 0.1), (0.95, 0.95, 0.9)))
    book = ObjectSpec("book", appearance=Appearance("box", (0.2, 0.15, 0.03), (0.2, 0.3, 0.7)))
    views = sim.render_object(mug)
    assert views.shape == (3, 224, 224, 3) and views.dtype == np.uint8 and views.std() > 0
    k = gift.get_kernel("vision")
    K = k.similarity([cup], [mug, book])
    assert (K >= 0).all() and (K <= 1).all()
    assert K[0, 0] > K[0, 1]  # white cylinder ~ white cylinder, not a blue slab
