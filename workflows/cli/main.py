"""The ``filmfriction`` command line.

Each sub-command is one module of this folder; this module only lists them.
A sub-command module exposes ``register(subparsers)``, which adds its parser
and sets ``func`` (called with the parsed arguments, returns an exit code).
"""
from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from ..inputs import EXIT_BAD_INPUT, EXIT_FAILED, UserError

# name -> module providing register(subparsers)
COMMANDS = {
    "run": "filmfriction.workflows.cli.run_cli",
    "scenes": "filmfriction.workflows.cli.run_cli",
    "geometry": "filmfriction.workflows.cli.run_cli",
    "bench": "filmfriction.workflows.cli.bench_cli",
    "analyze": "filmfriction.workflows.cli.analyze_cli",
    "map": "filmfriction.workflows.cli.map_cli",
    "calibrate": "filmfriction.workflows.cli.calibrate_cli",
    # the slip law of several runs pooled
    "slip-law": "filmfriction.workflows.cli.slip_law_cli",
    "sfb": "filmfriction.workflows.cli.sfb_cli",
    "report": "filmfriction.workflows.cli.report_cli",
    "tradeoff": "filmfriction.workflows.cli.tradeoff_cli",
    "sweep": "filmfriction.workflows.cli.sweep_cli",
    # the slider-mass ladder: one sweep per rung
    "ladder": "filmfriction.workflows.cli.ladder_cli",
    # bulk LJ viscosity by Green-Kubo
    "viscosity": "filmfriction.workflows.cli.viscosity_cli",
}


USAGE_HINT = """\
Stick-slip friction of confined films: MD scenes, analysis, reduced model and
comparison with SFB experiments.

  filmfriction run               the default study end to end (LAMMPS, analysis,
                                 calibration, SFB check, report), as `make run`
  filmfriction scenes            the scenes 'run' can run
  filmfriction COMMAND --help    what COMMAND does and its options
  filmfriction --help            every command"""


def _undecodable_file(exc: UnicodeDecodeError) -> str | None:
    """Where a UnicodeDecodeError came from, as "FILE, line N" (None: not found): the
    file the failing read was reading (a ``Path`` whose ``read_text`` failed, an open
    text file, a ``path`` argument), its first byte that is not UTF-8 located anew."""
    import io

    tb, frames = exc.__traceback__, []
    while tb is not None:
        frames.append(tb.tb_frame)
        tb = tb.tb_next
    for frame in reversed(frames):                     # the innermost reader first
        for name, value in frame.f_locals.items():
            if isinstance(value, io.TextIOWrapper) and isinstance(value.name, str):
                value = value.name
            elif not (isinstance(value, Path) or (isinstance(value, str) and name in (
                    "path", "file", "filename", "source"))):
                continue
            try:
                path = Path(value)
                if not path.is_file() or path.stat().st_size > 1 << 28:
                    continue
                path.read_bytes().decode("utf-8")
            except UnicodeDecodeError as again:
                line = path.read_bytes()[:again.start].count(b"\n") + 1
                return f"{path}, line {line}"
            except (OSError, ValueError):
                continue
    return None


def _one_line(exc: BaseException, command: str | None = None) -> tuple[str, int]:
    """The message and exit code for an exception that reached the command line.

    Bad input (UserError, a scene's SceneError, a file that cannot be read or
    written, a file that is not UTF-8) is exit 2; anything else is a failed
    run, exit 1.  The message names the input and the value.  A full disk is
    a failure; only ``run`` is advised to resume.
    """
    from ..md.scene import SceneError

    if isinstance(exc, (UserError, SceneError)):
        return str(exc), EXIT_BAD_INPUT
    if isinstance(exc, UnicodeDecodeError):
        where = _undecodable_file(exc)
        return (f"{where or 'a file'}: not UTF-8 text ({exc.reason}: byte "
                f"{exc.object[exc.start:exc.start + 1]!r}); save it as UTF-8",
                EXIT_BAD_INPUT)
    if isinstance(exc, OSError):
        import errno

        what = exc.strerror or str(exc)
        where = f"{exc.filename}: " if exc.filename else ""
        if exc.errno in (errno.ENOSPC, errno.EDQUOT):
            remedy = ("free space, then resume the run (--resume DIR) or run it again"
                      if command == "run" else
                      f"free space, then run filmfriction {command or 'the command'} again")
            return f"{where}{what}: the disk is full; {remedy}", EXIT_FAILED
        return f"{where}{what}", EXIT_BAD_INPUT
    from ..md.runner import RunFailed

    if isinstance(exc, RunFailed):
        return str(exc), EXIT_FAILED
    return (f"{type(exc).__name__}: {exc} (an internal error; run with --debug for the "
            "traceback and report it)", EXIT_FAILED)


def _habits() -> argparse.ArgumentParser:
    """The options every sub-command has: how much it says while it works."""
    parent = argparse.ArgumentParser(add_help=False)
    said = parent.add_argument_group("what the command says")
    group = said.add_mutually_exclusive_group()
    group.add_argument("-q", "--quiet", action="store_true",
                       help="no progress and no notes on stderr (results, warnings and "
                            "errors still)")
    group.add_argument("-v", "--verbose", action="store_true",
                       help="more detail on stderr: the commands started and, when stderr "
                            "is not a terminal, a progress line at every tenth of a stage")
    return parent


class _Commands:
    """The sub-commands' parsers: a sub-command's --help opens with what it does, its
    one-line help when it gives no longer description; every one has the options of
    :func:`_habits`."""

    def __init__(self, subparsers):
        self._subparsers = subparsers
        self._parent = _habits()

    def add_parser(self, name: str, **kwargs) -> argparse.ArgumentParser:
        short = kwargs.get("help")
        if short and not kwargs.get("description"):
            kwargs["description"] = short[0].upper() + short[1:] + "."
        kwargs["parents"] = [*kwargs.get("parents", ()), self._parent]
        return self._subparsers.add_parser(name, **kwargs)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="filmfriction",
        description="Stick-slip friction of confined films: MD scenes, analysis, "
                    "reduced model and comparison with SFB experiments.")
    from filmfriction import __version__

    parser.add_argument("--version", action="version", version=f"filmfriction {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show a Python traceback on errors (they are one line otherwise)")
    sub = _Commands(parser.add_subparsers(dest="command", metavar="COMMAND"))
    registered = set()
    for name, module_name in COMMANDS.items():
        if module_name in registered:
            continue
        importlib.import_module(module_name).register(sub)
        registered.add(module_name)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    for stream in (sys.stdout, sys.stderr):
        # a path the terminal's encoding cannot show (a non-ASCII name under LANG=C) is
        # printed escaped, never an error after the outputs are written
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):
            pass
    parser = build_parser()
    if not argv:
        # `filmfriction` alone says what it does and how to start; it runs nothing
        print(parser.format_usage().rstrip())
        print(USAGE_HINT)
        return 2
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    from .. import progress

    progress.set_level(progress.QUIET if args.quiet else
                       progress.VERBOSE if args.verbose else progress.NORMAL)
    try:
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (`filmfriction sfb | head`): stop quietly, as a tool that
        # SIGPIPE ends does; stdout to /dev/null so that the exit's flush does not fail again
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception as exc:  # noqa: BLE001 -- the one error path of the CLI
        if args.debug:
            import traceback

            traceback.print_exc()
        message, code = _one_line(exc, args.command)
        print(f"filmfriction {args.command}: error: {message}", file=sys.stderr)
        return code
