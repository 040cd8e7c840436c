"""One explicit central-difference step and the per-chunk time loop (DESIGN: engine).

Step n, at time t_n = n dt, in a fixed order:
  1. rotations from quaternions; the step lowered (never raised) if a block is so fast that its
     points would move more than KINEMATIC_SHARE of the tracking tolerance in one; contact
     detection when any block may have moved half the tracking tolerance since the last one by
     the end of this step, or an edge-edge pair would now be classified otherwise
     (:func:`rockdem.kernels.detect.edge_pairs_changed`);
  2. forces at x_n: gravity and body loads, sub-contacts of face pairs and point contacts of edge
     pairs (joint law of paper §3, :mod:`rockdem.kernels.contact`) and SP dashpots on the relative
     velocities of the last half step;
  3. velocities v_{n+1/2}: translation, and Euler's equations in the principal body frame with the
     gyroscopic term; MP damping -alpha m v (and -alpha I omega) taken at the step mid-point
     (semi-implicit, unconditionally stable in alpha); local damping for quasi-static runs;
     driven blocks take their prescribed velocity;
  4. recording of the frame t_n (energies use mid-step velocities) with the divergence and
     lost-block checks, then positions x_{n+1} and quaternions by the exponential map.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .bound import contact_bound
from .detect import detect, edge_pairs_changed, update_rotations
from .forces import compute_forces, compute_forces_parallel
from .implicit import couple, driven_dashpot_forces, factor_block, finalize, has_dashpots, mark_damped, solve_block, sweep
from .layout import (
    DASHPOTS_EXPLICIT,
    DASHPOTS_IMPLICIT,
    E_DAMPING_MASS,
    E_DAMPING_STIFFNESS,
    E_ELASTIC,
    E_KINETIC,
    E_LOCAL_DAMPING,
    E_POTENTIAL,
    FAILED_SHEAR,
    FAILED_TENSION,
    PAIR_EDGE,
    SLOTS,
    STATUS_DIVERGED,
    STATUS_DONE,
    STATUS_GROW,
    STATUS_LOST,
    W_BODY,
    W_DRIVEN,
    ModelArrays,
    Records,
    Scratch,
    State,
)
from .rotation import quat_integrate, quat_integrate_xyz
from .series import interpolate
from .variants import rebind

DIVERGENCE_ERROR = 0.2
"""Energy-balance error, as a fraction of the run's energy scale so far, that marks a divergence."""


@njit(cache=True, _nrt=False, inline="always")
def _free_energies(
    m: ModelArrays, s: State, sc: Scratch, b: int, vg: np.ndarray, wa0: float, wa1: float, wa2: float, dt: float
) -> tuple[float, float, float, float]:
    """(MP dissipation over the step, work of the body loads, kinetic energy, potential energy) [J]
    of free block b from its mid-step velocity ``sc.velocity_mid[b]`` and body-frame angular
    velocity wa."""
    mass = m.block_mass[b]
    va = sc.velocity_mid[b]
    inert = m.block_inertia[b]
    e_mp = 0.0
    w_body = 0.0
    ke = 0.0
    pe = 0.0
    for i in range(3):
        e_mp += m.alpha * mass * (va[i] - vg[i]) ** 2 * dt
        w_body += mass * sc.body_acc[i] * va[i] * dt
        ke += 0.5 * mass * va[i] * va[i]
        pe -= mass * m.gravity[i] * s.position[b, i]
    rot = inert[0] * wa0 * wa0 + inert[1] * wa1 * wa1 + inert[2] * wa2 * wa2
    e_mp += m.alpha * rot * dt
    ke += 0.5 * rot
    r = sc.rotation[b]
    for i in range(3):
        sc.omega_mid[b, i] = r[i, 0] * wa0 + r[i, 1] * wa1 + r[i, 2] * wa2
    return e_mp, w_body, ke, pe


