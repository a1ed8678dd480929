"""The ``gift`` command line. Plugins add subcommands through ``gift_register_commands``."""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from collections.abc import Sequence

from gift.core.errors import GiftError
from gift.core.interfaces import DEFAULT_LM_TIMEOUT_S, LM_TIMEOUT_ENV
from gift.core.redaction import redact_text
from gift.plugins.manager import KINDS, get_manager


def _cmd_plugins(args: argparse.Namespace) -> int:
    manager = get_manager()
    comps = [c for c in manager.components() if c.kind not in ("command", "doctor_check") or args.all]
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
        logging.getLogger("gift").warning("failed plugin %s: %s", name, why)
    return 0


def _verbosity_parser(suppress: bool) -> argparse.ArgumentParser:
    """``-v``/``-q``, accepted before and after the subcommand (``gift -q reproduce`` = ``gift reproduce -q``)."""
    p = argparse.ArgumentParser(add_help=False)
    default = argparse.SUPPRESS if suppress else 0
    p.add_argument("-v", "--verbose", action="count", default=default, help="more log lines (-vv: debug)")
    p.add_argument("-q", "--quiet", action="count", default=default,
                   help="fewer log lines (-q: warnings only, no progress lines; -qq: errors only)")
    return p


class StderrHandler(logging.StreamHandler):
    """A handler that writes to whatever ``sys.stderr`` is at the time of the record (tests swap it)."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)

    @property
    def stream(self):  # type: ignore[override]
        return sys.stderr

    @stream.setter
    def stream(self, value) -> None:  # the base class assigns it; the live sys.stderr always wins
        pass


def configure_logging(verbose: int = 0, quiet: int = 0) -> int:
    """Log lines of gift to stderr: INFO by default (progress lines), ``-v`` DEBUG, ``-q`` WARNING, ``-qq`` ERROR.

    The level is also put in ``GIFT_LOG_LEVEL`` so that worker processes log at the same level."""
    level = {-2: logging.ERROR, -1: logging.WARNING, 0: logging.INFO}.get(max(-2, min(0, verbose - quiet)),
                                                                          logging.DEBUG)
    root = logging.getLogger("gift")
    if not any(getattr(h, "_gift_cli", False) for h in root.handlers):
        handler = StderrHandler()
        handler.setFormatter(logging.Formatter("%(message)s"))
        handler._gift_cli = True  # type: ignore[attr-defined]
        root.addHandler(handler)
    root.setLevel(level)
    os.environ["GIFT_LOG_LEVEL"] = logging.getLevelName(level)
    return level


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


def add_answer_arguments(parser: argparse.ArgumentParser) -> None:
    """``--policy NAME --abstain BAND --[no-]rescore``: how a command that asks about test objects chooses them,
    which it flags instead of deciding, and whether the kernel re-scores with the answers."""
    parser.add_argument("--policy", default="uncertainty", metavar="NAME",
                        help="which test objects to ask about: uncertainty (default), disagreement, error-bound, "
                             "expected-error, random, or another registered query policy (gift plugins)")
    parser.add_argument("--abstain", type=float, default=0.0, metavar="BAND",
                        help="flag instead of decide the objects whose decision score is within BAND of the cut; "
                             "their features are dropped like a distractor's (default 0: never)")
    parser.add_argument("--rescore", action=argparse.BooleanOptionalAction, default=True,
                        help="a kernel that can use the answers scores the scene again after each answer (the "
                             "default; gift-prob weighs them as evidence, no LM call, or with "
                             "gift-prob:rescore_with=ladder names its ladder again); --no-rescore: answers only "
                             "re-threshold the first scores")


def check_answer_arguments(args: argparse.Namespace) -> None:
    """Raise a :class:`GiftError` for an ``--abstain`` outside [0, 1] or a ``--policy`` nobody registered."""
    if not 0.0 <= args.abstain <= 1.0:
        raise GiftError(f"--abstain must be in [0, 1] (a distance to the cut), got {args.abstain}")
    policies = get_manager().names("query_policy")
    if args.policy not in policies:
        raise GiftError(f"unknown query policy {args.policy!r}; registered: {', '.join(policies)}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="gift", description="Generalizing Intent for Flexible Test-time rewards",
                                     parents=[_verbosity_parser(False)])
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    common = _verbosity_parser(True)
    p = sub.add_parser("plugins", help="list every registered component by kind, with its distribution",
                       parents=[common])
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--all", action="store_true", help="include CLI subcommands and doctor checks of plugins")
    p.set_defaults(run=_cmd_plugins)
    from gift import doctor

    d = sub.add_parser("doctor", help="check the install; print what is missing with the command that fixes it",
                       description=doctor.__doc__.splitlines()[0], parents=[common])
    doctor.configure(d)
    d.set_defaults(run=doctor.run)
    for comp in get_manager().components("command"):
        sp = sub.add_parser(comp.name, help=comp.description or None,
                            description=comp.description or None, parents=[common])
        configure = comp.extra.get("configure")
        if configure is not None:
            configure(sp)
        sp.set_defaults(run=comp.factory)
    add_lm_timeout_argument(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    configure_logging(args.verbose, args.quiet)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    previous = os.environ.get(LM_TIMEOUT_ENV)
    if getattr(args, "lm_timeout", None) is not None:  # the environment reaches every worker process too
        os.environ[LM_TIMEOUT_ENV] = repr(args.lm_timeout)
    try:
        code = args.run(args)
    except GiftError as e:
        logging.getLogger("gift").error("gift %s: error: %s", args.command, redact_text(str(e)))
        return 1
    except KeyboardInterrupt:
        logging.getLogger("gift").error("interrupted")
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
