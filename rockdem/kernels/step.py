"""One explicit central-difference step and the per-chunk time loop (DESIGN §2).

Step n, at time t_n = n dt, in a fixed order:
  1. rotations from quaternions; contact detection when any block may have moved half the
     tracking tolerance since the last one;
  2. forces at x_n: gravity and body loads, sub-contact springs (joint law) and SP dashpots on
     the relative velocities of the last half step;
  3. velocities v_{n+1/2}: translation, and Euler's equations in the principal body frame with the
     gyroscopic term; MP damping -alpha m v (and -alpha I omega) taken at the step mid-point
     (semi-implicit, unconditionally stable in alpha); local damping for quasi-static runs;
     driven blocks take their prescribed velocity;
  4. recording of the frame t_n (energies use mid-step velocities), then positions x_{n+1} and
     quaternions by the exponential map.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .contact import coulomb_limit, normal_force, slip_dissipation, spring_energy
from .bound import contact_bound
from .detect import detect, point_in_target, update_rotations
from .layout import (
    E_BOND,
    E_DAMPING_MASS,
    E_DAMPING_STIFFNESS,
    E_ELASTIC,
    E_FRICTION,
    E_KINETIC,
    E_LOCAL_DAMPING,
    E_POTENTIAL,
    FAILED_SHEAR,
    FAILED_TENSION,
    W_BODY,
    W_DRIVEN,
    ModelArrays,
    Records,
    Scratch,
    State,
)
from .rotation import quat_integrate


@njit(cache=True)
def interpolate(times: np.ndarray, values: np.ndarray, start: int, end: int, t: float, out: np.ndarray) -> None:
    """Linear interpolation of rows start:end of a (N, 3) table at time t, holding the end values."""
    if end <= start:
        out[:] = 0.0
        return
    if t <= times[start]:
        out[:] = values[start]
        return
    if t >= times[end - 1]:
        out[:] = values[end - 1]
        return
    lo, hi = start, end - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    w = (t - times[lo]) / (times[hi] - times[lo])
    for i in range(3):
        out[i] = (1.0 - w) * values[lo, i] + w * values[hi, i]


@njit(cache=True, inline="always")
def _cross_acc(r0: float, r1: float, r2: float, f: np.ndarray, out: np.ndarray, sign: float) -> None:
    out[0] += sign * (r1 * f[2] - r2 * f[1])
    out[1] += sign * (r2 * f[0] - r0 * f[2])
    out[2] += sign * (r0 * f[1] - r1 * f[0])


@njit(cache=True)
def compute_forces(m: ModelArrays, s: State, sc: Scratch, t: float, dt: float) -> None:
    """Forces and torques on every block at the current poses (DESIGN §2, joint law of paper §3)."""
    nb = m.block_mass.shape[0]
    sc.force[:] = 0.0
    sc.torque[:] = 0.0
    interpolate(m.body_time, m.body_acceleration, 0, m.body_time.shape[0], t, sc.body_acc)
    for b in range(nb):
        r = sc.rotation[b]
        for i in range(3):
            sc.omega_world[b, i] = r[i, 0] * s.omega[b, 0] + r[i, 1] * s.omega[b, 1] + r[i, 2] * s.omega[b, 2]
        if m.block_free[b]:
            for i in range(3):
                sc.force[b, i] = m.block_mass[b] * (m.gravity[i] + sc.body_acc[i])
    elastic = 0.0
    active = 0
    e_fric = 0.0
    e_bond = 0.0
    sc.sums[2] = 0.0
    sc.sums[3] = 0.0
    sc.sums[4] = 0.0
    tmp = sc.point_tmp
    f = np.empty(3)
    for k in range(s.track_count[0]):
        p = s.track[k]
        o = m.point_block[p]
        tb = s.point_partner[p]
        tf = s.point_target_face[p]
        gap = point_in_target(m, s, sc, p, tb, tf, tmp)
        go = m.block_group[o]
        gt = m.block_group[tb]
        area = m.point_area[p]
        kna = m.mat_kn[go, gt] * area
        ksa = m.mat_ks[go, gt] * area
        un = -gap
        sh = s.point_shear[p]
        sc.dashpot_force[k, 0] = 0.0
        sc.dashpot_force[k, 1] = 0.0
        sc.dashpot_force[k, 2] = 0.0
        # A point may sit outside the face polygon by its own penetration when the partner turns
        # about the shared edge (soft joints), plus the edge tolerance.
        if tmp[3] > m.edge_tol + max(un, 0.0) or (un <= 0.0 and not s.point_bonded[p]):
            # Not in contact: the stored shear energy is lost (friction), a bond slid off breaks.
            if s.point_bonded[p]:
                e_bond += spring_energy(s.point_normal_force[p], kna)
                s.point_bonded[p] = False
                s.point_failed[p] = FAILED_SHEAR if un > 0.0 else FAILED_TENSION
            e_fric += spring_energy(math.sqrt(sh[0] ** 2 + sh[1] ** 2 + sh[2] ** 2), ksa)
            sh[:] = 0.0
            s.point_normal_force[p] = 0.0
            continue
        rt = sc.rotation[tb]
        fn_ = m.face_normal[tf]
        n0 = rt[0, 0] * fn_[0] + rt[0, 1] * fn_[1] + rt[0, 2] * fn_[2]
        n1 = rt[1, 0] * fn_[0] + rt[1, 1] * fn_[1] + rt[1, 2] * fn_[2]
        n2 = rt[2, 0] * fn_[0] + rt[2, 1] * fn_[1] + rt[2, 2] * fn_[2]
        # Contact point: midway between the point and the target plane, in world coordinates.
        c0 = rt[0, 0] * tmp[0] + rt[0, 1] * tmp[1] + rt[0, 2] * tmp[2] + s.position[tb, 0] + 0.5 * un * n0
        c1 = rt[1, 0] * tmp[0] + rt[1, 1] * tmp[1] + rt[1, 2] * tmp[2] + s.position[tb, 1] + 0.5 * un * n1
        c2 = rt[2, 0] * tmp[0] + rt[2, 1] * tmp[1] + rt[2, 2] * tmp[2] + s.position[tb, 2] + 0.5 * un * n2
        ro0, ro1, ro2 = c0 - s.position[o, 0], c1 - s.position[o, 1], c2 - s.position[o, 2]
        rt0, rt1, rt2 = c0 - s.position[tb, 0], c1 - s.position[tb, 1], c2 - s.position[tb, 2]
        wo = sc.omega_world[o]
        wt = sc.omega_world[tb]
        v0 = s.velocity[o, 0] + wo[1] * ro2 - wo[2] * ro1 - (s.velocity[tb, 0] + wt[1] * rt2 - wt[2] * rt1)
        v1 = s.velocity[o, 1] + wo[2] * ro0 - wo[0] * ro2 - (s.velocity[tb, 1] + wt[2] * rt0 - wt[0] * rt2)
        v2 = s.velocity[o, 2] + wo[0] * ro1 - wo[1] * ro0 - (s.velocity[tb, 2] + wt[0] * rt1 - wt[1] * rt0)
        vn = v0 * n0 + v1 * n1 + v2 * n2  # > 0: separating
        vs0, vs1, vs2 = v0 - vn * n0, v1 - vn * n1, v2 - vn * n2
        fn = normal_force(m.mat_kn[go, gt], area, un)
        bonded = s.point_bonded[p]
        if bonded and fn < -m.mat_tension[go, gt] * area:
            # Tension cut-off: the bond fails and the point opens.
            e_bond += spring_energy(fn, kna) + spring_energy(math.sqrt(sh[0] ** 2 + sh[1] ** 2 + sh[2] ** 2), ksa)
            s.point_bonded[p] = False
            s.point_failed[p] = FAILED_TENSION
            sh[:] = 0.0
            s.point_normal_force[p] = 0.0
            continue
        # Shear: carry the stored force into the current tangent plane, then add the increment.
        mag = math.sqrt(sh[0] ** 2 + sh[1] ** 2 + sh[2] ** 2)
        d = sh[0] * n0 + sh[1] * n1 + sh[2] * n2
        sh[0] -= d * n0
        sh[1] -= d * n1
        sh[2] -= d * n2
        mag2 = math.sqrt(sh[0] ** 2 + sh[1] ** 2 + sh[2] ** 2)
        if mag2 > 0.0:
            sh *= mag / mag2
        sh[0] -= ksa * vs0 * dt
        sh[1] -= ksa * vs1 * dt
        sh[2] -= ksa * vs2 * dt
        trial = math.sqrt(sh[0] ** 2 + sh[1] ** 2 + sh[2] ** 2)
        if bonded:
            fmax = coulomb_limit(m.mat_cohesion[go, gt], m.mat_tan_friction[go, gt], area, fn)
        else:
            fmax = coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], area, fn)
        slipping = trial > fmax
        if slipping:
            e_fric += slip_dissipation(trial, fmax, ksa)
            if bonded:
                # Shear failure: drop to the residual strength; the released energy is the bond's.
                s.point_bonded[p] = False
                s.point_failed[p] = FAILED_SHEAR
                fres = coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], area, fn)
                e_bond += spring_energy(fmax, ksa) - spring_energy(fres, ksa)
                fmax = fres
                if un <= 0.0:
                    e_bond += spring_energy(fn, kna) + spring_energy(fmax, ksa)
                    sh[:] = 0.0
                    s.point_normal_force[p] = 0.0
                    continue
            sc_ = fmax / trial if trial > 0.0 else 0.0
            sh *= sc_
        s.point_normal_force[p] = fn
        elastic += spring_energy(fn, kna) + spring_energy(min(trial, fmax), ksa)
        active += 1
        # Stiffness-proportional dashpots on the active sub-contact (paper Eq. 4, alpha = 0 part).
        # Rayleigh SP damping follows the tangent stiffness: no shear dashpot while slipping.
        beta = m.mat_beta[go, gt]
        fdn = -beta * kna * vn
        bs = 0.0 if slipping else beta * ksa
        fd = sc.dashpot_force[k]
        fd[0] = fdn * n0 - bs * vs0
        fd[1] = fdn * n1 - bs * vs1
        fd[2] = fdn * n2 - bs * vs2
        sc.dashpot_point[k, 0] = c0
        sc.dashpot_point[k, 1] = c1
        sc.dashpot_point[k, 2] = c2
        f[0] = fn * n0 + sh[0] + fd[0]
        f[1] = fn * n1 + sh[1] + fd[1]
        f[2] = fn * n2 + sh[2] + fd[2]
        for i in range(3):
            sc.force[o, i] += f[i]
            sc.force[tb, i] -= f[i]
        _cross_acc(ro0, ro1, ro2, f, sc.torque[o], 1.0)
        _cross_acc(rt0, rt1, rt2, f, sc.torque[tb], -1.0)
        if m.block_free[o] and not m.block_free[tb]:
            for i in range(3):
                sc.sums[2 + i] += f[i]
        elif m.block_free[tb] and not m.block_free[o]:
            for i in range(3):
                sc.sums[2 + i] -= f[i]
    sc.sums[0] = elastic
    sc.sums[1] = active
    s.energy[E_FRICTION] += e_fric
    s.energy[E_BOND] += e_bond


@njit(cache=True)
def integrate_velocities(
    m: ModelArrays, s: State, sc: Scratch, t: float, dt: float, rec: Records, frame: int
) -> None:
    """v_{n-1/2} -> v_{n+1/2} for every block; records frame ``frame`` (if >= 0) at t_n."""
    nb = m.block_mass.shape[0]
    alpha = m.alpha
    ha = 0.5 * alpha * dt
    vg = sc.ground_velocity
    if m.alpha_relative and m.ground_motion >= 0:
        k = m.ground_motion
        interpolate(m.motion_time, m.motion_velocity, m.motion_start[k], m.motion_start[k + 1], t, vg)
    else:
        vg[:] = 0.0
    vd = np.empty(3)
    va = np.empty(3)
    wa = np.empty(3)
    ke = 0.0
    pe = 0.0
    e_mp = 0.0
    e_loc = 0.0
    w_body = 0.0
    w_drv = 0.0
    jd = 0
    for b in range(nb):
        r = sc.rotation[b]
        if m.block_free[b]:
            mass = m.block_mass[b]
            for i in range(3):
                fi = sc.force[b, i]
                if m.local_damping > 0.0 and s.velocity[b, i] != 0.0:
                    fl = m.local_damping * abs(fi) * (1.0 if s.velocity[b, i] > 0.0 else -1.0)
                    fi -= fl
                    e_loc += abs(fl * s.velocity[b, i]) * dt
                vold = s.velocity[b, i]
                vnew = (vold * (1.0 - ha) + dt * fi * m.block_inv_mass[b] + 2.0 * ha * vg[i]) / (1.0 + ha)
                va[i] = 0.5 * (vold + vnew)
                s.velocity[b, i] = vnew
                e_mp += alpha * mass * (va[i] - vg[i]) ** 2 * dt
                w_body += mass * sc.body_acc[i] * va[i] * dt
                ke += 0.5 * mass * va[i] * va[i]
                pe -= mass * m.gravity[i] * s.position[b, i]
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
            tbs = (tb0 - g0, tb1 - g1, tb2 - g2)
            for i in range(3):
                tl = tbs[i]
                if m.local_damping > 0.0 and w[i] != 0.0:
                    fl = m.local_damping * abs(tl) * (1.0 if w[i] > 0.0 else -1.0)
                    tl -= fl
                    e_loc += abs(fl * w[i]) * dt
                wold = w[i]
                wnew = (wold * (1.0 - ha) + dt * tl * m.block_inv_inertia[b, i]) / (1.0 + ha)
                wa[i] = 0.5 * (wold + wnew)
                w[i] = wnew
                e_mp += alpha * inert[i] * wa[i] * wa[i] * dt
                ke += 0.5 * inert[i] * wa[i] * wa[i]
        else:
            k = m.block_motion[b]
            if k >= 0:
                interpolate(m.motion_time, m.motion_velocity, m.motion_start[k], m.motion_start[k + 1], t + 0.5 * dt, vd)
            else:
                vd[:] = 0.0
            if frame >= 0:
                for i in range(3):
                    rec.driven_reaction[frame, jd, i] = -sc.force[b, i]
            jd += 1
            for i in range(3):
                w_drv -= sc.force[b, i] * vd[i] * dt
                s.velocity[b, i] = vd[i]
                s.omega[b, i] = 0.0
                va[i] = vd[i]
                wa[i] = 0.0
        for i in range(3):
            sc.velocity_mid[b, i] = va[i]
            sc.omega_mid[b, i] = r[i, 0] * wa[0] + r[i, 1] * wa[1] + r[i, 2] * wa[2]
        if frame >= 0:
            for i in range(3):
                rec.position[frame, b, i] = s.position[b, i]
                rec.velocity[frame, b, i] = va[i]
                rec.omega[frame, b, i] = sc.omega_mid[b, i]
            for i in range(4):
                rec.quaternion[frame, b, i] = s.quaternion[b, i]
    s.energy[E_DAMPING_MASS] += e_mp
    s.energy[E_LOCAL_DAMPING] += e_loc
    s.energy[W_BODY] += w_body
    s.energy[W_DRIVEN] += w_drv
    if frame >= 0:
        rec.time[frame] = t
        for i in range(s.energy.shape[0]):
            rec.energy[frame, i] = s.energy[i]
        rec.energy[frame, E_KINETIC] = ke
        rec.energy[frame, E_POTENTIAL] = pe
        rec.energy[frame, E_ELASTIC] = sc.sums[0]
        bonded = 0
        ften = 0
        fshear = 0
        for p in range(s.point_bonded.shape[0]):
            if s.point_bonded[p]:
                bonded += 1
            if s.point_failed[p] == FAILED_TENSION:
                ften += 1
            elif s.point_failed[p] == FAILED_SHEAR:
                fshear += 1
        rec.counts[frame, 0] = int(sc.sums[1])
        rec.counts[frame, 1] = bonded
        rec.counts[frame, 2] = ften
        rec.counts[frame, 3] = fshear
        for i in range(3):
            rec.reaction[frame, i] = sc.sums[2 + i]


@njit(cache=True)
def dashpot_work(m: ModelArrays, s: State, sc: Scratch, h: float) -> None:
    """Energy dissipated by the SP dashpots over the step: -F_d . v_rel(mid-step) h, the same
    velocities that change the kinetic energy, so that the energy balance closes."""
    e = 0.0
    for k in range(s.track_count[0]):
        fd = sc.dashpot_force[k]
        if fd[0] == 0.0 and fd[1] == 0.0 and fd[2] == 0.0:
            continue
        p = s.track[k]
        o = m.point_block[p]
        tb = s.point_partner[p]
        c = sc.dashpot_point[k]
        vr = np.empty(3)
        ro = c - s.position[o]
        rt = c - s.position[tb]
        wo = sc.omega_mid[o]
        wt = sc.omega_mid[tb]
        vr[0] = sc.velocity_mid[o, 0] + wo[1] * ro[2] - wo[2] * ro[1] - sc.velocity_mid[tb, 0] - wt[1] * rt[2] + wt[2] * rt[1]
        vr[1] = sc.velocity_mid[o, 1] + wo[2] * ro[0] - wo[0] * ro[2] - sc.velocity_mid[tb, 1] - wt[2] * rt[0] + wt[0] * rt[2]
        vr[2] = sc.velocity_mid[o, 2] + wo[0] * ro[1] - wo[1] * ro[0] - sc.velocity_mid[tb, 2] - wt[0] * rt[1] + wt[1] * rt[0]
        e -= (fd[0] * vr[0] + fd[1] * vr[1] + fd[2] * vr[2]) * h
    s.energy[E_DAMPING_STIFFNESS] += e


@njit(cache=True)
def integrate_positions(m: ModelArrays, s: State, dt: float) -> None:
    """x_{n+1} = x_n + v_{n+1/2} dt; quaternions by the exponential map; movement since detection."""
    for b in range(m.block_mass.shape[0]):
        v2 = 0.0
        for i in range(3):
            s.position[b, i] += s.velocity[b, i] * dt
            v2 += s.velocity[b, i] ** 2
        w = s.omega[b]
        if m.block_free[b]:
            quat_integrate(s.quaternion[b], w, dt)
        s.moved[b] += (math.sqrt(v2) + math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2) * m.block_radius[b]) * dt


@njit(cache=True)
def advance(
    m: ModelArrays, s: State, sc: Scratch, t_stop: float, record_interval: float, rec: Records, frame: int
) -> int:
    """Step until time ``t_stop`` [s], recording a frame every ``record_interval``; returns the next frame.

    ``s.clock`` holds [t, dt, dt of the previous step, safety, smallest dt used, -]. After each
    detection the bound of the tracked contacts is recomputed and dt is lowered (never raised)
    to safety times the bound, so that contacts stiffer than those at the start (a toppling block
    landing on a side face) stay stable. Velocities use the mean of the two step lengths.
    """
    bound = np.empty(3)
    while s.clock[0] < t_stop - 1e-12 * max(1.0, t_stop):
        update_rotations(m, s, sc)
        moved = 0.0
        for b in range(m.block_mass.shape[0]):
            moved = max(moved, s.moved[b])
        if 2.0 * moved >= m.contact_tol:
            detect(m, s, sc)
            contact_bound(m, s, sc, bound)
            safe = s.clock[3] * bound[0]
            if safe < s.clock[1]:
                s.clock[1] = safe
                s.clock[4] = min(s.clock[4], safe)
        t = s.clock[0]
        dt = s.clock[1]
        h = 0.5 * (s.clock[2] + dt)
        compute_forces(m, s, sc, t, s.clock[2])
        now = -1
        if frame < rec.time.shape[0] and t >= frame * record_interval - 0.5 * dt:
            now = frame
        integrate_velocities(m, s, sc, t, h, rec, now)
        dashpot_work(m, s, sc, h)
        if now >= 0:
            frame += 1
        integrate_positions(m, s, dt)
        s.clock[2] = dt
        s.clock[0] = t + dt
        s.step[0] += 1
    return frame
