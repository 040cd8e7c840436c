"""Measurements the paper uses to judge damping, on plain arrays and on rockdem results.

Functions on plain NumPy arrays come first (usable on a measured history read from a CSV), then
thin adapters for a rockdem result (an ``xarray.Dataset`` with coordinate ``time`` [s], variables
``rocking_angle (time, block)`` [rad], ``block_position (time, block, xyz)`` [m], ``block_free
(block)``). References are to Galvez et al. 2022 (the founding paper, "§", "Eq.").

Definitions:
    * half-cycle peak: a local maximum of |theta| between two impacts (zero crossings or touches);
    * apparent restitution e_a (Eq. 6):
      e_a(n) = [(1 - (1 - |theta_n|/eta)^2) / (1 - (1 - |theta_0|/eta)^2)]^(1/(2n));
    * WME = sum |x_i - y_i| |x_i| / sum x_i^2 on the reference time base (x reference, y simulation);
    * bouncing magnitude (§3.1, Fig. 5B) = airborne amplitude / airborne duration [m/s].
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray
from ._warn import warn_user
from .materials import real_number

__all__ = [
    "rocking_direction",
    "ground_acceleration",
    "HalfCyclePeaks",
    "Restitution",
    "Bouncing",
    "half_cycle_peaks",
    "prominent_peaks",
    "apparent_restitution",
    "wme",
    "rest_time",
    "bouncing",
    "rocking_lift",
    "max_rotation",
    "residual_drift",
    "overturned",
    "first_impact_time",
    "rocking_onset_time",
    "summarize",
    "free_rocking_run",
    "lowest_point_height",
    "lowest_vertex_height",
    "result_eta",
    "eta_of",
    "FALL_FRACTION",
    "fallen",
    "block_thickness_of",
    "TIPPED_ANGLE",
    "fallen_blocks",
    "is_free_rocking",
    "is_pushover",
    "summarize_result",
]


@dataclass(frozen=True)
class HalfCyclePeaks:
    """Peaks of |theta| per half cycle.

    Attributes:
        time: (k,) peak times [s].
        value: (k,) signed peak values (same unit as the input, e.g. rad).
    """

    time: NDArray[np.float64]
    value: NDArray[np.float64]


@dataclass(frozen=True)
class Restitution:
    """Apparent coefficient of restitution (Eq. 6).

    Attributes:
        per_impact: (n,) e_a(n) for impacts n = 1..N [-].
        mean: mean of ``per_impact`` [-] (nan if there is no impact).
    """

    per_impact: NDArray[np.float64]
    mean: float


@dataclass(frozen=True)
class Bouncing:
    """Airborne phases of a block (§3.1, Fig. 5B).

    Attributes:
        start: (k,) take-off times [s].
        duration: (k,) airborne durations [s].
        amplitude: (k,) maximum height above the contact level [m].
        magnitude: (k,) (amplitude - tol) / duration [m/s].
        max_magnitude: largest magnitude [m/s] (0 without any airborne phase).
    """

    start: NDArray[np.float64]
    duration: NDArray[np.float64]
    amplitude: NDArray[np.float64]
    magnitude: NDArray[np.float64]
    max_magnitude: float


def _scalar(value: Any, what: str, *, positive: bool = False) -> float:
    """``value`` as a finite float >= 0 (> 0 with ``positive``), or ValueError naming ``what``."""
    v = real_number(value, what)
    if not (v > 0 if positive else v >= 0):
        raise ValueError(f"{what} must be {'> 0' if positive else '>= 0'}, got {value!r}")
    return v


def _history(t: ArrayLike, x: ArrayLike, name: str = "x") -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validate a history: 1-D, same length, finite, strictly increasing time."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t.ndim != 1 or x.ndim != 1 or t.shape != x.shape:
        raise ValueError(f"{name}: time and values must be 1-D arrays of equal length, got {t.shape} and {x.shape}")
    if len(t) < 2:
        raise ValueError(f"{name}: need at least 2 samples, got {len(t)}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(x))):
        raise ValueError(f"{name}: time and values must be finite (remove NaN/inf rows)")
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{name}: time must be strictly increasing (sort the rows, drop duplicates)")
    return t, x


def half_cycle_peaks(
    t: ArrayLike, theta: ArrayLike, *, min_prominence: float | None = None, refine: bool = True
) -> HalfCyclePeaks:
    """Peak |theta| of every half cycle (the peaks of paper Eq. 6 and Figs. 6, 8).

    A peak is a local maximum of |theta| whose prominence exceeds ``min_prominence``, so both
    two-sided rocking (sign changes) and one-sided rocking (touches of zero) are handled. A history
    that starts at its maximum (free rocking released from theta_0) gives theta_0 as the first peak.
    The last, unfinished half cycle is not a peak.

    Args:
        t: (n,) time [s], strictly increasing.
        theta: (n,) rotation [rad] (or any oscillating history).
        min_prominence: smallest accepted prominence, same unit as theta; default 1e-3 x max |theta|.
        refine: refine interior peaks by a parabola through the three samples around them
            (error O(dt^3) instead of O(dt^2) for smooth peaks).

    Returns:
        HalfCyclePeaks with (k,) times [s] and signed values.
    """
    t, x = _history(t, theta, "half_cycle_peaks")
    a = np.abs(x)
    if min_prominence is None:
        min_prominence = 1e-3 * float(a.max())
    min_prominence = _scalar(min_prominence, "half_cycle_peaks: min_prominence")
    padded = np.concatenate(([0.0], a))  # lets a release at t[0] count as a peak
    idx = prominent_peaks(padded, max(min_prominence, np.finfo(float).tiny)) - 1
    times, values = t[idx].copy(), x[idx].copy()
    if refine:
        inner = idx[(idx > 0) & (idx < len(x) - 1)]
        k = np.searchsorted(idx, inner)
        times[k], values[k] = _parabola_peaks(t, x, inner)
    return HalfCyclePeaks(times, values)


def prominent_peaks(x: ArrayLike, min_prominence: float) -> NDArray[np.intp]:
    """Indices of the local maxima of ``x`` (n,) whose prominence is at least ``min_prominence``.

    The same peaks as ``scipy.signal.find_peaks(x, prominence=min_prominence)`` (tested against
    it), without importing SciPy's signal and stats packages (0.4 s): a peak is a sample, or the
    middle (rounded down) of a run of equal samples, with strictly lower neighbours, neither first
    nor last; its prominence is its height above the higher of the lowest samples reached on each
    side before a higher sample (or the end). ``x`` must be finite.
    """
    x = np.asarray(x, dtype=float).ravel()
    if x.size < 3:
        return np.zeros(0, dtype=np.intp)
    start = np.flatnonzero(np.concatenate(([True], x[1:] != x[:-1])))  # the runs of equal samples
    end = np.append(start[1:] - 1, x.size - 1)
    v = x[start]
    run = np.flatnonzero((v[1:-1] > v[:-2]) & (v[1:-1] > v[2:])) + 1
    peaks = ((start[run] + end[run]) // 2).astype(np.intp)
    base = np.maximum(_base_min(x, peaks), _base_min(x[::-1], x.size - 1 - peaks[::-1])[::-1])
    return peaks[x[peaks] - base >= min_prominence]


def _base_min(x: NDArray[np.float64], peaks: NDArray[np.intp]) -> NDArray[np.float64]:
    """For each of the local maxima ``peaks`` (ascending) of x, the lowest sample of x[M + 1 : p + 1],
    M the nearest earlier peak higher than peak p (-1 if none): the left base of p's prominence.
    SciPy scans instead from p to the nearest higher sample L, but no sample in (M, L] is lower than
    x[p] (a dip there would leave a higher local maximum between it and p, nearer than M)."""
    h, at = x[peaks].tolist(), peaks.tolist()
    start: list[int] = []
    higher: list[int] = []  # stack of earlier peaks, heights decreasing
    for j, v in enumerate(h):
        while higher and h[higher[-1]] <= v:
            higher.pop()
        start.append(at[higher[-1]] + 1 if higher else 0)
        higher.append(j)
    bounds = np.empty(2 * len(h), dtype=np.intp)
    bounds[0::2], bounds[1::2] = start, peaks + 1
    return np.minimum.reduceat(np.append(x, np.inf), bounds)[0::2] if len(h) else np.zeros(0)


def _parabola_peaks(t: NDArray[np.float64], x: NDArray[np.float64], i: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Vertices of the parabolas through the samples i-1, i, i+1 of each interior index ``i``
    (time [s], value); the middle sample where the parabola is flat or its vertex falls outside."""
    a, b = t[i - 1] - t[i], t[i + 1] - t[i]  # a < 0 < b
    d0, d2 = x[i - 1] - x[i], x[i + 1] - x[i]
    with np.errstate(divide="ignore", invalid="ignore"):
        c2 = (d0 / a - d2 / b) / (a - b)  # x = x_i + c1 s + c2 s^2, s = time - t_i
        c1 = d0 / a - c2 * a
        sv = -c1 / (2.0 * c2)
        ok = (c2 != 0.0) & (sv >= a) & (sv <= b)
        return np.where(ok, t[i] + sv, t[i]), np.where(ok, x[i] + c1 * sv + c2 * sv * sv, x[i])


