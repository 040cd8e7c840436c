"""Joint law per sub-contact: 3DEC Mohr-Coulomb with tension cut-off and bond breakage (paper §3).

Per sub-contact of effective area A with normal overlap u_n (compression > 0) and elastic shear
displacement u_s:
  F_n = kn A u_n, tension only while bonded and down to -ft A (else the bond fails in tension);
  F_s = ks A u_s with |F_s| <= c A + F_n tan(phi) while bonded, c_r A + F_n tan(phi_r) after
  failure (else slip, and a bonded point fails in shear, dropping to its residual strength);
  SP dashpots beta kn A du_n/dt and beta ks A du_s/dt act on active sub-contacts; as Rayleigh
  damping is proportional to the tangent stiffness, the shear dashpot is off while a point slips
  (and both are off while it is open).
Contact onset and release: an unbonded spring switches on when its overlap crosses zero, most
often inside a step. Evaluated only at the step's time, the leapfrog scheme then misses the part
of the force ramp's impulse that falls between the crossing and the step (an energy error of order
(omega dt)^2 of the impact's kinetic energy, several per cent at the stable step). For a ramp at
the current normal speed the exact mean force over the step's velocity interval is known in
closed form; :func:`ramp_overlap` gives the overlap that produces it, at the first step in contact
and at the first step out of contact.

Energy bookkeeping: over a step the shear spring's extension goes from e0 (carried into the
current tangent plane) by the relative motion du to the trial e0 + du, and a slip scales it back by
lam = F_max / F_trial. The energy dissipated is the work of the mean spring force on du minus the
change of stored energy, ks A [(e0 + e_new) . du / 2 - (|e_new|^2 - |e0|^2) / 2]: exactly zero for an
elastic step, F_max |du| for steady sliding, and the released spring energy when the Coulomb limit
drops at a standing contact (a contact unloading at a bounce), where the constant-force estimate
F_max (F_trial - F_max) / (ks A) missed up to 12 % of an impact's kinetic energy.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, _nrt=False, inline="always")
def normal_force(kn: float, area: float, overlap: float) -> float:
    """Elastic normal force kn A u_n [N] (compression positive)."""
    return kn * area * overlap


@njit(cache=True, _nrt=False, inline="always")
def coulomb_limit(cohesion: float, tan_friction: float, area: float, fn: float) -> float:
    """Shear strength c A + max(F_n, 0) tan(phi) [N]."""
    return cohesion * area + max(fn, 0.0) * tan_friction


@njit(cache=True, _nrt=False, inline="always")
def slip_dissipation(ks_area: float, lam: float, e0_du: float, e0_sq: float, du_sq: float) -> float:
    """Energy dissipated by a slip step [J]: ks A [(e0 + lam e_t) . du / 2 - (lam^2 |e_t|^2 - |e0|^2) / 2]
    with e_t = e0 + du the trial extension, given e0 . du, |e0|^2, |du|^2 [m^2] (see the module notes)."""
    et_du = e0_du + du_sq
    et_sq = e0_sq + 2.0 * e0_du + du_sq
    return 0.5 * ks_area * (e0_du + lam * et_du - lam * lam * et_sq + e0_sq)


@njit(cache=True, _nrt=False, inline="always")
def drop_dissipation(f_from: float, f_to: float, ks_area: float) -> float:
    """Energy released when a standing spring's force drops from f_from to f_to [J]: (f_from^2 - f_to^2) / (2 ks A)."""
    return 0.5 * (f_from * f_from - f_to * f_to) / ks_area


@njit(cache=True, _nrt=False, inline="always")
def spring_energy(force: float, stiffness: float) -> float:
    """Energy stored in a linear spring F^2 / (2 k) [J]."""
    return 0.5 * force * force / stiffness if stiffness > 0.0 else 0.0


@njit(cache=True, _nrt=False, inline="always")
def ramp_overlap(un: float, un_prev: float, vn: float, dt: float) -> float:
    """Overlap [m] whose spring force equals the exact mean force of an unbonded contact over the
    velocity interval [t - dt/2, t + dt/2] when it opened or closed during the last position step.

    Args:
        un: overlap now (> 0 compression) [m]; un_prev: at the previous step [m].
        vn: normal relative velocity over the last step (> 0 separating) [m/s]; dt: that step [s].

    The overlap is linear in time through the crossing at t - s dt. Closing (un_prev <= 0 < un,
    approach speed w = -vn): the ramp's impulse before the half step was missed at the previous
    step, so the overlap becomes un + w dt (s - 1/2)^2 / 2. Opening (un_prev > 0 >= un, crossing
    at t - s dt): the ramp's impulse that reaches into this step's interval, or that the previous
    step's value did not cover, is applied now: the overlap becomes vn dt (1/2 - s)^2 / 2.
    Otherwise ``un``. Both corrections assume the overlap varies linearly over a step, which holds
    when the contact lasts several steps (omega dt <~ 0.5, see :mod:`rockdem.timestep`).
    """
    if un > 0.0 and un_prev <= 0.0 and vn < 0.0:
        frac = min(un / (-vn * dt), 1.0)
        return un + 0.5 * (-vn) * dt * (frac - 0.5) ** 2
    if un <= 0.0 and un_prev > 0.0 and vn > 0.0:
        d = 0.5 - min(-un / (vn * dt), 1.0)
        return 0.5 * vn * dt * d * d
    return un


