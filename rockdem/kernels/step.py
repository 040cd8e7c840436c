"""One explicit central-difference step and the per-chunk time loop (DESIGN: engine).

Step n, at time t_n = n dt, in a fixed order:
  1. rotations from quaternions; contact detection when any block may have moved half the
     tracking tolerance since the last one;
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
from .contact import (
    coulomb_limit,
    drop_dissipation,
    ramp_overlap,
    release_shear,
    shear_increment,
    slip_dissipation,
    spring_energy,
)
from .detect import detect, update_rotations
from .faces import cover, face_map
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
from .polygon import segment_closest
from .rotation import quat_integrate

DIVERGENCE_ERROR = 0.2
"""Energy-balance error, as a fraction of the run's energy scale so far, that marks a divergence."""


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
def _apply(m: ModelArrays, s: State, sc: Scratch, o: int, t: int, f0: float, f1: float, f2: float, c0: float, c1: float, c2: float) -> None:
    """Force f on block o and -f on block t, both acting at world point c."""
    r0, r1, r2 = c0 - s.position[o, 0], c1 - s.position[o, 1], c2 - s.position[o, 2]
    q0, q1, q2 = c0 - s.position[t, 0], c1 - s.position[t, 1], c2 - s.position[t, 2]
    sc.force[o, 0] += f0
    sc.force[o, 1] += f1
    sc.force[o, 2] += f2
    sc.force[t, 0] -= f0
    sc.force[t, 1] -= f1
    sc.force[t, 2] -= f2
    sc.torque[o, 0] += r1 * f2 - r2 * f1
    sc.torque[o, 1] += r2 * f0 - r0 * f2
    sc.torque[o, 2] += r0 * f1 - r1 * f0
    sc.torque[t, 0] -= q1 * f2 - q2 * f1
    sc.torque[t, 1] -= q2 * f0 - q0 * f2
    sc.torque[t, 2] -= q0 * f1 - q1 * f0
    if m.block_free[o] and not m.block_free[t]:
        sc.reaction[0] += f0
        sc.reaction[1] += f1
        sc.reaction[2] += f2
    elif m.block_free[t] and not m.block_free[o]:
        sc.reaction[0] -= f0
        sc.reaction[1] -= f1
        sc.reaction[2] -= f2


@njit(cache=True, inline="always")
def _relative_velocity(s: State, sc: Scratch, o: int, t: int, c0: float, c1: float, c2: float) -> tuple[float, float, float]:
    """Velocity of block o relative to block t at world point c (last half step)."""
    wo = sc.omega_world[o]
    wt = sc.omega_world[t]
    r0, r1, r2 = c0 - s.position[o, 0], c1 - s.position[o, 1], c2 - s.position[o, 2]
    q0, q1, q2 = c0 - s.position[t, 0], c1 - s.position[t, 1], c2 - s.position[t, 2]
    v0 = s.velocity[o, 0] + wo[1] * r2 - wo[2] * r1 - (s.velocity[t, 0] + wt[1] * q2 - wt[2] * q1)
    v1 = s.velocity[o, 1] + wo[2] * r0 - wo[0] * r2 - (s.velocity[t, 1] + wt[2] * q0 - wt[0] * q2)
    v2 = s.velocity[o, 2] + wo[0] * r1 - wo[1] * r0 - (s.velocity[t, 2] + wt[0] * q1 - wt[1] * q0)
    return v0, v1, v2