def apparent_restitution(peaks: ArrayLike, theta0: float, eta: float, *, exact: bool = False) -> Restitution:
    """Apparent coefficient of restitution per impact (paper Eq. 6).

    e_a(n) = [(1 - (1 - |theta_n|/eta)^2) / (1 - (1 - |theta_0|/eta)^2)]^(1/(2n)), n = 1..N.

    Eq. 6 inverts Housner's *linearised* energy; with ``exact=True`` the exact potential energy of
    the rectangular block is used instead, e_a(n) = [(cos(eta-|theta_n|) - cos eta) /
    (cos(eta-|theta_0|) - cos eta)]^(1/(2n)), which inverts the nonlinear Housner model exactly.

    Args:
        peaks: (N,) peak rotations |theta_n| after impacts 1..N [rad] (sign ignored).
        theta0: initial (release) amplitude [rad].
        eta: slenderness angle atan(B/H) [rad].
        exact: use the exact energy form instead of Eq. 6.

    Returns:
        Restitution with per-impact values and their mean.

    Raises:
        ValueError: eta not in (0, pi/2), or theta0 not in (0, eta).
    """
    if isinstance(peaks, HalfCyclePeaks):
        raise ValueError("apparent_restitution: give the peak values after the release, e.g. "
                         "half_cycle_peaks(t, theta).value[1:], not the HalfCyclePeaks result itself")
    if not (0.0 < eta < 0.5 * np.pi):
        raise ValueError(f"eta must be the slenderness angle in (0, pi/2) rad, got {eta!r}")
    if np.ndim(peaks) > 1:
        raise ValueError(f"apparent_restitution: peaks must be a 1-D array of peak rotations, got shape {np.shape(peaks)}")
    th0 = abs(float(theta0))
    if not (0.0 < th0 < eta):
        raise ValueError(f"theta0 must lie in (0, eta = {eta:.6g}) rad, got {theta0!r} (a release beyond eta overturns)")
    p = np.abs(np.asarray(peaks, dtype=float)).ravel()
    if not np.all(np.isfinite(p)):
        raise ValueError("apparent_restitution: peaks must be finite rotations [rad] (remove NaN/inf)")
    if np.any(p > eta):
        warn_user("apparent_restitution: some peaks exceed eta (overturning?); Eq. 6 is not defined there")
    n = np.arange(1, len(p) + 1)

    def energy(th: NDArray[np.float64] | float) -> NDArray[np.float64]:
        if exact:
            return np.cos(eta - np.asarray(th)) - np.cos(eta)
        return 1.0 - (1.0 - np.asarray(th) / eta) ** 2

    ratio = np.clip(energy(p) / energy(th0), 0.0, None)
    e = ratio ** (1.0 / (2.0 * n))
    return Restitution(e, float(np.mean(e)) if len(e) else float("nan"))