@njit(cache=True, _nrt=False, inline="always")
def _record_pose(
    s: State, sc: Scratch, rec: Records, frame: int, b: int, tau: float, h: float, w_old: float, w_new: float
) -> None:
    """Record block b's pose and velocities at the frame time t_n + tau (|tau| <= half a step) on the
    leapfrog trajectory: x = x_n + tau v (v the half-step velocity on tau's side, the path the scheme
    itself takes between t_n and t_n +- one step), q the exponential map of tau omega; velocities
    from their values at t_n (``sc.velocity_mid``, ``sc.omega_mid``) plus tau times the step's
    acceleration (v_{n+1/2} - v_{n-1/2}) / h. v_{n-1/2} is recovered from the value at t_n, the
    interpolation of the two half-step velocities with weights w_old, w_new."""
    r = sc.rotation[b]
    wn = s.omega[b]
    wm = sc.omega_mid[b]
    q = rec.quaternion[frame, b]
    for i in range(4):
        q[i] = s.quaternion[b, i]
    if tau == 0.0:
        for i in range(3):
            rec.position[frame, b, i] = s.position[b, i]
            rec.velocity[frame, b, i] = sc.velocity_mid[b, i]
            rec.omega[frame, b, i] = wm[i]
        return
    for i in range(3):
        vn = s.velocity[b, i]
        vo = (sc.velocity_mid[b, i] - w_new * vn) / w_old
        rec.position[frame, b, i] = s.position[b, i] + tau * (vn if tau > 0.0 else vo)
        rec.velocity[frame, b, i] = sc.velocity_mid[b, i] + tau * (vn - vo) / h
    # Angular velocity at t_n in the body frame, and that of the last half step recovered from it.
    wb0 = r[0, 0] * wm[0] + r[1, 0] * wm[1] + r[2, 0] * wm[2]
    wb1 = r[0, 1] * wm[0] + r[1, 1] * wm[1] + r[2, 1] * wm[2]
    wb2 = r[0, 2] * wm[0] + r[1, 2] * wm[1] + r[2, 2] * wm[2]
    wo0, wo1, wo2 = (wb0 - w_new * wn[0]) / w_old, (wb1 - w_new * wn[1]) / w_old, (wb2 - w_new * wn[2]) / w_old
    if tau > 0.0:
        quat_integrate_xyz(q, wn[0], wn[1], wn[2], tau)
    else:
        quat_integrate_xyz(q, wo0, wo1, wo2, tau)
    d0, d1, d2 = wn[0] - wo0, wn[1] - wo1, wn[2] - wo2
    for i in range(3):
        rec.omega[frame, b, i] = wm[i] + tau * (r[i, 0] * d0 + r[i, 1] * d1 + r[i, 2] * d2) / h


