"""Earthquake ground-motion records: reading, unit conversion and simple processing.

Readers convert to SI (m/s^2) once, at read time; everything downstream works in SI. Supported files:
PEER NGA AT2 (NGA-West2 and older PEER headers, the "Peknold" 8F10.5 variant), two-column
time/acceleration text or CSV files, and single-column files with a separately given time step.
A :class:`GroundMotion` is immutable: processing methods (scaling, baseline correction, tail,
resampling) return new records. Integration uses the trapezoid rule, starting from rest.

Seven public records ship with the package (``rockdem/data/ground-motions``, provenance in its
``SOURCES.md``), each with a short name (:data:`SHIPPED_RECORDS`, ``rockdem records``). A record is
found by :func:`record_path`, in this order:

1. an existing file at the given path (absolute, or relative to the working folder);
2. a bare file name in the folder named by the environment variable ``ROCKDEM_DATA`` (or in its
   ``ground-motions`` sub-folder), when that variable is set;
3. a shipped record, by short name (``"elcentro-rsn6"``, any case) or by file name
   (``"RSN6_IMPVALL.I_I-ELC180.AT2"``).
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import math
import os
import re
from dataclasses import dataclass, field, replace
from enum import StrEnum
from importlib import resources
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray
from ._warn import warn_user

__all__ = [
    "STANDARD_GRAVITY",
    "AccelerationUnit",
    "RecordFormat",
    "GroundMotion",
    "read_at2",
    "read_columns",
    "read_single_column",
    "read_record",
    "ShippedRecord",
    "SHIPPED_RECORDS",
    "DATA_ENV",
    "records_folder",
    "shipped_record",
    "record_path",
    "file_sha256",
    "record_table",
    "register_cli",
]

STANDARD_GRAVITY = 9.80665
"""Standard gravity g [m/s^2], used to convert records given in g."""

DT_RTOL = 1e-6
"""Relative tolerance on the spacing of a time column, as a fraction of dt."""

MAX_TAIL_SAMPLES = 10_000_000
"""Most zero samples :meth:`GroundMotion.with_tail` appends (80 MB per component)."""

_HEADER_SCAN_LINES = 12  # an AT2 header (NPTS/DT line included) must lie within the first lines


class AccelerationUnit(StrEnum):
    """Units an acceleration record may be written in."""

    G = "g"
    M_S2 = "m/s2"
    CM_S2 = "cm/s2"

    @property
    def to_si(self) -> float:
        """Factor converting a value in this unit to m/s^2."""
        return {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}[self.value]


class RecordFormat(StrEnum):
    """Closed set of record file formats."""

    AT2 = "at2"
    COLUMNS = "columns"
    SINGLE = "single"


_UNIT_ALIASES = {
    "g": AccelerationUnit.G, "g's": AccelerationUnit.G,
    "m/s2": AccelerationUnit.M_S2, "m/s^2": AccelerationUnit.M_S2, "m/s/s": AccelerationUnit.M_S2,
    "m/s**2": AccelerationUnit.M_S2, "m/sec/sec": AccelerationUnit.M_S2, "m/sec2": AccelerationUnit.M_S2,
    "cm/s2": AccelerationUnit.CM_S2, "cm/s^2": AccelerationUnit.CM_S2, "cm/s/s": AccelerationUnit.CM_S2,
    "cm/s**2": AccelerationUnit.CM_S2, "cm/sec/sec": AccelerationUnit.CM_S2,
    "cm/sec2": AccelerationUnit.CM_S2, "gal": AccelerationUnit.CM_S2,
}


def _parse_units(units: str | AccelerationUnit, where: str = "units") -> AccelerationUnit:
    key = str(units).strip().lower().replace(" ", "").replace("sec", "s") if units is not None else ""
    unit = _UNIT_ALIASES.get(key) or _UNIT_ALIASES.get(str(units).strip().lower())
    if unit is None:
        raise ValueError(f"{where}: unknown acceleration units {units!r}; use 'g', 'm/s2' or 'cm/s2'")
    return unit


# One number: optional sign, mantissa, optional E or Fortran D exponent. Numbers may run together when a
# sign that is not part of an exponent starts the next one: "1.234-5.678", ".1E-02-.2E-03".
_UNSIGNED = r"(?:\d+\.?\d*|\.\d+)(?:[EeDd][+-]?\d+)?"
_NUMBER_RE = re.compile(rf"[+-]?{_UNSIGNED}")
_TOKEN_RE = re.compile(rf"[+-]?{_UNSIGNED}(?:[+-]{_UNSIGNED})*")
MAX_PLAUSIBLE_DT = 0.1
"""[s] a time/acceleration file with a larger time step is warned about (times in milliseconds?)."""

_SPLIT_RE = re.compile(r"[\s,;]+")


def _parse_numbers(text: str, *, path: Path, lineno: int, delimiter: str | None = None) -> list[float]:
    """Numbers on one line, stuck-together values split; ValueError naming file, line and token."""
    pieces = _SPLIT_RE.split(text.strip()) if delimiter is None else [p.strip() for p in text.split(delimiter)]
    while pieces and not pieces[-1]:
        pieces.pop()  # a trailing delimiter ends the line, it does not open an empty column
    values: list[float] = []
    for token in pieces:
        if not token and delimiter is None:
            continue
        if not _TOKEN_RE.fullmatch(token):
            raise ValueError(
                f"{path}, line {lineno}: cannot read {token!r} as a number (line text: {text.strip()!r})"
            )
        values.extend(float(s.replace("D", "E").replace("d", "e")) for s in _NUMBER_RE.findall(token))
    return values


def _is_numeric_line(text: str, delimiter: str | None) -> bool:
    pieces = _SPLIT_RE.split(text.strip()) if delimiter is None else [p.strip() for p in text.split(delimiter)]
    while pieces and not pieces[-1]:
        pieces.pop()
    return bool(pieces) and all(_TOKEN_RE.fullmatch(p) for p in pieces if p or delimiter is not None)


def _read_lines(path: str | os.PathLike[str]) -> tuple[Path, list[str]]:
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"ground-motion file not found: {p} (check the path, or give a shipped "
                                "record's short name: `rockdem records` lists them)")
    lines = p.read_text(encoding="utf-8", errors="replace").splitlines()
    if not any(line.strip() for line in lines):
        raise ValueError(f"{p} is empty: a ground-motion file needs at least two acceleration values")
    return p, lines


@dataclass(frozen=True, eq=False)
class GroundMotion:
    """A uniformly sampled earthquake acceleration record in SI units.

    Attributes:
        acceleration: (n,) horizontal ground acceleration [m/s^2], applied along ``direction``.
        dt: time step [s], > 0.
        name: short identifier (the file stem for records read from files).
        source: file the record was read from, or None.
        units_in: units the values had in the source, before conversion to m/s^2.
        description: free text from the file header (event, station, component).
        start_time: time of the first sample [s]; ``time = start_time + dt * arange(n)``.
        direction: (3,) horizontal unit vector along which ``acceleration`` acts; z is up.
        vertical: (n,) optional vertical ground acceleration [m/s^2], positive up, or None.
    """

    acceleration: NDArray[np.float64]
    dt: float
    name: str = ""
    source: Path | None = None
    units_in: str = AccelerationUnit.M_S2.value
    description: str = ""
    start_time: float = 0.0
    direction: NDArray[np.float64] = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))
    vertical: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        label = self.name or "GroundMotion"
        dt = float(self.dt)
        if not np.isfinite(dt) or dt <= 0.0:
            raise ValueError(f"{label}: dt must be a positive time step in seconds, got {self.dt!r}")
        if not np.isfinite(self.start_time):
            raise ValueError(f"{label}: start_time must be finite, got {self.start_time!r}")
        acc = _frozen_samples(self.acceleration, "acceleration", label)
        vertical = None
        if self.vertical is not None:
            vertical = _frozen_samples(self.vertical, "vertical", label)
            if vertical.shape != acc.shape:
                raise ValueError(f"{label}: vertical has {vertical.size} samples but acceleration has "
                                 f"{acc.size}; give both on the same time grid")
        d = np.array(self.direction, dtype=float).reshape(-1)
        norm = float(np.linalg.norm(d)) if d.shape == (3,) and np.all(np.isfinite(d)) else 0.0
        if norm == 0.0:
            raise ValueError(f"{label}: direction must be a finite non-zero 3-vector, got {self.direction!r}")
        if abs(d[2]) > 1e-9 * norm:
            raise ValueError(f"{label}: direction must be horizontal (z is up), got {self.direction!r}; "
                             "give vertical motion as `vertical`")
        d = d / norm
        d[2] = 0.0
        d.setflags(write=False)
        object.__setattr__(self, "dt", dt)
        object.__setattr__(self, "start_time", float(self.start_time))
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "vertical", vertical)
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "units_in", _parse_units(self.units_in, f"{label}: units_in").value)

    @classmethod
    def from_samples(cls, values: ArrayLike, *, dt: float, units: str | AccelerationUnit,
                     name: str = "", **kwargs: object) -> GroundMotion:
        """Build a record from samples in any supported unit, converting them to m/s^2.

        Args:
            values: (n,) acceleration samples in ``units``.
            dt: time step [s].
            units: "g", "m/s2" or "cm/s2".
            name: identifier.
            **kwargs: other :class:`GroundMotion` fields (source, description, start_time, direction).
        """
        unit = _parse_units(units)
        acc = _frozen_samples(values, "acceleration", name or "GroundMotion") * unit.to_si  # (checked before the conversion)
        return cls(acc, dt, name=name, units_in=unit.value, **kwargs)  # type: ignore[arg-type]

    def __repr__(self) -> str:
        return (f"GroundMotion(name={self.name!r}, npts={self.npts}, dt={self.dt:g} s, "
                f"duration={self.duration:g} s, pga={self.pga_g:.4f} g, units_in={self.units_in!r})")

    @property
    def npts(self) -> int:
        """Number of samples n."""
        return int(self.acceleration.size)

    @property
    def time(self) -> NDArray[np.float64]:
        """(n,) sample times [s]."""
        return self.start_time + self.dt * np.arange(self.npts)

    @property
    def duration(self) -> float:
        """Time from the first to the last sample, (n - 1) * dt [s]."""
        return (self.npts - 1) * self.dt

    @property
    def pga(self) -> float:
        """Peak ground acceleration max |a| of the horizontal component [m/s^2]."""
        return float(np.max(np.abs(self.acceleration)))

    @property
    def pga_g(self) -> float:
        """Peak ground acceleration in units of standard gravity [g]."""
        return self.pga / STANDARD_GRAVITY

    @property
    def pga_time(self) -> float:
        """Time of the (first) peak of |a| [s]."""
        return self.start_time + self.dt * int(np.argmax(np.abs(self.acceleration)))

    def scaled(self, factor: float) -> GroundMotion:
        """Return the record with horizontal and vertical accelerations multiplied by ``factor``."""
        if not np.isfinite(factor):
            raise ValueError(f"{self.name}: scale factor must be finite, got {factor!r}")
        vertical = None if self.vertical is None else self.vertical * factor
        return replace(self, acceleration=self.acceleration * factor, vertical=vertical)

    def scaled_to_pga(self, pga: float) -> GroundMotion:
        """Return the record scaled so that its horizontal PGA equals ``pga`` [m/s^2].

        The vertical component, if any, gets the same factor (the V/H ratio is kept).
        """
        if not np.isfinite(pga) or pga <= 0.0:
            raise ValueError(f"{self.name}: target pga must be positive, in m/s^2, got {pga!r}")
        if self.pga == 0.0:
            raise ValueError(f"{self.name}: the record is all zeros and cannot be scaled to a PGA")
        return self.scaled(pga / self.pga)

    def with_tail(self, seconds: float) -> GroundMotion:
        """Return the record followed by a free-vibration tail of zero acceleration.

        Args:
            seconds: tail length [s] >= 0; rounded to a whole number of steps of the same dt.
        """
        if not np.isfinite(seconds) or seconds < 0.0:
            raise ValueError(f"{self.name}: tail length must be >= 0 seconds, got {seconds!r}")
        n = round(seconds / self.dt)
        if n > MAX_TAIL_SAMPLES:
            raise ValueError(
                f"{self.name}: a tail of {seconds:g} s at dt = {self.dt:g} s is {n:.3g} samples of zeros "
                f"(at most {MAX_TAIL_SAMPLES:.0e}); shorten the tail (a simulation holds the record's end "
                "value after it: no tail beyond the run's end is needed)")
        zeros = np.zeros(int(n))
        vertical = None if self.vertical is None else np.concatenate([self.vertical, zeros])
        return replace(self, acceleration=np.concatenate([self.acceleration, zeros]), vertical=vertical)

    def with_direction(self, direction: ArrayLike) -> GroundMotion:
        """Return the record applied along another horizontal ``direction`` (3-vector, normalised)."""
        return replace(self, direction=np.asarray(direction, dtype=float))

    def baseline_corrected(self, order: int = 1) -> GroundMotion:
        """Return the record with a polynomial velocity baseline removed, ending at rest.

        The velocity v(t) (trapezoid integral of a, v(t0) = 0) is fitted in the least-squares sense by
        a polynomial p(t) of degree ``order`` (constant term included), and the acceleration becomes
        a(t) - p'(t) at every sample. For ``order`` <= 2, p' is at most linear, which the trapezoid rule
        integrates exactly, so the corrected velocity is exactly v(t) - p(t) + p(t0): its least-squares
        trend is gone. ``order=1`` removes a constant acceleration offset.

        The velocity still left at the end (a record cut inside its strong motion, ``window`` of
        :func:`rockdem.loading.prepare_record`) is then taken out smoothly over the last tenth of the
        record (at least two samples): a deceleration V r'(t), r = sin^2 rising from 0 to 1, sized so
        that the record followed by zero acceleration (:meth:`with_tail`) ends exactly at rest (a
        trapezoid integral). Before that last tenth the record is only trend-corrected, and a
        permanent ground displacement (a velocity pulse) is kept. The vertical component, if any, is corrected the
        same way, separately.

        Args:
            order: degree of the velocity polynomial, 1 <= order < npts.
        """
        if int(order) != order or not 1 <= order < self.npts:
            raise ValueError(f"{self.name}: baseline order must be an integer in [1, {self.npts - 1}], "
                             f"got {order!r}")
        # Fit on t - t0 scaled to [0, 1] to keep the polynomial basis well conditioned.
        span = max(self.duration, self.dt)
        s = (self.time - self.start_time) / span
        ramp = max(0.1 * span, 2.0 * self.dt)  # [s]
        x = np.clip((self.time - (self.time[-1] - ramp)) / ramp, 0.0, 1.0)
        stop = np.append(np.pi / (2.0 * ramp) * np.sin(np.pi * x), 0.0)  # r'(t) [1/s], then a zero sample

        def corrected(acc: NDArray[np.float64]) -> NDArray[np.float64]:
            vel = _integral(acc, self.dt)
            fit = np.polynomial.Polynomial.fit(s, vel, int(order), domain=[0.0, 1.0], window=[0.0, 1.0])
            acc = acc - fit.deriv()(s) / span
            left = _integral(np.append(acc, 0.0), self.dt)[-1]  # [m/s] after the record, at rest after
            return acc - left / _integral(stop, self.dt)[-1] * stop[:-1]

        vertical = None if self.vertical is None else corrected(self.vertical)
        return replace(self, acceleration=corrected(self.acceleration), vertical=vertical)

    def resampled(self, dt: float) -> GroundMotion:
        """Return the record linearly interpolated onto a new time step ``dt`` [s].

        The new grid starts at the same time and stops at or before the last sample. No anti-alias
        filter is applied, so coarsening a record can lose or alias its high-frequency content.
        """
        if not np.isfinite(dt) or dt <= 0.0:
            raise ValueError(f"{self.name}: dt must be a positive time step in seconds, got {dt!r}")
        n = int(np.floor(self.duration / dt * (1.0 + 1e-12))) + 1
        t_new = self.start_time + dt * np.arange(n)
        t_old = self.time
        vertical = None if self.vertical is None else np.interp(t_new, t_old, self.vertical)
        return replace(self, acceleration=np.interp(t_new, t_old, self.acceleration), dt=dt, vertical=vertical)

    def velocity(self) -> NDArray[np.float64]:
        """(n,) horizontal ground velocity [m/s], trapezoid integral of the acceleration from rest."""
        return _integral(self.acceleration, self.dt)

    def displacement(self) -> NDArray[np.float64]:
        """(n,) horizontal ground displacement [m], trapezoid integral of the velocity from zero."""
        return _integral(self.velocity(), self.dt)

    def vector_acceleration(self) -> NDArray[np.float64]:
        """(n, 3) ground acceleration [m/s^2]: a(t) * direction, plus the vertical component on z."""
        out = self.acceleration[:, None] * self.direction[None, :]
        if self.vertical is not None:
            out[:, 2] += self.vertical
        return out

    def vector_velocity(self) -> NDArray[np.float64]:
        """(n, 3) ground velocity [m/s], trapezoid integral of :meth:`vector_acceleration` from rest."""
        return _integral(self.vector_acceleration(), self.dt)


def _integral(y: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
    """Trapezoid integral of ``y`` (n, ...) along its first axis from 0, at step ``dt`` [s]
    (SciPy's integrate package is imported here, not with the module: 0.08 s of every command)."""
    from scipy.integrate import cumulative_trapezoid

    return cumulative_trapezoid(y, dx=dt, axis=0, initial=0.0)


MAX_SAMPLE = 1e12
"""Largest |sample| of a record accepted, in any units (a trillion m/s^2, or cm/s^2, or g)."""


def _frozen_samples(values: ArrayLike, what: str, label: str) -> NDArray[np.float64]:
    arr = np.array(values, dtype=float)
    if arr.ndim != 1 or arr.size < 2:
        raise ValueError(f"{label}: {what} must be a 1-D array of at least 2 samples, got shape {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ValueError(f"{label}: {what} has {bad.size} non-finite value(s) (NaN or inf), first at "
                         f"sample {bad[0]}; clean the record before use")
    bad = np.flatnonzero(np.abs(arr) > MAX_SAMPLE)
    if bad.size:  # (1e300 overflowed to inf in the unit conversion, blamed on the scale, before 2026-12-08)
        raise ValueError(f"{label}: {what} has {bad.size} value(s) beyond any plausible acceleration (|value| > "
                         f"{MAX_SAMPLE:g}), first {arr[bad[0]]:g} at sample {bad[0]}; check the record's column and units")
    arr.setflags(write=False)
    return arr


# --------------------------------------------------------------------------------------------------- readers

_NPTS_RE = re.compile(r"NPTS\s*[=:]\s*(\d+)", re.IGNORECASE)
_DT_RE = re.compile(rf"(?<![A-Za-z])DT\s*[=:]\s*([+-]?{_UNSIGNED})", re.IGNORECASE)
# Older PEER header: "  4000    0.01000   NPTS, DT"
_OLD_NPTS_DT_RE = re.compile(rf"^\s*(\d+)[\s,]+({_UNSIGNED})\s+NPTS\s*,?\s*DT", re.IGNORECASE)
_PER_S2 = r"\s*/\s*(?:s|sec|second)s?\s*(?:\^\s*2|\*\*\s*2|2|/\s*(?:s|sec|second)s?)"
_HEADER_UNITS = (
    (AccelerationUnit.CM_S2, re.compile(rf"(?<![a-z])(?:cm|centimet(?:er|re)s?){_PER_S2}|(?<![a-z])gals?(?![a-z])", re.IGNORECASE)),
    (AccelerationUnit.M_S2, re.compile(rf"(?<![a-z])(?:m|met(?:er|re)s?){_PER_S2}", re.IGNORECASE)),
    (AccelerationUnit.G, re.compile(r"units?\s*(?:of|are|in|:|=)?\s*[(\[']?\s*g(?:'s)?(?![a-z/])|\(g\)", re.IGNORECASE)),
)
"""Acceleration units as AT2 headers state them: ``UNITS OF G``, ``The units are (g)``, ``Units:
cm/s^2``, ``ACCELERATION IN CM/SEC**2``, ``(gal)``, ``M/S/S``, ..."""
_NOT_ACCEL_RE = re.compile(r"\b(VELOCITY|DISPLACEMENT)\b.*\bUNITS?\b", re.IGNORECASE)


DT_OVERRIDE_SHARE = 0.02
"""A dt that overrides an AT2 header's by more than its rounding (half a unit in the header's last
digit), or by more than this share of it, is warned about: data providers round DT to a few
digits (``.0029`` for 0.00293 s, 1 %), not by half a sample (``.01`` for 0.0149 s)."""


def _half_last_digit(text: str) -> float:
    """Half a unit in the last digit of a number as written (``".0029"``: 5e-5, ``"1.0E-02"``:
    5e-4): how far the value it stands for may be from it by rounding alone."""
    mantissa, _, exponent = text.upper().replace("D", "E").partition("E")
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def _at2_header(p: Path, lines: list[str]) -> tuple[int, int, float, float]:
    """Line index of the NPTS/DT line, NPTS, DT [s] and the rounding of DT as written [s] (half a
    unit in its last digit)."""
    for i, line in enumerate(lines[:_HEADER_SCAN_LINES]):
        m_n, m_dt = _NPTS_RE.search(line), _DT_RE.search(line)
        old = _OLD_NPTS_DT_RE.search(line)
        if m_n and m_dt:
            npts, dt_text = int(m_n.group(1)), m_dt.group(1)
        elif old:
            npts, dt_text = int(old.group(1)), old.group(2)
        else:
            continue
        dt = float(dt_text.replace("D", "E").replace("d", "e"))
        for head in lines[:i]:
            if _NOT_ACCEL_RE.search(head):
                raise ValueError(f"{p}: the header says {head.strip()!r}; rockdem reads acceleration records "
                                 "(use the matching .AT2 acceleration file)")
        return i, npts, dt, _half_last_digit(dt_text)
    raise ValueError(f"{p}: no 'NPTS= ..., DT= ...' header line in the first {_HEADER_SCAN_LINES} lines; "
                     "for a headerless file use read_single_column(path, dt=..., units=...) or read_columns")


def _header_units(head: list[str]) -> tuple[AccelerationUnit | None, str]:
    """The acceleration units the header lines ``head`` state (:data:`_HEADER_UNITS`; None when
    they name none), and why they cannot be taken ("" when they can): two different units, or a
    line that speaks of units in a form not read here (such headers were read as g before
    2026-11-30: "Units: cm/s^2" gave a record of 196 g)."""
    found = sorted({(unit.value, line.strip()) for line in head for unit, pattern in _HEADER_UNITS if pattern.search(line)})
    units = {unit for unit, _ in found}
    if len(units) > 1:
        return None, f"the header names several units ({'; '.join(line for _, line in found)})"
    if units:
        return AccelerationUnit(units.pop()), ""
    unread = [line.strip() for line in head if re.search(r"\bunits?\b", line, re.IGNORECASE)]
    return None, f"the header speaks of units rockdem cannot read ({unread[0]!r})" if unread else ""


def read_at2(path: str | os.PathLike[str], *, units: str | AccelerationUnit | None = None,
             dt: float | None = None) -> GroundMotion:
    """Read a PEER NGA ``.AT2`` acceleration record.

    Header variants: NGA-West2 (``NPTS=  5372, DT=   .0100 SEC,``), the Peknold 8F10.5 file
    (``NPTS=  1559, DT= .02000 SEC``), any case, comma or ``SEC`` optional, and the older PEER
    ``4000  0.01000  NPTS, DT``. Values may be in E, D or plain format, any number per line, and may run
    together when a sign starts the next one (``1.234-5.678``, ``.1E-02-.2E-03``).

    Args:
        path: the file.
        units: units of the values. Default: those the header states ("UNITS OF G", "units are (g)"),
            else g. An explicit value that contradicts the header is an error.
        dt: time step [s] overriding the header's (which some files round, e.g. ``.0029``). A
            dt farther from the header's than its rounding (half a unit in its last digit, at
            most :data:`DT_OVERRIDE_SHARE` of it) is used, with a warning: it stretches or
            shrinks the record in time.

    Returns:
        The record in m/s^2, named after the file stem, with header line 2 as description.

    Raises:
        FileNotFoundError: missing file.
        ValueError: no NPTS/DT line, unparsable value (file, line number and text given), value count
            different from NPTS, bad units or dt.
    """
    p, lines = _read_lines(path)
    i_head, npts, dt_head, rounding = _at2_header(p, lines)
    header_units, problem = _header_units(lines[:i_head])
    if problem and units is None:
        raise ValueError(f"{p}: {problem}; give units ('g', 'm/s2' or 'cm/s2')")
    unit = header_units or AccelerationUnit.G
    if units is not None:
        unit = _parse_units(units, f"{p}: units")
        if header_units is not None and unit != header_units:
            raise ValueError(f"{p}: units={str(units)!r} contradicts the header, which says "
                             f"{header_units.value!r}; omit units to use the header's")
    values: list[float] = []
    for k in range(i_head + 1, len(lines)):
        if lines[k].strip():
            values.extend(_parse_numbers(lines[k], path=p, lineno=k + 1))
    if len(values) != npts:
        raise ValueError(f"{p}: header (line {i_head + 1}) says NPTS={npts} but {len(values)} values were read")
    step = dt_head if dt is None else dt
    if not np.isfinite(step) or step <= 0.0:
        raise ValueError(f"{p}: dt must be positive, got {step!r} (pass dt=... to override the header)")
    allowed = min(rounding, DT_OVERRIDE_SHARE * dt_head)
    if dt is not None and abs(dt - dt_head) > allowed * (1.0 + 1e-9):
        warn_user(f"{p}: dt = {dt:g} s overrides the header's DT = {dt_head:g} s (line {i_head + 1}) by more "
                      f"than its rounding ({allowed:g} s): the record's {npts * dt_head:g} s become "
                      f"{npts * dt:g} s; omit dt to use the header's")
    # NGA files put the event and station on line 2 under a fixed banner; other variants on line 1.
    banner = lines[0].strip().upper().startswith("PEER")
    description = lines[1].strip() if banner and i_head >= 2 else lines[0].strip() if i_head >= 1 else ""
    return GroundMotion.from_samples(values, dt=step, units=unit, name=p.stem, source=p,
                                     description=description)


def read_columns(path: str | os.PathLike[str], *, units: str | AccelerationUnit, time_column: int = 0,
                 acc_column: int = 1, delimiter: str | None = None,
                 skip_comments: str | None = "#") -> GroundMotion:
    """Read a time/acceleration text or CSV file with a uniform time step.

    Lines starting with ``skip_comments`` are skipped anywhere (text after it on a data line is
    dropped too); blank lines are skipped; non-numeric lines are skipped only before the first data
    line (column titles). The time step is checked to be uniform within ``DT_RTOL * dt``.

    Args:
        path: the file.
        units: units of the acceleration column: "g", "m/s2" or "cm/s2".
        time_column: zero-based index of the time column [s].
        acc_column: zero-based index of the acceleration column.
        delimiter: column separator; None for commas and/or whitespace.
        skip_comments: comment marker, or None.

    Returns:
        The record in m/s^2 with ``start_time`` the first time and dt the mean step.

    Raises:
        FileNotFoundError: missing file.
        ValueError: unparsable line, missing column, time not increasing or not uniform (line named).
    """
    p, lines = _read_lines(path)
    unit = _parse_units(units, f"{p}: units")
    rows: list[list[float]] = []
    linenos: list[int] = []
    comments: list[str] = []
    need = max(time_column, acc_column) + 1
    for k, raw in enumerate(lines, start=1):
        text = raw
        if skip_comments and skip_comments in raw:
            at = raw.index(skip_comments)
            text = raw[:at]
            if not text.strip():
                comments.append(raw[at + len(skip_comments):].strip())
        if not text.strip():
            continue
        if not rows and not _is_numeric_line(text, delimiter):
            continue  # column titles above the data
        row = _parse_numbers(text, path=p, lineno=k, delimiter=delimiter)
        if len(row) < need:
            raise ValueError(f"{p}, line {k}: {len(row)} column(s), but time_column={time_column} and "
                             f"acc_column={acc_column} need {need} (line text: {raw.strip()!r})")
        rows.append(row)
        linenos.append(k)
    if len(rows) < 2:
        raise ValueError(f"{p}: found {len(rows)} data line(s); a record needs at least 2")
    t = np.array([r[time_column] for r in rows])
    acc = np.array([r[acc_column] for r in rows])
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        j = int(np.flatnonzero(steps <= 0.0)[0])
        raise ValueError(f"{p}, line {linenos[j + 1]}: time {float(t[j + 1]):g} does not increase "
                         f"(previous {float(t[j]):g} on line {linenos[j]}); if column {time_column} is not the time, "
                         "give time_column and acc_column (zero-based)")
    dt_typ = float(np.median(steps))
    # 1e-6 relative catches any missing or repeated sample; the eps term absorbs float noise in long times.
    tol = DT_RTOL * dt_typ + 16 * np.finfo(float).eps * float(np.max(np.abs(t)))
    off = np.flatnonzero(np.abs(steps - dt_typ) > tol)
    if off.size:
        j = int(off[0])
        raise ValueError(f"{p}, line {linenos[j + 1]}: time step {float(steps[j]):.6g} s differs from the record's "
                         f"{dt_typ:.6g} s; rockdem needs a uniform dt (resample the file first)")
    dt = (t[-1] - t[0]) / (t.size - 1)
    if dt >= 1.0 and (dt == 1.0 or t.size >= 10) and np.all(t == np.round(t)):
        # A time step of whole seconds is no strong-motion record's: the column is a sample index or
        # a time in milliseconds, and read as seconds it stretched the record 1000 times unnoticed.
        raise ValueError(f"{p}: column {time_column} holds whole numbers ({t[0]:g}, {t[1]:g}, {t[2] if t.size > 2 else t[1]:g}, "
                         f"...), a time step of {dt:g} s: sample numbers, or times in milliseconds? rockdem reads times "
                         "in seconds: give time_column (zero-based) for the column of times in seconds, or convert the "
                         "column to seconds")
    if dt > MAX_PLAUSIBLE_DT:
        warn_user(f"{p}: a time step of {dt:g} s; strong-motion records are sampled every 0.005 to 0.02 s: if column "
                  f"{time_column} is in milliseconds, convert it to seconds")
    return GroundMotion.from_samples(acc, dt=dt, units=unit, name=p.stem, source=p,
                                     description=" | ".join(c for c in comments if c), start_time=float(t[0]))


def read_single_column(path: str | os.PathLike[str], *, dt: float, units: str | AccelerationUnit,
                       skip_header: int = 0) -> GroundMotion:
    """Read a file with one acceleration value per line, sampled every ``dt`` seconds.

    Args:
        path: the file.
        dt: time step [s], > 0.
        units: "g", "m/s2" or "cm/s2".
        skip_header: number of lines to skip at the top; blank and ``#`` lines are skipped anywhere.

    Raises:
        FileNotFoundError: missing file.
        ValueError: bad dt, unparsable line, or a line with more than one value.
    """
    p, lines = _read_lines(path)
    if dt is None or not np.isfinite(dt) or dt <= 0.0:
        raise ValueError(f"{p}: dt must be a positive time step in seconds, got {dt!r}")
    unit = _parse_units(units, f"{p}: units")
    values: list[float] = []
    for k in range(skip_header, len(lines)):
        text = lines[k].split("#", 1)[0]
        if not text.strip():
            continue
        row = _parse_numbers(text, path=p, lineno=k + 1)
        if len(row) != 1:
            raise ValueError(f"{p}, line {k + 1}: {len(row)} values where a single-column file has one "
                             "(use read_columns for time/acceleration pairs)")
        values.append(row[0])
    if len(values) < 2:
        raise ValueError(f"{p}: found {len(values)} value(s); a record needs at least 2")
    return GroundMotion.from_samples(values, dt=dt, units=unit, name=p.stem, source=p)


def _sniff_format(p: Path, lines: list[str]) -> RecordFormat:
    if p.suffix.lower() == ".at2":
        return RecordFormat.AT2
    if any(re.search(r"\d,\d", line) and re.search(r"[;\t]", line) for line in lines[:_HEADER_SCAN_LINES]):
        raise ValueError(f"{p}: the file looks like a spreadsheet export with decimal commas (1,5 for 1.5) and ';' or "
                         "tabs between the fields: save it with '.' decimals (any of ',', ';', tab or space between "
                         "the fields then reads)")
    head = lines[:_HEADER_SCAN_LINES]
    if any((_NPTS_RE.search(s) and _DT_RE.search(s)) or _OLD_NPTS_DT_RE.search(s) for s in head):
        return RecordFormat.AT2
    for line in lines:
        text = line.split("#", 1)[0]
        if text.strip() and _is_numeric_line(text, None):
            count = len(_SPLIT_RE.split(text.strip()))
            if count == 1:
                return RecordFormat.SINGLE
            if count == 2:
                return RecordFormat.COLUMNS
            raise ValueError(f"{p}: cannot tell the format from a first data line of {count} values; give the "
                             "columns: time_column and acc_column (zero-based; in a case file, keys of [loading], "
                             "e.g. time_column = 0, acc_column = 2), or call read_columns")
    raise ValueError(f"{p}: no numeric data line found")


def read_record(path: str | os.PathLike[str], *, units: str | AccelerationUnit | None = None,
                dt: float | None = None, format: str | RecordFormat | None = None,
                time_column: int | None = None, acc_column: int | None = None) -> GroundMotion:
    """Read a ground-motion record of any supported format, from a file or by name.

    The format is ``format`` if given, else AT2 for a ``.AT2`` suffix or an NPTS/DT header line, else
    two-column time/acceleration or single-column values, from the first data line.

    Args:
        path: a file, or a name found by :func:`record_path` (a shipped record's short name such as
            "nahanni" or its file name, or a file name in ``$ROCKDEM_DATA``).
        units: "g", "m/s2" or "cm/s2"; optional for AT2 (header, else g) and for shipped records
            (their registry units), required otherwise.
        dt: time step [s]; required for single-column files, overrides the header for AT2, and for
            two-column files must agree with the time column.
        format: "at2", "columns" or "single".
        time_column, acc_column: zero-based columns of the time [s] and the acceleration of a
            columns file (defaults 0 and 1); giving either reads the file as columns.
    """
    if dt is not None and (isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating, np.integer))
                           or not math.isfinite(dt) or dt <= 0.0):
        raise ValueError(f"{path}: dt must be a positive time step in seconds (a number), got {dt!r}")
    columns = {"time_column": 0 if time_column is None else time_column, "acc_column": 1 if acc_column is None else acc_column}
    for key, value in columns.items():
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
            raise ValueError(f"{path}: {key} must be a zero-based column index (0, 1, 2, ...), got {value!r}")
    chosen = time_column is not None or acc_column is not None
    found = record_path(path)
    if units is None and (entry := _shipped_entry(found)) is not None:
        units = entry.units
    p, lines = _read_lines(found)
    if format is not None and str(format).lower() not in {f.value for f in RecordFormat}:
        raise ValueError(f"{p}: unknown format {format!r}; use 'at2', 'columns' or 'single' (or omit it)")
    try:
        fmt = RecordFormat(str(format).lower()) if format is not None else _sniff_format(p, lines)
    except ValueError:  # three columns or more: with columns chosen, a columns file of any width
        if not chosen:
            raise
        fmt = RecordFormat.COLUMNS
    if chosen and fmt is not RecordFormat.COLUMNS:
        raise ValueError(f"{p}: time_column and acc_column choose the columns of a time/acceleration file, "
                         f"and do not apply to the {fmt.value} format; leave them out")
    if fmt is RecordFormat.COLUMNS and columns["time_column"] == columns["acc_column"]:
        raise ValueError(f"{p}: time_column and acc_column are both {columns['acc_column']}; give two different columns")
    if fmt is RecordFormat.AT2:
        return read_at2(p, units=units, dt=dt)
    if units is None:
        raise ValueError(f"{p}: the units of a {fmt.value} file are not known; pass units='g', 'm/s2' or "
                         "'cm/s2'")
    if fmt is RecordFormat.SINGLE:
        if dt is None:
            raise ValueError(f"{p} is a single-column file with no time information; pass dt=<time step "
                             "in seconds>")
        return read_single_column(p, dt=dt, units=units)
    gm = read_columns(p, units=units, time_column=int(columns["time_column"]), acc_column=int(columns["acc_column"]))
    if dt is not None and abs(gm.dt - dt) > DT_RTOL * dt:
        hint = "; if that column counts samples, give time_column" if gm.dt == 1.0 else ""
        raise ValueError(f"{p}: dt={dt!r} disagrees with the time column's {gm.dt!r} s (column {columns['time_column']}); "
                         f"omit dt{hint}")
    return gm


