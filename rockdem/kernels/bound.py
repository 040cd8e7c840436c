"""Stable-timestep bound from the tracked sub-contacts (DESIGN §2 "Timestep").

A Gershgorin-type bound of the highest circular frequency: each tracked sub-contact adds, for each
of its three spring directions d (normal kn A, two tangents ks A), a rank-one stiffness term
k g g^T with g = [d; r x d] on each of its two blocks. With u_b = sqrt(k (1/m_b + sum_j (r_b x
d)_j^2 / I_bj)) (principal body frame; 0 for a driven block), the row sum of block b is
sum u_b (u_b + u_o), an upper bound of omega^2 over the whole system. Then, per block,
dt_b = (2 / omega_b) (sqrt(1 + xi^2) - xi), xi = beta omega_b / 2 (Belytschko), beta the largest
of its joints. Tracked points include every point within the tracking tolerance, so the bound
holds until the next detection, when it is computed again.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .layout import ModelArrays, Scratch, State


@njit(cache=True, inline="always")
def _flex(m: ModelArrays, sc: Scratch, b: int, r0: float, r1: float, r2: float, d0: float, d1: float, d2: float) -> float:
    """1/m + sum_j (r x d)_j^2 / I_j in block b's principal frame (0 for driven blocks)."""
    if not m.block_free[b]:
        return 0.0
    c0 = r1 * d2 - r2 * d1
    c1 = r2 * d0 - r0 * d2
    c2 = r0 * d1 - r1 * d0
    rot = sc.rotation[b]
    out = m.block_inv_mass[b]
    for j in range(3):
        cj = rot[0, j] * c0 + rot[1, j] * c1 + rot[2, j] * c2
        out += cj * cj * m.block_inv_inertia[b, j]
    return out


@njit(cache=True)
def contact_bound(m: ModelArrays, s: State, sc: Scratch, out: np.ndarray) -> None:
    """Critical timestep of the tracked contacts (safety 1).

    ``out`` (3,) receives [dt_critical s, omega_max rad/s, SP factor] of the limiting block;
    dt_critical is +inf when no block has a contact.
    """
    nb = m.block_mass.shape[0]
    row = np.zeros(nb)
    beta = np.zeros(nb)
    for k in range(s.track_count[0]):
        p = s.track[k]
        o = m.point_block[p]
        t = s.point_partner[p]
        tf = s.point_target_face[p]
        go, gt = m.block_group[o], m.block_group[t]
        area = m.point_area[p]
        rt = sc.rotation[t]
        ro = sc.rotation[o]
        n = rt @ m.face_normal[tf]
        pl = m.point_local[p]
        r_o = ro @ pl
        r_t = r_o + s.position[o] - s.position[t]
        # tangents
        if abs(n[0]) < 0.9:
            t1 = np.array([0.0, n[2], -n[1]])
        else:
            t1 = np.array([-n[2], 0.0, n[0]])
        t1 /= math.sqrt(t1[0] ** 2 + t1[1] ** 2 + t1[2] ** 2)
        t2 = np.array([n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2], n[0] * t1[1] - n[1] * t1[0]])
        for dir_ in range(3):
            if dir_ == 0:
                d = n
                k_ = m.mat_kn[go, gt] * area
            elif dir_ == 1:
                d = t1
                k_ = m.mat_ks[go, gt] * area
            else:
                d = t2
                k_ = m.mat_ks[go, gt] * area
            uo = math.sqrt(k_ * _flex(m, sc, o, r_o[0], r_o[1], r_o[2], d[0], d[1], d[2]))
            ut = math.sqrt(k_ * _flex(m, sc, t, r_t[0], r_t[1], r_t[2], d[0], d[1], d[2]))
            row[o] += uo * (uo + ut)
            row[t] += ut * (ut + uo)
        bt = m.mat_beta[go, gt]
        beta[o] = max(beta[o], bt)
        beta[t] = max(beta[t], bt)
    out[0] = np.inf
    out[1] = 0.0
    out[2] = 1.0
    for b in range(nb):
        if not m.block_free[b] or row[b] <= 0.0:
            continue
        w = math.sqrt(row[b])
        xi = 0.5 * beta[b] * w
        f = math.sqrt(1.0 + xi * xi) - xi
        dtb = 2.0 / w * f
        if dtb < out[0]:
            out[0] = dtb
            out[1] = w
            out[2] = f
