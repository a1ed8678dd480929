"""Code blocks of the docs pages: extraction (with snippet includes and skip markers) and execution."""

from __future__ import annotations

import re
from pathlib import Path

import attrs

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SKIP_MARKER = "<!-- skip -->"

#: Pages written by other parts of the project; their code blocks are theirs to test.
FOREIGN_PAGES = ("suites.md", "scaling.md", "results/")

_FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>```+)(?P<lang>[\w+-]*)[^\n]*$")
_SNIPPET = re.compile(r'^\s*--8<--\s+"(?P<path>[^"]+)"\s*$')


@attrs.frozen
class Block:
    """One fenced code block: its page, first line number (1-based), language, source, and skip flag."""

    page: str
    line: int
    lang: str
    source: str
    skipped: bool


def expand_snippets(text: str, base: Path = ROOT) -> str:
    """Replace ``--8<-- "path"`` lines (pymdownx.snippets) by the file they name, relative to ``base``."""
    out = []
    for line in text.splitlines():
        m = _SNIPPET.match(line)
        if m:
            path = base / m["path"]
            if not path.is_file():
                raise FileNotFoundError(f"snippet {m['path']!r} does not exist (looked in {base})")
            out.append(path.read_text().rstrip("\n"))
        else:
            out.append(line)
    return "\n".join(out)


def blocks(markdown: str, page: str = "<text>") -> list[Block]:
    """The fenced blocks of ``markdown``; a block right after a ``<!-- skip -->`` line is marked skipped."""
    lines = markdown.splitlines()
    found: list[Block] = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        fence, indent, start = m["fence"], m["indent"], i
        prev = next((lines[j].strip() for j in range(i - 1, -1, -1) if lines[j].strip()), "")
        body = []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(fence):
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i])
            i += 1
        source = expand_snippets("\n".join(body))
        found.append(Block(page, start + 1, m["lang"].lower(), source, prev == SKIP_MARKER))
        i += 1
    return found


def own_pages() -> list[Path]:
    """Docs pages whose code blocks the docs tests execute (every page except :data:`FOREIGN_PAGES`)."""
    pages = []
    for path in sorted(DOCS.rglob("*.md")):
        rel = path.relative_to(DOCS).as_posix()
        if rel.startswith(("_hooks/", "dev/")) or any(rel == f or rel.startswith(f) for f in FOREIGN_PAGES
                                                      if f.endswith("/")) or rel in FOREIGN_PAGES:
            continue
        pages.append(path)
    return pages


def python_blocks(path: Path) -> list[Block]:
    rel = path.relative_to(DOCS).as_posix()
    return [b for b in blocks(path.read_text(), rel) if b.lang in ("python", "py")]


def run_page(path: Path) -> dict:
    """Execute the page's Python blocks in order in one namespace (like a session); return the namespace."""
    namespace: dict = {"__name__": "gift_docs_page"}
    for block in python_blocks(path):
        if block.skipped:
            continue
        code = compile(block.source, f"{block.page}:{block.line}", "exec")
        exec(code, namespace)  # noqa: S102 - running the documentation's own examples is the point
    return namespace
