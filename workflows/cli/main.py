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
    "run": "filmfriction.workflows.cli.run_cli",
    "scenes": "filmfriction.workflows.cli.run_cli",
    "geometry": "filmfriction.workflows.cli.run_cli",
    "bench": "filmfriction.workflows.cost.bench",
    "analyze": "filmfriction.workflows.cli.analyze_cli",
    "map": "filmfriction.workflows.cli.map_cli",
    "calibrate": "filmfriction.workflows.cli.calibrate_cli",
    "sfb": "filmfriction.workflows.cli.sfb_cli",
    "report": "filmfriction.workflows.cli.report_cli",
    "tradeoff": "filmfriction.workflows.cost.tradeoff",
    "sweep": "filmfriction.workflows.sweep",
    # bulk LJ viscosity by Green-Kubo (branch viscosity)
    "viscosity": "filmfriction.workflows.cli.viscosity_cli",
}


class UserError(Exception):
    """A problem with the user's input: printed without a traceback, exit code 2."""


# Exit codes: 0 done, 1 a run or computation failed, 2 bad input, 130 interrupted.
EXIT_FAILED = 1
EXIT_BAD_INPUT = 2


def _one_line(exc: BaseException) -> tuple[str, int]:
    """The message and exit code for an exception that reached the command line.

    Bad input (UserError, a scene's SceneError, a file that cannot be read or
    written, a file that is not UTF-8) is exit 2; anything else is a failed
    run, exit 1.  The message names the input and the value.
    """
    from ..md.scene import SceneError

    if isinstance(exc, (UserError, SceneError)):
        return str(exc), EXIT_BAD_INPUT
    if isinstance(exc, UnicodeDecodeError):
        return (f"a file is not UTF-8 text ({exc.reason} at byte {exc.start}); give a "
                f"UTF-8 file", EXIT_BAD_INPUT)
    if isinstance(exc, OSError):
        import errno

        what = exc.strerror or str(exc)
        where = f"{exc.filename}: " if exc.filename else ""
        if exc.errno in (errno.ENOSPC, errno.EDQUOT):
            return (f"{where}{what}: the disk is full; free space and resume the run "
                    "(--resume DIR) or run again", EXIT_FAILED)
        return f"{where}{what}", EXIT_BAD_INPUT
    try:
        from ..md.runner import RunFailed
    except ImportError:  # pragma: no cover
        RunFailed = ()
    if RunFailed and isinstance(exc, RunFailed):
        return str(exc), EXIT_FAILED
    return (f"{type(exc).__name__}: {exc} (an internal error; run with --debug for the "
            "traceback and report it)", EXIT_FAILED)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="filmfriction",
        description="Stick-slip friction of confined films: MD scenes, analysis, "
                    "reduced model and comparison with SFB experiments.")
    from filmfriction import __version__

    parser.add_argument("--version", action="version", version=f"filmfriction {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show a Python traceback on errors (they are one line otherwise)")
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
    # a sub-command's --help opens with what it does: its one-line help when it
    # gives no longer description
    helps = {action.dest: action.help for action in sub._choices_actions}
    for name, command in sub.choices.items():
        if not command.description and helps.get(name):
            command.description = helps[name][0].upper() + helps[name][1:] + "."
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
        message, code = _one_line(exc)
        print(f"filmfriction {args.command}: error: {message}", file=sys.stderr)
        return code


def check_writable(path, flag: str, *, directory: bool = False) -> None:
    """Refuse (UserError) an output path that cannot be written, before any compute.

    ``directory``: the path is a directory to create or write into; otherwise a
    file (an existing directory there is refused).  Nothing is created.
    """
    import os
    from pathlib import Path

    path = Path(path)
    if not directory and path.is_dir():
        raise UserError(f"{flag} {path}: is a directory; give a file name")
    if directory and path.exists() and not path.is_dir():
        raise UserError(f"{flag} {path}: is a file; give a directory")
    # the nearest existing ancestor must be a writable directory
    probe = path if directory and path.exists() else path.parent
    probe = probe if str(probe) else Path(".")
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        raise UserError(f"{flag} {path}: {probe} is a file, not a directory")
    # a real probe (os.access says yes to root, and knows nothing of /proc):
    # create and remove one hidden file
    import tempfile

    try:
        fd, name = tempfile.mkstemp(prefix=".ff-probe-", dir=probe)
    except OSError as exc:
        raise UserError(f"{flag} {path}: cannot write in {probe}: "
                        f"{exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(name)


def check_run_json(run_dir, flag: str = "") -> dict | None:
    """``RUN_DIR/run.json`` as a dict (None when absent); UserError when it is not
    UTF-8, not JSON, or not a JSON object."""
    from pathlib import Path

    path = Path(run_dir) / "run.json"
    if not path.is_file():
        return None
    from filmfriction.analysis.util import read_json_object

    where = f"{flag} {path}" if flag else str(path)
    try:
        return read_json_object(path, where, what="a JSON object (a run record)")
    except ValueError as exc:
        raise UserError(str(exc)) from None


def check_run_source(path) -> None:
    """``path`` holds something to calibrate or report on: a run directory
    (``trace.csv``), a finished sweep (``aggregate.json``) or an analysed trace
    file (``analysis.json``), with a readable ``run.json`` if any; UserError
    otherwise."""
    from pathlib import Path

    path = Path(path)
    if not any((path / name).exists() for name in ("trace.csv", "aggregate.json",
                                                  "analysis.json")):
        raise UserError(f"{path}: neither a run directory (trace.csv), a finished sweep "
                        "(aggregate.json) nor an analysed trace file (analysis.json; "
                        "'filmfriction analyze TRACE_FILE' writes it)")
    check_run_json(path)