@njit(cache=True)
def _face_pair(m: ModelArrays, s: State, sc: Scratch, i: int, dt: float) -> tuple[float, int, float, float]:
    """Forces of the sub-contacts of FACE pair i; returns (elastic energy, active count, friction
    and bond energy dissipated)."""
    fo = s.pair_owner_face[i]
    ft = s.pair_target_face[i]
    o = m.face_block[fo]
    t = m.face_block[ft]
    go = m.block_group[o]
    gt = m.block_group[t]
    kn = m.mat_kn[go, gt]
    ks = m.mat_ks[go, gt]
    beta = m.mat_beta[go, gt]
    fm = face_map(m, s, sc, fo, ft)
    flat = abs(fm.det) < 1e-9  # faces at right angles: no sub-contact can act
    n0, n1, n2 = fm.nx, fm.ny, fm.nz
    elastic = 0.0
    active = 0
    e_fric = 0.0
    e_bond = 0.0
    for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
        code = s.track[k]
        p = code // SLOTS
        j = code - SLOTS * p
        sc.dashpot_force[k, 0] = 0.0
        sc.dashpot_force[k, 1] = 0.0
        sc.dashpot_force[k, 2] = 0.0
        area, yu, yw = (0.0, 0.0, 0.0) if flat else cover(m, sc, p, ft, fm, 0.0)
        un = -(fm.h0 + fm.hu * yu + fm.hw * yw)
        un_prev = s.slot_overlap[p, j]
        s.slot_overlap[p, j] = un if area > 0.0 else min(un, 0.0)
        us = s.slot_shear[p, j]
        bonded = s.slot_bonded[p, j]
        prev_area = s.slot_area[p, j]
        s.slot_area[p, j] = area
        # Contact point: midway between the owner-plane point and the target plane.
        x0 = fm.ox + yu * fm.eux + yw * fm.ewx + 0.5 * un * n0
        x1 = fm.oy + yu * fm.euy + yw * fm.ewy + 0.5 * un * n1
        x2 = fm.oz + yu * fm.euz + yw * fm.ewz + 0.5 * un * n2
        if area <= 0.0 or (un <= 0.0 and not bonded):
            # Not in contact: the stored shear energy is lost (friction), a bond slid off breaks.
            e = 0.5 * ks * prev_area * (us[0] * us[0] + us[1] * us[1] + us[2] * us[2])
            if bonded:
                e_bond += e + (spring_energy(s.slot_normal_force[p, j], kn * prev_area) if prev_area > 0.0 else 0.0)
                s.slot_bonded[p, j] = False
                s.point_failed[p] = FAILED_SHEAR if un > 0.0 else FAILED_TENSION
            elif area > 0.0 and un_prev > 0.0 and prev_area > 0.0:
                # Opened during the last step: complete the impulses of the normal ramp and of the
                # capped shear force up to the opening time (contact.ramp_overlap, release_shear).
                v0, v1, v2 = _relative_velocity(s, sc, o, t, x0, x1, x2)
                vn = v0 * n0 + v1 * n1 + v2 * n2
                fnc = kn * area * ramp_overlap(un, un_prev, vn, dt)
                c0, c1, c2, d = release_shear(
                    us, ks * prev_area, m.mat_res_tan_friction[go, gt] * kn * prev_area, un_prev, vn,
                    v0 - vn * n0, v1 - vn * n1, v2 - vn * n2, dt,
                )
                e_fric += d
                _apply(m, s, sc, o, t, fnc * n0 + c0, fnc * n1 + c1, fnc * n2 + c2, x0, x1, x2)
            else:
                e_fric += e
            us[:] = 0.0
            s.slot_normal_force[p, j] = 0.0
            continue
        kna = kn * area
        ksa = ks * area
        v0, v1, v2 = _relative_velocity(s, sc, o, t, x0, x1, x2)
        vn = v0 * n0 + v1 * n1 + v2 * n2  # > 0: separating
        vs0, vs1, vs2 = v0 - vn * n0, v1 - vn * n1, v2 - vn * n2
        fn = kna * un
        if bonded and fn < -m.mat_tension[go, gt] * area:
            # Tension cut-off: the bond fails and the point opens.
            e_bond += spring_energy(fn, kna) + 0.5 * ksa * (us[0] * us[0] + us[1] * us[1] + us[2] * us[2])
            s.slot_bonded[p, j] = False
            s.point_failed[p] = FAILED_TENSION
            us[:] = 0.0
            s.slot_normal_force[p, j] = 0.0
            continue
        # An unbonded contact that closed during the last step: its springs act since the crossing
        # (a fraction of the step) and its impulse is completed (contact.ramp_overlap).
        ramp = 1.0
        since = dt
        if not bonded and un_prev <= 0.0 and vn < 0.0:
            since = min(un / (-vn * dt), 1.0) * dt
            ramp = ramp_overlap(un, un_prev, vn, dt) / un
        f_applied = fn * ramp
        et, e0_du, e0_sq, du_sq = shear_increment(us, n0, n1, n2, vs0, vs1, vs2, since)
        trial = ksa * et
        if bonded:
            fmax = coulomb_limit(m.mat_cohesion[go, gt], m.mat_tan_friction[go, gt], area, fn)
        else:
            fmax = coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], area, fn)
        slipping = trial > fmax
        if slipping:
            e_fric += slip_dissipation(ksa, fmax / trial, e0_du, e0_sq, du_sq)
            if bonded:
                # Shear failure: drop to the residual strength; the released energy is the bond's.
                s.slot_bonded[p, j] = False
                s.point_failed[p] = FAILED_SHEAR
                fres = min(coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], area, fn), fmax)
                e_bond += drop_dissipation(fmax, fres, ksa)
                fmax = fres
                if un <= 0.0:
                    e_bond += spring_energy(fn, kna) + spring_energy(fmax, ksa)
                    us[:] = 0.0
                    s.slot_normal_force[p, j] = 0.0
                    continue
            f = fmax / trial if trial > 0.0 else 0.0
            us[0] *= f
            us[1] *= f
            us[2] *= f
        s.slot_normal_force[p, j] = fn
        elastic += spring_energy(fn, kna) + spring_energy(min(trial, fmax), ksa)
        active += 1
        # Stiffness-proportional dashpots on the active sub-contact (paper Eq. 4, alpha = 0 part).
        # Rayleigh SP damping follows the tangent stiffness: no shear dashpot while slipping.
        fdn = -beta * kna * vn
        bs = 0.0 if slipping else beta * ksa
        d0 = fdn * n0 - bs * vs0
        d1 = fdn * n1 - bs * vs1
        d2 = fdn * n2 - bs * vs2
        sc.dashpot_force[k, 0] = d0
        sc.dashpot_force[k, 1] = d1
        sc.dashpot_force[k, 2] = d2
        sc.dashpot_point[k, 0] = x0
        sc.dashpot_point[k, 1] = x1
        sc.dashpot_point[k, 2] = x2
        fs = ksa * ramp
        _apply(
            m, s, sc, o, t,
            f_applied * n0 + fs * us[0] + d0, f_applied * n1 + fs * us[1] + d1, f_applied * n2 + fs * us[2] + d2,
            x0, x1, x2,
        )
    return elastic, active, e_fric, e_bond