@njit(cache=True, _nrt=False)
def integrate_velocities(
    m: ModelArrays, s: State, sc: Scratch, t: float, dt: float, rec: Records, frame: int, frame_end: int,
    step: float, interval: float,
) -> None:
    """v_{n-1/2} -> v_{n+1/2} for every block over ``dt`` [s] (``State.velocity_lag`` plus half the
    next step: the mean of the last and the next step, half the next at a fresh start); records
    frames ``frame`` to ``frame_end`` - 1 (none if equal), frame k at its time k ``interval`` [s]
    within half a step of t_n (several when the step exceeds the interval).

    Driven blocks first take their prescribed velocity at the middle of the next position step
    ``step`` [s]. A free block with an active
    dashpot under implicit dashpots (``State.dashpots``) solves its 6 x 6 velocity equations
    (:mod:`rockdem.kernels.implicit`, block-Jacobi sweeps where dashpots join free blocks); the
    others take the explicit update with MP damping at the step mid-point.
    """
    nb = m.block_mass.shape[0]
    alpha = m.alpha
    ha = 0.5 * alpha * dt
    vg = sc.ground_velocity
    if m.alpha_relative and m.ground_motion >= 0:
        k = m.ground_motion
        interpolate(m.motion_time, m.motion_velocity, m.motion_start[k], m.motion_start[k + 1], t, vg)
    else:
        vg[:] = 0.0
    vd = sc.driven_velocity
    moving = False  # a driven block has a motion: only such blocks do work
    for b in range(nb):
        if m.block_free[b]:
            continue
        k = m.block_motion[b]
        if k >= 0:
            moving = True
            interpolate(m.motion_time, m.motion_velocity, m.motion_start[k], m.motion_start[k + 1], t + 0.5 * step, vd)
        else:
            vd[:] = 0.0
        for i in range(3):
            sc.driven_velocity_last[b, i] = s.velocity[b, i]
            s.velocity[b, i] = vd[i]
            s.omega[b, i] = 0.0
            sc.velocity_mid[b, i] = vd[i]
            sc.omega_mid[b, i] = 0.0
    # The velocity at t_n: the velocities at t_n - velocity_lag and t_n + step / 2
    # interpolated (their mean when the two steps are equal; dt is their mean).
    w_new = 1.0 - 0.5 * step / dt
    w_old = 1.0 - w_new
    implicit = s.dashpots[0] == DASHPOTS_IMPLICIT and has_dashpots(m)
    coupled = False
    it = sc.block_iterate[0]
    if implicit:
        coupled = mark_damped(m, s, sc)
        for b in range(nb):
            if sc.block_damped[b]:
                for i in range(3):
                    it[b, i] = s.velocity[b, i]
                    it[b, 3 + i] = s.omega[b, i]
        couple(m, s, sc, it)
    e_mp = 0.0
    e_loc = 0.0
    w_body = 0.0
    ke = 0.0
    pe = 0.0
    for b in range(nb):
        if not m.block_free[b]:
            continue
        r = sc.rotation[b]
        damped = implicit and sc.block_damped[b]
        mass = m.block_mass[b]
        va = sc.velocity_mid[b]
        for i in range(3):
            fi = sc.force[b, i]
            if m.local_damping > 0.0 and s.velocity[b, i] != 0.0:
                fl = m.local_damping * abs(fi) * (1.0 if s.velocity[b, i] > 0.0 else -1.0)
                fi -= fl
                e_loc += abs(fl * s.velocity[b, i]) * dt
            vold = s.velocity[b, i]
            if damped:
                sc.block_rhs[b, i] = mass * (vold * (1.0 - ha) + 2.0 * ha * vg[i]) + dt * fi
            else:
                vnew = (vold * (1.0 - ha) + dt * fi * m.block_inv_mass[b] + 2.0 * ha * vg[i]) / (1.0 + ha)
                va[i] = w_old * vold + w_new * vnew
                s.velocity[b, i] = vnew
        # Euler's equations in the principal body frame.
        tq = sc.torque[b]
        tb0 = r[0, 0] * tq[0] + r[1, 0] * tq[1] + r[2, 0] * tq[2]
        tb1 = r[0, 1] * tq[0] + r[1, 1] * tq[1] + r[2, 1] * tq[2]
        tb2 = r[0, 2] * tq[0] + r[1, 2] * tq[1] + r[2, 2] * tq[2]
        w = s.omega[b]
        inert = m.block_inertia[b]
        g0 = w[1] * inert[2] * w[2] - w[2] * inert[1] * w[1]
        g1 = w[2] * inert[0] * w[0] - w[0] * inert[2] * w[2]
        g2 = w[0] * inert[1] * w[1] - w[1] * inert[0] * w[0]
        wa0 = wa1 = wa2 = 0.0
        for i in range(3):
            tl = (tb0 - g0) if i == 0 else ((tb1 - g1) if i == 1 else (tb2 - g2))
            if m.local_damping > 0.0 and w[i] != 0.0:
                fl = m.local_damping * abs(tl) * (1.0 if w[i] > 0.0 else -1.0)
                tl -= fl
                e_loc += abs(fl * w[i]) * dt
            wold = w[i]
            if damped:
                sc.block_rhs[b, 3 + i] = inert[i] * wold * (1.0 - ha) + dt * tl
                continue
            wnew = (wold * (1.0 - ha) + dt * tl * m.block_inv_inertia[b, i]) / (1.0 + ha)
            wai = w_old * wold + w_new * wnew
            w[i] = wnew
            if i == 0:
                wa0 = wai
            elif i == 1:
                wa1 = wai
            else:
                wa2 = wai
        if damped:
            factor_block(m, sc, b, dt, ha)
            solve_block(sc, b, dt, it)
            continue
        e1, e2, e3, e4 = _free_energies(m, s, sc, b, vg, wa0, wa1, wa2, dt)
        e_mp += e1
        w_body += e2
        ke += e3
        pe += e4
    if coupled:
        sweep(m, s, sc, dt, dt * math.sqrt(m.gravity[0] ** 2 + m.gravity[1] ** 2 + m.gravity[2] ** 2))
    if implicit:
        for b in range(nb):
            if not sc.block_damped[b]:
                continue
            for i in range(3):
                sc.velocity_mid[b, i] = w_old * s.velocity[b, i] + w_new * it[b, i]
                s.velocity[b, i] = it[b, i]
            wa0 = w_old * s.omega[b, 0] + w_new * it[b, 3]
            wa1 = w_old * s.omega[b, 1] + w_new * it[b, 4]
            wa2 = w_old * s.omega[b, 2] + w_new * it[b, 5]
            for i in range(3):
                s.omega[b, i] = it[b, 3 + i]
            e1, e2, e3, e4 = _free_energies(m, s, sc, b, vg, wa0, wa1, wa2, dt)
            e_mp += e1
            w_body += e2
            ke += e3
            pe += e4
        s.energy[E_DAMPING_STIFFNESS] += finalize(m, s, sc, dt)
    dashpots = moving and has_dashpots(m)  # (a fixed block's force does no work: its split is not needed)
    if dashpots:
        driven_dashpot_forces(m, s, sc)
    w_drv = 0.0
    jd = 0
    for b in range(nb):
        if not m.block_free[b]:
            for f in range(frame, frame_end):
                for i in range(3):
                    rec.driven_reaction[f, jd, i] = -sc.force[b, i]
            jd += 1
            # Its work up to x_n, where the elastic energy is measured: its displacement over the last
            # position step (the last velocity over 2 lag, none at a fresh start) times the mean of
            # the forces at the step's two ends (the trapezoidal rule, exact for a linear spring).
            # The work over [t - lag, t + step / 2] at the force at t ran half a step ahead of the
            # springs: a rod starting to withdraw at 10 m/s showed 0.39 J created at t, its whole
            # half step's work, and the rule's error where the force falls within the step stayed
            # (the rod released 0.27 J and booked 0.46; before 2026-11-29). Its dashpots' share is
            # booked over the velocity interval, as their dissipation counts it (implicit: its
            # displacement over [t - lag, t + step / 2], kernels.implicit.finalize; explicit: the new
            # velocity over it, dashpot_work).
            lag = dt - 0.5 * step
            for i in range(3):
                fd = sc.driven_dashpot[b, i] if dashpots else 0.0
                fs = sc.force[b, i] - fd
                w_drv -= 0.5 * (sc.driven_force_last[b, i] + fs) * sc.driven_velocity_last[b, i] * 2.0 * lag
                sc.driven_force_last[b, i] = fs
                if fd != 0.0:
                    w_drv -= fd * (sc.driven_velocity_last[b, i] * lag + s.velocity[b, i] * 0.5 * step if implicit else s.velocity[b, i] * dt)
        for f in range(frame, frame_end):
            _record_pose(s, sc, rec, f, b, f * interval - t, dt, w_old, w_new)
    s.energy[E_DAMPING_MASS] += e_mp
    s.energy[E_LOCAL_DAMPING] += e_loc
    s.energy[W_BODY] += w_body
    s.energy[W_DRIVEN] += w_drv
    for f in range(frame, frame_end):
        rec.time[f] = f * interval
        for i in range(s.energy.shape[0]):
            rec.energy[f, i] = s.energy[i]
        rec.energy[f, E_KINETIC] = ke
        rec.energy[f, E_POTENTIAL] = pe
        rec.energy[f, E_ELASTIC] = sc.elastic_energy[0]
        _record_counts(s, sc, rec, f)


