"""Ground-motion intensity measures (IM) of the applied inputs, computed with eqsig.

For fragility analysis the collapse of a rocking block can be related to any IM of the input
(paper §3 refs 45-47). This module gives, for the record a case applies (after windowing, scaling,
baseline correction: :func:`rockdem.loading.earthquake_record`):

* ``pga_g``: peak ground acceleration [g] (the requested one in IDA tables);
* ``pgv_m_s``: peak ground velocity [m/s], of the trapezoid integral of the acceleration;
* ``arias_m_s``: Arias intensity pi / (2 g) int a^2 dt [m/s] (eqsig takes g = 9.81 m/s^2);
* ``sa_g``: 5 %-damped pseudo-spectral acceleration Sa(T) [g] at the block's characteristic period
  T = 2 pi / p, p = sqrt(m g R / I_O) Housner's frequency parameter about the base edge
  (:func:`rocking_period`; sqrt(3 g / 4 R) for a rectangular block), or a period the user gives.
  Sa is computed exactly for the piecewise-linear record (Nigam and Jennings 1969, eqsig), read at
  40 points per period at least (the record sampled finer by linear interpolation where T < 40 dt).

eqsig (Millen, https://github.com/eng-tools/eqsig) computes them; the functions here pick the
signal and convert units. IDA tables get these columns from :func:`spec_intensities`: the IMs of
each record are computed once at its own amplitude and scaled linearly to every level (squared for
Arias): the processing (scaling, baseline correction, tail) is linear, so this equals computing
them for each scaled input, up to rounding.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .records import STANDARD_GRAVITY

__all__ = [
    "IM_COLUMNS",
    "SPECTRAL_DAMPING",
    "Intensity",
    "intensity_measures",
    "response_spectrum",
    "rocking_period",
    "input_intensity",
    "spec_intensities",
]

SPECTRAL_DAMPING = 0.05
"""Damping ratio of the response spectra [-]."""

IM_COLUMNS: dict[str, str] = {
    "pga_g": "PGA [g]",
    "pgv_m_s": "PGV [m/s]",
    "arias_m_s": "Arias intensity [m/s]",
    "sa_g": "Sa(T) [g]",
}
"""Intensity-measure columns of IDA tables and their axis labels."""


@dataclass(frozen=True)
class Intensity:
    """Intensity measures of one input.

    Attributes:
        pga_g: peak ground acceleration [g].
        pgv_m_s: peak ground velocity [m/s].
        arias_m_s: Arias intensity [m/s].
        sa_g: pseudo-spectral acceleration at ``period`` [g] (5 % damping).
        period: the spectral period [s].
    """

    pga_g: float
    pgv_m_s: float
    arias_m_s: float
    sa_g: float
    period: float

    def scaled(self, factor: float) -> Intensity:
        """The IMs of the input multiplied by ``factor`` (Arias by its square)."""
        f = float(factor)
        return Intensity(self.pga_g * f, self.pgv_m_s * abs(f), self.arias_m_s * f * f, self.sa_g * abs(f), self.period)


def _signal(acceleration: ArrayLike, dt: float) -> tuple[NDArray[np.float64], float]:
    if np.ndim(acceleration) != 1:
        raise ValueError(f"intensity measures need a 1-D acceleration history [m/s^2], got shape {np.shape(acceleration)}")
    a = np.asarray(acceleration, dtype=float).reshape(-1)
    if a.size < 2 or not np.all(np.isfinite(a)):
        raise ValueError(f"intensity measures need at least 2 finite acceleration samples, got {a.size}")
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"intensity measures: dt must be a positive time step [s], got {dt!r}")
    return a, float(dt)


SA_POINTS_PER_PERIOD = 40
"""Samples per period at which :func:`response_spectrum` reads the oscillator (the record is
sampled finer where its own dt is coarser): the peak is then within 1 - cos(pi / 40) = 0.3 %."""
SA_MAX_REFINEMENT = 64
"""Most sub-samples per record interval :func:`response_spectrum` takes."""


def response_spectrum(acceleration: ArrayLike, dt: float, periods: ArrayLike, damping: float = SPECTRAL_DAMPING) -> NDArray[np.float64]:
    """Pseudo-spectral acceleration Sa(T) = (2 pi / T)^2 Sd(T) [m/s^2] of a record (eqsig,
    Nigam-Jennings), read at least SA_POINTS_PER_PERIOD times per period (periods below
    6 dt / SA_MAX_REFINEMENT give the PGA: eqsig's convention).

    Args:
        acceleration: (n,) ground acceleration [m/s^2], uniformly sampled.
        dt: sampling interval [s].
        periods: (k,) positive oscillator periods [s].
        damping: damping ratio [-].
    """
    from eqsig.sdof import pseudo_response_spectra

    a, dt = _signal(acceleration, dt)
    t = np.asarray(periods, dtype=float).reshape(-1)
    if t.size == 0 or not np.all(np.isfinite(t) & (t > 0)):
        raise ValueError(f"response_spectrum: periods must be positive finite times [s], got {periods!r}")
    if isinstance(damping, bool) or not isinstance(damping, (int, float, np.number)) or not 0.0 <= damping < 1.0:
        raise ValueError(f"response_spectrum: damping is a ratio in [0, 1), e.g. 0.05 for 5 %, got {damping!r}")
    # Nigam-Jennings is exact at the samples; the peak between them is missed by up to
    # 1 - cos(pi dt / T) (5 % at T = 10 dt). The record is piecewise linear, so sampling it finer
    # (linear interpolation) changes nothing but where the response is read.
    # (Each period at its own refinement, so that its Sa does not depend on the other periods asked.)
    fine = np.minimum(np.maximum(np.ceil(SA_POINTS_PER_PERIOD * dt / t), 1), SA_MAX_REFINEMENT).astype(int)
    out = np.empty(t.size)
    for f in np.unique(fine):
        sel = fine == f
        af = a if f == 1 else np.interp(np.arange((a.size - 1) * f + 1) / f, np.arange(a.size), a)
        out[sel] = pseudo_response_spectra(af, dt / f, t[sel], float(damping))[2]
    return out


def intensity_measures(acceleration: ArrayLike, dt: float, period: float, damping: float = SPECTRAL_DAMPING) -> Intensity:
    """PGA, PGV, Arias intensity and Sa(period) of a record (see the module notes).

    Args:
        acceleration: (n,) ground acceleration [m/s^2] along its direction, uniformly sampled.
        dt: sampling interval [s].
        period: spectral period [s], > 0.
    """
    import eqsig

    a, dt = _signal(acceleration, dt)
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"the spectral period must be a positive time [s], got {period!r}")
    sig = eqsig.AccSignal(a, dt)
    arias = float(eqsig.im.calc_arias_intensity(sig)[-1])
    sa = float(response_spectrum(a, dt, [period], damping)[0])
    return Intensity(float(sig.pga) / STANDARD_GRAVITY, float(sig.pgv), arias, sa / STANDARD_GRAVITY, float(period))


def rocking_period(model: Any, block: int | None = None) -> float:
    """Characteristic period of a rocking block T = 2 pi / p [s], p = sqrt(m g R / I_O) about the
    base edge of the smaller instability angle (Housner 1963; 2.3 s for a 0.2 x 2 m block).

    Args:
        model: a :class:`rockdem.model.Model`.
        block: the free block (default the first).

    Raises:
        ValueError: the block has no base to rock on.
    """
    from .results import rocking_pivots

    b = int(np.flatnonzero(model.arrays.block_free)[0]) if block is None else int(block)
    pivots = rocking_pivots(model, b)
    if pivots is None:
        raise ValueError(f"block {model.block_names[b]!r} has no base edge to rock on: give the spectral period")
    return float(2.0 * math.pi / min(pivots, key=lambda p: p.eta).p)


_UNIT: dict[str, tuple[Intensity, float]] = {}
"""Per process: (IMs of the record at its own amplitude, its PGA before scaling [m/s^2]) by
loading table (without scale and pga_g) and period."""


def input_intensity(loading: Mapping[str, Any], period: float) -> Intensity:
    """IMs of the record an ``earthquake`` loading table applies (scale or pga_g included), from
    those of the record at its own amplitude (computed once per process) times the scale factor."""
    from .loading import earthquake_record

    table = {k: v for k, v in loading.items() if k not in ("scale", "pga_g")}
    key = json.dumps([table, period], sort_keys=True, default=str)
    if key not in _UNIT:
        gm = earthquake_record(table, scale=1.0)
        _UNIT[key] = (intensity_measures(gm.acceleration, gm.dt, period), _raw_pga(table))
    unit, raw_pga = _UNIT[key]
    if loading.get("pga_g") is not None:
        factor = float(loading["pga_g"]) * STANDARD_GRAVITY / raw_pga
    else:
        factor = float(loading.get("scale", 1.0))
    return unit.scaled(factor)


def _raw_pga(table: Mapping[str, Any]) -> float:
    """PGA [m/s^2] of the record before scaling (windowed): what ``pga_g`` scales to."""
    from .loading import earthquake_record

    return earthquake_record({**table, "baseline": False, "tail": 0.0}, scale=1.0).pga


def spec_intensities(specs: Sequence[Any], period: float) -> dict[str, Intensity | None]:
    """IMs of each spec's input by spec id (None for a spec without an earthquake loading or
    whose record cannot be read)."""
    out: dict[str, Intensity | None] = {}
    for s in specs:
        try:
            load = s.case_dict().get("loading", {})
            out[s.id] = input_intensity(load, period) if load.get("type") == "earthquake" else None
        except (ValueError, FileNotFoundError, OSError):
            out[s.id] = None
    return out
