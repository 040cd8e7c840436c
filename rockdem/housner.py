"""Housner reference models of a rigid rectangular block rocking on a rigid base (DESIGN §4).

Exact nonlinear equation of motion (Housner 1963; paper ref. 64), rotation theta about the base
corner on the side of sgn(theta):

    theta'' = -p^2 [ sin(eta sgn(theta) - theta) + (a_g / g) cos(eta sgn(theta) - theta) ]

with p = sqrt(3 g / (4 R)), R the semi-diagonal, eta = atan(B/H), a_g the horizontal ground
acceleration [m/s^2]. Impacts at theta = 0 are instantaneous with restitution e on the angular
velocity (default Housner's e_eta = 1 - 1.5 sin^2(eta), paper §3.2.1):

* two-sided: theta' <- e theta', the block goes on rocking about the other corner;
* one-sided (façade against return walls, paper §2.2 and §4.2): the wall stops rotation to its
  side, the impact at theta = 0 (base and wall together) reflects the motion, theta' <- -e theta',
  so the block stays on its side. The default e is then still e_eta, a convention: pass the e of
  your one-sided model (e.g. calibrated on a test).

A block at rest starts rocking only when the ground acceleration overcomes the restoring moment,
|a_g| > g tan(eta) (one-sided: only when it pushes the block away from the wall). After an impact
whose outgoing velocity could lift the block by less than ``rest_amplitude`` x eta, the block is at
rest (this ends the infinite impact sequence of e < 1 in finite time). Limits: no sliding, no
bouncing (no free flight), rigid base and block, impacts instantaneous.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from .materials import real_number

__all__ = [
    "G",
    "HousnerBlock",
    "RockingResponse",
    "rock",
    "quarter_period",
    "quarter_period_linear",
]

G = 9.81
"""Default gravitational acceleration [m/s^2]."""

_RTOL = 1e-10
_MAX_SEGMENTS = 200_000


@dataclass(frozen=True)
class HousnerBlock:
    """A rigid rectangular block for Housner's rocking model.

    Attributes:
        b: full width B in the rocking direction [m].
        h: full height H [m].
        g: gravitational acceleration [m/s^2].
    """

    b: float
    h: float
    g: float = G

    def __post_init__(self) -> None:
        for name in ("b", "h", "g"):
            v = getattr(self, name)
            if not real_number(v, f"HousnerBlock.{name}") > 0:
                raise ValueError(f"HousnerBlock.{name} must be a positive finite number, got {v!r}")
            object.__setattr__(self, name, float(v))  # a NumPy scalar kept as a float

    @property
    def R(self) -> float:
        """Semi-diagonal, centroid to base corner [m]."""
        return 0.5 * math.hypot(self.b, self.h)

    @property
    def eta(self) -> float:
        """Slenderness angle atan(B/H) [rad]."""
        return math.atan2(self.b, self.h)

    @property
    def p(self) -> float:
        """Frequency parameter sqrt(3 g / (4 R)) [rad/s]."""
        return math.sqrt(3.0 * self.g / (4.0 * self.R))

    @property
    def e_eta(self) -> float:
        """Housner's coefficient of restitution 1 - 1.5 sin^2(eta) [-] (paper §3.2.1)."""
        return 1.0 - 1.5 * math.sin(self.eta) ** 2


@dataclass(frozen=True)
class RockingResponse:
    """Housner rocking history, comparable with a DEM result.

    Attributes:
        block: the block.
        time: (n,) [s], uniform step ``dt_out`` (plus the overturning instant if any).
        rotation: (n,) theta [rad]; positive: rocking about the corner on the +x side.
        angular_velocity: (n,) theta' [rad/s].
        top_displacement: (n,) horizontal displacement of the top corner above the pivot,
            H sin(theta) [m].
        impacts: (k,) impact times [s].
        peak_time: (j,) times of the half-cycle peaks (theta' = 0 while rocking) [s].
        peak_rotation: (j,) signed peak rotations [rad]; a release from rest is the first peak.
        overturned: whether |theta| reached the overturning angle moving outward.
        overturn_time: that instant [s] (None if it did not overturn).
        onset_time: first time the block rocks [s] (0 for a free-rocking release; None if never).
        restitution: e used at every impact [-].
    """

    block: HousnerBlock
    time: NDArray[np.float64]
    rotation: NDArray[np.float64]
    angular_velocity: NDArray[np.float64]
    top_displacement: NDArray[np.float64]
    impacts: NDArray[np.float64]
    peak_time: NDArray[np.float64]
    peak_rotation: NDArray[np.float64]
    overturned: bool
    overturn_time: float | None
    onset_time: float | None
    restitution: float

    @property
    def top_displacement_ratio(self) -> NDArray[np.float64]:
        """Top displacement normalised by the width B [-]."""
        return self.top_displacement / self.block.b

    def to_dataset(self):  # -> xarray.Dataset (import kept local: xarray is heavy)
        """The history as an ``xarray.Dataset`` shaped like a rockdem result (one free block).

        Variables: ``rocking_angle (time, block)`` [rad], ``top_displacement (time, block)`` [m],
        ``block_free (block)``, ``block_eta (block)`` [rad].
        """
        import xarray as xr

        return xr.Dataset(
            {
                "rocking_angle": (("time", "block"), self.rotation[:, None], {"units": "rad"}),
                "top_displacement": (("time", "block"), self.top_displacement[:, None], {"units": "m"}),
                "block_free": ("block", np.array([True])),
                "block_eta": ("block", np.array([self.block.eta]), {"units": "rad"}),
            },
            coords={"time": ("time", self.time, {"units": "s"}), "block": [0]},
            attrs={"model": "housner", "restitution": self.restitution, "overturned": int(self.overturned)},
        )


