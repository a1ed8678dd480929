"""Replays of trajectories on the real scene plant in Drake's Meshcat: live (a local URL) or as one
self-contained HTML file that opens with no server and no network.

A replay is a sequence of :class:`Clip` (one trajectory each, played one after the other in one
animation) on one :class:`~gift.core.data.Scene`, plus optional :class:`Marker` discs under objects (e.g.
coloured by their alignment). Every frame is a state of the :class:`gift_sim_drake.plant.SceneModel`
(arm joints and object positions set on the ``MultibodyPlant``), drawn by Drake's ``MeshcatVisualizer``
and recorded into a Meshcat animation.

:meth:`Replay.static_html` is ``Meshcat.StaticHtml()`` (which inlines meshcat.js and the scene; checked:
no script or style is fetched) with a caption panel added: what each clip shows and when.
"""

from __future__ import annotations

import html
import json
import logging
import re
from collections.abc import Sequence

import attrs
import numpy as np

from gift.core.data import Scene, TrajectoryBatch
from gift.core.errors import GiftError
from gift_sim_drake.robots import RobotSpec

logging.getLogger("drake").setLevel(logging.ERROR)

#: Seconds of animation per trajectory step (61 steps: about 3.7 s per clip) and the still pause between clips.
STEP_S = 0.06
PAUSE_S = 0.6
#: Camera: in front of the table, to the arm's left, looking at the middle of the table (m, world frame).
CAMERA = (1.3, 0.78, 0.72)
TARGET = (0.38, 0.0, 0.08)


def _rgb(value) -> tuple[float, float, float]:
    rgb = tuple(float(v) for v in value)
    if len(rgb) != 3 or not all(0.0 <= v <= 1.0 for v in rgb):
        raise GiftError(f"a colour must be three numbers in [0, 1] (RGB), got {value!r}")
    return rgb  # type: ignore[return-value]


@attrs.frozen
class Clip:
    """One trajectory to replay: ``trajectory`` is a :class:`TrajectoryBatch` of exactly one trajectory
    (``batch[i]``); ``caption`` says what it is (shown in the caption panel)."""

    caption: str
    trajectory: TrajectoryBatch

    def __attrs_post_init__(self) -> None:
        if not isinstance(self.trajectory, TrajectoryBatch) or len(self.trajectory) != 1:
            n = len(self.trajectory) if isinstance(self.trajectory, TrajectoryBatch) else type(self.trajectory)
            raise GiftError(f"Clip {self.caption!r}: needs a TrajectoryBatch of one trajectory (batch[i]), got {n}")


@attrs.frozen
class Marker:
    """A flat disc on the table under ``object``'s start position, in colour ``rgb`` (three floats in
    [0, 1]); ``caption`` appears in the legend (e.g. ``"paintbrush → crayon"``)."""

    object: str
    rgb: tuple[float, float, float] = attrs.field(converter=_rgb)
    caption: str = ""


@attrs.frozen
class Segment:
    """Where a clip sits in the animation: ``start_s`` to ``end_s`` (seconds)."""

    caption: str
    start_s: float
    end_s: float


@attrs.define
class Replay:
    """A recorded replay in ``meshcat`` (live at :attr:`url` while this process runs)."""

    meshcat: object
    title: str
    segments: tuple[Segment, ...]
    markers: tuple[Marker, ...]
    notes: tuple[str, ...] = ()

    @property
    def url(self) -> str:
        return self.meshcat.web_url()

    @property
    def duration_s(self) -> float:
        return self.segments[-1].end_s if self.segments else 0.0

    def static_html(self) -> str:
        """The page of ``Meshcat.StaticHtml()`` with the caption panel: one self-contained HTML document."""
        page = self.meshcat.StaticHtml()
        page = re.sub(r"<title>.*?</title>", f"<title>{html.escape(self.title)}</title>", page, count=1, flags=re.S)
        end = page.rfind("</body>")
        if end < 0:
            raise GiftError("Meshcat.StaticHtml() returned a page without </body>: this Drake version is not supported")
        return page[:end] + _caption_panel(self) + "\n" + page[end:]


def _caption_panel(replay: Replay) -> str:
    rows = "".join(f'<li data-start="{s.start_s:.3f}" data-end="{s.end_s:.3f}">'
                   f"<b>{s.start_s:.1f}–{s.end_s:.1f} s</b> {html.escape(s.caption)}</li>" for s in replay.segments)
    legend = "".join(
        f'<li><span class="gift-swatch" style="background: rgb({",".join(str(int(255 * c)) for c in m.rgb)})">'
        f"</span>{html.escape(m.caption or m.object)}</li>" for m in replay.markers)
    notes = "".join(f"<p>{html.escape(n)}</p>" for n in replay.notes)
    segments = json.dumps([[s.start_s, s.end_s] for s in replay.segments])
    return f"""<div id="gift-caption">
<style>
#gift-caption {{ position: absolute; left: 8px; bottom: 8px; max-width: 36em; max-height: 45vh; overflow: auto;
  background: rgba(255, 255, 255, 0.9); font: 12px/1.3 sans-serif; padding: 6px 10px; border-radius: 4px;
  box-shadow: 0 1px 4px rgba(0, 0, 0, 0.3); z-index: 10; }}
#gift-caption h1 {{ font-size: 14px; margin: 0 0 4px 0; }}
#gift-caption ul {{ margin: 2px 0; padding-left: 18px; }}
#gift-caption li.gift-now {{ background: #ffe9a8; }}
#gift-caption p {{ margin: 3px 0; color: #444; }}
.gift-swatch {{ display: inline-block; width: 11px; height: 11px; margin-right: 5px; border: 1px solid #333;
  vertical-align: -1px; }}
</style>
<h1>{html.escape(replay.title)}</h1>
<ul id="gift-clips">{rows}</ul>
{"<ul id='gift-legend'>" + legend + "</ul>" if legend else ""}
{notes}
<p>Animation controls: the <i>Animations</i> folder of the menu (top right). Drag to orbit, scroll to zoom.</p>
<script>
(function () {{
  // highlight the clip being played (reads the animation clock of meshcat's viewer when it has one)
  var segments = {segments};
  var items = document.querySelectorAll("#gift-clips li");
  function tick() {{
    try {{
      var t = viewer.animator.time;
      var total = segments.length ? segments[segments.length - 1][1] : 0;
      if (total > 0) {{ t = t % total; }}
      for (var i = 0; i < items.length; i++) {{
        items[i].className = (t >= segments[i][0] && t < segments[i][1]) ? "gift-now" : "";
      }}
    }} catch (e) {{ return; }}
    requestAnimationFrame(tick);
  }}
  requestAnimationFrame(tick);
}})();
</script>
</div>"""