# ------------------------------------------------------------------------------------- shipped records

DATA_ENV = "ROCKDEM_DATA"
"""Environment variable naming a folder of the user's own records (or its parent data folder)."""

_PEER = "PEER NGA-West2 terms of use apply (a PEER database product)"
_EEUQ = ("NHERI-SimCenter/EE-UQ @ 3c5339f74b86998fc68af0df7cf1b4e2ce7b1cf7; the repository's BSD-2-Clause "
         "licence covers its source code only, not these data files")
_IRPINIA_SOURCE = ("vacalderon/GroundmotionSelection @ 4575a07afb90e2a254291c19a0518df52a87846d (Mainshocks/, "
                   "deleted in a later commit)")
_IRPINIA_LICENCE = (f"PROVISIONAL: repository without licence; {_PEER}; Italian recording, redistribution terms "
                    "not verified; header dt printed to 4 decimals only")


@dataclass(frozen=True)
class ShippedRecord:
    """One ground-motion record shipped with rockdem (facts from the folder's ``SOURCES.md``).

    Attributes:
        name: short name used to refer to it (lower case, e.g. "elcentro-rsn6").
        file: file name in the package's ``data/ground-motions`` folder.
        event: earthquake.
        date: its date (ISO 8601; the year only where SOURCES.md gives no more).
        station: recording station.
        component: horizontal component (azimuth or orientation).
        units: units of the file's values ("g" for all shipped records).
        sha256: SHA-256 of the file, as listed in ``SOURCES.md``.
        source: repository (and commit) the file was copied from, byte for byte.
        licence: what is known of its licence and terms of use.
        provisional: True while its redistribution terms are not confirmed.
        paper_name: the name of the closest record in Galvez et al. (2022), if any.
    """

    name: str
    file: str
    event: str
    date: str
    station: str
    component: str
    units: str
    sha256: str
    source: str
    licence: str
    provisional: bool = False
    paper_name: str = ""