@njit(cache=True, _nrt=False)
def _record_counts(s: State, sc: Scratch, rec: Records, frame: int) -> None:
    bonded = 0
    ften = 0
    fshear = 0
    for p in range(s.point_failed.shape[0]):
        for k in range(SLOTS):
            if s.slot_bonded[p, k]:
                bonded += 1
        if s.point_failed[p] == FAILED_TENSION:
            ften += 1
        elif s.point_failed[p] == FAILED_SHEAR:
            fshear += 1
    rec.counts[frame, 0] = sc.active_count[0]
    rec.counts[frame, 1] = bonded
    rec.counts[frame, 2] = ften
    rec.counts[frame, 3] = fshear
    for i in range(3):
        rec.reaction[frame, i] = sc.reaction[i]


@njit(cache=True, _nrt=False, inline="always")
def _dashpot_power(s: State, sc: Scratch, o: int, t: int, fd: np.ndarray, c: np.ndarray) -> float:
    """-F_d . v_rel at the step mid-point velocities (the same that change the kinetic energy)."""
    wo = sc.omega_mid[o]
    wt = sc.omega_mid[t]
    r0, r1, r2 = c[0] - s.position[o, 0], c[1] - s.position[o, 1], c[2] - s.position[o, 2]
    q0, q1, q2 = c[0] - s.position[t, 0], c[1] - s.position[t, 1], c[2] - s.position[t, 2]
    v0 = sc.velocity_mid[o, 0] + wo[1] * r2 - wo[2] * r1 - sc.velocity_mid[t, 0] - wt[1] * q2 + wt[2] * q1
    v1 = sc.velocity_mid[o, 1] + wo[2] * r0 - wo[0] * r2 - sc.velocity_mid[t, 1] - wt[2] * q0 + wt[0] * q2
    v2 = sc.velocity_mid[o, 2] + wo[0] * r1 - wo[1] * r0 - sc.velocity_mid[t, 2] - wt[0] * q1 + wt[1] * q0
    return -(fd[0] * v0 + fd[1] * v1 + fd[2] * v2)


@njit(cache=True, _nrt=False)
def dashpot_work(m: ModelArrays, s: State, sc: Scratch, h: float) -> None:
    """Energy dissipated by the SP dashpots over the step: -F_d . v_rel(mid-step) h, the same
    velocities that change the kinetic energy, so that the energy balance closes."""
    e = 0.0
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            fd = sc.pair_dashpot_force[i]
            if fd[0] != 0.0 or fd[1] != 0.0 or fd[2] != 0.0:
                e += _dashpot_power(s, sc, s.pair_a[i], s.pair_b[i], fd, sc.pair_point[i]) * h
            continue
        a = m.face_block[s.pair_owner_face[i]]
        b = m.face_block[s.pair_target_face[i]]
        split = s.pair_track_split[i]
        for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
            fd = sc.dashpot_force[k]
            if fd[0] == 0.0 and fd[1] == 0.0 and fd[2] == 0.0:
                continue
            if k < split:
                e += _dashpot_power(s, sc, a, b, fd, sc.contact_point[k]) * h
            else:  # the target face's points (kernels.blend): the force acts on the target's block
                e += _dashpot_power(s, sc, b, a, fd, sc.contact_point[k]) * h
    s.energy[E_DAMPING_STIFFNESS] += e