def rest_time(t: ArrayLike, x: ArrayLike, *, rest_tol: float | None = None) -> float:
    """End of the motion: the last time |x - x_final| exceeds ``rest_tol`` [s].

    Args:
        t: (n,) time [s].
        x: (n,) history.
        rest_tol: motion threshold, unit of x; default 1 % of max |x - x_final|.
    """
    t, x = _history(t, x, "rest_time")
    dev = np.abs(x - x[-1])
    tol = 0.01 * float(dev.max()) if rest_tol is None else float(rest_tol)
    if not (math.isfinite(tol) and tol >= 0):
        raise ValueError(f"rest_tol must be a finite threshold >= 0 (unit of the history), got {rest_tol!r}")
    moving = np.flatnonzero(dev > tol)
    if len(moving) == 0:
        return float(t[0])
    return float(t[min(moving[-1] + 1, len(t) - 1)])


def wme(
    t_ref: ArrayLike,
    x_ref: ArrayLike,
    t_sim: ArrayLike,
    x_sim: ArrayLike,
    *,
    cut_at_rest: bool = True,
    rest_tol: float | None = None,
    overlap_only: bool = False,
) -> float:
    """Weighted mean error between a reference and a simulated history (paper §3.1).

    WME = sum_i |x_i - y_i| |x_i| / sum_i x_i^2, with x the reference at its own samples and y the
    simulation linearly interpolated there. Amplitude-weighted; 0 for a perfect match; invariant to
    a common scale factor; **not symmetric**: wme(x, y) != wme(y, x) in general (e.g. y = 2x gives
    1 one way and 0.5 the other). Also wme(x, 0) = 1 and wme(x, -x) = 2.

    Args:
        t_ref, x_ref: (n,) reference time [s] and history.
        t_sim, x_sim: (m,) simulated time [s] and history (any sampling).
        cut_at_rest: keep only the reference samples up to the end of the reference motion
            (:func:`rest_time`), so the late low-amplitude motion of the simulation does not count.
        rest_tol: motion threshold for the cut, unit of x; default 1 % of the reference's range.
        overlap_only: compare over the times the simulation covers when it does not cover the
            reference's (warned about); by default that is refused: a history cut short (a
            stopped run) would read as a match over what it has.

    Returns:
        WME [-].

    Raises:
        ValueError: bad histories, no overlap, a simulation that does not cover the reference (unless
            ``overlap_only``), or a reference identically zero.
    """
    tr, xr = _history(t_ref, x_ref, "wme reference")
    ts, xs = _history(t_sim, x_sim, "wme simulation")
    t_end = rest_time(tr, xr, rest_tol=rest_tol) if cut_at_rest else float(tr[-1])
    keep = tr <= t_end
    if np.count_nonzero(keep) < 2:
        raise ValueError(f"wme: the reference never moves by more than rest_tol = {rest_tol!r} from its end value, so "
                         "the cut at rest leaves nothing to compare; lower rest_tol or pass cut_at_rest=False")
    inside = keep & (tr >= ts[0]) & (tr <= ts[-1])
    if not np.any(inside):
        raise ValueError("wme: the simulation does not overlap the reference in time")
    if np.count_nonzero(inside) < np.count_nonzero(keep):
        if not overlap_only:
            raise ValueError(
                f"wme: the simulation covers [{ts[0]:.4g}, {ts[-1]:.4g}] s only and the reference runs to {t_end:.4g} s: "
                "a history cut short would read as a match over what it has; run it longer, cut the reference, or "
                "pass overlap_only=True")
        warn_user(
            f"wme: the simulation covers [{ts[0]:.4g}, {ts[-1]:.4g}] s only; reference samples up to "
            f"{t_end:.4g} s outside it are ignored")
    x = xr[inside]
    y = np.interp(tr[inside], ts, xs)
    den = float(np.sum(x * x))
    if den == 0.0:
        raise ValueError("wme: the reference is identically zero on the compared interval")
    return float(np.sum(np.abs(x - y) * np.abs(x)) / den)


