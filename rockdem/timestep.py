"""Stable and accurate timestep of the explicit scheme (paper §3: Delta t and its SP reduction).

Default rule ("bound"): dt = (2 / omega_max) min(safety f_SP, resolution), from a Gershgorin-type
bound omega_max of the highest frequency of the contacts tracked at the start
(:mod:`rockdem.kernels.bound`) and Belytschko's reduction f_SP = sqrt(1 + xi^2) - xi for explicit SP
dashpots (``dashpots="explicit"``); f_SP = 1 for the default implicit dashpots, stable at the
undamped step for any beta (:mod:`rockdem.kernels.implicit`, ``docs/dashpots.md``).

* ``safety`` (0.9) keeps the scheme stable: the critical step is (2 / omega_max) f_SP.
* ``resolution`` (0.3) keeps impacts accurate: a contact that closes and opens again within a
  few steps is integrated coarsely even when stable. With omega_max dt <= 2 x 0.3 an impact lasts
  at least pi / 0.6 ~ 5 steps, and its energy error (with the impulse-exact contact transitions of
  :mod:`rockdem.kernels.contact`) stays below 1 % of its kinetic energy: measured on an undamped
  0.5 x 0.8 m block with 2 interface points and mu = 5.7, -2.7 % at the stable step (0.9), -1.4 %
  at 0.45, -0.74 % at 0.3, -0.08 % at 0.1 (``docs/contacts.md``). With explicit SP dashpots the
  Belytschko reduction is usually the smaller of the two (beta = 2 / omega_crit gives f_SP ~ 0.1);
  implicit dashpots run at the resolution step, which also resolves a critically damped impact
  (e_a within 0.1 % of the converged answer on the Fig. 4 grid, ``docs/dashpots.md``).

Impact windows: under an earthquake the step above does not reach WME 0.01 of the converged history
(0.0023 to 0.18 on eight cases): rocking amplifies the scheme's second-order error, made at the
impacts, as it amplifies a 1 % change of beta. So the kernel divides the step by
:data:`IMPACT_REFINEMENT` (6: resolution 0.05) from one contact period before each predicted impact
until two periods after it (:func:`impact_windows`): WME 0.0001 to 0.0049 on the same eight cases for
2 to 6 % more steps, where :data:`QUAKE_RESOLUTION` everywhere takes 6 times the steps
(``docs/dashpots.md``). The window must open before the impact: a window opened one step into it
did no better than none (the step's change then falls inside the impact).

During the run the bound is recomputed at every contact detection and the step is lowered if
stiffer contacts form. A block with no contact at the start (in free fall) is bounded as if all
its interface points touched.

Rule "3dec": dt = 0.2 sqrt(m_min / k_max), k_max the stiffest sub-contact kn A of the model,
followed by the same SP reduction with omega = sqrt(k_max / m_min), to compare runtimes with the
paper's 3DEC figures.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from ._warn import warn_user
from .kernels.bound import contact_bound
from .kernels.contact import sp_critical_factor
from .kernels.step import IMPACT_SHARE
from .kernels.layout import DASHPOTS_EXPLICIT, DASHPOTS_IMPLICIT, Scratch, State
from .model import Model
from .state import initial_state

__all__ = ["TimestepInfo", "stable_timestep", "DEFAULT_SAFETY", "DEFAULT_RESOLUTION", "QUAKE_RESOLUTION",
           "DASHPOT_SCHEMES", "resolve_dashpots", "dashpot_code", "MAX_DAMPING_RATIO", "IMPACT_REFINEMENT", "IMPACT_SHARE",
           "impact_windows"]

USER_DT_SHARE = 1e-3
"""A user dt below this share of the stable bound is warned about: it only multiplies the steps
(run.dt = 1e-9 s on a free-rocking block planned 1e8 steps without a word, before 2026-12-08)."""

DASHPOT_SCHEMES = ("auto", "implicit", "explicit")
"""How SP dashpots are integrated: "implicit" (trapezoidal, stable at the undamped step,
:mod:`rockdem.kernels.implicit`), "explicit" (on the last half step's velocities with Belytschko's
step reduction, as 3DEC) or "auto" (the default: implicit, but explicit for a model with local
damping, whose force -alpha_L |F| sign(v) needs the whole unbalanced force before the velocity update)."""

MAX_DAMPING_RATIO = 1e6
"""Largest damping ratio beta omega_max / 2 at the highest contact frequency that a run accepts
(implicit dashpots are stable for any; this refuses a beta given in the wrong unit)."""


def resolve_dashpots(model: Model, dashpots: str | None) -> str:
    """The scheme ("implicit" or "explicit") a run of ``model`` uses for ``dashpots`` (None: "auto").

    Raises:
        ValueError: not one of :data:`DASHPOT_SCHEMES`, or "implicit" with local damping.
    """
    dashpots = "auto" if dashpots is None else dashpots
    if dashpots not in DASHPOT_SCHEMES:
        raise ValueError(f"dashpots must be 'auto', 'implicit' or 'explicit', got {dashpots!r}")
    local = model.arrays.local_damping > 0.0
    if dashpots == "implicit" and local:
        raise ValueError(
            "dashpots = 'implicit' cannot be combined with local damping (damping.local > 0): its force "
            "-alpha_L |F| sign(v) needs the whole unbalanced force, dashpots included, before the velocity "
            "update; use dashpots = 'explicit' (or 'auto', which does so for local damping)"
        )
    if dashpots == "auto":
        return "explicit" if local else "implicit"
    return dashpots


def dashpot_code(dashpots: str) -> int:
    """The kernel code (``State.dashpots``) of a resolved scheme, "implicit" or "explicit"."""
    if dashpots not in ("implicit", "explicit"):
        raise ValueError(f"dashpots must be 'implicit' or 'explicit' here, got {dashpots!r}")
    return DASHPOTS_IMPLICIT if dashpots == "implicit" else DASHPOTS_EXPLICIT

DEFAULT_SAFETY = 0.9
"""Fraction of the critical (stability) step used by default."""

DEFAULT_RESOLUTION = 0.3
"""Largest omega_max dt / 2 by default: impacts last at least ~5 steps (energy error < 1 %)."""

QUAKE_RESOLUTION = 0.05
"""The resolution at which implicit-dashpot rocking under an earthquake matches the converged
history within WME 0.01 without impact windows (issue 12): measured on eight earthquake cases, worst
0.0052, against 0.0021 to 0.18 at the default 0.3 (``benchmarks/quake_convergence.py``,
``docs/dashpots.md``). It takes 6 times the steps; the default impact windows
(:data:`IMPACT_REFINEMENT`) reach the same level for a few per cent more."""


IMPACT_REFINEMENT = 6
"""The step inside an impact window is the run's step divided by this (resolution 0.3 -> 0.05 there):
see :func:`impact_windows`."""

MAX_IMPACT_REFINEMENT = 100.0
"""Largest impact refinement accepted (a larger one is a typo that would make a run endless)."""

IMPACT_WINDOW_PERIODS = 1.0
"""An impact window opens this many periods 2 pi / omega_max of the stiffest contact before a
predicted impact and closes twice as long after it (:data:`rockdem.kernels.step.IMPACT_AFTER`), or
later, once the impact has ended (:data:`rockdem.kernels.step.IMPACT_TAIL`)."""

IMPACT_OVERLAPS = 5.0
"""A touch is an impact (opens a window) when its dynamic overlap v / omega_max exceeds this many
static overlaps g / omega_max^2: closing speed v > IMPACT_OVERLAPS g / omega_max."""


def impact_windows(model: Model, info: TimestepInfo, refinement: float = IMPACT_REFINEMENT) -> tuple[float, float, float]:
    """(refinement, window [s], impact speed [m/s]) of a run with timestep ``info`` (window 0: none).

    The kernel (:func:`rockdem.kernels.step.advance`) divides the step by ``refinement`` from
    ``window`` before an open unbonded sub-contact is predicted to touch (its gap over its closing
    speed, when that speed exceeds ``impact speed``) until two windows after the touch
    (``kernels.step.IMPACT_AFTER``), or later while a pressed sub-contact still moves faster than
    the impact speed (``kernels.step.IMPACT_TAIL``), while the windows cover at most
    :data:`IMPACT_SHARE` of the time so far. The impact speed is :data:`IMPACT_OVERLAPS` g / omega_max: an
    impact whose dynamic overlap v / omega_max exceeds 5 static overlaps g / omega_max^2 (any closing
    speed without gravity). Refinement 1, the rules "user" and "3dec" and explicit dashpots (kept as
    3DEC's scheme) have no windows.

    Raises:
        ValueError: ``refinement`` not a number from 1 to :data:`MAX_IMPACT_REFINEMENT`.
    """
    if isinstance(refinement, bool) or not (isinstance(refinement, numbers.Real) and 1.0 <= refinement <= MAX_IMPACT_REFINEMENT):
        raise ValueError(f"impact_refinement must be a number from 1 (no impact windows) to {MAX_IMPACT_REFINEMENT:g} "
                         f"(default {IMPACT_REFINEMENT:g}), got {refinement!r}")
    if refinement == 1.0 or info.rule != "bound" or info.dashpots != "implicit" or not info.omega_max > 0.0:
        return float(refinement), 0.0, math.inf  # (a window of 0 never opens)
    window = IMPACT_WINDOW_PERIODS * 2.0 * math.pi / info.omega_max
    speed = IMPACT_OVERLAPS * float(np.linalg.norm(model.arrays.gravity)) / info.omega_max
    return float(refinement), window, speed


@dataclass(frozen=True)
class TimestepInfo:
    """Timestep figures.

    Attributes:
        dt: the initial timestep [s].
        critical: the stable bound (safety 1) at the start [s]; a user dt above it is refused.
        omega_max: bound of the highest circular frequency [rad/s].
        sp_factor: reduction sqrt(1+xi^2) - xi for SP damping (1 without, and with implicit dashpots).
        rule: "bound", "3dec" or "user".
        resolution: the impact-resolution fraction of 2 / omega_max used (rule "bound").
        dashpots: the scheme used, "implicit" or "explicit" (:func:`resolve_dashpots`).
        damping_ratio: beta omega_max / 2, the SP damping ratio at omega_max (largest beta of the
            limiting block; 0 without SP damping).
    """

    dt: float
    critical: float
    omega_max: float
    sp_factor: float
    rule: str
    resolution: float = DEFAULT_RESOLUTION
    dashpots: str = "explicit"  # checkpoints written before the implicit scheme existed
    damping_ratio: float = 0.0


def _all_faces_bound(model: Model, sp_reduction: bool) -> tuple[float, float, float]:
    """Critical step if every interface point of every free block touched a fixed partner: per free
    block, omega^2 = c sum_points A (kn f(n) + ks (f(t1) + f(t2))), f(d) = 1/m + (r x d)^2 . I^-1 the
    flexibility of the point along d (n its face normal, t1, t2 tangents; c = 2 with several free
    blocks), kn, ks, beta the largest of the block's group; returns (2 / omega f_SP, omega, f_SP) of
    the block with the smallest step (the first one on ties), computed for all blocks at once."""
    m = model.arrays
    groups = np.unique(m.block_group)
    coupling = 2.0 if int(np.count_nonzero(m.block_free)) > 1 else 1.0
    face_of_point = np.repeat(np.arange(len(m.face_area)), np.diff(m.face_point_start))
    nb = len(m.block_mass)
    g = m.block_group
    kn = np.max(m.mat_kn[g][:, groups], axis=1)  # (nb,) the largest over the groups present
    ks = np.max(m.mat_ks[g][:, groups], axis=1)
    beta = np.max(m.mat_beta[g][:, groups], axis=1)
    pb = m.point_block
    sel = m.block_free[pb]
    pb, r, area, n = pb[sel], m.point_local[sel], m.point_area[sel], m.face_normal[face_of_point[sel]]
    t1 = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(n, t1)
    with np.errstate(divide="ignore"):
        inv_mass, inv_inertia = 1.0 / m.block_mass[pb], 1.0 / m.block_inertia[pb]

    def flex(d: np.ndarray) -> np.ndarray:
        return inv_mass + np.sum(np.cross(r, d) ** 2 * inv_inertia, axis=1)

    terms = area * (kn[pb] * flex(n) + ks[pb] * (flex(t1) + flex(t2)))
    free = np.flatnonzero(m.block_free)
    if free.size == 0:
        return (np.inf, 0.0, 1.0)
    w = np.sqrt(coupling * np.bincount(pb, weights=terms, minlength=nb)[free])
    with np.errstate(divide="ignore"):
        xi = 0.5 * beta[free] * w
        f = 1.0 / (np.hypot(1.0, xi) + xi) if sp_reduction else np.ones_like(w)  # kernels.contact.sp_critical_factor
        steps = 2.0 / w * f
    best = int(np.argmin(steps))
    if not steps[best] < np.inf:
        return (np.inf, 0.0, 1.0)
    return (float(steps[best]), float(w[best]), float(f[best]))


def stable_timestep(
    model: Model,
    *,
    rule: str = "bound",
    safety: float = DEFAULT_SAFETY,
    resolution: float = DEFAULT_RESOLUTION,
    dt: float | None = None,
    dashpots: str | None = None,
    initial: tuple[State, Scratch] | None = None,
) -> TimestepInfo:
    """Timestep for ``model`` at its initial state (``initial``: that state and scratch when the
    caller has them, :func:`rockdem.state.initial_state`; computed here otherwise).

    Args:
        rule: "bound" (default) or "3dec".
        safety: fraction of the stable bound used (also when the step is lowered during a run).
        resolution: largest omega_max dt / 2 (impact resolution, see the module notes); 1 turns
            the accuracy limit off.
        dt: a user timestep [s]; refused if above the stable bound.
        dashpots: "auto" (default, None), "implicit" or "explicit" SP dashpots
            (:data:`DASHPOT_SCHEMES`): only explicit ones reduce the stable step by Belytschko's factor.

    Raises:
        ValueError: unknown rule or dashpot scheme, bad safety, or a user dt above the stable bound.
    """
    dashpots = resolve_dashpots(model, dashpots)
    explicit = dashpots == "explicit"
    if rule not in ("bound", "3dec"):
        raise ValueError(f"timestep rule must be 'bound' or '3dec', got {rule!r}")
    if not (math.isfinite(safety) and 0.0 < safety <= 1.0):
        raise ValueError(f"timestep safety must lie in (0, 1], got {safety!r}")
    if not (math.isfinite(resolution) and 0.0 < resolution <= 1.0):
        raise ValueError(f"timestep resolution must lie in (0, 1], got {resolution!r}")
    s, sc = initial_state(model) if initial is None else initial
    critical, om, fac = (float(v) for v in contact_bound(model.arrays, s, sc, explicit))
    free_fall = _all_faces_bound(model, explicit)
    if not math.isfinite(critical):
        critical, om, fac = free_fall
    xi = 0.5 * float(np.max(model.arrays.mat_beta)) * om
    if dt is not None:
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a positive time step [s], got {dt!r}")
        if dt > critical:
            raise ValueError(
                f"dt = {dt:.3e} s is above the stable bound {critical:.3e} s of this model "
                f"(omega_max = {om:.4g} rad/s, SP reduction {fac:.4f}); use dt <= {critical:.3e} s "
                "or leave dt unset for the automatic value"
            )
        if dt < USER_DT_SHARE * critical:
            warn_user(f"dt = {dt:.3e} s is {critical / dt:.3g} times below the stable bound {critical:.3e} s of this model: "
                      f"the run takes that many times the steps it needs (the automatic step resolves impacts); "
                      f"leave dt unset, or give a dt nearer the bound (a convergence check needs a tenth of it)")
        return TimestepInfo(float(dt), critical, om, fac, "user", dashpots=dashpots, damping_ratio=xi)
    if rule == "3dec":
        m = model.arrays
        free = m.block_free
        m_min = float(np.min(m.block_mass[free]))
        k_max = float(np.max(m.mat_kn)) * float(np.max(m.point_area[free[m.point_block]]))
        w = math.sqrt(k_max / m_min)
        f3 = sp_critical_factor(float(np.max(m.mat_beta)), w) if explicit else 1.0
        return TimestepInfo(0.2 * math.sqrt(m_min / k_max) * f3, critical, om, f3, "3dec", dashpots=dashpots, damping_ratio=xi)
    accurate = resolution * 2.0 / om if om > 0.0 else math.inf
    return TimestepInfo(min(safety * critical, accurate), critical, om, fac, "bound", resolution, dashpots, xi)
