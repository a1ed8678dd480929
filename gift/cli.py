"""The ``gift`` command line. Plugins add subcommands through ``gift_register_commands``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from gift.core.errors import GiftError
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
        print(f"failed plugin {name}: {why}", file=sys.stderr)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="gift", description="Generalizing Intent for Flexible Test-time rewards")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    p = sub.add_parser("plugins", help="list every registered component by kind, with its distribution")
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument("--all", action="store_true", help="include CLI subcommands and doctor checks of plugins")
    p.set_defaults(run=_cmd_plugins)
    from gift import doctor

    d = sub.add_parser("doctor", help="check the install; print what is missing with the command that fixes it",
                       description=doctor.__doc__.splitlines()[0])
    doctor.configure(d)
    d.set_defaults(run=doctor.run)
    for comp in get_manager().components("command"):
        sp = sub.add_parser(comp.name, help=comp.description or None,
                            description=comp.description or None)
        configure = comp.extra.get("configure")
        if configure is not None:
            configure(sp)
        sp.set_defaults(run=comp.factory)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    try:
        code = args.run(args)
    except GiftError as e:
        print(f"gift {args.command}: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