def rocking_lift(theta: ArrayLike, b: float, h: float) -> NDArray[np.float64]:
    """Rise of the centroid of a B x H block rocking on a corner without lifting off [m].

    z_c(theta) - z_c(0) = R [cos(eta - |theta|) - cos(eta)], R = semi-diagonal, eta = atan(b/h).
    Subtract it from a centroid height history to keep only the airborne part for :func:`bouncing`.
    """
    b, h = _scalar(b, "rocking_lift: b [m]", positive=True), _scalar(h, "rocking_lift: h [m]", positive=True)
    r = 0.5 * np.hypot(b, h)
    eta = np.arctan2(b, h)
    th = np.abs(np.asarray(theta, dtype=float))
    return r * (np.cos(eta - th) - np.cos(eta))


def bouncing(
    t: ArrayLike,
    z: ArrayLike,
    *,
    z_rest: float | None = None,
    tol: float | None = None,
    z_contact: ArrayLike | None = None,
) -> Bouncing:
    """Airborne phases and bouncing magnitude from a height history (paper §3.1, Fig. 5B).

    The block is airborne while d = z - z_contact exceeds ``tol``, with z_contact either an array
    (the height the measured point would have in contact, e.g. the centroid's rest height plus
    :func:`rocking_lift`) or the constant ``z_rest``. For each airborne phase: amplitude = max d,
    duration = time above tol, magnitude = (amplitude - tol) / duration (the paper's amplitude over
    time aloft, measured above the threshold so that phases grazing it do not give spurious large
    ratios; the same as amplitude / duration for flights well above tol). Pass the height of the block's
    lowest point (:func:`lowest_point_height`) with its ground level as ``z_rest``, or the centroid
    with ``z_contact``: the centroid alone also rises by plain rocking, which is not bouncing.

    Args:
        t: (n,) time [s].
        z: (n,) height [m].
        z_rest: contact level [m]; default z[0] (the block touches its support at the start).
        tol: airborne threshold [m], > 0; default 1e-5 m (above the elastic joint overlap of
            typical stiff joints, a few micrometres; lower it for small or very stiff models).
        z_contact: (n,) contact height history [m], overrides ``z_rest``.

    Returns:
        Bouncing with per-phase arrays and the largest magnitude.
    """
    t, z = _history(t, z, "bouncing")
    if z_contact is not None:
        base = np.asarray(z_contact, dtype=float)
        if base.shape != z.shape or not np.all(np.isfinite(base)):
            raise ValueError(f"bouncing: z_contact must be finite, of the shape of z {z.shape}, got {base.shape}")
    else:
        base = np.full_like(z, z[0] if z_rest is None else real_number(z_rest, "bouncing: z_rest [m]"))
    d = z - base
    tol = 1e-5 if tol is None else _scalar(tol, "bouncing: tol [m]", positive=True)
    air = d > tol
    edges = np.diff(air.astype(np.int8))
    starts = list(np.flatnonzero(edges == 1) + 1)
    ends = list(np.flatnonzero(edges == -1) + 1)
    if air[0]:
        starts.insert(0, 0)
    if air[-1]:
        ends.append(len(z))
    st, du, am = [], [], []
    for i0, i1 in zip(starts, ends):
        ta = _crossing(t, d - tol, i0 - 1, i0) if i0 > 0 else t[0]
        tb = _crossing(t, d - tol, i1 - 1, i1) if i1 < len(z) else t[-1]
        if tb <= ta:
            continue
        st.append(ta)
        du.append(tb - ta)
        am.append(float(d[i0:i1].max()))
    du_a, am_a = np.array(du), np.array(am)
    # the rise above the threshold over the time above it: a phase that just grazes the threshold
    # (an elastic rattle at the contact level) has both -> 0 and a magnitude -> 0, as a free flight
    # of apex delta has delta / (2 sqrt(2 delta / g)) -> 0; amplitude / duration would blow up
    mag = (am_a - tol) / du_a if len(du) else np.zeros(0)
    return Bouncing(np.array(st), du_a, am_a, mag, float(mag.max()) if len(mag) else 0.0)


def _crossing(t: NDArray[np.float64], f: NDArray[np.float64], i: int, j: int) -> float:
    """Linear-interpolated zero of f between samples i and j."""
    if f[j] == f[i]:
        return float(t[j])
    return float(t[i] + (t[j] - t[i]) * (0.0 - f[i]) / (f[j] - f[i]))


