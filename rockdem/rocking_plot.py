"""``rockdem run``'s plot (rotation and displacement versus time, and the input motion of an
earthquake run), drawn from plain arrays so that a second Python process can draw it.

Importing Matplotlib and drawing take about a quarter of a warm ``rockdem run --example``'s
time. :class:`PlotProcess` starts a plotting process when the run starts; it imports Matplotlib
on another core while this process simulates, receives the arrays (pickled over a pipe) when the
result is ready, and draws while this process writes ``result.nc`` and ``histories.csv``. The
image is the one :func:`draw_rocking` would draw here, byte for byte. Where the process cannot
start, dies or fails, the plot is drawn here, so an error is raised (and a warning shown) here as
without it. This module imports NumPy only; Matplotlib is imported when drawing.
"""

from __future__ import annotations

import gc
import os
import pickle
import subprocess
import sys
import threading
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["RockingSeries", "rocking_series", "draw_rocking", "PlotProcess"]


@dataclass(frozen=True)
class RockingSeries:
    """What the rocking plot draws. T frames, F free blocks, K displacement lines."""

    time: NDArray[np.float64]
    """(T,) time [s]."""
    blocks: tuple[str, ...]
    """(F,) names of the free blocks."""
    angle: NDArray[np.float64]
    """(T, F) rocking angle [rad]."""
    displacement: NDArray[np.float64]
    """(T, K) displacement along x [m]: the monitors' where there are monitors, else the free blocks'
    centroids."""
    monitors: tuple[str, ...]
    """(K,) monitor names, or empty where the lines are the free blocks' centroids."""
    quake: NDArray[np.float64] | None
    """(T,) input ground acceleration along the rocking direction [m/s^2], or None (no record)."""


def rocking_series(ds: Any) -> RockingSeries:
    """The arrays of a result Dataset (from :func:`rockdem.simulation.simulate`) that the rocking
    plot draws."""
    from .analysis import ground_acceleration

    free = np.flatnonzero(ds.block_free.values)
    monitors = tuple(str(m) for m in ds.monitor.values) if ds.sizes.get("monitor", 0) else ()
    if monitors:
        disp = ds.monitor_displacement.values[:, :, 0]
    else:
        disp = ds.block_displacement.values[:, free, 0]
    return RockingSeries(time=np.asarray(ds.time.values, dtype=float),
                         blocks=tuple(str(n) for n in ds.block_name.values[free]),
                         angle=np.asarray(ds.rocking_angle.values[:, free], dtype=float),
                         displacement=np.asarray(disp, dtype=float), monitors=monitors,
                         quake=ground_acceleration(ds))


def draw_rocking(series: RockingSeries, path: str | Path) -> Path:
    """Draw the rocking plot (rotation [deg] and displacement [mm] versus time, and the ground's
    acceleration, velocity and displacement for an earthquake run) and save it as PNG or PDF."""
    from matplotlib import rc_context

    from .style import STYLE, InlineFigure, save_figure

    t, quake = series.time, series.quake
    with rc_context(STYLE):
        fig = InlineFigure(figsize=(8, 6 if quake is None else 9.5))
        axes = fig.subplots(2 if quake is None else 5, 1, sharex=True)
        for j, name in enumerate(series.blocks):
            axes[0].plot(t, np.degrees(series.angle[:, j]), label=name)
        axes[0].set_ylabel("rocking angle [deg]")
        if len(series.blocks) <= 8:
            axes[0].legend(loc="upper right", fontsize=8)
        if series.monitors:
            for j, name in enumerate(series.monitors):
                axes[1].plot(t, series.displacement[:, j] * 1e3, label=f"{name} (x)")
            axes[1].set_ylabel("displacement [mm]")
            axes[1].legend(loc="upper right", fontsize=8)
        else:
            for j in range(series.displacement.shape[1]):
                axes[1].plot(t, series.displacement[:, j] * 1e3)
            axes[1].set_ylabel("centroid displacement x [mm]")
        if quake is not None:
            from .spectra import plot_ground_motion_axes

            plot_ground_motion_axes(tuple(axes[2:]), t, quake)
        axes[-1].set_xlabel("time [s]")
        fig.align_ylabels()
        fig.tight_layout()
    return save_figure(fig, path, dpi=120)