@njit(cache=True, inline="always")
def _world_point(m: ModelArrays, s: State, sc: Scratch, b: int, v: int) -> tuple[float, float, float]:
    r = sc.rotation[b]
    x = m.vertex_local[v]
    return (
        r[0, 0] * x[0] + r[0, 1] * x[1] + r[0, 2] * x[2] + s.position[b, 0],
        r[1, 0] * x[0] + r[1, 1] * x[1] + r[1, 2] * x[2] + s.position[b, 1],
        r[2, 0] * x[0] + r[2, 1] * x[1] + r[2, 2] * x[2] + s.position[b, 2],
    )


EDGE_PARALLEL_SIN = 0.05
"""Below this sine of the angle between two edges their cross product no longer defines the
contact normal: the last normal is kept."""


@njit(cache=True)
def _edge_pair(m: ModelArrays, s: State, sc: Scratch, i: int, dt: float) -> tuple[float, int, float]:
    """Force of the point contact of EDGE pair i (edge of block a on edge of block b); returns
    (elastic energy, active count, friction energy dissipated).

    Stiffness: kn A_e and ks A_e with A_e the smaller of the two edges' ``edge_area`` (the mean
    tributary area of the interface points of the faces meeting at the edge): an edge-edge contact
    is as stiff as one interface point of the coarser-discretised side would be.
    """
    a = s.pair_a[i]
    b = s.pair_b[i]
    ea = s.pair_edge_a[i]
    eb = s.pair_edge_b[i]
    sc.pair_dashpot_force[i, :] = 0.0
    a00, a01, a02 = _world_point(m, s, sc, a, m.edge_vertex[ea, 0])
    a10, a11, a12 = _world_point(m, s, sc, a, m.edge_vertex[ea, 1])
    b00, b01, b02 = _world_point(m, s, sc, b, m.edge_vertex[eb, 0])
    b10, b11, b12 = _world_point(m, s, sc, b, m.edge_vertex[eb, 1])
    da0, da1, da2 = a10 - a00, a11 - a01, a12 - a02
    db0, db1, db2 = b10 - b00, b11 - b01, b12 - b02
    sa, sb = segment_closest(a00, a01, a02, da0, da1, da2, b00, b01, b02, db0, db1, db2)
    qa0, qa1, qa2 = a00 + sa * da0, a01 + sa * da1, a02 + sa * da2
    qb0, qb1, qb2 = b00 + sb * db0, b01 + sb * db1, b02 + sb * db2
    c0, c1, c2 = da1 * db2 - da2 * db1, da2 * db0 - da0 * db2, da0 * db1 - da1 * db0
    cn = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    la = math.sqrt(da0 * da0 + da1 * da1 + da2 * da2)
    lb = math.sqrt(db0 * db0 + db1 * db1 + db2 * db2)
    m0, m1, m2 = s.pair_normal[i, 0], s.pair_normal[i, 1], s.pair_normal[i, 2]
    if cn > EDGE_PARALLEL_SIN * la * lb:
        n0, n1, n2 = c0 / cn, c1 / cn, c2 / cn
        if n0 * m0 + n1 * m1 + n2 * m2 < 0.0:
            n0, n1, n2 = -n0, -n1, -n2
    else:
        n0, n1, n2 = m0, m1, m2
    s.pair_normal[i, 0] = n0
    s.pair_normal[i, 1] = n1
    s.pair_normal[i, 2] = n2
    un = -(n0 * (qa0 - qb0) + n1 * (qa1 - qb1) + n2 * (qa2 - qb2))
    ga = m.block_group[a]
    gb = m.block_group[b]
    area = min(m.edge_area[ea], m.edge_area[eb])
    kna = m.mat_kn[ga, gb] * area
    ksa = m.mat_ks[ga, gb] * area
    us = s.pair_shear[i]
    un_prev = s.pair_overlap[i]
    s.pair_overlap[i] = un
    x0, x1, x2 = 0.5 * (qa0 + qb0), 0.5 * (qa1 + qb1), 0.5 * (qa2 + qb2)
    v0, v1, v2 = _relative_velocity(s, sc, a, b, x0, x1, x2)
    vn = v0 * n0 + v1 * n1 + v2 * n2
    vs0, vs1, vs2 = v0 - vn * n0, v1 - vn * n1, v2 - vn * n2
    if un <= 0.0:
        e = 0.5 * ksa * (us[0] * us[0] + us[1] * us[1] + us[2] * us[2])
        if un_prev > 0.0:
            fnc = kna * ramp_overlap(un, un_prev, vn, dt)
            c0, c1, c2, e = release_shear(us, ksa, m.mat_res_tan_friction[ga, gb] * kna, un_prev, vn, vs0, vs1, vs2, dt)
            _apply(m, s, sc, a, b, fnc * n0 + c0, fnc * n1 + c1, fnc * n2 + c2, x0, x1, x2)
        us[:] = 0.0
        s.pair_normal_force[i] = 0.0
        return 0.0, 0, e
    ramp = 1.0
    since = dt
    if un_prev <= 0.0 and vn < 0.0:
        since = min(un / (-vn * dt), 1.0) * dt
        ramp = ramp_overlap(un, un_prev, vn, dt) / un
    fn = kna * un
    f_applied = fn * ramp
    et, e0_du, e0_sq, du_sq = shear_increment(us, n0, n1, n2, vs0, vs1, vs2, since)
    trial = ksa * et
    fmax = coulomb_limit(m.mat_res_cohesion[ga, gb], m.mat_res_tan_friction[ga, gb], area, fn)
    e_fric = 0.0
    slipping = trial > fmax
    if slipping:
        e_fric = slip_dissipation(ksa, fmax / trial, e0_du, e0_sq, du_sq)
        f = fmax / trial
        us[0] *= f
        us[1] *= f
        us[2] *= f
    s.pair_normal_force[i] = fn
    beta = m.mat_beta[ga, gb]
    fdn = -beta * kna * vn
    bs = 0.0 if slipping else beta * ksa
    d0, d1, d2 = fdn * n0 - bs * vs0, fdn * n1 - bs * vs1, fdn * n2 - bs * vs2
    sc.pair_dashpot_force[i, 0] = d0
    sc.pair_dashpot_force[i, 1] = d1
    sc.pair_dashpot_force[i, 2] = d2
    sc.pair_dashpot_point[i, 0] = x0
    sc.pair_dashpot_point[i, 1] = x1
    sc.pair_dashpot_point[i, 2] = x2
    fs = ksa * ramp
    _apply(m, s, sc, a, b, f_applied * n0 + fs * us[0] + d0, f_applied * n1 + fs * us[1] + d1, f_applied * n2 + fs * us[2] + d2, x0, x1, x2)
    return spring_energy(fn, kna) + spring_energy(min(trial, fmax), ksa), 1, e_fric