def max_rotation(theta: ArrayLike) -> float:
    """Largest |theta| of a history (same unit as theta)."""
    th = np.asarray(theta, dtype=float)
    if th.size == 0:
        raise ValueError("max_rotation: empty history")
    if not np.all(np.isfinite(th)):
        raise ValueError("max_rotation: the history must be finite (remove NaN/inf samples)")
    return float(np.max(np.abs(th)))


def residual_drift(t: ArrayLike, x: ArrayLike, *, tail: float = 0.0) -> float:
    """Residual value of a history: its mean over the last ``tail`` seconds (the last sample if 0).

    Args:
        t: (n,) time [s].
        x: (n,) history (rotation [rad] or displacement [m]).
        tail: averaging window at the end [s], >= 0.
    """
    t, x = _history(t, x, "residual_drift")
    tail = _scalar(tail, "residual_drift: tail [s]")
    sel = t >= t[-1] - tail
    return float(np.mean(x[sel]))


def overturned(theta: ArrayLike, eta: float, *, rtol: float = 1e-9) -> bool:
    """Whether the history ends beyond the instability angle: |theta_end| >= eta (1 - rtol).

    A block that went past eta and came back (possible under ground motion) is not overturned.
    """
    if not (0.0 < eta < 0.5 * np.pi):
        raise ValueError(f"eta must be the slenderness angle in (0, pi/2) rad, got {eta!r}")
    th = np.asarray(theta, dtype=float)
    if th.size == 0:
        raise ValueError("overturned: empty history")
    if not np.all(np.isfinite(th)):
        raise ValueError("overturned: the history must be finite (remove NaN/inf samples)")
    return bool(abs(th[-1]) >= eta * (1.0 - rtol))


def rocking_onset_time(t: ArrayLike, theta: ArrayLike, threshold: float) -> float | None:
    """First time |theta| exceeds ``threshold`` [s], or None if it never does.

    Args:
        t: (n,) time [s].
        theta: (n,) rotation [rad].
        threshold: rotation that counts as rocking [rad], > 0.
    """
    t, th = _history(t, theta, "rocking_onset_time")
    if not threshold > 0:
        raise ValueError(f"rocking_onset_time: threshold must be > 0 rad, got {threshold!r}")
    above = np.flatnonzero(np.abs(th) > threshold)
    return float(t[above[0]]) if len(above) else None


def first_impact_time(t: ArrayLike, theta: ArrayLike, threshold: float | None = None) -> float | None:
    """Time of the first impact [s] after the rotation first exceeds ``threshold`` (a block
    released from a tilt, or rocking under an input): its first zero crossing, linearly
    interpolated between samples, or, for one-sided rocking (a façade against its return walls,
    which comes back to zero and rebounds without crossing), its first return to zero: the vertex of
    the V of its first dip below ``threshold`` (where the lines of its descent and of its rebound,
    through the two samples either side of the dip's deepest one, meet). None if it never comes back.

    Args:
        t: (n,) time [s].
        theta: (n,) rotation [rad].
        threshold: rotation that counts as rocking [rad]; default 1 % of max |theta|.
    """
    t, th = _history(t, theta, "first_impact_time")
    thr = 0.01 * float(np.abs(th).max()) if threshold is None else _scalar(threshold, "first_impact_time: threshold [rad]", positive=True)
    above = np.flatnonzero(np.abs(th) > thr)
    if not len(above):
        return None
    i0 = above[0]
    sign = np.sign(th[i0])
    s = sign * th[i0:]  # > 0 on the side it was released to
    dip = np.flatnonzero(s <= thr)
    if not len(dip):
        return None
    j = dip[0]
    if s[j] < 0.0:  # crossed zero between two samples
        i = i0 + j
        return float(t[i - 1] + (t[i] - t[i - 1]) * th[i - 1] / (th[i - 1] - th[i]))
    end = np.flatnonzero(s[j:] > thr)
    stop = j + (end[0] if len(end) else len(s) - j)
    k = j + int(np.argmin(s[j:stop]))  # the deepest sample of the dip
    if s[k] < 0.0:  # it crosses inside the dip: the crossing
        i = i0 + j + int(np.flatnonzero(s[j:stop] < 0.0)[0])
        return float(t[i - 1] + (t[i] - t[i - 1]) * th[i - 1] / (th[i - 1] - th[i]))
    i = i0 + k
    if i < 2 or i + 2 >= len(t):
        return float(t[i])
    down = (th[i - 1] - th[i - 2]) * sign / (t[i - 1] - t[i - 2])  # the descent's slope, < 0
    up = (th[i + 2] - th[i + 1]) * sign / (t[i + 2] - t[i + 1])  # the rebound's, > 0
    if not (down < 0.0 < up):
        return float(t[i])
    a, b = sign * th[i - 1], sign * th[i + 1]
    vertex = (b - a + down * t[i - 1] - up * t[i + 1]) / (down - up)
    return float(min(max(vertex, t[i - 1]), t[i + 1]))


