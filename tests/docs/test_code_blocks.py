"""Every Python block of the docs pages runs (in page order, one namespace per page), except the few
marked ``<!-- skip -->``; snippet includes (``--8<--``) are expanded first, so included files run too."""

from __future__ import annotations

from pathlib import Path

import pytest

from gift.plugins.manager import reset_manager

from doc_blocks import DOCS, blocks, expand_snippets, own_pages, python_blocks, run_page

#: Pages whose blocks need the real Drake plant or the embedded LM (slow; marked accordingly).
DRAKE_PAGES = {"tutorials/task-plugin.md", "tutorials/pipeline.md"}
LM_PAGES = {"lm.md", "caching.md"}
#: The blocks that are not run: hosted/remote LMs, and code that needs the example packages installed
#: (tests/docs/test_example_packages.py runs that code in a fresh venv instead).
MAX_SKIPPED = 7


def _param(path: Path):
    rel = path.relative_to(DOCS).as_posix()
    marks = []
    if rel in DRAKE_PAGES:
        marks += [pytest.mark.slow, pytest.mark.drake]
    if rel in LM_PAGES:
        marks += [pytest.mark.slow, pytest.mark.lm]
    return pytest.param(path, id=rel, marks=marks)


@pytest.mark.parametrize("page", [_param(p) for p in own_pages() if python_blocks(p)])
def test_python_blocks_of_page_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    reset_manager()
    try:
        run_page(page)
    finally:
        reset_manager()


def test_pages_have_runnable_examples_and_few_skips():
    all_blocks = [b for p in own_pages() for b in python_blocks(p)]
    skipped = [f"{b.page}:{b.line}" for b in all_blocks if b.skipped]
    assert len(all_blocks) - len(skipped) >= 15
    assert len(skipped) <= MAX_SKIPPED, f"too many skipped doc blocks: {skipped}"


def test_block_extraction_honours_skip_markers_and_indentation():
    text = ("Intro\n\n```python\nx = 1\n```\n\n<!-- skip -->\n```python\nraise SystemExit\n```\n"
            "- item\n  ```bash\n  echo hi\n  ```\n")
    found = blocks(text)
    assert [(b.lang, b.skipped, b.line) for b in found] == [("python", False, 3), ("python", True, 8),
                                                            ("bash", False, 12)]
    assert found[2].source == "echo hi"


def test_snippet_includes_are_expanded_and_missing_files_named(tmp_path):
    (tmp_path / "inc.py").write_text("x = 41\n")
    assert expand_snippets('--8<-- "inc.py"\nx += 1', tmp_path) == "x = 41\nx += 1"
    with pytest.raises(FileNotFoundError, match="missing.py"):
        expand_snippets('--8<-- "missing.py"', tmp_path)


def test_a_failing_block_reports_page_and_line(tmp_path):
    page = tmp_path / "docs" / "bad.md"
    page.parent.mkdir()
    page.write_text("# Bad\n\n```python\nx = 1\n```\n\n```python\nassert x == 2, 'wrong'\n```\n")
    with pytest.raises(AssertionError) as info:
        namespace: dict = {}
        for b in blocks(page.read_text(), "bad.md"):
            exec(compile(b.source, f"{b.page}:{b.line}", "exec"), namespace)
    assert any(str(entry.path) == "bad.md:7" for entry in info.traceback)