@njit(cache=True)
def compute_forces(m: ModelArrays, s: State, sc: Scratch, t: float, dt: float) -> None:
    """Forces and torques on every block at the current poses (DESIGN: engine, joint law of paper §3)."""
    nb = m.block_mass.shape[0]
    sc.force[:] = 0.0
    sc.torque[:] = 0.0
    sc.reaction[:] = 0.0
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
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            el, ac, ef = _edge_pair(m, s, sc, i, dt)
            eb = 0.0
        else:
            el, ac, ef, eb = _face_pair(m, s, sc, i, dt)
        elastic += el
        active += ac
        e_fric += ef
        e_bond += eb
    sc.elastic_energy[0] = elastic
    sc.active_count[0] = active
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
    vd = sc.driven_velocity
    ke = 0.0
    pe = 0.0
    e_mp = 0.0
    e_loc = 0.0
    w_body = 0.0
    w_drv = 0.0
    jd = 0
    for b in range(nb):
        r = sc.rotation[b]
        va = sc.velocity_mid[b]
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
            wa0 = wa1 = wa2 = 0.0
            for i in range(3):
                tl = (tb0 - g0) if i == 0 else ((tb1 - g1) if i == 1 else (tb2 - g2))
                if m.local_damping > 0.0 and w[i] != 0.0:
                    fl = m.local_damping * abs(tl) * (1.0 if w[i] > 0.0 else -1.0)
                    tl -= fl
                    e_loc += abs(fl * w[i]) * dt
                wold = w[i]
                wnew = (wold * (1.0 - ha) + dt * tl * m.block_inv_inertia[b, i]) / (1.0 + ha)
                wai = 0.5 * (wold + wnew)
                w[i] = wnew
                e_mp += alpha * inert[i] * wai * wai * dt
                ke += 0.5 * inert[i] * wai * wai
                if i == 0:
                    wa0 = wai
                elif i == 1:
                    wa1 = wai
                else:
                    wa2 = wai
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
            wa0 = wa1 = wa2 = 0.0
        for i in range(3):
            sc.omega_mid[b, i] = r[i, 0] * wa0 + r[i, 1] * wa1 + r[i, 2] * wa2
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
        rec.energy[frame, E_ELASTIC] = sc.elastic_energy[0]
        _record_counts(s, sc, rec, frame)