def _ground(ground_acc: Callable[[float], float] | tuple[ArrayLike, ArrayLike] | None):
    """Normalise the ground acceleration to (callable a(t) [m/s^2], sample times or None)."""
    if ground_acc is None:
        return (lambda t: 0.0), None
    if callable(ground_acc):
        return (lambda t: float(ground_acc(t))), None
    try:
        ta, aa = (np.asarray(v, dtype=float) for v in ground_acc)
    except (TypeError, ValueError) as exc:
        raise ValueError("ground_acc must be a callable a(t) or a pair of arrays (t [s], a [m/s^2])") from exc
    if ta.ndim != 1 or ta.shape != aa.shape or len(ta) < 2:
        raise ValueError(f"ground_acc arrays must be 1-D of equal length >= 2, got {ta.shape} and {aa.shape}")
    if np.any(np.diff(ta) <= 0) or not np.all(np.isfinite(aa)):
        raise ValueError("ground_acc: time must be strictly increasing and accelerations finite")
    return (lambda t: float(np.interp(t, ta, aa, left=0.0, right=0.0))), ta


def rock(
    block: HousnerBlock,
    *,
    theta0: float,
    omega0: float = 0.0,
    duration: float,
    e: float | None = None,
    ground_acc: Callable[[float], float] | tuple[ArrayLike, ArrayLike] | None = None,
    one_sided: bool = False,
    wall_side: int = -1,
    dt_out: float = 1e-3,
    overturn_angle: float | None = None,
    rest_amplitude: float = 1e-6,
) -> RockingResponse:
    """Integrate Housner's exact rocking equation with impacts (module docstring).

    Args:
        block: the block.
        theta0: initial rotation [rad] (0 with omega0 = 0: at rest until the ground moves it).
        omega0: initial angular velocity [rad/s].
        duration: end time [s].
        e: restitution at each impact [-], in [0, 1]; default ``block.e_eta``.
        ground_acc: horizontal ground acceleration [m/s^2]: callable a(t) or (t, a) arrays
            (linear interpolation, zero outside the record).
        one_sided: a wall on ``wall_side`` prevents rotation to that side.
        wall_side: -1 (the wall stops theta < 0; the block rocks with theta >= 0) or +1.
        dt_out: output step [s].
        overturn_angle: |theta| at which the block is declared overturned when moving outward
            [rad]; default eta (exact for free rocking, conservative under ground motion, where a
            block past eta may still be recovered: pass e.g. pi/2 to follow it further).
        rest_amplitude: rest criterion, fraction of eta (module docstring).

    Returns:
        RockingResponse on a uniform time grid.

    Raises:
        ValueError: bad arguments (named in the message).
    """
    eta, p, g = block.eta, block.p, block.g
    e = block.e_eta if e is None else float(e)
    if not (0.0 <= e <= 1.0):
        raise ValueError(f"restitution e must lie in [0, 1], got {e!r} (block e_eta = {block.e_eta:.4f})")
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be > 0 s, got {duration!r}")
    if not (math.isfinite(dt_out) and 0 < dt_out <= duration):
        raise ValueError(f"dt_out must lie in (0, duration], got {dt_out!r}")
    if wall_side not in (-1, 1):
        raise ValueError(f"wall_side must be -1 or +1, got {wall_side!r}")
    real_number(theta0, "theta0 [rad]")
    real_number(omega0, "omega0 [rad/s]")
    if not real_number(rest_amplitude, "rest_amplitude (a fraction of eta)") > 0:
        raise ValueError(f"rest_amplitude must be a positive fraction of eta, got {rest_amplitude!r}")
    th_over = eta if overturn_angle is None else float(overturn_angle)
    if not (eta <= th_over <= 0.5 * math.pi):
        raise ValueError(f"overturn_angle must lie in [eta, pi/2] = [{eta:.4g}, {0.5 * math.pi:.4g}] rad")
    if abs(theta0) >= th_over:
        raise ValueError(f"|theta0| = {abs(theta0):.4g} rad must be below the overturning angle {th_over:.4g} rad")
    allowed = -wall_side  # sign of theta the one-sided block can take
    if one_sided and theta0 * allowed < 0:
        raise ValueError(f"one-sided block: theta0 must have the sign of {allowed:+d} (the wall is on side {wall_side:+d})")
    acc, t_rec = _ground(ground_acc)
    grid = np.arange(0.0, duration + 0.5 * dt_out, dt_out)
    grid = grid[grid <= duration * (1 + 1e-12)]
    eps = 1e-12 * eta  # event offsets: keep events from firing at a segment's own start
    v_eps = 1e-12 * p * eta
    max_step = np.inf
    if ground_acc is not None:
        max_step = float(np.min(np.diff(t_rec))) if t_rec is not None else dt_out

    def rhs(side: int):
        def f(t: float, y: NDArray[np.float64]) -> list[float]:
            phi = eta * side - y[0]
            return [y[1], -p * p * (math.sin(phi) + acc(t) / g * math.cos(phi))]

        return f

    def lift(v: float) -> float:
        """Amplitude reached from theta = 0 with speed v, exact energy; inf if it overturns."""
        c = math.cos(eta) + 0.5 * v * v / (p * p)
        return math.inf if c >= 1.0 else eta - math.acos(c)

    out_t: list[NDArray[np.float64]] = []
    out_y: list[NDArray[np.float64]] = []
    impacts: list[float] = []
    peaks_t: list[float] = []
    peaks_y: list[float] = []
    t, th, om = 0.0, float(theta0), float(omega0)
    onset: float | None = 0.0 if (th != 0.0 or om != 0.0) else None
    if th != 0.0 and om == 0.0:
        peaks_t.append(0.0)
        peaks_y.append(th)
    rocking = onset is not None
    side = int(np.sign(th)) if th != 0.0 else int(np.sign(om))
    if one_sided:
        side = allowed
    over_t: float | None = None

    def emit(t_a: float, t_b: float, values: Callable[[NDArray[np.float64]], NDArray[np.float64]], last: bool) -> None:
        sel = (grid >= t_a) & ((grid <= t_b) if last else (grid < t_b))
        if np.any(sel):
            out_t.append(grid[sel])
            out_y.append(values(grid[sel]))

    for _ in range(_MAX_SEGMENTS):
        if t >= duration:
            break
        if not rocking:
            t_on = _onset(acc, t, duration, t_rec, dt_out, g * math.tan(eta), allowed if one_sided else 0)
            t_b = duration if t_on is None else t_on
            emit(t, t_b, lambda ts: np.zeros((2, len(ts))), last=t_on is None)
            if t_on is None:
                t = duration
                break
            t, th, om, rocking = t_on, 0.0, 0.0, True
            onset = t if onset is None else onset
            a_on = acc(t)
            side = allowed if one_sided else (-1 if a_on > 0 else 1)
            continue

        def impact(tt: float, y: NDArray[np.float64], s: int = side) -> float:
            return s * y[0] + eps

        impact.terminal, impact.direction = True, -1  # type: ignore[attr-defined]

        def over(tt: float, y: NDArray[np.float64], s: int = side) -> float:
            return s * y[0] - th_over

        over.terminal, over.direction = True, 1  # type: ignore[attr-defined]

        def peak(tt: float, y: NDArray[np.float64], s: int = side) -> float:
            return s * y[1] - v_eps

        peak.terminal, peak.direction = False, -1  # type: ignore[attr-defined]

        sol = solve_ivp(
            rhs(side), (t, duration), [th, om], method="DOP853", rtol=_RTOL, atol=_RTOL * eta * 1e-2,
            events=(impact, over, peak), dense_output=True, max_step=max_step,
        )
        if sol.status == -1:
            raise RuntimeError(f"Housner integration failed at t = {t:.6g} s: {sol.message}")
        peaks_t.extend(sol.t_events[2].tolist())
        peaks_y.extend([float(y[0]) for y in sol.y_events[2]])
        t_end = float(sol.t[-1])
        hit_over = len(sol.t_events[1]) > 0
        hit_impact = len(sol.t_events[0]) > 0
        emit(t, t_end, sol.sol, last=not (hit_over or hit_impact))
        if hit_over:
            over_t = float(sol.t_events[1][0])
            out_t.append(np.array([over_t]))
            out_y.append(sol.y_events[1][0][:, None])
            keep = np.array(peaks_t) <= over_t
            peaks_t = list(np.array(peaks_t)[keep])
            peaks_y = list(np.array(peaks_y)[keep])
            break
        if not hit_impact:
            t = duration
            break
        t = float(sol.t_events[0][0])
        impacts.append(t)
        v_in = float(sol.y_events[0][0][1])
        if one_sided:
            om, th = -e * v_in, 0.0
        else:
            om, th, side = e * v_in, float(sol.y_events[0][0][0]), -side
        if lift(abs(om)) < rest_amplitude * eta:
            rocking, th, om = False, 0.0, 0.0
    else:
        raise RuntimeError(f"Housner integration: more than {_MAX_SEGMENTS} segments (chattering?)")

    tt = np.concatenate(out_t) if out_t else np.zeros(0)
    yy = np.concatenate(out_y, axis=1) if out_y else np.zeros((2, 0))
    return RockingResponse(
        block=block,
        time=tt,
        rotation=yy[0],
        angular_velocity=yy[1],
        top_displacement=block.h * np.sin(yy[0]),
        impacts=np.array(impacts),
        peak_time=np.array(peaks_t, dtype=float),
        peak_rotation=np.array(peaks_y, dtype=float),
        overturned=over_t is not None,
        overturn_time=over_t,
        onset_time=onset,
        restitution=e,
    )