SUMMARY_PEAK_PROMINENCE = 0.02
"""Smallest half-cycle peak counted by :func:`summarize`, as a fraction of the largest rotation."""


def summarize(
    t: ArrayLike,
    theta: ArrayLike,
    *,
    eta: float | None = None,
    onset_threshold: float | None = None,
    z: ArrayLike | None = None,
    z_rest: float | None = None,
    bounce_tol: float | None = None,
    free_rocking: bool = True,
) -> dict[str, Any]:
    """Summary of one rotation history (keys carry their unit).

    Args:
        t: (n,) time [s].
        theta: (n,) rotation [rad].
        eta: slenderness angle [rad]; enables e_a (Eq. 6, meaningful for free rocking) and the
            overturning flags.
        onset_threshold: rotation counted as rocking [rad]; default 1 % of eta, else 1e-3 rad.
        z: (n,) height of the block's lowest point [m], enables the bouncing entries.
        z_rest: ground level for ``z`` [m] (default z[0]).
        bounce_tol: airborne threshold [m] (default that of :func:`bouncing`).
        free_rocking: the history is free rocking from a release (False: under a ground motion or
            a pushover); e_a (Eq. 6) measures only the decay of free rocking and is left out
            otherwise.

    Returns:
        dict of scalars; absent measurements are omitted, a never-reached onset is None.
    """
    t, th = _history(t, theta, "summarize")
    if eta is not None:
        eta = _scalar(eta, "summarize: eta [rad]", positive=True)
    out: dict[str, Any] = {
        "max_rotation_rad": max_rotation(th),
        "residual_rad": residual_drift(t, th),
    }
    thr = onset_threshold if onset_threshold is not None else (0.01 * eta if eta else 1e-3)
    out["onset_time_s"] = rocking_onset_time(t, th, thr)
    # half cycles of rocking reach back to ~0, so their prominence is their height; 2 % of the largest
    # rotation keeps every real half cycle but not the vibration of a brick riding on a rocking wall
    pk = half_cycle_peaks(t, th, min_prominence=SUMMARY_PEAK_PROMINENCE * max_rotation(th))
    out["half_cycles"] = int(len(pk.value)) if out["onset_time_s"] is not None else 0  # vibration below the onset is not rocking
    if eta is not None:
        out["eta_rad"] = float(eta)
        out["overturned"] = overturned(th, eta)
        out["exceeded_eta"] = bool(max_rotation(th) > eta) or out["overturned"]  # one that ends at eta reached it
        th0 = abs(float(pk.value[0])) if len(pk.value) else 0.0
        if free_rocking and out["onset_time_s"] is not None and len(pk.value) >= 2 and 0.0 < th0 < eta:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ea = apparent_restitution(pk.value[1:], th0, eta)
            out["e_a_mean"] = ea.mean
            out["e_a_first"] = float(ea.per_impact[0])
    if z is not None:
        bo = bouncing(t, np.asarray(z, dtype=float), z_rest=z_rest, tol=bounce_tol)
        out["bounces"] = int(len(bo.magnitude))
        out["bounce_max_m_s"] = bo.max_magnitude
    return out


def rocking_direction(ds: Any) -> np.ndarray:
    """Unit horizontal direction (3,) in which a positive rocking angle moves the top: axis x up."""
    axis = np.asarray(ds.attrs.get("rocking_axis", (0.0, 1.0, 0.0)), dtype=float)
    g = np.asarray(ds.attrs.get("gravity", (0.0, 0.0, -9.81)), dtype=float)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    d = np.cross(axis, up)
    return d / np.linalg.norm(d)


def ground_acceleration(ds: Any) -> np.ndarray | None:
    """Input ground acceleration (T,) [m/s^2] of an earthquake result along the rocking direction
    (the horizontal magnitude when the record acts across it), or None for other results."""
    if "ground_acceleration" not in ds:
        return None
    a = np.asarray(ds.ground_acceleration.values, dtype=float)
    along = a @ rocking_direction(ds)
    if np.max(np.abs(along), initial=0.0) < 1e-6 * max(float(np.max(np.abs(a), initial=0.0)), 1e-300):
        return np.linalg.norm(a[:, :2], axis=1)
    return along


def lowest_point_height(ds: Any, block: int) -> NDArray[np.float64] | None:
    """Height of a block's lowest vertex over time [m], from a rockdem result's geometry.

    Uses ``block_position``, ``block_quaternion`` (w, x, y, z; body -> world), ``vertex_local`` and
    ``block_vertex_start``; returns None when any of them is missing.
    """
    need = ("block_position", "block_quaternion", "vertex_local", "block_vertex_start")
    if any(name not in ds for name in need):
        return None
    start = np.asarray(ds["block_vertex_start"].values, dtype=np.int64)
    v = np.asarray(ds["vertex_local"].values, dtype=float)[start[block] : start[block + 1]]
    return lowest_vertex_height(ds["block_position"].values[:, block], ds["block_quaternion"].values[:, block], v)