@njit(cache=True)
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


@njit(cache=True, inline="always")
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


@njit(cache=True)
def dashpot_work(m: ModelArrays, s: State, sc: Scratch, h: float) -> None:
    """Energy dissipated by the SP dashpots over the step: -F_d . v_rel(mid-step) h, the same
    velocities that change the kinetic energy, so that the energy balance closes."""
    e = 0.0
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            fd = sc.pair_dashpot_force[i]
            if fd[0] != 0.0 or fd[1] != 0.0 or fd[2] != 0.0:
                e += _dashpot_power(s, sc, s.pair_a[i], s.pair_b[i], fd, sc.pair_dashpot_point[i]) * h
            continue
        o = m.face_block[s.pair_owner_face[i]]
        t = m.face_block[s.pair_target_face[i]]
        for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
            fd = sc.dashpot_force[k]
            if fd[0] == 0.0 and fd[1] == 0.0 and fd[2] == 0.0:
                continue
            e += _dashpot_power(s, sc, o, t, fd, sc.dashpot_point[k]) * h
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
def check_frame(m: ModelArrays, s: State, sc: Scratch, rec: Records, frame: int) -> int:
    """Status of recorded frame ``frame``: STATUS_DIVERGED when the state is not finite or the
    energy balance error exceeds DIVERGENCE_ERROR of the energy scale reached so far (kinetic +
    elastic + |potential change| + dissipated + |work|, at least the work of lifting the free blocks
    by 1 mm); STATUS_LOST when a free block's centroid left the model's extent; else STATUS_DONE.
    ``sc.lost_block`` names the block (-1 for an energy divergence)."""
    e = rec.energy[frame]
    e0 = rec.energy[0]
    total = 0.0
    total0 = 0.0
    scale = 0.0
    for k in range(e.shape[0]):
        sign = -1.0 if k == W_DRIVEN or k == W_BODY else 1.0
        total += sign * e[k]
        total0 += sign * e0[k]
        if k == E_POTENTIAL:
            scale += abs(e[k] - e0[k])
        elif k != E_KINETIC and k != E_ELASTIC:
            scale += abs(e[k])
    scale += e[E_KINETIC] + e[E_ELASTIC]
    sc.energy_scale[0] = max(sc.energy_scale[0], scale)
    err = total - total0
    sc.lost_block[0] = -1
    if not (math.isfinite(err) and abs(err) <= DIVERGENCE_ERROR * sc.energy_scale[0]):
        return STATUS_DIVERGED
    for b in range(m.block_mass.shape[0]):
        if not m.block_free[b]:
            continue
        for i in range(3):
            x = s.position[b, i]
            if not math.isfinite(x):
                sc.lost_block[0] = b
                return STATUS_DIVERGED
            if x < m.extent_low[i] or x > m.extent_high[i]:
                sc.lost_block[0] = b
                return STATUS_LOST
    return STATUS_DONE