_SERVE_CODE = ("import signal; signal.signal(signal.SIGINT, signal.SIG_IGN); import sys; sys.path.insert(0, {root!r}); "
               "from rockdem.rocking_plot import _serve; _serve()")
"""The plotting process's program: Ctrl-C (sent to the terminal's whole process group) is ignored
from its first line, since the run it stops still saves its plot."""
_EARLY: PlotProcess | None = None  # started by PlotProcess.start_early, not yet taken


class PlotProcess:
    """A second Python process that draws the rocking plot: started before the run, given the
    arrays by :meth:`draw` when the result is ready. A context manager: leaving it ends the process.
    """

    def __init__(self) -> None:
        code = _SERVE_CODE.format(root=str(Path(__file__).resolve().parent.parent))
        self._sender: threading.Thread | None = None
        self._process: subprocess.Popen[bytes] | None
        try:
            self._process = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE,
                                             stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        except OSError:  # no interpreter to start (embedded Python) or no process to spare
            self._process = None

    @classmethod
    def start_early(cls) -> None:
        """Start the process now, for the next :meth:`take` (``rockdem run`` calls this before it
        imports its modules, so that the process has imported Matplotlib before the run ends)."""
        global _EARLY
        if _EARLY is None:
            _EARLY = cls()

    @classmethod
    def take(cls) -> PlotProcess:
        """The process :meth:`start_early` started, or a new one."""
        global _EARLY
        early, _EARLY = _EARLY, None
        return early if early is not None else cls()

    @classmethod
    def discard_early(cls) -> None:
        """End the process :meth:`start_early` started, if no :meth:`take` took it."""
        global _EARLY
        early, _EARLY = _EARLY, None
        if early is not None:
            early.close()

    def __enter__(self) -> PlotProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def submit(self, series: RockingSeries, path: str | Path) -> None:
        """Send the arrays and the output path (on a thread: the process may still be importing)."""
        payload = pickle.dumps((series, str(path)), protocol=pickle.HIGHEST_PROTOCOL)

        def send() -> None:
            try:
                assert self._process is not None and self._process.stdin is not None
                self._process.stdin.write(payload)
                self._process.stdin.close()
            except OSError:  # the process died: draw() draws here
                pass

        if self._process is not None:
            self._sender = threading.Thread(target=send, daemon=True)
            self._sender.start()

    def draw(self, series: RockingSeries, path: str | Path) -> Path:
        """The saved plot: the process's (after :meth:`submit`), or drawn here where it failed."""
        proc = self._process
        if proc is not None and self._sender is not None:
            self._sender.join()
            assert proc.stdout is not None
            reply = proc.stdout.read()
            if proc.wait() == 0 and reply:
                try:
                    caught = pickle.loads(reply)
                except Exception:  # something else wrote on its stdout (a sitecustomize): the plot is saved
                    caught = []
                for message, module, name in caught:  # the category if loaded here, else UserWarning
                    category = getattr(sys.modules.get(module), name, UserWarning)
                    warnings.warn(message, category if isinstance(category, type) and issubclass(category, Warning)
                                  else UserWarning, stacklevel=2)
                return Path(path)
        return draw_rocking(series, path)

    def close(self) -> None:
        """End the process: killed if it was given nothing to draw, else waited for (it exits once
        it has saved the plot, so that no half-written image is left)."""
        proc, self._process = self._process, None
        if proc is None:
            return
        try:
            if self._sender is None:
                proc.kill()
            else:
                self._sender.join()
            proc.wait()
        finally:
            if proc.stdout is not None:
                proc.stdout.close()


def _serve() -> None:
    """The plotting process: import Matplotlib, read one (series, path) from stdin, draw, and reply
    on stdout with the warnings raised while drawing. Exits quietly if stdin closes first."""
    gc.disable()  # a short life: no collections (a quarter of the drawing's time)
    import matplotlib.figure  # noqa: F401  (the work this process overlaps with the run)

    from . import spectra, style  # noqa: F401

    try:
        series, path = pickle.load(sys.stdin.buffer)
    except EOFError:  # no plot wanted (or the run ended without one)
        return
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        draw_rocking(series, path)
    sys.stdout.buffer.write(pickle.dumps([(str(w.message), w.category.__module__, w.category.__qualname__)
                                          for w in caught]))
    sys.stdout.flush()
    os._exit(0)  # the image is saved and closed: skip the interpreter's tear-down of Matplotlib
