"""Stable-timestep bound from the tracked contacts (DESIGN: engine, timestep).

A Gershgorin-type bound of the highest circular frequency: each tracked contact adds, for each of
its three spring directions d (normal kn A, two tangents ks A), a rank-one stiffness term
k g g^T with g = [d; r x d] on each of its two blocks. With u_b = sqrt(k (1/m_b + sum_j (r_b x
d)_j^2 / I_bj)) (principal body frame; 0 for a driven block), the row sum of block b is
sum u_b (u_b + u_o), an upper bound of omega^2 over the whole system. Then, per block,
dt_b = (2 / omega_b) (sqrt(1 + xi^2) - xi), xi = beta omega_b / 2 (Belytschko), beta the largest
of its joints. A sub-contact counts with its full cell area (the most its partner can cover) at its
point (a landing corner with its stiffened area, :func:`rockdem.kernels.forces.corner_stiffening`),
an edge contact with its area at the middle of its edge; tracked contacts include every one
within the tracking tolerance, so the bound holds until the next detection, when it is computed
again.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .contact import sp_critical_factor
from .faces import face_map
from .forces import flexibility as _flex
from .forces import landing_corner
from .layout import DASHPOTS_IMPLICIT, PAIR_EDGE, SLOTS, STIFFENING_AT_START, ModelArrays, Scratch, State


@njit(cache=True, _nrt=False, inline="always")
def _contact_rows(
    m: ModelArrays, s: State, sc: Scratch, beta: np.ndarray, o: int, t: int,
    x0: float, x1: float, x2: float, n0: float, n1: float, n2: float, area: float,
) -> tuple[float, float]:
    """Row-sum terms (of blocks o and t) of the three springs of a contact at world point x with
    normal n between blocks o and t; raises their largest beta."""
    go, gt = m.block_group[o], m.block_group[t]
    ro = sc.rotation[o]
    rt = sc.rotation[t]
    a0, a1, a2 = x0 - s.position[o, 0], x1 - s.position[o, 1], x2 - s.position[o, 2]
    b0, b1, b2 = x0 - s.position[t, 0], x1 - s.position[t, 1], x2 - s.position[t, 2]
    if abs(n0) < 0.9:
        u0, u1, u2 = 0.0, n2, -n1
    else:
        u0, u1, u2 = -n2, 0.0, n0
    inv = 1.0 / math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    u0, u1, u2 = u0 * inv, u1 * inv, u2 * inv
    w0, w1, w2 = n1 * u2 - n2 * u1, n2 * u0 - n0 * u2, n0 * u1 - n1 * u0
    kn_ = m.mat_kn[go, gt] * area
    ks_ = m.mat_ks[go, gt] * area
    row_o = 0.0
    row_t = 0.0
    for dir_ in range(3):
        if dir_ == 0:
            d0, d1, d2, k_ = n0, n1, n2, kn_
        elif dir_ == 1:
            d0, d1, d2, k_ = u0, u1, u2, ks_
        else:
            d0, d1, d2, k_ = w0, w1, w2, ks_
        uo = math.sqrt(k_ * _flex(ro, m.block_inv_mass[o], m.block_inv_inertia[o], a0, a1, a2, d0, d1, d2))
        ut = math.sqrt(k_ * _flex(rt, m.block_inv_mass[t], m.block_inv_inertia[t], b0, b1, b2, d0, d1, d2))
        row_o += uo * (uo + ut)
        row_t += ut * (ut + uo)
    bt = m.mat_beta[go, gt]
    beta[o] = max(beta[o], bt)
    beta[t] = max(beta[t], bt)
    return row_o, row_t


@njit(cache=True, _nrt=False)
def contact_bound(m: ModelArrays, s: State, sc: Scratch, sp_reduction: bool) -> tuple[float, float, float]:
    """Critical timestep of the tracked contacts (safety 1).

    Returns (dt_critical [s], omega_max [rad/s], SP factor) of the limiting block; dt_critical is
    +inf when no block has a contact. ``sp_reduction``: explicit dashpots, whose critical step is
    reduced by Belytschko's factor; implicit dashpots (:mod:`rockdem.kernels.implicit`) are stable
    at the undamped step 2 / omega (factor 1).
    """
    nb = m.block_mass.shape[0]
    row = sc.bound_stiffness
    beta = sc.bound_beta
    row[:] = 0.0
    beta[:] = 0.0
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            a, b = s.pair_a[i], s.pair_b[i]
            ea, eb = s.pair_edge_a[i], s.pair_edge_b[i]
            ra = sc.rotation[a]
            va = m.vertex_local[m.edge_vertex[ea, 0]]
            vb = m.vertex_local[m.edge_vertex[ea, 1]]
            x0 = ra[0, 0] * (va[0] + vb[0]) * 0.5 + ra[0, 1] * (va[1] + vb[1]) * 0.5 + ra[0, 2] * (va[2] + vb[2]) * 0.5 + s.position[a, 0]
            x1 = ra[1, 0] * (va[0] + vb[0]) * 0.5 + ra[1, 1] * (va[1] + vb[1]) * 0.5 + ra[1, 2] * (va[2] + vb[2]) * 0.5 + s.position[a, 1]
            x2 = ra[2, 0] * (va[0] + vb[0]) * 0.5 + ra[2, 1] * (va[1] + vb[1]) * 0.5 + ra[2, 2] * (va[2] + vb[2]) * 0.5 + s.position[a, 2]
            area = min(m.edge_area[ea], m.edge_area[eb])
            ra_, rb_ = _contact_rows(m, s, sc, beta, a, b, x0, x1, x2, s.pair_normal[i, 0], s.pair_normal[i, 1], s.pair_normal[i, 2], area)
            row[a] += ra_
            row[b] += rb_
            continue
        # The owner's points and (while the pair may blend, kernels.blend) the target's carry the
        # shares 1 - lambda and lambda: the pair's stiffness is at most the larger of the two sets'.
        a = m.face_block[s.pair_owner_face[i]]
        b = m.face_block[s.pair_target_face[i]]
        split = s.pair_track_split[i]
        side_a0 = side_b0 = side_a1 = side_b1 = 0.0
        # Each side's face map, for the corners that may land before the next detection.
        fm0 = face_map(m, s, sc, s.pair_owner_face[i], s.pair_target_face[i])
        fm1 = face_map(m, s, sc, s.pair_target_face[i], s.pair_owner_face[i])
        for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
            # The owner's points press on the target face, the target's on the owner face.
            ft = s.pair_target_face[i] if k < split else s.pair_owner_face[i]
            t = m.face_block[ft]
            rt = sc.rotation[t]
            fn = m.face_normal[ft]
            n0 = rt[0, 0] * fn[0] + rt[0, 1] * fn[1] + rt[0, 2] * fn[2]
            n1 = rt[1, 0] * fn[0] + rt[1, 1] * fn[1] + rt[1, 2] * fn[2]
            n2 = rt[2, 0] * fn[0] + rt[2, 1] * fn[1] + rt[2, 2] * fn[2]
            p = s.track[k] // SLOTS
            o = m.point_block[p]
            ro = sc.rotation[o]
            pl = m.point_local[p]
            x0 = ro[0, 0] * pl[0] + ro[0, 1] * pl[1] + ro[0, 2] * pl[2] + s.position[o, 0]
            x1 = ro[1, 0] * pl[0] + ro[1, 1] * pl[1] + ro[1, 2] * pl[2] + s.position[o, 1]
            x2 = ro[2, 0] * pl[0] + ro[2, 1] * pl[1] + ro[2, 2] * pl[2] + s.position[o, 2]
            # A landed corner counts with its stiffening, an open one with what it would get if it
            # landed now (kernels.forces.corner_stiffening), so that the step comes down to resolve
            # it; its stiffening never exceeds what the step at its landing resolves.
            j = s.track[k] - SLOTS * p
            stiff = s.slot_stiffening[p, j]
            if m.point_corner[p] >= 0 and not s.slot_bonded[p, j] and (
                    s.slot_area[p, j] == 0.0 or s.slot_overlap[p, j] <= 0.0 or stiff == STIFFENING_AT_START):
                fm = fm0 if k < split else fm1
                stiff = landing_corner(m, p, m.point_face[p], ft, fm.h0, fm.hu, fm.hw) if s.dashpots[0] == DASHPOTS_IMPLICIT else 1.0
            r_o, r_t = _contact_rows(m, s, sc, beta, o, t, x0, x1, x2, n0, n1, n2, m.point_area[p] * stiff)
            if k < split:
                side_a0 += r_o
                side_b0 += r_t
            else:
                side_b1 += r_o
                side_a1 += r_t
        row[a] += max(side_a0, side_a1)
        row[b] += max(side_b0, side_b1)
    dt_crit = np.inf
    omega = 0.0
    factor = 1.0
    for b in range(nb):
        if not m.block_free[b] or row[b] <= 0.0:
            continue
        w = math.sqrt(row[b])
        f = sp_critical_factor(beta[b], w) if sp_reduction else 1.0
        dtb = 2.0 / w * f
        if dtb < dt_crit:
            dt_crit, omega, factor = dtb, w, f
    return dt_crit, omega, factor