SHIPPED_RECORDS: tuple[ShippedRecord, ...] = (
    ShippedRecord(
        name="elcentro-rsn6",
        file="RSN6_IMPVALL.I_I-ELC180.AT2",
        event="Imperial Valley-02",
        date="1940-05-19",
        station="El Centro Array #9",
        component="180 (N-S)",
        units="g",
        sha256="ab219fe7bc8060fb5dba31669b5c29a782435bef113eda51ab81b8f6ff05824d",
        source=_EEUQ + " (Tests/eeuq-0003/templatedir, added in c3e5482d382b062f5bfd1ecd86e376bfa516f229)",
        licence=_PEER + "; a US federal record (USGS station 117): public domain inferred, not verified",
        paper_name="El Centro 1940 NS",
    ),
    ShippedRecord(
        name="elcentro-peknold",
        file="elCentro.AT2",
        event="Imperial Valley (El Centro)",
        date="1940-05-19",
        station="El Centro",
        component="N-S (Peknold version)",
        units="g",
        sha256="e096f0458ae7565ac8e9fac80eda018e4715a357ea4c14504ce1cfa6556c53a6",
        source=_EEUQ + " (Examples/eeuq-0001/src, last changed in 30457c6dc757084137075e893452b31ff4ba942b)",
        licence="processing history of the Peknold version undocumented; licence as the EE-UQ note",
        paper_name="El Centro 1940 NS",
    ),
    ShippedRecord(
        name="pacoima",
        file="RSN77_SFERN_PUL164.AT2",
        event="San Fernando",
        date="1971-02-09",
        station="Pacoima Dam (upper left abut.)",
        component="164",
        units="g",
        sha256="ea1186e852208172b90d20416fb18e9a9683881ed49fff92299982d73f131b16",
        source=_EEUQ + " (Tests/eeuq-0003/templatedir, added in c3e5482d382b062f5bfd1ecd86e376bfa516f229)",
        licence=_PEER + "; a California state record (CDMG station 279): public domain not verified",
        paper_name="Pacoima Dam 1971",
    ),
    ShippedRecord(
        name="nahanni",
        file="Nahanni_1985_NS1-280.csv",
        event="Nahanni, Canada",
        date="1985",
        station="Site 1",
        component="280",
        units="g",
        sha256="0775c99a96c957a87bfded82e89a5da71b8cc116f98fc11b35917559f142c690",
        source=("pySLAMMER/pySLAMMER @ dd8cfad35ab4b0a7258ff2e1b7389af0ad9d0325 (src/pyslammer/sample_ground_motions, "
                "last changed in 4c622266be28eca4ab05f89cf9ff0cd25244b5a1)"),
        licence="repository GPL-3.0; recorded by the Geological Survey of Canada, whose terms were not verified",
        paper_name="Nahanni 1985",
    ),
    ShippedRecord(
        name="bagnoli",
        file="RSN285_ITALY_A-BAG270.AT2",
        event="Irpinia Italy-01",
        date="1980-11-23",
        station="Bagnoli Irpinio",
        component="270 (W-E)",
        units="g",
        sha256="42dee7d3b555fcbf2f0b0a66379bc8b2f4d88ba5fe1b3cebd344bf2f696bdb63",
        source=_IRPINIA_SOURCE,
        licence=_IRPINIA_LICENCE,
        provisional=True,
        paper_name="BagnirWE",
    ),
    ShippedRecord(
        name="calitri",
        file="RSN289_ITALY_A-CTR270.AT2",
        event="Irpinia Italy-01",
        date="1980-11-23",
        station="Calitri",
        component="270 (W-E)",
        units="g",
        sha256="2ed09f077491311be312b67099100412865653d4e9212cd669e6a566dd2577a1",
        source=_IRPINIA_SOURCE,
        licence=_IRPINIA_LICENCE,
        provisional=True,
        paper_name="CalitWE",
    ),
    ShippedRecord(
        name="sturno",
        file="RSN292_ITALY_A-STU270.AT2",
        event="Irpinia Italy-01",
        date="1980-11-23",
        station="Sturno (STN)",
        component="270 (W-E)",
        units="g",
        sha256="f5c3bd51b15a75b6dfc902ea40e49fe0b7f733e08eb270b20020eb2224c478a0",
        source=_IRPINIA_SOURCE,
        licence=_IRPINIA_LICENCE,
        provisional=True,
        paper_name="SturWE",
    ),
)
"""The records shipped in ``rockdem/data/ground-motions`` (details in that folder's SOURCES.md)."""