def _onset(
    acc: Callable[[float], float],
    t0: float,
    t1: float,
    t_rec: NDArray[np.float64] | None,
    step: float,
    a_crit: float,
    allowed: int,
) -> float | None:
    """First time >= t0 at which the ground acceleration starts rocking a block at rest.

    Two-sided (allowed = 0): |a| > a_crit = g tan(eta). One-sided: -allowed * a > a_crit (the
    inertial force pushes the block away from the wall). Scans the record samples (or a grid of
    ``step``/4 for a callable) and refines the crossing with Brent's method.
    """

    def drive(t: float) -> float:
        a = acc(t)
        return (abs(a) if allowed == 0 else -allowed * a) - a_crit

    if drive(t0) > 0:
        return t0
    if t_rec is not None:
        ts = np.concatenate(([t0], t_rec[(t_rec > t0) & (t_rec < t1)], [t1]))
    else:
        ts = np.arange(t0, t1, 0.25 * step)
        ts = np.append(ts, t1)
    vals = np.array([drive(float(x)) for x in ts])
    above = np.flatnonzero(vals > 0)
    if len(above) == 0:
        return None
    k = int(above[0])
    return float(brentq(drive, ts[k - 1], ts[k], xtol=1e-14, rtol=4 * np.finfo(float).eps))