KINEMATIC_SHARE = 0.25
"""Largest share of the tracking tolerance that a block's fastest point may move in one step
(:func:`advance`): a contact is tracked, and counted in the timestep bound, before it presses."""


@njit(cache=True, _nrt=False, inline="always")
def block_speed(m: ModelArrays, s: State, b: int, c0: float = 0.0, c1: float = 0.0, c2: float = 0.0) -> float:
    """Upper bound [m/s] of the speed of block b's points relative to a frame translating at c
    [m/s]: |v - c| + |omega| r (r its bounding radius)."""
    w = s.omega[b]
    return (math.sqrt((s.velocity[b, 0] - c0) ** 2 + (s.velocity[b, 1] - c1) ** 2 + (s.velocity[b, 2] - c2) ** 2)
            + math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2) * m.block_radius[b])


@njit(cache=True, _nrt=False, inline="always")
def _next_velocity(m: ModelArrays, s: State, sc: Scratch, b: int, t: float) -> tuple[float, float, float]:
    """Velocity [m/s] of block b over the next position step: its own, or for a driven block with a
    prescribed motion that motion's at ``t`` (the next step's middle)."""
    k = m.block_motion[b]
    if m.block_free[b] or k < 0:
        return s.velocity[b, 0], s.velocity[b, 1], s.velocity[b, 2]
    v = sc.driven_velocity
    interpolate(m.motion_time, m.motion_velocity, m.motion_start[k], m.motion_start[k + 1], t, v)
    return v[0], v[1], v[2]


@njit(cache=True, _nrt=False)
def kinematic_step(m: ModelArrays, s: State, sc: Scratch, t: float) -> float:
    """The longest step [s] in which no block's points move, relative to the others, by more than
    KINEMATIC_SHARE of the tracking tolerance: speeds |v - c| + |omega| r, c the mid-range of the
    blocks' velocities (a common translation, the ground's under an earthquake, moves no block
    relative to another); +inf when nothing moves. A driven block counts with the velocity its
    motion prescribes for the next step (at ``t`` [s], its middle at the present step): a rod that
    starts withdrawing at 10 m/s moved 6 mm in its first step, 8 times its contact's overlap, and
    that contact's release booked 4.8 J of work where its spring held 0.27 J."""
    nb = m.block_mass.shape[0]
    lo0 = lo1 = lo2 = np.inf
    hi0 = hi1 = hi2 = -np.inf
    for b in range(nb):
        if s.fell_off[b] < 0.0:
            v0, v1, v2 = _next_velocity(m, s, sc, b, t)
            lo0, hi0 = min(lo0, v0), max(hi0, v0)
            lo1, hi1 = min(lo1, v1), max(hi1, v1)
            lo2, hi2 = min(lo2, v2), max(hi2, v2)
    c0, c1, c2 = 0.5 * (lo0 + hi0), 0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2)
    speed = 0.0
    for b in range(nb):
        if s.fell_off[b] < 0.0:
            speed = max(speed, block_speed(m, s, b, c0, c1, c2))
            if not m.block_free[b] and m.block_motion[b] >= 0:  # (a driven block does not rotate)
                v0, v1, v2 = _next_velocity(m, s, sc, b, t)
                speed = max(speed, math.sqrt((v0 - c0) ** 2 + (v1 - c1) ** 2 + (v2 - c2) ** 2))
    return KINEMATIC_SHARE * m.contact_tol / speed if speed > 0.0 else np.inf


@njit(cache=True, _nrt=False)
def integrate_positions(m: ModelArrays, s: State, dt: float) -> None:
    """x_{n+1} = x_n + v_{n+1/2} dt; quaternions by the exponential map; movement since detection."""
    for b in range(m.block_mass.shape[0]):
        for i in range(3):
            s.position[b, i] += s.velocity[b, i] * dt
        if m.block_free[b]:
            quat_integrate(s.quaternion[b], s.omega[b], dt)
        s.moved[b] += block_speed(m, s, b) * dt


@njit(cache=True, _nrt=False, inline="always")
def _driven_shift(m: ModelArrays, s: State, rec: Records, i: int) -> tuple[float, float]:
    """(lowest, highest) displacement [m] along axis i of the driven blocks since the first
    recorded frame, 0 where none moved that way."""
    lo = 0.0
    hi = 0.0
    for b in range(m.block_mass.shape[0]):
        if not m.block_free[b]:
            d = s.position[b, i] - rec.position[0, b, i]
            lo = min(lo, d)
            hi = max(hi, d)
    return lo, hi