@functools.lru_cache(maxsize=1)
def records_folder() -> Path:
    """Folder of the shipped records (package data, installed with rockdem)."""
    return Path(str(resources.files("rockdem").joinpath("data", "ground-motions")))


def shipped_record(name: str) -> ShippedRecord | None:
    """The shipped record with this short name (any case) or file name, or None."""
    key = str(name).strip()
    for rec in SHIPPED_RECORDS:
        if key.lower() == rec.name or key == rec.file:
            return rec
    return None


def _user_folder() -> Path | None:
    """The ``ROCKDEM_DATA`` folder (its ``ground-motions`` sub-folder if it has one), or None if unset.

    Raises:
        FileNotFoundError: the variable names no folder.
    """
    env = os.environ.get(DATA_ENV)
    if not env:
        return None
    root = Path(env).expanduser()
    if not root.is_dir():
        raise FileNotFoundError(f"{DATA_ENV}={env!r} is not a folder; point it at the folder holding your "
                                f"records (or unset it to use only the shipped records)")
    return root / "ground-motions" if (root / "ground-motions").is_dir() else root


def record_path(name: str | os.PathLike[str]) -> Path:
    """Find a record file (lookup order in the module docstring).

    Args:
        name: a path, a file name in ``$ROCKDEM_DATA``, or a shipped record's short or file name.

    Raises:
        FileNotFoundError: found nowhere (the message lists the shipped names and the user folder's
            files), or ``ROCKDEM_DATA`` set to something that is not a folder.
    """
    p = Path(name).expanduser()
    if p.is_file():
        return p
    if p.exists():
        raise FileNotFoundError(f"record {str(name)!r} is not a file ({p} is a folder or a device)")
    text = str(name)
    if p.name != text or not text.strip():  # a path with a folder part: it had to exist
        raise FileNotFoundError(f"record file not found: {p}; a folder-less name is also looked up in "
                                f"${DATA_ENV} and among the shipped records (`rockdem records`)")
    user = _user_folder()
    if user is not None and (user / text).is_file():
        return user / text
    rec = shipped_record(text)
    if rec is not None:
        return records_folder() / rec.file
    have = ", ".join(r.name for r in SHIPPED_RECORDS)
    extra = ""
    if user is not None:
        own = sorted(f.name for f in user.iterdir() if f.is_file() and f.suffix.lower() != ".md")
        extra = f"; in ${DATA_ENV} ({user}): {', '.join(own) or 'no files'}"
    raise FileNotFoundError(f"no record {text!r}: not a file in the working folder, not a shipped record "
                            f"(short names: {have}; `rockdem records` lists their files){extra}")


