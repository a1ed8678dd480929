"""report.html and the Meshcat replays of a reduced real run, opened in headless Chromium: every section and
object row is there, the plots are drawn and name the object under the pointer, the LM calls of the run are
listed, the Meshcat page holds the robot's links and its animation, nothing is fetched and nothing errs."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from gift.core.data import DISTRACTOR
from gift_experiments.browser import console_errors, network_fetches, open_page

pytestmark = [pytest.mark.slow, pytest.mark.lm, pytest.mark.drake]

INTENT = "valuables"
JACO_LINKS = [f"j2s7s300_link_{i}" for i in range(1, 8)]


def _png_looks_drawn(path, min_colours: int = 50) -> None:
    """A real screenshot: a PNG with many distinct colours (not a blank page)."""
    from PIL import Image

    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    img = np.asarray(Image.open(path).convert("RGB"))
    assert img.shape[0] > 300 and img.shape[1] > 600
    assert len(np.unique(img.reshape(-1, 3), axis=0)) >= min_colours


def _spec(cfg):
    import gift

    return gift.load_suite(cfg.suite).intent(INTENT)


def test_report_html_has_every_section_and_object_row(viewing_run, browser, tmp_path_factory):
    from selenium.webdriver.common.by import By

    cfg, out, results, _ = viewing_run
    open_page(browser, out / "report.html")
    ids = {e.get_attribute("id") for e in browser.find_elements(By.CSS_SELECTOR, "section")}
    assert {"run", "headline", f"intent-{INTENT}", "views", "rq3", "sanity", "lm-calls", "failures", "timing",
            "figures"} <= ids
    assert browser.find_elements(By.CSS_SELECTOR, ".section-error") == []
    # headline: one row per kernel and the label alignment, with the run's win rates
    rows = browser.find_elements(By.CSS_SELECTOR, "#headline table.headline tbody tr")
    names = [r.find_element(By.CSS_SELECTOR, "td").text.strip() for r in rows]
    assert names == ["vision", "language", "gift-prob", "oracle-labels"]
    wr = results["rq1"][INTENT]["gift-prob"]["mean"]
    assert f"{wr:.3f}" in rows[2].text
    # the inferred intent, as results.json holds it
    shown = browser.find_element(By.CSS_SELECTOR, f"#intent-{INTENT} .intent-text").text
    assert results["intents"][INTENT]["text"] in shown
    # every test object: a row with three decoded renders, its label and, per kernel, score, decision and target
    spec = _spec(cfg)
    rows = browser.find_elements(By.CSS_SELECTOR, f"#intent-{INTENT} tr.object-row")
    assert [r.get_attribute("data-object") for r in rows] == [t.object for t in spec.test]
    head = browser.find_element(By.CSS_SELECTOR, f"#intent-{INTENT} table.objects thead").text
    records = results["alignment"][INTENT]
    for k in cfg.kernels:
        cut = records[k]["thresholds"]["train-calibrated"]["cut"]
        assert k in head and f"cut {cut:.3f}" in head
    for row, t in zip(rows, spec.test):
        imgs = row.find_elements(By.CSS_SELECTOR, ".renders img")
        assert len(imgs) == 3
        assert all(browser.execute_script("return arguments[0].complete && arguments[0].naturalWidth", i) > 0
                   for i in imgs)
        cells = row.find_elements(By.CSS_SELECTOR, "td")
        assert ("not relevant" if not t.relevant else "relevant") in cells[3].text
        for k, cell in zip(cfg.kernels, cells[4:]):
            target = records[k]["thresholds"]["train-calibrated"]["mapping"][t.object]
            assert f"{records[k]['objects'][t.object]['decision']:.3f}" in cell.text
            assert (f"→ {target}" if target != DISTRACTOR else "distractor") in cell.text
    # links to the replays, which exist
    links = [a.get_attribute("href") for a in browser.find_elements(By.CSS_SELECTOR, "#views a")]
    assert len(links) == 2 and all(link.startswith("file://") for link in links)
    assert console_errors(browser) == [] and network_fetches(browser) == []
    shot = tmp_path_factory.mktemp("screenshots") / "report.png"
    browser.find_element(By.ID, f"intent-{INTENT}").location_once_scrolled_into_view  # noqa: B018
    assert browser.save_screenshot(str(shot))
    _png_looks_drawn(shot)


def _uncovered(driver, marks):
    """The first mark that is the topmost element at its own centre (points may overlap), scrolled into view."""
    for m in marks:
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", m)
        on_top = driver.execute_script(
            "var r = arguments[0].getBoundingClientRect();"
            "return document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2) === arguments[0];", m)
        if on_top:
            return m
    pytest.fail("every mark is covered by another one")


def test_report_plots_are_drawn_and_name_the_object_under_the_pointer(viewing_run, browser):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    cfg, out, results, _ = viewing_run
    open_page(browser, out / "report.html")
    n = len(_spec(cfg).test)
    bars = browser.find_elements(By.CSS_SELECTOR, 'svg[data-plot="win-rate"] rect.bar')
    assert len(bars) == len(cfg.kernels) + 1  # and the label alignment
    strips = browser.find_elements(By.CSS_SELECTOR, f'#intent-{INTENT} svg[data-plot="decisions"] circle.pt')
    assert len(strips) == n * len(cfg.kernels)
    dots = browser.find_elements(By.CSS_SELECTOR, f'#intent-{INTENT} svg[data-plot="similarity"] circle.pt')
    assert len(dots) == n
    assert {d.get_attribute("data-label") for d in dots} == {t.object for t in _spec(cfg).test}
    # drawn: the marks have a size on screen
    assert all(d.size["width"] > 0 for d in dots) and all(b.size["height"] >= 0 for b in bars)
    tip = browser.find_element(By.ID, "tip")
    for dot in (_uncovered(browser, dots), _uncovered(browser, strips[::-1])):
        ActionChains(browser).move_to_element(dot).perform()
        time.sleep(0.1)
        assert tip.is_displayed()
        assert tip.text.startswith(dot.get_attribute("data-label") + ":")
    bar = _uncovered(browser, bars[::-1])
    ActionChains(browser).move_to_element(bar).perform()
    time.sleep(0.1)
    assert tip.text == bar.get_attribute("data-tip")
    assert tip.text.startswith(f"{INTENT} / {bar.get_attribute('data-series')}: win rate")
    assert console_errors(browser) == [] and network_fetches(browser) == []


def test_report_lists_the_lm_calls_of_the_run(viewing_run, browser):
    from selenium.webdriver.common.by import By

    cfg, out, results, _ = viewing_run
    recorded = [json.loads(line) for line in (out / "lm_calls.jsonl").read_text().splitlines() if line.strip()]
    usage = results["manifest"]["lm"]["usage"]
    # every request of the run is recorded, with whether the cache answered it
    assert len(recorded) == usage["requests"] > 0
    assert sum(r["cached"] is True for r in recorded) == usage["hits"]
    assert sum(r["cached"] is False for r in recorded) == usage["misses"]
    open_page(browser, out / "report.html")
    calls = browser.find_elements(By.CSS_SELECTOR, "#lm-calls details.lm-call")
    assert len(calls) == len(recorded)
    assert [c.get_attribute("data-cached") for c in calls] == [str(r["cached"]).lower() for r in recorded]
    first = calls[0]
    assert first.get_attribute("open") is None  # collapsed
    prompt = recorded[0]["request"]["messages"][-1]["content"]
    first.find_element(By.TAG_NAME, "summary").click()
    assert first.get_attribute("open") is not None
    shown = [p.text for p in first.find_elements(By.CSS_SELECTOR, "pre")]
    assert prompt.strip().splitlines()[0] in shown[-2]
    answer = recorded[0]["response"]
    expected = answer["text"] if "text" in answer else max(answer, key=answer.get)
    assert expected.strip().splitlines()[0] in shown[-1]
    assert "failures" in {s.get_attribute("id") for s in browser.find_elements(By.TAG_NAME, "section")}


def _scene_names(driver) -> list[str]:
    return driver.execute_script(
        "var n = []; viewer.scene.traverse(function (o) { if (o.name) n.push(o.name); }); return n;")


def _wait_for(driver, names, timeout=60.0) -> list[str]:
    deadline = time.monotonic() + timeout
    while True:
        got = _scene_names(driver)
        if set(names) <= set(got) or time.monotonic() > deadline:
            return got
        time.sleep(0.2)


@pytest.mark.parametrize("view", ["test", "demos"])
def test_meshcat_export_holds_the_robot_and_plays_offline(viewing_run, browser, tmp_path_factory, view):
    cfg, out, results, _ = viewing_run
    index = {e["view"]: e for e in json.loads((out / "views" / "index.json").read_text()) if e["intent"] == INTENT}
    entry = index[view]
    assert "error" not in entry
    page = out / entry["file"]
    open_page(browser, page)
    names = _wait_for(browser, JACO_LINKS)
    assert set(JACO_LINKS) <= set(names)  # the Jaco's links, from the real plant's geometry
    n_objects = cfg.test_objects_per_scene
    assert sum(1 for x in names if re.fullmatch(r"object_\d+", x)) >= n_objects
    anim = browser.execute_script("return [viewer.animator.actions.length, viewer.animator.duration]")
    assert anim[0] > 0 and anim[1] == pytest.approx(entry["duration_s"], abs=0.2)
    if view == "test":
        markers = browser.execute_script(
            "var m = viewer.scene_tree.find(['gift', 'markers']); return Object.keys(m.children);")
        assert len(markers) == n_objects
        legend = browser.find_element("id", "gift-legend").text
        assert all(m in legend for m in markers)
    clips = [li.text for li in browser.find_elements("css selector", "#gift-clips li")]
    assert len(clips) == len(entry["clips"]) and all(c in t for c, t in zip(entry["clips"], clips))
    time.sleep(1.0)  # a few frames of the animation
    assert console_errors(browser) == [] and network_fetches(browser) == []
    shot = tmp_path_factory.mktemp("screenshots") / f"meshcat_{view}.png"
    assert browser.save_screenshot(str(shot))
    _png_looks_drawn(shot)


def test_gift_view_serves_the_replay_live_on_localhost(viewing_run, browser):
    cfg, out, results, _ = viewing_run
    proc = subprocess.Popen([sys.executable, "-m", "gift.cli", "view", str(out), "--seconds", "60"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        url = None
        deadline = time.monotonic() + 240  # a busy machine: imports, Drake scenes, IK
        while url is None and time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line and proc.poll() is not None:
                pytest.fail(f"gift view exited: {proc.stderr.read()}")
            m = re.search(r"Meshcat: (http://\S+)", line)
            url = m.group(1) if m else None
        assert url and url.startswith("http://localhost:")
        with urllib.request.urlopen(url, timeout=10) as r:
            assert r.status == 200 and b"meshcat" in r.read().lower()
        open_page(browser, url)
        names = _wait_for(browser, JACO_LINKS)
        assert set(JACO_LINKS) <= set(names)  # sent over the websocket by the live server
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def test_gift_report_writes_the_page_again_from_the_folder(viewing_run, browser, tmp_path):
    import shutil

    cfg, out, results, _ = viewing_run
    copy = tmp_path / "copy"
    shutil.copytree(out, copy, ignore=shutil.ignore_patterns("stages", "report.html"))
    done = subprocess.run([sys.executable, "-m", "gift.cli", "report", str(copy), "--no-render"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (copy / "report.html").read_text().count('class="object-row"') == len(_spec(cfg).test)
    open_page(browser, copy / "report.html")
    assert len(browser.find_elements("css selector", "img")) >= 3 * len(_spec(cfg).test)
    assert console_errors(browser) == []


def test_questions_asked_section_in_the_browser(viewing_run, browser, tmp_path):
    """The "Questions asked" section on a real run: gift-prob's real scores of the run, two uncertainty
    questions answered from the suite's labels (the chain's own query stage), and the committed query curves
    (docs/results/queries/curves.json) through ``gift report --query-curves``; drawn, hoverable, offline."""
    import shutil

    import attrs
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    from gift.core.alignment import AlignmentScores
    from gift.study.chain import query_label, query_stage

    cfg, out, _, _ = viewing_run
    copy = tmp_path / "queried"
    shutil.copytree(out, copy, ignore=shutil.ignore_patterns("stages", "report.html"))
    qcfg = attrs.evolve(cfg, queries=2, query_policy="uncertainty")
    spec = _spec(cfg)
    data = json.loads((copy / "results.json").read_text())
    rec = data["alignment"][INTENT]["gift-prob"]
    q = query_stage(qcfg, spec, AlignmentScores.from_dict(rec["scores"]))
    rec["queries"] = json.loads(json.dumps(q))
    row = query_label("gift-prob", qcfg)
    data["rq2"][INTENT][row] = {q["threshold"]: q["metrics"][q["threshold"]]}
    (copy / "results.json").write_text(json.dumps(data))
    curves_file = Path(__file__).resolve().parents[2] / "docs" / "results" / "queries" / "curves.json"
    curves = json.loads(curves_file.read_text())
    done = subprocess.run([sys.executable, "-m", "gift.cli", "report", str(copy), "--no-render",
                           "--query-curves", str(curves_file)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr

    open_page(browser, copy / "report.html")
    ids = [e.get_attribute("id") for e in browser.find_elements(By.CSS_SELECTOR, "section")]
    assert ids[:3] == ["run", "headline", "queries"]
    assert browser.find_elements(By.CSS_SELECTOR, ".section-error") == []
    section = browser.find_element(By.ID, "queries")
    # the questions in the order asked, each with the simulated human's answer (the suite's label)
    rows = section.find_elements(By.CSS_SELECTOR, "tr.query-row")
    assert [(r.get_attribute("data-intent"), r.get_attribute("data-kernel")) for r in rows] == [(INTENT, "gift-prob")]
    asked = rows[0].find_elements(By.CSS_SELECTOR, "li[data-object]")
    assert [li.get_attribute("data-object") for li in asked] == [a["object"] for a in q["answers"]]
    labels = {t.object: t.relevant for t in spec.test}
    assert q["asked"] == len(asked) > 0
    for li, a in zip(asked, q["answers"]):
        assert a["relevant"] == labels[a["object"]]
        assert ("yes, relevant" if a["relevant"] else "no, not relevant") in li.text
    f1 = q["metrics"][q["threshold"]]["all"]["f1"]
    assert f"{f1:.3f}" in rows[0].text
    # the before/after bars and one F1 and one win-rate plot per run of the curves file, drawn on screen
    assert section.find_elements(By.CSS_SELECTOR, 'svg[data-plot="queries-f1"] rect.bar')
    n_runs = len(curves["runs"])
    for key in ("f1", "win"):
        plots = section.find_elements(By.CSS_SELECTOR, f'svg[data-plot="query-curve-{key}"]')
        assert len(plots) == n_runs
        lines = section.find_elements(By.CSS_SELECTOR, f'svg[data-plot="query-curve-{key}"] polyline.curve')
        assert lines and all(ln.size["width"] > 0 for ln in lines)
    # a point of a curve names its run, policy, number of questions and value under the pointer
    run, sim = next(iter(curves["runs"].items()))
    first = section.find_elements(By.CSS_SELECTOR, 'svg[data-plot="query-curve-f1"]')[0]
    pt = _uncovered(browser, first.find_elements(By.CSS_SELECTOR, "circle.pt")[::-1])
    ActionChains(browser).move_to_element(pt).perform()
    time.sleep(0.1)
    tip = browser.find_element(By.ID, "tip")
    assert tip.is_displayed() and tip.text == pt.get_attribute("data-tip")
    policy = pt.get_attribute("data-series")
    points = [f"{run}: {policy}, {k} question(s) per intent: alignment F1 (pooled) {v:.3f}"
              for k, v in zip(sim["grid"], sim["curves"][policy]["f1"]) if v is not None]
    assert any(tip.text.startswith(p) for p in points)
    assert console_errors(browser) == [] and network_fetches(browser) == []
