"""report.html from older or partial results.json files (no Drake, no LM, no browser: the page is written and
says what is missing), and the label placement of the similarity scatter PNG."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import gift
from gift_experiments.html_report import write_html_report
from gift_experiments.report import place_labels

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "docs" / "results" / "demo"
FRANKA = ROOT / "docs" / "results" / "reproduce" / "franka" / "results.json"


def _sections(page: str) -> list[str]:
    return re.findall(r'<section id="([^"]+)">', page)


def test_committed_demo_results_give_a_page_with_every_section(tmp_path):
    """The results.json of the committed demo predates per-object alignments and LM records."""
    out = tmp_path / "demo"
    shutil.copytree(DEMO, out)
    page = write_html_report(json.loads((out / "results.json").read_text()), out, render=False).read_text()
    assert _sections(page) == ["run", "headline", "intent-art_supplies", "views", "rq3", "sanity", "lm-calls",
                               "failures", "timing", "figures"]
    assert 'class="section-error"' not in page
    # the 22 test objects of gift-paper's art_supplies, labelled from the suite, without renders or decisions
    assert page.count('class="object-row"') == 22
    assert page.count("no render") == 22
    assert "No LM call record" in page and "RQ3 did not run" in page
    assert "The person wanted to pick up the sketchbook" in page and "pack art supplies" in page
    assert page.count("<img") == 4  # the four PNG figures of the folder, inlined
    assert not re.search(r'(src|href)="https?:', page)  # nothing fetched


def test_partial_results_and_intent_candidates(tmp_path):
    results = {"config": {"suite": "gift-paper", "robot": "jaco", "thresholds": ["train-calibrated"]},
               "intents": {"valuables": {"text": "pack the valuable things", "source": "inferred",
                                         "candidates": [{"text": "pack the valuable things", "score": 0.71},
                                                        "pack the jewellery"]}},
               "errors": ["valuables/gift: LM answers completed by default: 'ring' unmapped"]}
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page
    assert "<b>Candidates</b>" in page and "pack the jewellery" in page and "score 0.710" in page
    assert "No win rates or alignment scores" in page
    assert "&#x27;ring&#x27; unmapped" in page  # the failure, escaped
    assert page.count('class="object-row"') == len(gift.load_suite("gift-paper").intent("valuables").test)


def test_a_broken_section_is_reported_and_the_rest_is_written(tmp_path):
    results = {"config": {"thresholds": ["oracle"]}, "rq1": {"x": {"vision": {"mean": "not a number"}}},
               "timing": {"total": 3.0}}
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert page.count('class="section-error"') == 1 and '<section id="timing">' in page


@pytest.mark.parametrize("intent", ["art_supplies", "electronics"])
def test_scatter_labels_do_not_overlap(tmp_path, intent):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.text import Text

    block = json.loads(FRANKA.read_text())["scatter"][intent]
    pts = block["points"]
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    xs = np.array([p["language"] for p in pts] + [1.0])
    ys = np.array([p["vision"] for p in pts] + [1.0])
    ax.scatter(xs, ys)
    ax.set_xlim(xs.min() - 0.05, xs.max() + 0.05)
    ax.set_ylim(ys.min() - 0.05, ys.max() + 0.05)
    fig.tight_layout()
    texts = place_labels(ax, xs, ys, [p["object"] for p in pts] + ["anchor"])
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    boxes = [Text.get_window_extent(t, r) for t in texts]  # the text alone, not the leader line
    frame = ax.get_window_extent(r)
    assert len(boxes) == len(pts) + 1
    for i, a in enumerate(boxes):
        assert frame.x0 <= a.x0 and a.x1 <= frame.x1 and frame.y0 <= a.y0 and a.y1 <= frame.y1
        for b in boxes[i + 1:]:
            assert not a.overlaps(b), texts[i].get_text()
    plt.close(fig)


def test_recording_sets_the_record_file_for_the_block_only(tmp_path, monkeypatch):
    import os

    from gift_experiments.lm_calls import recording

    monkeypatch.delenv("GIFT_LM_RECORD", raising=False)
    monkeypatch.delenv("GIFT_LM", raising=False)
    out = tmp_path / "run"
    out.mkdir()
    (out / "lm_calls.jsonl").write_text('{"old": 1}\n')
    with recording(out) as path:
        assert os.environ["GIFT_LM_RECORD"] == str(path) and path == (out / "lm_calls.jsonl").resolve()
        assert path.read_text() == ""  # the calls of this invocation only
    assert "GIFT_LM_RECORD" not in os.environ
    # replaying the folder's own record: the file is kept, and not recorded over
    path.write_text('{"recorded": 1}\n')
    with recording(out, lm=f"replay:{out / 'lm_calls.jsonl'}"):
        assert "GIFT_LM_RECORD" not in os.environ and path.read_text() == '{"recorded": 1}\n'
    # the user's own record file wins
    monkeypatch.setenv("GIFT_LM_RECORD", str(tmp_path / "mine.jsonl"))
    with recording(out) as p:
        assert p == tmp_path / "mine.jsonl" and path.read_text() == '{"recorded": 1}\n'


def test_undefined_numbers_of_strict_json_show_as_missing(tmp_path):
    """results.json writes an undefined number (a one-class subset's AUC, an empty mean) as null."""
    from test_results_json import results_with_undefined_numbers

    from gift.core.serialization import to_jsonable

    results = to_jsonable(results_with_undefined_numbers(), nonfinite="null")
    page = write_html_report(results, tmp_path, render=False).read_text()
    assert 'class="section-error"' not in page and "–" in page
    assert 'data-plot="win-rate"' in page