def new_meshcat(port: int | None = None):
    """A Meshcat server bound to localhost only (no stats plot)."""
    from pydrake.geometry import Meshcat, MeshcatParams

    logging.getLogger("drake").setLevel(logging.ERROR)  # not "Meshcat listening ..." on every export
    return Meshcat(MeshcatParams(host="localhost", port=port, show_stats_plot=False))


def replay(robot: RobotSpec, scene: Scene, clips: Sequence[Clip], *, markers: Sequence[Marker] = (),
           title: str = "", notes: Sequence[str] = (), meshcat=None, step_s: float = STEP_S,
           pause_s: float = PAUSE_S) -> Replay:
    """Record ``clips`` (played one after the other) on ``scene`` with ``robot`` into ``meshcat`` (default: a
    new localhost server, :func:`new_meshcat`). Every clip must be a trajectory of this scene (same objects)."""
    from pydrake.geometry import Cylinder, Rgba
    from pydrake.math import RigidTransform

    from gift_sim_drake.motion import check_scene
    from gift_sim_drake.plant import SceneModel, footprint_radius

    if not clips:
        raise GiftError("replay: give at least one clip")
    check_scene(scene)
    for c in clips:
        tr = c.trajectory
        if tuple(tr.object_names) != tuple(scene.object_names):
            raise GiftError(f"replay: clip {c.caption!r} moves objects {list(tr.object_names)}, but the scene holds "
                            f"{list(scene.object_names)}; replay each trajectory on the scene it was generated in")
        if tr.joint_positions.shape[2] != len(robot.rest):
            raise GiftError(f"replay: clip {c.caption!r} has {tr.joint_positions.shape[2]} joints, the {robot.name} "
                            f"has {len(robot.rest)}")
    by_name = {o.name: o for o in scene.objects}
    unknown = [m.object for m in markers if m.object not in by_name]
    if unknown:
        raise GiftError(f"replay: markers name objects not in the scene: {unknown}")

    meshcat = meshcat if meshcat is not None else new_meshcat()
    meshcat.Delete()  # /drake: what an earlier replay drew
    meshcat.Delete("/gift")
    meshcat.DeleteRecording()
    model = SceneModel(robot, scene.task, scene.objects, scene.landmarks, meshcat=meshcat)
    meshcat.SetProperty("/Grid", "visible", False)
    meshcat.SetProperty("/Axes", "visible", False)
    meshcat.SetCameraPose(np.asarray(CAMERA, dtype=float), np.asarray(TARGET, dtype=float))
    for m in markers:
        o = by_name[m.object]
        pos = np.asarray(scene.positions)[scene.object_names.index(m.object)]
        path = f"/gift/markers/{m.object}"
        meshcat.SetObject(path, Cylinder(footprint_radius(o.appearance) + 0.025, 0.004), Rgba(*m.rgb, 1.0))
        meshcat.SetTransform(path, RigidTransform([float(pos[0]), float(pos[1]), 0.002]))

    vis = model.visualizer
    animation = vis.StartRecording(set_transforms_while_recording=True)
    t = 0.0
    segments = []
    for c in clips:
        tr = c.trajectory
        moved = [(i, n) for i, n in enumerate(tr.object_names) if n in model.bodies]
        mug = [j for j, n in enumerate(tr.landmark_names) if n == "mug" and "mug" in model.bodies]
        start = t
        steps = tr.n_steps
        for k in range(steps):
            positions = {n: tr.object_positions[0, k, i] for i, n in moved}
            if mug:
                positions["mug"] = tr.landmark_positions[0, k, mug[0]]
            model.set_state(tr.joint_positions[0, k], positions)
            model.context.SetTime(t)
            model.diagram.ForcedPublish(model.context)
            t += step_s
        t += pause_s - step_s  # the last state stays still for the pause
        model.context.SetTime(t)
        model.diagram.ForcedPublish(model.context)
        segments.append(Segment(c.caption, round(start, 3), round(t, 3)))
        t += step_s
    vis.StopRecording()
    animation.set_autoplay(True)
    animation.set_loop_mode(animation.LoopMode.kLoopRepeat)
    animation.set_repetitions(10_000)
    vis.PublishRecording()
    return Replay(meshcat, title or f"{robot.name}: {scene.task}", tuple(segments), tuple(markers), tuple(notes))