def quarter_period(block: HousnerBlock, theta0: float) -> float:
    """Time from a release at theta0 (at rest) to the first impact, exact nonlinear equation [s].

    Energy integral T/4 = int_0^theta0 dtheta / sqrt(2 p^2 [cos(eta - theta0) - cos(eta - theta)]),
    evaluated by ``scipy.integrate.quad`` after the substitution theta = theta0 (1 - s^2) that
    removes the inverse-square-root singularity at the release.
    """
    eta, p = block.eta, block.p
    if not (0.0 < theta0 < eta):
        raise ValueError(f"theta0 must lie in (0, eta = {eta:.6g}) rad, got {theta0!r}")

    def f(s: float) -> float:
        # cos(eta - th0) - cos(eta - th0 + th0 s^2) = 2 sin(eta - th0 + th0 s^2/2) sin(th0 s^2/2)
        half = 0.5 * theta0 * s * s
        den = math.sin(eta - theta0 + half) * math.sin(half)
        return theta0 * s / (p * math.sqrt(den)) if den > 0 else theta0 / (p * math.sqrt(0.5 * theta0 * math.sin(eta - theta0)))

    val, _ = quad(f, 0.0, 1.0, epsabs=0.0, epsrel=1e-12, limit=200)
    return float(val)


def quarter_period_linear(block: HousnerBlock, theta0: float) -> float:
    """Quarter period of the linearised (small eta) equation: (1/p) arccosh(1 / (1 - theta0/eta)) [s]."""
    eta = block.eta
    if not (0.0 < theta0 < eta):
        raise ValueError(f"theta0 must lie in (0, eta = {eta:.6g}) rad, got {theta0!r}")
    return math.acosh(1.0 / (1.0 - theta0 / eta)) / block.p
