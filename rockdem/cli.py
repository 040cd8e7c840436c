"""The ``rockdem`` command line: one sub-command per module, all over the Python API.

Exit status: 0 done; 1 a study finished with failed runs; 2 bad input (the message names the key,
flag or file); 3 the run diverged (the result holds the frames before it); 128 + N stopped by
signal N (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP), after saving what was computed.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import math
import os
import signal
import sys
import tempfile
import threading
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

# The module that contributes each sub-command through ``register_cli(subparsers)``: a command line
# naming a command imports only its module (``rockdem run`` does not load Matplotlib or SciPy's
# signal package); ``rockdem --help`` and unknown commands import them all.
_COMMANDS = {
    "run": "rockdem.run_cli",
    "show": "rockdem.preview",
    "records": "rockdem.records",
    "advise": "rockdem.advisor",
    "plot": "rockdem.plots",
    "animate": "rockdem.animate",
    "export": "rockdem.vtk_export",
    "sweep": "rockdem.studies",
    "calibrate": "rockdem.studies",
    "fragility": "rockdem.studies",
    "reproduce": "rockdem.reproduce",
}
_COMMAND_MODULES = tuple(dict.fromkeys(_COMMANDS.values()))

EXIT_BAD_INPUT = 2
EXIT_DIVERGED = 3
EXIT_BROKEN_PIPE = 128 + 13
"""Standard output closed by its reader (SIGPIPE's status in a shell)."""
STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")
"""Signals that stop a run or a study like Ctrl-C: the work done so far is saved."""

MAX_NUMBER = 1e15
"""Largest magnitude accepted for a numeric flag (as for case-file numbers)."""


class Interrupted(KeyboardInterrupt):
    """A stop signal (SIGINT, SIGTERM, SIGHUP) raised as KeyboardInterrupt; exit status 128 + signum."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum

    def __reduce__(self) -> tuple[type, tuple[int]]:  # pickled by its number (from a pool or Dask worker)
        return (Interrupted, (self.signum,))


def exit_status(exc: KeyboardInterrupt) -> int:
    """128 + the signal number of an interruption (130 for a plain Ctrl-C)."""
    return 128 + int(getattr(exc, "signum", signal.SIGINT))


def _set_handlers(handler: Callable[[int, object], None] | int) -> dict[int, object]:
    """Install ``handler`` for the stop signals (main thread only); returns the previous ones."""
    old: dict[int, object] = {}
    if threading.current_thread() is not threading.main_thread():
        return old
    for name in STOP_SIGNALS:
        sig = getattr(signal, name, None)
        if sig is not None:
            old[sig] = signal.signal(sig, handler)
    return old


def _restore(old: dict[int, object]) -> None:
    for sig, h in old.items():
        signal.signal(sig, h)  # type: ignore[arg-type]


@contextlib.contextmanager
def stop_on_signals(received: list[int] | None = None) -> Iterator[list[int]]:
    """Within the block, SIGTERM and SIGHUP raise :class:`Interrupted` (a KeyboardInterrupt), as
    Ctrl-C does, so that ``simulate()`` returns the frames computed so far and a study stops its
    workers. The signal numbers received are appended to the yielded list."""
    got = [] if received is None else received

    def handler(signum: int, frame: object) -> None:
        got.append(signum)
        raise Interrupted(signum)

    old = _set_handlers(handler)
    try:
        yield got
    finally:
        _restore(old)


@contextlib.contextmanager
def hold_signals(received: list[int], what: str = "saving the results") -> Iterator[None]:
    """Within the block (e.g. saving), the first stop signal is held with a note on stderr and
    the work goes on; a second one raises :class:`Interrupted` (the save is abandoned)."""
    held: list[int] = []

    def handler(signum: int, frame: object) -> None:
        received.append(signum)
        if held:
            raise Interrupted(signum)
        held.append(signum)
        print(f"rockdem: {what}; interrupt again to abandon", file=sys.stderr, flush=True)

    old = _set_handlers(handler)
    try:
        yield
    finally:
        _restore(old)


def _number(kind: str) -> Callable[[str], float]:
    """An argparse type: a finite number that is ``kind`` ("positive" or "non-negative")."""

    def parse(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            v = math.nan
        if not math.isfinite(v) or (v <= 0 if kind == "positive" else v < 0):
            raise argparse.ArgumentTypeError(f"must be a {kind} number, got {text!r}")
        if abs(v) > MAX_NUMBER:
            raise argparse.ArgumentTypeError(f"{text} is beyond any plausible value (> {MAX_NUMBER:g}); check the units")
        return v

    parse.__name__ = f"{kind} number"
    return parse


MAX_DPI = 1200.0
"""Largest figure resolution [dots per inch] rockdem draws (print quality is 300 to 600; at 1e5 a
plot ran out of memory in Matplotlib's renderer, 2026-12-01)."""


def dots_per_inch(text: str) -> float:
    """An argparse type: a resolution [dots per inch] in (0, :data:`MAX_DPI`]."""
    try:
        v = float(text)
    except ValueError:
        v = math.nan
    if not (0.0 < v <= MAX_DPI):
        raise argparse.ArgumentTypeError(f"must be a resolution in (0, {MAX_DPI:g}] dots per inch, got {text!r}")
    return v


def integer_at_least(low: int) -> Callable[[str], int]:
    """An argparse type: an integer >= ``low``."""

    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            v = low - 1
        if v < low:
            raise argparse.ArgumentTypeError(f"must be an integer >= {low}, got {text!r}")
        return v

    parse.__name__ = f"integer >= {low}"
    return parse


def output_folder(path: str | Path, what: str, files: tuple[str, ...] = (), *, create: bool = True) -> Path:
    """Check an output folder before any work: it must be (or, with ``create`` False, its nearest
    existing parent must be) a writable folder, and none of ``files`` in it may be a folder.
    ``create``: make it now (else the command makes it when it writes). ``what`` names it in
    messages (a flag or a key). Raises ValueError."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{what} {path} is an existing file; give a folder for the results")
    probe = path
    while not create and not probe.exists() and probe != probe.parent:
        probe = probe.parent
    try:
        if create:
            path.mkdir(parents=True, exist_ok=True)
        elif not probe.is_dir():
            raise NotADirectoryError(20, f"{probe} is a file", str(probe))
        with tempfile.TemporaryFile(dir=probe):
            pass
    except OSError as exc:
        raise ValueError(f"{what} {path}: cannot write there ({exc.strerror or exc}); choose a writable folder") from None
    for name in files:
        if (path / name).is_dir():
            raise ValueError(f"{what} {path}: {name} is a folder; remove it or choose another output folder")
    return path


def output_file(path: str | Path, what: str) -> Path:
    """Check before any work that the file ``path`` can be written (its folder is created if
    needed): not a folder, in a writable folder. ``what`` names it in messages. Raises ValueError."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{what} {path} is a folder; give a file name")
    output_folder(path.parent, f"{what} {path}: the folder")
    return path


positive_float = _number("positive")
non_negative_float = _number("non-negative")
positive_int = integer_at_least(1)


def _add_commands(sub: argparse._SubParsersAction, modules: tuple[str, ...]) -> None:
    for name in modules:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:  # a module still being written: skip its command
                continue
            raise
        register = getattr(module, "register_cli", None)
        if callable(register):  # a module without a command yet (e.g. records before its CLI)
            register(sub)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The top-level parser: with a known ``command``, that command only; otherwise every one."""
    from . import __version__

    parser = argparse.ArgumentParser(
        prog="rockdem",
        description="3D rigid-block DEM for rocking masonry, with defensible damping "
        "(Galvez, Sorrentino, Dizhur & Ingham, Earthquake Engng Struct Dyn 2022, doi:10.1002/eqe.3598).",
        epilog="Exit status: 0 done; 1 a study with failed runs; 2 bad input; 3 the run diverged; "
        "128+N stopped by signal N (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP) after saving what was computed.",
    )
    parser.add_argument("--version", action="version", version=f"rockdem {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    _add_commands(sub, (_COMMANDS[command],) if command in _COMMANDS else _COMMAND_MODULES)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``rockdem`` console script; returns the exit status (see the module).

    Run as the program (``argv`` None: the command line is ``sys.argv``), the garbage collector is
    paused while the command's modules are imported (NumPy, xarray, SciPy, Numba: ~10^5 objects,
    kept to the end, hardly any garbage), then their objects, and again those alive at the end, are
    frozen (:func:`gc.freeze`): no collection scans them, during the command or at the
    interpreter's exit (0.1 s + 0.1 s + 0.4 s of a warm ``rockdem run``). Objects held only by
    reference cycles are then not finalized at exit, which Python does not promise anyway; the
    commands close their files themselves.
    """
    try:
        status = _main(argv)
    except KeyboardInterrupt as exc:  # a Ctrl-C while the command's modules load, before it runs
        print(f"rockdem: stopped by {signal.Signals(exit_status(exc) - 128).name} while starting", file=sys.stderr)
        return exit_status(exc)
    finally:
        if "rockdem.rocking_plot" in sys.modules:  # a plotting process the command did not take
            sys.modules["rockdem.rocking_plot"].PlotProcess.discard_early()
    if argv is None:
        gc.freeze()
    return status


def _main(argv: list[str] | None) -> int:
    words = sys.argv[1:] if argv is None else argv
    program = argv is None
    command = next((w for w in words if not w.startswith("-")), None)  # top-level flags take no value
    if program and command == "run" and "--no-plot" not in words and not {"-h", "--help"} & set(words):
        from .rocking_plot import PlotProcess

        PlotProcess.start_early()  # it imports Matplotlib while this process imports the rest and runs
    if program:
        gc.disable()  # the imports' objects live to the end: no collections over them as they load
    try:
        parser = build_parser(command)
    finally:
        if program:
            gc.freeze()
            gc.enable()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help, --version (0) or a bad flag (2, message printed)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else EXIT_BAD_INPUT)
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_BAD_INPUT
    def show_warning(message: Warning | str, category: type[Warning], *rest: object, **kw: object) -> None:
        print(f"rockdem {args.command}: warning: {message}", file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.showwarning = show_warning  # one line, no source excerpt
            return int(args.func(args) or 0)
    except (ValueError, FileNotFoundError) as exc:
        print(f"rockdem {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:  # the reader of the output left (| head); the commands write their files first
        try:
            sys.stdout = open(os.devnull, "w")  # no second error as Python flushes the closed pipe at exit
        except OSError:
            pass
        print(f"rockdem {args.command}: standard output closed by its reader (as with | head)", file=sys.stderr)
        return EXIT_BROKEN_PIPE
    except (TimeoutError, ConnectionError) as exc:  # a Dask scheduler that does not answer (OSError subclasses)
        print(f"rockdem {args.command}: error: {exc}; check the address given (--scheduler) and that it is running",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:  # a file or folder the command could not read or write
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"rockdem {args.command}: error: {where}{exc.strerror or exc}; check the path and its permissions",
              file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:
        name = signal.Signals(exit_status(exc) - 128).name
        print(f"rockdem {args.command}: stopped by {name}", file=sys.stderr)
        return exit_status(exc)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