@njit(cache=True, _nrt=False)
def _under_a_support(m: ModelArrays, s: State, sc: Scratch, x: float, y: float) -> bool:
    """Whether the plan point (x, y) [m] lies within the current plan (x, y bounding box of its
    vertices) of a driven block."""
    for b in range(m.block_mass.shape[0]):
        if m.block_free[b]:
            continue
        r = sc.rotation[b]
        x0 = y0 = np.inf
        x1 = y1 = -np.inf
        for v in range(m.block_vertex_start[b], m.block_vertex_start[b + 1]):
            p = m.vertex_local[v]
            wx = s.position[b, 0] + r[0, 0] * p[0] + r[0, 1] * p[1] + r[0, 2] * p[2]
            wy = s.position[b, 1] + r[1, 0] * p[0] + r[1, 1] * p[1] + r[1, 2] * p[2]
            x0, x1, y0, y1 = min(x0, wx), max(x1, wx), min(y0, wy), max(y1, wy)
        if x0 <= x <= x1 and y0 <= y <= y1:
            return True
    return False


@njit(cache=True, _nrt=False)
def _support_bottom(m: ModelArrays, s: State, sc: Scratch) -> float:
    """Height [m] of the lowest vertex of the driven blocks now (-inf without driven blocks)."""
    bottom = np.inf
    for b in range(m.block_mass.shape[0]):
        if m.block_free[b]:
            continue
        r = sc.rotation[b]
        for v in range(m.block_vertex_start[b], m.block_vertex_start[b + 1]):
            p = m.vertex_local[v]
            bottom = min(bottom, s.position[b, 2] + r[2, 0] * p[0] + r[2, 1] * p[1] + r[2, 2] * p[2])
    return bottom if bottom < np.inf else -np.inf


@njit(cache=True, _nrt=False)
def check_frame(m: ModelArrays, s: State, sc: Scratch, rec: Records, frame: int) -> int:
    """Status of recorded frame ``frame``: STATUS_DIVERGED when the state is not finite or energy
    was created: the mechanical energy (kinetic + potential + elastic) exceeds its initial value
    plus the work done on the model by more than DIVERGENCE_ERROR of the energy scale reached so far
    (kinetic + elastic + |potential change| + dissipated + |work|, at least the work of lifting the
    free blocks by 1 mm); STATUS_LOST when a free block's centroid left the model's extent through
    its bottom under a driven block's current plan (it fell through its support) or
    through its top (it flew away); else STATUS_DONE (the extent moves with the driven blocks).
    ``sc.lost_block`` names the block (-1 for an energy divergence). A block leaving the extent
    through its bottom beside the driven blocks' current plans, or through a side (thrown clear of the
    supports, it is falling), has left the supports: its time is noted in ``s.fell_off`` and it
    falls on unhindered, no longer checked. So has one whose centroid is below every driven block
    and beside their current plans, as soon as it is: a support that moves back over its plan later
    (a ground motion) must not read as one it fell through. (A dissipation term booked in excess
    shows in the recorded balance error but is not a divergence.)"""
    e = rec.energy[frame]
    e0 = rec.energy[0]
    scale = 0.0
    for k in range(e.shape[0]):
        if k == E_POTENTIAL:
            scale += abs(e[k] - e0[k])
        elif k != E_KINETIC and k != E_ELASTIC:
            scale += abs(e[k])
    scale += e[E_KINETIC] + e[E_ELASTIC]
    sc.energy_scale[0] = max(sc.energy_scale[0], scale)
    mech = e[E_KINETIC] + e[E_POTENTIAL] + e[E_ELASTIC] - (e0[E_KINETIC] + e0[E_POTENTIAL] + e0[E_ELASTIC])
    err = mech - (e[W_DRIVEN] + e[W_BODY] - e0[W_DRIVEN] - e0[W_BODY])
    sc.lost_block[0] = -1
    if not (math.isfinite(err) and err <= DIVERGENCE_ERROR * sc.energy_scale[0]):
        return STATUS_DIVERGED
    # The extent (and the quick test of the footprint below) moves with the driven blocks (a
    # foundation under a ground motion carries the blocks on it): widened by their displacement
    # since the first frame.
    lx, hx = _driven_shift(m, s, rec, 0)
    ly, hy = _driven_shift(m, s, rec, 1)
    lz, hz = _driven_shift(m, s, rec, 2)
    bottom = _support_bottom(m, s, sc)
    for b in range(m.block_mass.shape[0]):
        if not m.block_free[b] or s.fell_off[b] >= 0.0:
            continue
        x, y, z = s.position[b, 0], s.position[b, 1], s.position[b, 2]
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z)):
            sc.lost_block[0] = b
            return STATUS_DIVERGED
        if z < bottom and not _under_a_support(m, s, sc, x, y):  # below and beside the supports: it left them
            s.fell_off[b] = rec.time[frame]
            continue
        high = z > m.extent_high[2] + hz
        outside = (high or z < m.extent_low[2] + lz or x < m.extent_low[0] + lx or x > m.extent_high[0] + hx
                   or y < m.extent_low[1] + ly or y > m.extent_high[1] + hy)
        if outside:
            # Under a driven block where it is now: the footprint at the start widened by the
            # driven blocks' displacement is only a quick test (a foundation displaced by +d still
            # covered its old trailing edge there: a brick that fell just past that edge, 17 m
            # below, read as fallen through it, and the run stopped; parapet_pacoima_x2_strong).
            on_support = (m.support_low[0] + lx <= x <= m.support_high[0] + hx
                          and m.support_low[1] + ly <= y <= m.support_high[1] + hy) and _under_a_support(m, s, sc, x, y)
            if not high and not on_support:  # below the top, beside the supports: it left them
                s.fell_off[b] = rec.time[frame]
                continue
            sc.lost_block[0] = b
            return STATUS_LOST
    return STATUS_DONE


