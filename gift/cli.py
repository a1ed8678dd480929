"""The ``gift`` command line. Plugins add subcommands through ``gift_register_commands``."""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Sequence

from gift.core.errors import GiftError
from gift.core.interfaces import DEFAULT_LM_TIMEOUT_S, LM_TIMEOUT_ENV
from gift.core.redaction import redact_text
from gift.plugins.manager import KINDS, get_manager


def _cmd_plugins(args: argparse.Namespace) -> int:
    manager = get_manager()
    comps = [c for c in manager.components() if c.kind != "command" or args.all]
    if args.json:
        print(json.dumps({"components": [c.as_dict() for c in comps],
                          "failed_plugins": manager.failed}, indent=2))
        return 0
    for kind in KINDS:
        rows = [c for c in comps if c.kind == kind]
        if not rows:
            continue
        print(f"{kind}:")
        width = max(len(c.name) for c in rows)
        for c in rows:
            print(f"  {c.name:<{width}}  [{c.distribution}]  {c.description}")
    for name, why in manager.failed.items():
        print(f"failed plugin {name}: {why}", file=sys.stderr)
    return 0


def _positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text!r}")
    return value


def _parsers(parser: argparse.ArgumentParser) -> list[argparse.ArgumentParser]:
    """``parser`` and every sub-command parser below it."""
    out = [parser]
    for action in parser._actions:  # noqa: SLF001 - argparse keeps sub-parsers only there
        if isinstance(action, argparse._SubParsersAction):  # noqa: SLF001
            for sub in dict.fromkeys(action.choices.values()):
                out += _parsers(sub)
    return out


def add_lm_timeout_argument(parser: argparse.ArgumentParser) -> None:
    """Give every (sub-)command that takes ``--lm`` also ``--lm-timeout SECONDS`` (sets ``$GIFT_LM_TIMEOUT``)."""
    for p in _parsers(parser):
        options = {o for a in p._actions for o in a.option_strings}  # noqa: SLF001
        if "--lm" in options and "--lm-timeout" not in options:
            p.add_argument("--lm-timeout", type=_positive_seconds, default=None, metavar="SECONDS",
                           help=f"give up on a request to an LM server (retries included) after this long "
                                f"(default: ${LM_TIMEOUT_ENV}, else {DEFAULT_LM_TIMEOUT_S:g} s)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="gift", description="Generalizing Intent for Flexible Test-time rewards")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("plugins", help="list every registered component by kind, with its distribution")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--all", action="store_true", help="include CLI subcommands contributed by plugins")
    p.set_defaults(run=_cmd_plugins)
    for comp in get_manager().components("command"):
        sp = sub.add_parser(comp.name, help=comp.description or None,
                            description=comp.description or None)
        configure = comp.extra.get("configure")
        if configure is not None:
            configure(sp)
        sp.set_defaults(run=comp.factory)
    add_lm_timeout_argument(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    previous = os.environ.get(LM_TIMEOUT_ENV)
    if getattr(args, "lm_timeout", None) is not None:  # the environment reaches every worker process too
        os.environ[LM_TIMEOUT_ENV] = repr(args.lm_timeout)
    try:
        code = args.run(args)
    except GiftError as e:
        print(f"gift {args.command}: error: {redact_text(str(e))}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    finally:  # main() may be called in-process (tests, scripts): leave the environment as it was
        if previous is None:
            os.environ.pop(LM_TIMEOUT_ENV, None)
        else:
            os.environ[LM_TIMEOUT_ENV] = previous
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