def lowest_vertex_height(position: ArrayLike, quaternion: ArrayLike, vertices: ArrayLike) -> NDArray[np.float64]:
    """Height of a block's lowest vertex over time [m].

    Args:
        position: (T, 3) centroid [m].
        quaternion: (T, 4) body -> world rotation (w, x, y, z).
        vertices: (n, 3) the block's vertices in its body frame [m].
    """
    q = np.asarray(quaternion, dtype=float)
    w, x, y, zq = q.T
    row_z = np.column_stack((2 * (x * zq - w * y), 2 * (y * zq + w * x), 1 - 2 * (x * x + y * y)))
    zc = np.asarray(position, dtype=float)[:, 2]
    return zc + np.min(row_z @ np.asarray(vertices, dtype=float).T, axis=1)


def result_eta(ds: Any, block: int) -> float | None:
    """Instability angle [rad] of a block of a rockdem result, about the pivot it rocks on.

    For an assembly released by a free-rocking tilt (attrs ``tilted_blocks`` > 1): the assembly's
    angle ``tilt_angle_rad / tilt_fraction``; else ``block_eta[block]`` (the base contact face's
    edge, so a reduced parapet base counts); None when neither is known.
    """
    return eta_of(getattr(ds, "attrs", {}), ds["block_eta"].values if "block_eta" in ds.variables else None, block)


def eta_of(attrs: Mapping[str, Any], block_eta: ArrayLike | None, block: int) -> float | None:
    """:func:`result_eta` from a result's attributes and its ``block_eta`` values (nb,) [rad]."""
    if int(attrs.get("tilted_blocks", 0)) > 1 and float(attrs.get("tilt_fraction", 0.0)) > 0:
        return float(attrs["tilt_angle_rad"]) / float(attrs["tilt_fraction"])
    if block_eta is not None:
        eta = float(np.asarray(block_eta)[block])
        return eta if np.isfinite(eta) else None
    return None


TIPPED_ANGLE = 0.25 * np.pi
"""A block whose vertical axis (of its reference pose) is tilted by more than this [rad] (45 deg) has fallen
(:func:`fallen_blocks`): at rest it lies on another face or leans on something."""

FALL_FRACTION = 0.5
"""A free block has fallen when its centroid dropped by this fraction of its smallest dimension
(relative to the ground; :func:`fallen_blocks`, and the ``fell`` stop of :mod:`rockdem.stopping`)."""


def fallen_blocks(ds: Any, frame: int = -1) -> NDArray[np.int64]:
    """Ids of the free blocks of a rockdem result that have fallen by ``frame`` (default the last),
    by :func:`fallen`: their centroid is lower than in the reference (untilted) pose,
    ``block_position_reference`` (results before 2026-11-27: the first frame), relative to the
    ground's own vertical motion, by more than :data:`FALL_FRACTION` of the block's smallest
    dimension; or, with ``block_rotation`` (time, block, xyz; from the reference pose), they are
    tipped past :data:`TIPPED_ANGLE` (a squat block: past its own ``block_eta``).

    Uses ``block_position (time, block, xyz)``, ``block_free``, ``vertex_local`` and
    ``block_vertex_start`` (the smallest extent of each block in its body frame), the ``gravity``
    attribute (default -z) and ``ground_displacement (time, xyz)`` when present.
    """
    free = np.flatnonzero(np.asarray(ds["block_free"].values, dtype=bool))
    pos = np.asarray(ds["block_position"].values, dtype=float)
    ref = np.asarray(ds["block_position_reference"].values, dtype=float)[free] if "block_position_reference" in ds else pos[0, free]
    ground = np.asarray(ds["ground_displacement"].values[frame], dtype=float) if "ground_displacement" in ds else np.zeros(3)
    rotation = np.asarray(ds["block_rotation"].values[frame, free], dtype=float) if "block_rotation" in ds else None
    eta = np.asarray(ds["block_eta"].values, dtype=float)[free] if "block_eta" in ds else None
    mask = fallen(ref, pos[frame, free], block_thickness_of(ds["vertex_local"].values, ds["block_vertex_start"].values, free),
                  ground=ground, rotation=rotation, eta=eta, gravity=ds.attrs.get("gravity", (0.0, 0.0, -9.81)))
    return free[mask]


def block_thickness_of(vertex_local: ArrayLike, vertex_start: ArrayLike, blocks: ArrayLike) -> NDArray[np.float64]:
    """(n,) smallest extent [m] of each of ``blocks`` in its body frame, from ``vertex_local``
    (nv, 3) [m] and ``vertex_start`` (nb+1,)."""
    v = np.asarray(vertex_local, dtype=float)
    start = np.asarray(vertex_start, dtype=np.int64)
    return np.array([float(np.ptp(v[start[b]:start[b + 1]], axis=0).min()) for b in np.asarray(blocks, dtype=np.int64)])