IMPACT_SHARE = 0.03
"""No impact window opens while the windows so far cover more than this share of the simulated
time: isolated impacts (a block rocking under an earthquake: 1 to 2 % of the time in windows) are
refined; in a collapse whose debris impacts one another without pause the refinement would buy
nothing for its cost (a weak parapet under El Centro x3: 3.2 times the steps), which the share
bounds to 1 + 0.03 (refinement - 1) = 1.15 times."""

IMPACT_AFTER = 2.0
"""An impact window closes this many windows (``State.impact_window``, one period of the stiffest
contact) after the predicted touch: the impact itself lasts longer than half that period, its
frequency being below the bound omega_max (the undamped 0.5 x 0.8 m block with 2 points lost
-0.12 % of its kinetic energy at its impact with one window after the touch, -0.014 % with 1.5 to 4)."""


IMPACT_TAIL = 0.5
"""An open impact window lasts at least this many windows past a force pass that found an impact
still going on (``Scratch.impacting``: a pressed unbonded sub-contact moving faster than the
impact speed at more than the impact's depth, forces._law_range): it closes when the impact has
ended, not while a face landing flat still presses. The step grows from the refined one to the
coarse one only then: growing it under load made an undamped cube bouncing flat gain 0.023 to
0.18 % of its drop energy per bounce (2 x 2 to 5 x 5 points)."""

IMPACT_LONGEST = 6.0
"""A window lasts at most this many windows after its predicted touch, however long its impacts
go on (a ringing stack, debris rolling on debris): the budget :data:`IMPACT_SHARE` bounds the
windows that open, this bounds how long each lasts."""