@njit(cache=True, _nrt=False, inline="always")
def dashpot_onset_share(since: float, h: float) -> float:
    """Share of the velocity step [t - h/2, t + h/2] (length h [s]) of a dashpot whose contact closed
    ``since`` [s] before t, with the part the last step missed when it closed before t - h/2:
    since / h + 1/2, at most 3/2 (implicit dashpots, :mod:`rockdem.kernels.implicit`)."""
    return min(since / h + 0.5, 1.5)


@njit(cache=True, _nrt=False, inline="always")
def dashpot_release_share(un: float, vn: float, dt: float) -> float:
    """Share of the velocity step to add, at the first step out of contact, to a dashpot whose contact
    opened at t - s dt during the last position step dt (overlap un <= 0 now [m], separating at vn
    > 0 [m/s]): 1/2 - s, negative when the last step applied it past the opening."""
    return 0.5 - min(-un / (vn * dt), 1.0)


RELEASE_INTERVALS = 8
"""Simpson intervals per segment for the impulse of a releasing shear spring (the profile is
linear except where the Coulomb cap takes over)."""


@njit(cache=True, _nrt=False, inline="always")
def release_shear(
    us0: float, us1: float, us2: float, ks_area: float, cap_slope: float, un_prev: float, vn: float,
    vs0: float, vs1: float, vs2: float, dt: float,
) -> tuple[float, float, float, float]:
    """The shear spring of an unbonded contact that opened during the last step.

    Over the last step the spring force followed F(t) = F_el(t) min(1, C(t) / |F_el(t)|), the elastic
    force F_el = ks A (us - v_s t) capped by the Coulomb limit C = mu kn A (un_prev - vn t), which
    falls to zero at the opening time t* = un_prev / vn (t from the previous step). The previous
    step applied F(0) over [-dt/2, dt/2]; this returns the force that completes the exact impulse
    of F over [-dt/2, t*] (a 6-point Gauss rule) and the energy dissipated in the spring from the
    previous step to t*, E(0) - int_0^t* F . v_s dt [J]. (The profile is integrated by Simpson's
    rule with nodes computed in place: a table of nodes would be an array, which in this inlined
    function would cost the caller's loop its reference-count pruning.)

    Args:
        us0, us1, us2: elastic extension at the previous step [m]; ks_area: ks A [N/m];
        cap_slope: mu kn A [N/m]; un_prev: overlap at the previous step [m];
        vn: separation speed (> 0) [m/s]; vs: tangential relative velocity [m/s]; dt [s].
    """
    t_star = min(un_prev / vn, dt) if vn > 0.0 else dt
    imp0 = imp1 = imp2 = 0.0
    work = 0.0
    for seg in range(2):
        a = -0.5 * dt if seg == 0 else 0.0
        b = 0.0 if seg == 0 else t_star
        h = (b - a) / RELEASE_INTERVALS
        for k in range(RELEASE_INTERVALS + 1):
            t = a + k * h
            e0 = ks_area * (us0 - vs0 * t)
            e1 = ks_area * (us1 - vs1 * t)
            e2 = ks_area * (us2 - vs2 * t)
            mag = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            cap = cap_slope * max(un_prev - vn * t, 0.0)
            f = cap / mag if mag > cap else 1.0
            w = h / 3.0 * (1.0 if k == 0 or k == RELEASE_INTERVALS else (4.0 if k % 2 == 1 else 2.0))
            imp0 += w * f * e0
            imp1 += w * f * e1
            imp2 += w * f * e2
            if seg == 1:
                work += w * f * (e0 * vs0 + e1 * vs1 + e2 * vs2)
    f0 = ks_area * us0
    f1 = ks_area * us1
    f2 = ks_area * us2
    stored = 0.5 * (f0 * f0 + f1 * f1 + f2 * f2) / ks_area if ks_area > 0.0 else 0.0
    return imp0 / dt - f0, imp1 / dt - f1, imp2 / dt - f2, stored - work


@njit(cache=True, _nrt=False, inline="always")
def sp_critical_factor(beta: float, omega_max: float) -> float:
    """Timestep reduction sqrt(1 + xi^2) - xi, xi = beta omega_max / 2 (Belytschko, SP damping),
    evaluated as 1 / (sqrt(1 + xi^2) + xi), free of cancellation and overflow for large xi."""
    xi = 0.5 * beta * omega_max
    return 1.0 / (math.hypot(1.0, xi) + xi)


@njit(cache=True, _nrt=False, inline="always")
def shear_increment(
    e0: float, e1: float, e2: float, n0: float, n1: float, n2: float, vs0: float, vs1: float, vs2: float, dt: float
) -> tuple[float, float, float, float, float, float]:
    """Carry the elastic shear extension e (3 components) [m] into the current tangent plane
    (normal n, keeping its length) and add the relative tangential motion du = -v_s dt.

    Returns the new extension (3 components), e_carried . du, |e_carried|^2 and |du|^2 (the last
    three for :func:`slip_dissipation`)."""
    mag = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    d = e0 * n0 + e1 * n1 + e2 * n2
    e0 -= d * n0
    e1 -= d * n1
    e2 -= d * n2
    mag2 = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    if mag2 > 0.0:
        f = mag / mag2
        e0 *= f
        e1 *= f
        e2 *= f
    du0, du1, du2 = -vs0 * dt, -vs1 * dt, -vs2 * dt
    e0_du = e0 * du0 + e1 * du1 + e2 * du2
    e0_sq = e0 * e0 + e1 * e1 + e2 * e2
    return e0 + du0, e1 + du1, e2 + du2, e0_du, e0_sq, du0 * du0 + du1 * du1 + du2 * du2
