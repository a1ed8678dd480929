"""RGB images of one object alone, from three viewpoints, by Drake's ``RgbdSensor`` and the VTK render
engine (headless EGL). Cached on disk under ``$GIFT_CACHE_DIR/renders`` (default: the user cache dir of
gift), keyed by the object's appearance and the image size: the name does not change how it looks.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import threading
from pathlib import Path

import numpy as np

from gift.core.data import Appearance, ObjectSpec
from gift.core.errors import GiftError
from gift.core.paths import cache_root

logging.getLogger("drake").setLevel(logging.ERROR)

#: Camera directions from the object centre: front, side, and from above at an angle. The distance is
#: :data:`FRAMING` times the radius of the object's bounding sphere, so every object fills the view alike.
VIEWPOINTS = ((1.0, 0.0, 0.4), (0.1, 1.0, 0.45), (0.55, 0.45, 0.9))
FRAMING = 3.2
RENDER_VERSION = 3
#: Background colour (RGB in [0, 1]): mid grey, so that white and black objects both stand out.
BACKGROUND = (0.5, 0.5, 0.5)
_LOCK = threading.Lock()


def render_cache_dir(cache_dir: str | os.PathLike | None = None) -> Path:
    if cache_dir is None:
        cache_dir = cache_root() / "renders"
    path = Path(cache_dir)
    path.mkdir(parents=True, exist_ok=True)
    return path


def appearance_key(appearance: Appearance, size: int) -> str:
    blob = json.dumps({"shape": appearance.shape, "size": [round(v, 6) for v in appearance.size],
                       "color": [round(v, 6) for v in appearance.color], "px": size, "v": RENDER_VERSION},
                      sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:24]


def _look_at(eye: np.ndarray, target: np.ndarray):
    """Camera pose (Drake convention: +z forward, +y down in the image) looking from ``eye`` at ``target``."""
    from pydrake.math import RigidTransform, RotationMatrix

    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-9 else np.array([1.0, 0.0, 0.0])
    y = np.cross(z, x)
    return RigidTransform(RotationMatrix(np.column_stack([x, y, z])), eye)


def _draw(appearance: Appearance, size: int) -> np.ndarray:
    from pydrake.geometry import (
        ClippingRange,
        ColorRenderCamera,
        DepthRange,
        DepthRenderCamera,
        MakeRenderEngineVtk,
        RenderCameraCore,
        RenderEngineVtkParams,
    )
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder
    from pydrake.systems.sensors import CameraInfo, RgbdSensor

    from gift_sim_drake.plant import shape_of

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    params = RenderEngineVtkParams()
    params.backend = "EGL"
    params.default_clear_color = list(BACKGROUND)
    scene_graph.AddRenderer("vtk", MakeRenderEngineVtk(params))
    plant.RegisterVisualGeometry(plant.world_body(), RigidTransform(), shape_of(appearance), "object",
                                 np.array([*appearance.color, 1.0]))
    plant.Finalize()
    sz = appearance.size
    radius = {"box": 0.5 * float(np.linalg.norm(sz)), "cylinder": float(np.hypot(sz[0], sz[-1] / 2))}.get(
        appearance.shape, sz[0])
    core = RenderCameraCore("vtk", CameraInfo(size, size, np.pi / 4), ClippingRange(0.01, 10.0), RigidTransform())
    color_cam = ColorRenderCamera(core, False)
    depth_cam = DepthRenderCamera(core, DepthRange(0.02, 9.0))
    sensors = []
    for i, direction in enumerate(VIEWPOINTS):
        eye = np.asarray(direction) / np.linalg.norm(direction) * FRAMING * radius
        pose = _look_at(eye, np.zeros(3))
        sensor = builder.AddSystem(RgbdSensor(scene_graph.world_frame_id(), pose, color_cam, depth_cam))
        sensor.set_name(f"camera_{i}")
        builder.Connect(scene_graph.get_query_output_port(), sensor.query_object_input_port())
        sensors.append(sensor)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    images = []
    for sensor in sensors:
        rgba = sensor.color_image_output_port().Eval(sensor.GetMyContextFromRoot(context)).data
        images.append(np.asarray(rgba)[:, :, :3].copy())
    return np.stack(images).astype(np.uint8)


def render_object(obj: ObjectSpec | Appearance, size: int = 224,
                  cache_dir: str | os.PathLike | None = None) -> np.ndarray:
    """Images ``[3, size, size, 3]`` uint8 RGB of one object alone on :data:`BACKGROUND`, from :data:`VIEWPOINTS`."""
    appearance = obj.appearance if isinstance(obj, ObjectSpec) else obj
    if not isinstance(appearance, Appearance):
        raise GiftError(f"render_object needs an ObjectSpec or Appearance, got {type(obj).__name__}")
    if not isinstance(size, (int, np.integer)) or not 16 <= size <= 2048:
        raise GiftError(f"render_object: size must be an integer in [16, 2048] pixels, got {size!r}")
    path = render_cache_dir(cache_dir) / f"{appearance_key(appearance, int(size))}.npz"
    if path.exists():
        with np.load(path) as f:
            return f["images"]
    with _LOCK:  # VTK/EGL contexts are not safe to create concurrently
        images = _draw(appearance, int(size))
    tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
    np.savez_compressed(tmp, images=images)
    os.replace(tmp, path)
    return images
