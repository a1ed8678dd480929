"""The documentation builds with ``mkdocs build --strict`` and its generated parts match what is installed."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from gift.cli import build_parser

from doc_blocks import DOCS, ROOT

MKDOCS = Path(sys.executable).with_name("mkdocs")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    proc = subprocess.run([str(MKDOCS), "build", "--strict", "--site-dir", str(out)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"mkdocs build --strict failed:\n{proc.stdout}\n{proc.stderr}"
    return out


@pytest.mark.slow
def test_strict_build_writes_every_nav_page(site):
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())

    def pages(nav):
        for item in nav:
            for value in item.values():
                yield from (pages(value) if isinstance(value, list) else [value])

    listed = list(pages(config["nav"]))
    assert "concepts.md" in listed and "plugins/checklist.md" in listed
    for page in listed:
        assert (DOCS / page).is_file(), f"nav names {page}, which does not exist"
        stem = page.removesuffix(".md")
        html = site / (stem.removesuffix("index") + "index.html" if stem.split("/")[-1] == "index"
                       else stem + "/index.html")
        assert html.is_file(), f"{page} was not built"


@pytest.mark.slow
def test_cli_page_documents_every_installed_command(site):
    html = (site / "cli" / "index.html").read_text()
    sub = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    assert set(sub.choices) >= {"plugins"}
    for name in sub.choices:
        assert f"gift {name}" in html, f"the CLI page lacks `gift {name}`"
        assert f"usage: gift {name}" in html, f"the CLI page lacks the --help of `gift {name}`"


@pytest.mark.slow
def test_api_reference_is_rendered_from_docstrings(site):
    interfaces = (site / "reference" / "interfaces" / "index.html").read_text()
    for name in ("SimilarityKernel", "score_aligned", "AlignmentOperator", "IntentEstimator"):
        assert name in interfaces
    testing = (site / "reference" / "testing" / "index.html").read_text()
    assert "check_kernel_contract" in testing and "gift_plugin_manager" in testing


@pytest.mark.slow
def test_performance_page_lists_the_benchmark_modules(site):
    html = (site / "performance" / "index.html").read_text()
    modules = sorted(p.relative_to(ROOT).as_posix() for p in ROOT.glob("tests/benchmarks/test_*.py"))
    modules.append("examples/gift-example-kernel/benchmarks/test_scoring_loop.py")
    for module in modules:
        assert module in html