def fallen(
    position_reference: ArrayLike, position: ArrayLike, thickness: ArrayLike, *, ground: ArrayLike = (0.0, 0.0, 0.0),
    rotation: ArrayLike | None = None, eta: ArrayLike | None = None, gravity: ArrayLike = (0.0, 0.0, -9.81),
) -> NDArray[np.bool_]:
    """(n,) whether each of n blocks has fallen: its centroid ``position`` (n, 3) [m] is lower than
    ``position_reference`` (n, 3) [m], relative to the ``ground`` displacement (3,) [m], by more than
    :data:`FALL_FRACTION` of its ``thickness`` (n,) [m] (smallest dimension); or, given its
    ``rotation`` (n, 3) [rad] from the reference pose (a rotation vector), the axis that was
    vertical there is tilted past :data:`TIPPED_ANGLE`, or past the block's ``eta`` (n,) [rad] where
    larger (a squat block may stand tilted up to it): it lies on another face, or leans (a block
    toppled onto its side drops only (h - w) / 2, less than the fraction for h < 2 w). "Vertical"
    is against ``gravity`` (3,) [m/s^2] (+z without gravity)."""
    g = np.asarray(gravity, dtype=float).reshape(3)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    drop = (np.asarray(position_reference, dtype=float) - np.asarray(position, dtype=float)) @ up
    drop = drop + np.asarray(ground, dtype=float) @ up
    out = drop > FALL_FRACTION * np.asarray(thickness, dtype=float)
    if rotation is not None:
        # The tilt of the axis that was vertical in the block's reference (untilted) pose: for a
        # rotation by theta about unit k, up . R up = cos theta + (k . up)^2 (1 - cos theta).
        w = np.asarray(rotation, dtype=float).reshape(-1, 3)
        theta = np.linalg.norm(w, axis=1)
        k_up = (w @ up) / np.where(theta > 0.0, theta, 1.0)
        e = np.zeros(len(w)) if eta is None else np.nan_to_num(np.asarray(eta, dtype=float))
        limit = np.maximum(TIPPED_ANGLE, e)
        out |= np.cos(theta) + k_up**2 * (1.0 - np.cos(theta)) < np.cos(limit)
    return out


def is_pushover(ds: Any) -> bool:
    """Whether a result is a pushover (a ``load_factor`` variable or the ``pushover_*`` attributes
    that :func:`rockdem.loading.pushover` and the TOML pushover loadings write)."""
    return "load_factor" in ds or any(str(k).startswith("pushover_") for k in ds.attrs)


def free_rocking_run(attrs: Mapping[str, Any], *, released: bool, ground_moved: bool = False) -> bool:
    """Whether a run with result attributes ``attrs`` is free rocking: released from a tilt (attrs
    ``tilt_angle_rad``, or ``released``: a free block's rocking angle is not zero at t = 0), with no
    earthquake (attrs ``earthquake_mode``, or ``ground_moved``) and no pushover (attrs
    ``pushover_*``). Only then is e_a (paper Eq. 6) a restitution."""
    if any(str(k).startswith("pushover_") for k in attrs) or "earthquake_mode" in attrs or ground_moved:
        return False
    return "tilt_angle_rad" in attrs or released


def is_free_rocking(ds: Any) -> bool:
    """Whether a result is a free-rocking run (:func:`free_rocking_run`)."""
    if "load_factor" in ds:
        return False
    moved = "ground_displacement" in ds and bool(np.any(ds.ground_displacement.values != 0.0))
    free = np.flatnonzero(ds.block_free.values)
    return free_rocking_run(ds.attrs, released=bool(np.any(ds.rocking_angle.values[0, free] != 0.0)), ground_moved=moved)


def summarize_result(ds: Any, block: int | str | None = None, *, eta: float | None = None) -> dict[str, Any]:
    """:func:`summarize` for one block of a rockdem result (``xarray.Dataset``).

    Args:
        ds: result with ``time``, ``rocking_angle (time, block)`` [rad] and ``block_free (block)``;
            optional ``block_eta (block)`` [rad] and the geometry used by
            :func:`lowest_point_height` (for bouncing).
        block: block index or name; default the first free block.
        eta: slenderness angle [rad]; default :func:`result_eta` (the assembly's angle for a
            released assembly, else ``block_eta[block]``), else no e_a and no overturning flag.

    Raises:
        ValueError: missing variables, no free block, or a bad block index or name.
    """
    for name in ("time", "rocking_angle", "block_free"):
        if name not in ds.variables:
            raise ValueError(f"result has no variable {name!r} (not a rockdem result?)")
    free = np.asarray(ds["block_free"].values, dtype=bool)
    if block is None:
        idx = np.flatnonzero(free)
        if len(idx) == 0:
            raise ValueError("result has no free block to summarize")
        block = int(idx[0])
    elif isinstance(block, str):
        names = [str(n) for n in ds["block_name"].values] if "block_name" in ds.variables else []
        if block not in names:
            raise ValueError(f"block {block!r} not in the result; give one of {names[:10]}{' ...' if len(names) > 10 else ''}")
        block = names.index(block)
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or not (0 <= block < len(free)):
        raise ValueError(f"block index {block!r} out of range 0..{len(free) - 1} (or give a block's name)")
    block = int(block)
    if eta is None:
        eta = result_eta(ds, block)
    t = np.asarray(ds["time"].values, dtype=float)
    theta = np.asarray(ds["rocking_angle"].values[:, block], dtype=float)
    z = lowest_point_height(ds, block)
    return summarize(t, theta, eta=eta, z=z, free_rocking=is_free_rocking(ds))