def _shipped_entry(path: Path) -> ShippedRecord | None:
    """The registry entry of a resolved path inside the shipped folder, else None."""
    rec = shipped_record(path.name)
    if rec is not None and path.resolve() == (records_folder() / rec.file).resolve():
        return rec
    return None


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 hex digest of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def record_table() -> list[dict[str, object]]:
    """One row per shipped record: registry facts plus dt [s], npts, duration [s] and PGA [g]
    read from the file itself (with :func:`read_record`)."""
    rows: list[dict[str, object]] = []
    for rec in SHIPPED_RECORDS:
        gm = read_record(rec.name)
        rows.append({"name": rec.name, "file": rec.file, "event": rec.event, "date": rec.date, "station": rec.station,
                     "component": rec.component, "dt_s": gm.dt, "npts": gm.npts, "duration_s": gm.duration,
                     "pga_g": gm.pga_g, "provisional": rec.provisional, "paper_name": rec.paper_name,
                     "licence": rec.licence, "source": rec.source, "sha256": rec.sha256})
    return rows


def _records_cli(args: argparse.Namespace) -> int:
    if args.plot:
        if not args.name:
            raise ValueError("--plot needs a record: rockdem records --plot NAME (a short name, a file name or a path)")
        from .cli import output_file
        from .spectra import save_record_plot

        try:
            gm = read_record(args.name, units=args.units, dt=args.dt, time_column=args.time_column,
                             acc_column=args.acc_column)
        except ValueError as exc:  # the reader's advice names its keyword arguments: name the options too
            raise ValueError(f"{exc} (options of rockdem records --plot: --units, --dt, --time-column, "
                             "--acc-column)") from None
        shipped = shipped_record(args.name)
        label = f"{shipped.name} ({shipped.event} {shipped.date[:4]}, {shipped.station})" if shipped else gm.name
        out = Path(args.output) if args.output else Path(f"{shipped.name if shipped else Path(args.name).stem}_record.png")
        if out.suffix.lower() not in (".png", ".pdf"):
            raise ValueError(f"-o {out}: the suffix must be .png or .pdf")
        output_file(out, "-o")
        print(f"rockdem records: wrote {save_record_plot(gm, out, name=label)} (acceleration, velocity, displacement, "
              "5 % damped response spectrum)")
        return 0
    rows = record_table()
    if args.name:
        rec = shipped_record(args.name)
        if rec is None:
            raise ValueError(f"no shipped record {args.name!r}; short names: "
                             f"{', '.join(r.name for r in SHIPPED_RECORDS)}")
        row = next(r for r in rows if r["name"] == rec.name)
        path = records_folder() / rec.file
        for key, value in row.items():
            print(f"{key:11s} {value}")
        print(f"{'path':11s} {path}")
        ok = file_sha256(path) == rec.sha256
        print(f"{'checksum':11s} {'matches SOURCES.md' if ok else 'DOES NOT MATCH SOURCES.md (file altered)'}")
        return 0 if ok else 1
    head = ("name", "file", "event", "station", "comp.", "dt [s]", "npts", "PGA [g]", "provisional")
    table = [[str(r["name"]), str(r["file"]), f"{r['event']} {str(r['date'])[:4]}", str(r["station"]),
              str(r["component"]), f"{r['dt_s']:.4g}", str(r["npts"]), f"{r['pga_g']:.4f}",
              "YES" if r["provisional"] else "no"] for r in rows]
    widths = [max(len(h), *(len(t[k]) for t in table)) for k, h in enumerate(head)]
    for line in (head, *table):
        print("  ".join(f"{c:<{w}}" for c, w in zip(line, widths)).rstrip())
    print(f"\nShipped in {records_folder()} (provenance, SHA-256 and licence notes: SOURCES.md there).")
    print("Provisional (the three Irpinia records): licence not confirmed, do not redistribute them until "
          "it is (re-download from PEER NGA-West2 or ITACA/ESM); their header prints dt to 4 decimals only.")
    print(f"Refer to a record by short name or file name; a path or a file in ${DATA_ENV} takes "
          "precedence (`rockdem records NAME` shows one record's provenance).")
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``records`` sub-command."""
    p = subparsers.add_parser(
        "records", help="list the ground-motion records shipped with rockdem",
        description="List the shipped ground-motion records (dt, npts and PGA read from the files), or "
                    "show one record's provenance and verify its checksum.")
    p.add_argument("name", nargs="?", help="a short name or file name: show that record's provenance")
    p.add_argument("--plot", action="store_true",
                   help="plot NAME (a shipped record, a file in $ROCKDEM_DATA or a path): acceleration, velocity, "
                        "displacement and its 5 %% damped response spectrum")
    p.add_argument("-o", "--output", help="file for --plot (.png or .pdf; default NAME_record.png)")
    p.add_argument("--units", choices=("g", "m/s2", "cm/s2"),
                   help="--plot: acceleration units of a file that does not say them (columns or single-column files)")
    p.add_argument("--dt", type=float, help="--plot: time step [s] of a single-column file")
    p.add_argument("--time-column", type=int, help="--plot: zero-based time column of a columns file (default 0)")
    p.add_argument("--acc-column", type=int, help="--plot: zero-based acceleration column of a columns file (default 1)")
    p.set_defaults(func=_records_cli)
