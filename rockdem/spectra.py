"""The input motion: elastic response spectra (pyrotd) and plots of a record's acceleration,
velocity, displacement and spectrum.

:func:`response_spectrum` computes the pseudo-spectral acceleration PSA(T) of a single-degree-of-
freedom oscillator of period T and damping ratio zeta under a record, with pyrotd (frequency-domain
solution, the record zero-padded and, where needed, resampled so that its Nyquist frequency is at
least 5 times the oscillator's). PSA = omega^2 SD, and SD = PSA / omega^2, PSV = PSA / omega.

The CLI is ``rockdem records --plot NAME`` (a shipped short name, a file in ``ROCKDEM_DATA`` or a path).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import ArrayLike, NDArray

from .records import STANDARD_GRAVITY, GroundMotion

__all__ = ["DEFAULT_PERIODS", "Spectrum", "response_spectrum", "plot_record", "plot_ground_motion_axes"]

DEFAULT_PERIODS: NDArray[np.float64] = np.geomspace(0.02, 5.0, 80)
"""Oscillator periods [s] of the default spectrum (log-spaced, 0.02 to 5 s)."""

SPECTRUM_MAX_SAMPLES = 20_000_000
"""Most samples of one oscillator's response that :func:`response_spectrum` computes (pyrotd refines
the record's Fourier grid to five times the oscillator's frequency): a record of a few hundred
seconds at any ordinary dt needs well under a million; a dt off by orders of magnitude (1e-9 or
1e5 s) needed terabytes or ran for hours, and is refused."""


@dataclass(frozen=True, repr=False)
class Spectrum:
    """An elastic response spectrum.

    Attributes:
        period: (k,) oscillator periods T [s].
        psa: (k,) pseudo-spectral acceleration [m/s^2].
        damping: oscillator damping ratio zeta [-].
        name: the record's name.
    """

    period: NDArray[np.float64]
    psa: NDArray[np.float64]
    damping: float
    name: str = ""

    @property
    def sd(self) -> NDArray[np.float64]:
        """(k,) spectral displacement PSA / omega^2 [m]."""
        return self.psa * (self.period / (2.0 * np.pi)) ** 2

    @property
    def psv(self) -> NDArray[np.float64]:
        """(k,) pseudo-spectral velocity PSA / omega [m/s]."""
        return self.psa * self.period / (2.0 * np.pi)

    def __repr__(self) -> str:
        k = int(np.argmax(self.psa))
        return (f"Spectrum({self.name!r}, {self.period.size} periods {self.period[0]:g}..{self.period[-1]:g} s, "
                f"damping {self.damping:g}, peak PSA {self.psa[k]:.4g} m/s^2 at T = {self.period[k]:.3g} s)")

    def at(self, period: float) -> float:
        """PSA [m/s^2] at ``period`` [s] (log-log interpolation between the computed periods; a
        period outside them is refused: the end value would be returned for it)."""
        lo, hi = float(self.period.min()), float(self.period.max())
        if isinstance(period, bool) or not isinstance(period, (int, float, np.integer, np.floating)) \
                or not lo * (1 - 1e-12) <= period <= hi * (1 + 1e-12):
            raise ValueError(f"Spectrum.at: period must lie within the computed {lo:g} to {hi:g} s, got {period!r}; "
                             "compute the spectrum at it (response_spectrum(motion, periods))")
        return float(np.exp(np.interp(np.log(period), np.log(self.period), np.log(self.psa))))


SPECTRUM_MIN_DECAY = 0.01
"""Damping ratio below which the zero padding of :func:`response_spectrum` is sized as for 1 % (an
undamped oscillator's free vibration never decays: its spectrum is that of the record and its
padding)."""


def response_spectrum(
    motion: GroundMotion, periods: ArrayLike | None = None, *, damping: float = 0.05
) -> Spectrum:
    """Pseudo-spectral acceleration of ``motion``'s horizontal component (pyrotd).

    Args:
        motion: the record.
        periods: oscillator periods [s] (default :data:`DEFAULT_PERIODS`).
        damping: damping ratio [-] (default 0.05).

    Raises:
        ValueError: non-positive periods or a damping ratio outside [0, 1).
    """
    import pyrotd

    if not isinstance(motion, GroundMotion):
        raise ValueError(f"response_spectrum: motion must be a GroundMotion (rockdem.records.read_record, or "
                         f"GroundMotion(acceleration, dt)), got {type(motion).__name__}")
    t = DEFAULT_PERIODS if periods is None else np.asarray(periods, dtype=float).reshape(-1)
    if t.size == 0 or not np.all(np.isfinite(t) & (t > 0)):
        raise ValueError(f"spectrum periods must be positive times [s], got {periods!r}")
    if not (np.isfinite(damping) and 0.0 <= damping < 1.0):
        raise ValueError(f"spectrum damping must be a ratio in [0, 1) (0.05 for 5 %), got {damping!r}")
    # pyrotd solves in the frequency domain, i.e. for a periodic record: zeros are appended so that
    # each oscillator's free vibration after the record decays (to e^-5 = 0.7 %) instead of wrapping
    # round onto the record's start (without them PSA was 20 to 25 % off at T = 2 to 5 s).
    tail = 5.0 / (max(damping, SPECTRUM_MIN_DECAY) * 2.0 * np.pi / float(t.max()))
    n = motion.acceleration.size + np.ceil(tail / motion.dt)  # (a float: tail / dt may be huge)
    need = 2.0 * max(n / 2.0 + 1.0, 5.0 * n * motion.dt / float(t.min()))  # pyrotd's irfft of the shortest period
    if need > SPECTRUM_MAX_SAMPLES:
        raise ValueError(
            f"{motion.name or 'the record'}: its response spectrum from T = {float(t.min()):g} s to {float(t.max()):g} s "
            f"at dt = {motion.dt:g} s would compute {need:.3g} samples per oscillator (at most {SPECTRUM_MAX_SAMPLES:.0e}): "
            "check the record's dt (recorded ground motions are sampled every 0.001 to 0.05 s)")
    acc = np.concatenate([motion.acceleration, np.zeros(int(np.ceil(tail / motion.dt)))])
    res = pyrotd.calc_spec_accels(motion.dt, acc, 1.0 / t, osc_damping=damping)
    return Spectrum(t.copy(), np.abs(np.asarray(res.spec_accel, dtype=float)), float(damping), motion.name)


def plot_ground_motion_axes(axes: tuple, time: NDArray[np.float64], acceleration: NDArray[np.float64]) -> None:
    """Draw acceleration [g], velocity [m/s] and displacement [mm] (trapezoid integrals from rest)
    of a record sampled at ``time`` [s] on three axes."""
    from scipy.integrate import cumulative_trapezoid

    vel = cumulative_trapezoid(acceleration, time, initial=0.0)
    disp = cumulative_trapezoid(vel, time, initial=0.0)
    rows = ((acceleration / STANDARD_GRAVITY, "ground acc. [g]", "C3"), (vel, "ground vel. [m/s]", "C2"),
            (disp * 1e3, "ground disp. [mm]", "C4"))
    for ax, (y, label, color) in zip(axes, rows):
        ax.plot(time, y, color=color, lw=0.8)
        ax.set_ylabel(label)
        k = int(np.argmax(np.abs(y))) if y.size else 0
        if y.size:
            ax.annotate(f"peak {abs(y[k]):.3g}", (time[k], y[k]), fontsize=7, xytext=(3, 0), textcoords="offset points")


def plot_record(motion: GroundMotion, *, damping: float = 0.05, periods: ArrayLike | None = None,
                name: str = "") -> Figure:
    """A record's acceleration, velocity and displacement vs time and its response spectrum
    (``name`` for the title; default the record's).

    Returns:
        A Matplotlib figure (displays inline in a notebook).
    """
    from .plots import InlineFigure, STYLE
    from matplotlib import rc_context

    spec = response_spectrum(motion, periods, damping=damping)
    with rc_context(STYLE):
        fig = InlineFigure(figsize=(7.0, 7.0), layout="constrained")
        grid = fig.add_gridspec(4, 1, height_ratios=(1, 1, 1, 1.6))
        ax_t = [fig.add_subplot(grid[0])]
        ax_t += [fig.add_subplot(grid[k], sharex=ax_t[0]) for k in (1, 2)]
        plot_ground_motion_axes(tuple(ax_t), motion.time, motion.acceleration)
        ax_t[0].set_title(f"{name or motion.name or 'record'}: PGA {motion.pga_g:.3f} g, dt {motion.dt:g} s, "
                          f"{motion.duration:.1f} s")
        ax_t[2].set_xlabel("time [s]")
        for a in ax_t[:2]:
            a.tick_params(labelbottom=False)
        ax = fig.add_subplot(grid[3])
        ax.semilogx(spec.period, spec.psa / STANDARD_GRAVITY, color="C0")
        ax.set_xlabel("period T [s]")
        ax.set_ylabel(f"PSA [g], ζ = {100 * damping:g} %")
        k = int(np.argmax(spec.psa))
        ax.annotate(f"peak {spec.psa[k] / STANDARD_GRAVITY:.3g} g at T = {spec.period[k]:.3g} s",
                    (spec.period[k], spec.psa[k] / STANDARD_GRAVITY), fontsize=7, xytext=(5, -10),
                    textcoords="offset points")
        fig.get_layout_engine().set(h_pad=0.06)
        fig.align_ylabels()
    return fig


def save_record_plot(motion: GroundMotion, path: str | Path, *, name: str = "") -> Path:
    """Write :func:`plot_record` to a PNG or PDF file."""
    from .plots import save_figure

    return save_figure(plot_record(motion, name=name), path)
