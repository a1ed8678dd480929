"""Session fixtures of the experiment tests: a headless browser, and one reduced real run with its pages."""

from __future__ import annotations

import time

import pytest


@pytest.fixture(scope="session")
def browser():
    """Headless Chromium (selenium), one per session."""
    from gift_experiments.browser import start_chromium

    driver = start_chromium()
    yield driver
    driver.quit()


@pytest.fixture(scope="session")
def viewing_run(tmp_path_factory):
    """A reduced real run written as ``gift demo`` writes it: the mini ``valuables`` suite on the Jaco (real
    Drake plant, MaxEnt IRL, MiniLM, EfficientNet, the embedded LM with its calls recorded), then
    report.md, the Meshcat replays and report.html. Returns ``(cfg, out, results, seconds per step)``."""
    from mini_suite import mini_suite

    from gift_experiments.html_report import write_html_report
    from gift_experiments.lm_calls import recording
    from gift_experiments.report import write_report
    from gift_experiments.reproduce import Progress, ReproduceConfig, run
    from gift_experiments.views import export_views

    out = tmp_path_factory.mktemp("viewing")
    suite = mini_suite(out / "mini-suite.yaml")
    # the training and test sizes of test_reproduce.py's run (same LM questions); fewer kernels, no sanity reps
    cfg = ReproduceConfig(suite=str(suite), kernels=("vision", "language", "gift-prob"), seeds=2, pairs=60,
                          samples=1, train_scenes=2, demos_per_scene=4, alternatives_per_scene=12,
                          trajectories_per_generator=6, sanity_reps=0, thresholds=("train-calibrated", "oracle"),
                          rq3=True)
    seconds = {}
    t0 = time.perf_counter()
    with recording(out):
        results = run(cfg, out, Progress(False), log=lambda m: None)
    seconds["run"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_report(results, out, command="gift demo (reduced: mini valuables suite)")
    seconds["report.md"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    export_views(results, out)
    seconds["views"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_html_report(results, out, command="gift demo (reduced: mini valuables suite)")
    seconds["report.html"] = time.perf_counter() - t0
    return cfg, out, results, seconds
