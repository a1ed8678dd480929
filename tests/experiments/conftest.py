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
    """A reduced real run through ``gift demo``'s own code path (``run_study_command``): the mini
    ``valuables`` suite on the Jaco (real Drake plant, MaxEnt IRL, MiniLM, EfficientNet, the embedded LM with
    its calls recorded), then report.md, the Meshcat replays and report.html. Returns ``(cfg, out, results,
    seconds)``."""
    from mini_suite import mini_suite

    from gift.study.chain import StudyConfig
    from gift_experiments.plugin import run_study_command

    out = tmp_path_factory.mktemp("viewing")
    suite = mini_suite(out / "mini-suite.yaml")
    # the training and test sizes of test_reproduce.py's run (the same LM questions); fewer kernels, no sanity reps
    cfg = StudyConfig(suite=str(suite), kernels=("vision", "language", "gift-prob"), seeds=2, pairs=60, samples=1,
                      train_scenes=2, demos_per_scene=4, alternatives_per_scene=12, trajectories_per_generator=6,
                      sanity_reps=0, thresholds=("train-calibrated", "oracle"), rq3=True)
    t0 = time.perf_counter()
    results = run_study_command(cfg, out, "gift demo (reduced: mini valuables suite)")
    return cfg, out, results, time.perf_counter() - t0
