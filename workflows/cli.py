"""The ``filmfriction`` command line.

Each sub-command lives next to the code it drives; this module only lists
them.  A sub-command module exposes ``register(subparsers)``, which adds its
parser and sets ``func`` (called with the parsed arguments, returns an exit
code).  Modules are imported only when listed, so a broken optional part does
not take the whole CLI down.
"""
from __future__ import annotations

import argparse
import importlib
import sys

# name -> module providing register(subparsers)
COMMANDS = {
    "run": "filmfriction.workflows.run_cli",
    "scenes": "filmfriction.workflows.run_cli",
    "bench": "filmfriction.workflows.bench",
    "analyze": "filmfriction.workflows.analyze_cli",
    "map": "filmfriction.workflows.map_cli",
    "calibrate": "filmfriction.workflows.calibrate_cli",
    "sfb": "filmfriction.workflows.sfb_cli",
    "report": "filmfriction.workflows.report_cli",
    "tradeoff": "filmfriction.workflows.tradeoff",
    "sweep": "filmfriction.workflows.sweep",
    # bulk LJ viscosity by Green-Kubo (branch viscosity)
    "viscosity": "filmfriction.workflows.viscosity_cli",
}


class UserError(Exception):
    """A problem with the user's input: printed without a traceback, exit code 2."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="filmfriction",
        description="Stick-slip friction of confined films: MD scenes, analysis, "
                    "reduced model and comparison with SFB experiments.")
    from filmfriction import __version__

    parser.add_argument("--version", action="version", version=f"filmfriction {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    registered = set()
    for name, module_name in COMMANDS.items():
        if module_name in registered:
            continue
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name == module_name:
                continue  # not written yet
            raise
        module.register(sub)
        registered.add(module_name)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser()
    if not argv:
        # `filmfriction` alone runs the default study, like `make run`.
        argv = ["run"]
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except UserError as exc:
        print(f"filmfriction {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    # run through the package module, so that sub-commands and this entry
    # point share one UserError class (not a second copy in __main__)
    from filmfriction.workflows.cli import main as _main

    sys.exit(_main())
