"""Meshcat replays on the real scene plant: what the recording holds, the static page (no script or style
fetched from anywhere), the place_mug scene (the carried mug is a body too), and clear errors for clips and
markers that do not fit the scene. The page itself is opened in a browser by
tests/experiments/test_viewing_browser.py."""

from __future__ import annotations

import re

import pytest
from sim_drake_catalog import RELEVANT

from gift.core.errors import GiftError
from gift_sim_drake.viewer import Clip, Marker, new_meshcat

pytestmark = [pytest.mark.drake]


@pytest.fixture(scope="module")
def meshcat():
    return new_meshcat()


def test_replay_records_every_clip_and_writes_a_self_contained_page(simulators, objects, meshcat):
    sim = simulators["drake-jaco"]
    scene = sim.make_scene("pack_backpack", objects, RELEVANT, seed=7)
    pref = sim.generate(scene, "preferred", 2, seed=1)
    default = sim.generate(scene, "default", 1, seed=2)
    clips = [Clip("preferred 1", pref[0]), Clip("preferred 2", pref[1]), Clip("default", default[0])]
    rep = sim.replay(scene, clips, markers=[Marker("banana", (0.5, 0.5, 0.5), "banana: distractor")],
                     title="three clips", meshcat=meshcat)
    assert rep.url.startswith("http://localhost:")
    assert [s.caption for s in rep.segments] == ["preferred 1", "preferred 2", "default"]
    clip_s = 60 * 0.06 + 0.6  # 61 states 0.06 s apart, then the last one held for the pause
    for k, s in enumerate(rep.segments):  # clips one step apart
        assert s.start_s == pytest.approx(k * (clip_s + 0.06)) and s.end_s - s.start_s == pytest.approx(clip_s)
    page = rep.static_html()
    assert "<title>three clips</title>" in page and 'id="gift-caption"' in page and "banana: distractor" in page
    # meshcat.js and the scene are inline: no script, stylesheet or image comes from a URL
    assert not re.search(r"<(script|link|img)[^>]+(src|href)=[\"']?(https?:)?//", page)
    # the scene tree of the live server holds the plant's geometry and the markers
    assert meshcat.HasPath("/drake/visualizer/j2s7s300/j2s7s300_link_7")
    assert meshcat.HasPath("/drake/visualizer/object_1") and meshcat.HasPath("/gift/markers/banana")


def test_place_mug_replays_the_carried_mug(simulators, objects, meshcat):
    sim = simulators["drake-franka"]
    scene = sim.make_scene("place_mug", objects, RELEVANT, seed=3)
    rep = sim.replay(scene, [Clip("carry", sim.generate(scene, "preferred", 1, seed=0))], meshcat=meshcat)
    assert rep.static_html().count("</body>") == 1
    assert meshcat.HasPath("/drake/visualizer/panda/panda_link7") and meshcat.HasPath("/drake/visualizer/mug")
    assert not meshcat.HasPath("/gift/markers")  # what the previous replay drew is gone


def test_clips_and_markers_must_fit_the_scene(simulators, objects, meshcat):
    sim = simulators["drake-jaco"]
    scene = sim.make_scene("pack_backpack", objects, RELEVANT, seed=7)
    other = sim.make_scene("pack_backpack", objects[:3], RELEVANT, seed=7)
    batch = sim.generate(scene, "default", 2, seed=0)
    with pytest.raises(GiftError, match="one trajectory"):
        Clip("two", batch)
    with pytest.raises(GiftError, match="replay each trajectory on the scene it was generated in"):
        sim.replay(other, [Clip("wrong scene", batch[0])], meshcat=meshcat)
    with pytest.raises(GiftError, match="not in the scene"):
        sim.replay(scene, [Clip("ok", batch[0])], markers=[Marker("teapot", (1, 0, 0))], meshcat=meshcat)
    with pytest.raises(GiftError, match="three numbers in"):
        Marker("banana", (2.0, 0, 0))
    with pytest.raises(GiftError, match="at least one clip"):
        sim.replay(scene, [], meshcat=meshcat)