@njit(cache=True)
def advance(
    m: ModelArrays, s: State, sc: Scratch, t_stop: float, record_interval: float, rec: Records, frame: int
) -> tuple[int, int]:
    """Step until time ``t_stop`` [s], recording a frame every ``record_interval``.

    Returns (next frame, status). The loop stops early with STATUS_GROW when a detection found
    its buffers too small (nothing was stepped since), or with STATUS_DIVERGED / STATUS_LOST after
    recording the first bad frame (see :func:`check_frame`). After each detection the bound of the
    tracked contacts is recomputed and dt is lowered (never raised) to (2 / omega_max)
    min(safety f_SP, resolution) (:mod:`rockdem.timestep`), so that contacts stiffer than those at
    the start (a toppling block landing on a side face) stay stable and resolved. Velocities use
    the mean of the two step lengths.
    """
    while s.time[0] < t_stop - 1e-12 * max(1.0, t_stop):
        update_rotations(m, s, sc)
        moved = 0.0
        for b in range(m.block_mass.shape[0]):
            moved = max(moved, s.moved[b])
        if 2.0 * moved >= m.contact_tol:
            detect(m, s, sc)
            if sc.overflow[0] > 0:
                for b in range(m.block_mass.shape[0]):
                    s.moved[b] = m.contact_tol  # detect again once the buffers are enlarged
                return frame, STATUS_GROW
            dt_crit, omega, _ = contact_bound(m, s, sc)
            safe = min(s.safety[0] * dt_crit, s.resolution[0] * 2.0 / omega) if omega > 0.0 else np.inf
            if safe < s.dt[0]:
                s.dt[0] = safe
                s.dt_min[0] = min(s.dt_min[0], safe)
        t = s.time[0]
        dt = s.dt[0]
        h = 0.5 * (s.dt_prev[0] + dt)
        compute_forces(m, s, sc, t, s.dt_prev[0])
        now = -1
        if frame < rec.time.shape[0] and t >= frame * record_interval - 0.5 * dt:
            now = frame
        integrate_velocities(m, s, sc, t, h, rec, now)
        dashpot_work(m, s, sc, h)
        integrate_positions(m, s, dt)
        s.dt_prev[0] = dt
        s.time[0] = t + dt
        s.step[0] += 1
        if now >= 0:
            frame += 1
            status = check_frame(m, s, sc, rec, now)
            if status != STATUS_DONE:
                return frame, status
    return frame, STATUS_DONE