@njit(cache=True, _nrt=False)
def advance(
    m: ModelArrays, s: State, sc: Scratch, t_stop: float, record_interval: float, rec: Records, frame: int
) -> tuple[int, int]:
    """Step until time ``t_stop`` [s], recording a frame every ``record_interval``.

    Returns (next frame, status). The loop stops early with STATUS_GROW when a detection found
    its buffers too small (nothing was stepped since), or with STATUS_DIVERGED / STATUS_LOST after
    recording the first bad frame (see :func:`check_frame`). After each detection the bound of the
    tracked contacts is recomputed and dt is lowered (never raised) to (2 / omega_max)
    min(safety f_SP, resolution) (:mod:`rockdem.timestep`), so that contacts stiffer than those at
    the start (a toppling block landing on a side face) stay stable and resolved. It is also
    lowered while a block moves fast (:data:`KINEMATIC_SHARE`), and detection looks one step
    ahead, so that such a contact is tracked and bounded before it presses: without it, a
    0.25 x 1.25 m block toppling at 3.57e-4 s steps landed on its face 0.7 mm deep at the first
    step and lost 7 % of its kinetic energy unbooked (collapse_scenarios.topple_near_edge).
    Velocities use the mean of the two step lengths. Inside an impact window the step is
    ``s.dt_coarse`` (the step the rules above lower) divided by ``s.refinement``: a window opens (or
    lasts longer) when the force pass predicts an impact (``sc.touch_time``, forces._law_range)
    within ``s.impact_window`` while the windows so far (``s.refined_time``) cover at most the share
    :data:`IMPACT_SHARE` of the time, and closes :data:`IMPACT_AFTER` windows after the predicted
    touch, or later while the impact goes on (:data:`IMPACT_TAIL`, at most :data:`IMPACT_LONGEST`
    windows after the touch; :func:`rockdem.timestep.impact_windows`).
    """
    while s.time[0] < t_stop - 1e-12 * max(1.0, t_stop):
        update_rotations(m, s, sc)
        # Detect when any block may have moved half the tolerance by the end of this step (two
        # blocks then closed it at most): every contact is tracked before it presses, and the
        # timestep bound counts it before the impact.
        moved = 0.0
        speed = 0.0
        for b in range(m.block_mass.shape[0]):
            if s.fell_off[b] < 0.0:  # blocks that fell off the edge meet nothing more
                moved = max(moved, s.moved[b])
                speed = max(speed, block_speed(m, s, b))
        # The step is lowered (never raised) to the kinematic limit: a step shortened only while a
        # block is fast changes at every step, and the leapfrog then books the impacts' dashpot
        # work wrongly (a façade toppling with SP damping: balance 4.9 % against 2.3 %) and a
        # continuous cap created 10 % of the two-block wall's energy scale under Nahanni.
        dt_kin = kinematic_step(m, s, sc, s.time[0] + 0.5 * s.dt[0])
        if dt_kin < s.dt_coarse[0]:
            s.dt_coarse[0] = dt_kin
        dt = s.dt_coarse[0]
        if 2.0 * (moved + speed * dt) >= m.contact_tol or edge_pairs_changed(m, s, sc):
            detect(m, s, sc)
            if sc.overflow[0] > 0:
                for b in range(m.block_mass.shape[0]):
                    s.moved[b] = m.contact_tol  # detect again once the buffers are enlarged
                return frame, STATUS_GROW
            dt_crit, omega, _ = contact_bound(m, s, sc, s.dashpots[0] == DASHPOTS_EXPLICIT)
            safe = min(s.safety[0] * dt_crit, s.resolution[0] * 2.0 / omega) if omega > 0.0 else np.inf
            if safe < s.dt_coarse[0]:
                s.dt_coarse[0] = safe
        t = s.time[0]
        # Inside an impact window (opened by the last force pass) the step is refined.
        dt = s.dt_coarse[0]
        if t < s.refine_until[0]:
            dt /= s.refinement[0]
            s.refined_time[0] += dt
        s.dt[0] = dt
        s.dt_min[0] = min(s.dt_min[0], dt)
        # Frames whose time is nearest to this step (k interval <= t + dt / 2, not yet recorded).
        end = frame
        while end < rec.time.shape[0] and end * record_interval <= t + 0.5 * dt:
            end += 1
        # The velocity update's interval [t - lag, t + dt/2]: lag = dt_prev / 2 (the leapfrog's
        # half-step velocities), 0 at a fresh start, whose velocities are those at t = 0 (so the
        # first update is v0 + a dt / 2: with dt, every trajectory from rest ran half a step early).
        lag = s.velocity_lag[0]
        h = lag + 0.5 * dt
        # Body loads at the middle of that interval (t itself unless the step was just lowered).
        compute_forces(m, s, sc, t + 0.5 * (0.5 * dt - lag), s.dt_prev[0])
        if sc.touch_time[0] < s.impact_window[0] and s.refined_time[0] <= IMPACT_SHARE * t:
            # An impact within the window ahead: refine from the next step until IMPACT_AFTER
            # windows past it, while the windows' share of the time so far is within the budget.
            s.refine_until[0] = max(s.refine_until[0], t + sc.touch_time[0] + IMPACT_AFTER * s.impact_window[0])
            s.refine_limit[0] = max(s.refine_limit[0], t + sc.touch_time[0] + IMPACT_LONGEST * s.impact_window[0])
        if t < s.refine_until[0] and sc.impacting[0]:
            # Inside a window, an impact still going on: the window lasts until IMPACT_TAIL windows
            # past its end, up to IMPACT_LONGEST windows after its touch (a window opened within
            # the budget is completed, not cut by it).
            s.refine_until[0] = max(s.refine_until[0], min(t + IMPACT_TAIL * s.impact_window[0], s.refine_limit[0]))
        integrate_velocities(m, s, sc, t, h, rec, frame, end, dt, record_interval)
        if s.dashpots[0] == DASHPOTS_EXPLICIT and has_dashpots(m):
            dashpot_work(m, s, sc, h)
        integrate_positions(m, s, dt)
        s.dt_prev[0] = dt
        s.velocity_lag[0] = 0.5 * dt
        s.time[0] = t + dt
        s.step[0] += 1
        s.slot_updates[0] += s.track_count[0]
        if end > frame:
            frame = end
            status = check_frame(m, s, sc, rec, end - 1)
            if status != STATUS_DONE:
                return frame, status
    return frame, STATUS_DONE


advance_parallel = njit(cache=True, _nrt=False)(rebind(getattr(advance, "py_func", advance), "advance_parallel", compute_forces=compute_forces_parallel))
"""(m, s, sc, t_stop, record_interval, rec, frame) -> (frame, status): :func:`advance` with the face
pairs' joint law on Numba's threads (:func:`rockdem.kernels.forces.compute_forces_parallel`): the
same answer bit for bit on any number of threads. Compiled on first use only (a one-thread run
never pays for it)."""
