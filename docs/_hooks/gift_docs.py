"""MkDocs hook of the gift docs: generates the parts of pages that must match what is installed.

- ``<!-- gift-cli-reference -->``: one section per ``gift`` subcommand (and per action of commands with
  sub-actions, such as ``gift lm``) holding its ``--help``, from the installed parser.
- ``<!-- gift-benchmarks -->``: one entry per benchmark module of the repository (``tests/benchmarks``,
  ``plugins/*/benchmarks``, ``examples/*/benchmarks``) with its docstring and the command that runs it.
- the nav gets the pages of :data:`OPTIONAL_PAGES` that exist (scaling notes, results).
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

MARKER = "<!-- gift-cli-reference -->"
BENCH_MARKER = "<!-- gift-benchmarks -->"
ROOT = Path(__file__).resolve().parents[2]


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:  # argparse keeps subcommands in a private action; no public accessor
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def cli_reference() -> str:
    from gift.cli import build_parser

    parser = build_parser()
    parts = ["## `gift`\n", "```text", parser.format_help().rstrip(), "```\n"]
    for name, sub in sorted(_subparsers(parser).items()):
        parts += [f"## `gift {name}`\n", "```text", sub.format_help().rstrip(), "```\n"]
        for action, subsub in sorted(_subparsers(sub).items()):
            parts += [f"### `gift {name} {action}`\n", "```text", subsub.format_help().rstrip(), "```\n"]
    return "\n".join(parts)


def benchmark_list() -> str:
    paths = sorted(ROOT.glob("tests/benchmarks/test_*.py")) + sorted(ROOT.glob("plugins/*/benchmarks/test_*.py")) \
        + sorted(ROOT.glob("examples/*/benchmarks/test_*.py"))
    parts = []
    for path in paths:
        rel = path.relative_to(ROOT).as_posix()
        doc = ast.get_docstring(ast.parse(path.read_text())) or ""
        parts += [f"### `{rel}`\n", doc.split("\n\n")[0].replace("\n", " ") + "\n",
                  "```bash", f".venv/bin/python -m pytest {rel} --benchmark-only", "```\n"]
    if (ROOT / "docs" / "scaling.md").is_file():
        parts.append("Scaling a study over many intents, seeds and machines (executors, Ray, the shared LM "
                     "cache) is described in [Scaling a study](scaling.md).\n")
    return "\n".join(parts) if parts else "(no benchmark modules found)"


#: Pages written by other parts of the project, added to the nav when they exist (so a build never
#: references a page that has not landed): (section title, glob relative to docs/).
OPTIONAL_PAGES = (("Scaling a study", "scaling.md"), ("Results", "results/*.md"))


def on_config(config):
    """Append the optional pages that exist to the nav."""
    docs = Path(config["docs_dir"])
    nav = config["nav"]
    for title, pattern in OPTIONAL_PAGES:
        found = sorted(p.relative_to(docs).as_posix() for p in docs.glob(pattern))
        if not found:
            continue
        if "*" in pattern:
            nav.append({title: [{_title(docs / f, f): f} for f in found]})
        else:
            nav.append({title: found[0]})
    return config


def _title(path: Path, fallback: str) -> str:
    for line in path.read_text().splitlines():
        if line.startswith("# "):
            return line[2:].strip().replace("`", "")
    return fallback


def on_page_markdown(markdown: str, page, config, files) -> str:
    if MARKER in markdown:
        markdown = markdown.replace(MARKER, cli_reference())
    if BENCH_MARKER in markdown:
        markdown = markdown.replace(BENCH_MARKER, benchmark_list())
    return markdown
