"""Implicit SP dashpots: the velocity update with the damping at the step mid-point (trapezoidal).

The leapfrog step of a block with generalised velocity V = [v (world), omega (body frame)] and
mass M = diag(m, m, m, I_1, I_2, I_3) becomes, with the dashpot force of every active sub-contact
k at the mean of the old and new velocities, f_k = -C_k (v_rel(V-) + v_rel(V+)) / 2,

    (M + h/2 sum_k J_k^T C_k J_k) V+ = M V- + h (F_spring + F_d(V-) / 2) + h/2 sum_k J_k^T C_k u_k+

with C_k = c_n n n^T + c_s (I - n n^T) (c_n = beta kn A, c_s = beta ks A, 0 while slipping), J_k
the map from V to the velocity of the block's material point at the contact, and u_k+ the
partner's point velocity over the step: known for a driven partner (exact in one solve), the last
iterate for a free one (block-Jacobi sweeps to a tolerance). The gyroscopic term, the springs and
the local damping stay explicit; MP damping is on the diagonal as in the explicit update.

Contact onset and release (:mod:`rockdem.kernels.forces`): a dashpot acts from the time its contact
closed to the time it opened, not over whole velocity steps. At the first step in contact its
coefficient is scaled by the share of the velocity step [t - h/2, t + h/2] since the crossing (up to
3/2 with the part the last step missed, :func:`rockdem.kernels.contact.dashpot_onset_share`); at
the first step out of contact the share between the opening and the middle of the step is applied
at the last half step's velocity (negative when the last step applied it past the opening,
:func:`~rockdem.kernels.contact.dashpot_release_share`). Without them a heavily damped impact
(beta = 2 / omega_e: h c / m_eff of a landing corner near 1 at the undamped step) is off by up to
5 % in restitution, with a sign that depends on where the crossing falls in the step; with them the
first rebound of a 0.19 x 0.9 m block converges monotonically (-0.96 %, -0.34 %, -0.10 % at 1, 1/2
and 1/6 of the default step).

Stability (any damping): for a linear system M x'' + C x' + K x = 0 with M > 0 and C, K >= 0 (any
C: the dashpots of many contacts and materials need not be proportional to K), this scheme keeps
E = 1/2 v+^T M v+ + 1/2 x_n^T K x_{n+1} and E_{n+1/2} - E_{n-1/2} = -h v_mid^T C v_mid <= 0; E is a
positive norm of (x_n, x_{n+1}) iff M - h^2 K / 4 >= 0, i.e. omega_max h <= 2, the undamped limit.
So beta no longer shrinks the stable step (explicit: (2 / omega)(sqrt(1 + xi^2) - xi)). The block-
Jacobi sweeps converge for any step: with A = M + h/2 C split into its block diagonal D and the rest,
2 D - A = M + h/2 sum_k c_k H_k H_k^T > 0 (each dashpot couples two blocks by a rank-one term per
direction; H_k is its coupling vector with the partner's sign flipped), the condition for block
Jacobi on a symmetric positive definite system. The dissipation booked is h v_mid^T C v_mid per
dashpot (mid-step relative velocity), the work of the forces applied, so the energy balance closes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .forces import _apply, has_dashpots
from .layout import PAIR_EDGE, ModelArrays, Scratch, State

DASHPOT_SWEEP_TOL = 1e-9
"""Block-Jacobi sweeps stop when no block's velocity changes by more than this fraction of the
largest block velocity (|v| + radius |omega|), or of the velocity gravity gives in one step."""

DASHPOT_MAX_SWEEPS = 200
"""Most sweeps per step; a step that needs more is counted in ``State.dashpot_unconverged``."""


@njit(cache=True, _nrt=False, inline="always")
def _add_damping(k: np.ndarray, r0: float, r1: float, r2: float, cn: float, cs: float, n0: float, n1: float, n2: float) -> None:
    """k (6, 6) += J^T C J for a dashpot at arm r (world, from the centroid) with normal n:
    (c_n - c_s) g g^T with g = [n; r x n], plus c_s [[I, -S], [S, |r|^2 I - r r^T]] (S u = r x u)."""
    g0, g1, g2 = n0, n1, n2
    g3, g4, g5 = r1 * n2 - r2 * n1, r2 * n0 - r0 * n2, r0 * n1 - r1 * n0
    c = cn - cs
    for i in range(6):
        gi = g0 if i == 0 else (g1 if i == 1 else (g2 if i == 2 else (g3 if i == 3 else (g4 if i == 4 else g5))))
        ci = c * gi
        k[i, 0] += ci * g0
        k[i, 1] += ci * g1
        k[i, 2] += ci * g2
        k[i, 3] += ci * g3
        k[i, 4] += ci * g4
        k[i, 5] += ci * g5
    if cs > 0.0:
        rr = r0 * r0 + r1 * r1 + r2 * r2
        k[0, 0] += cs
        k[1, 1] += cs
        k[2, 2] += cs
        # -S (rows force, columns angular velocity) and S (rows torque, columns velocity)
        k[0, 4] += cs * r2
        k[0, 5] -= cs * r1
        k[1, 3] -= cs * r2
        k[1, 5] += cs * r0
        k[2, 3] += cs * r1
        k[2, 4] -= cs * r0
        k[4, 0] += cs * r2
        k[5, 0] -= cs * r1
        k[3, 1] -= cs * r2
        k[5, 1] += cs * r0
        k[3, 2] += cs * r1
        k[4, 2] -= cs * r0
        k[3, 3] += cs * (rr - r0 * r0)
        k[4, 4] += cs * (rr - r1 * r1)
        k[5, 5] += cs * (rr - r2 * r2)
        k[3, 4] -= cs * r0 * r1
        k[4, 3] -= cs * r0 * r1
        k[3, 5] -= cs * r0 * r2
        k[5, 3] -= cs * r0 * r2
        k[4, 5] -= cs * r1 * r2
        k[5, 4] -= cs * r1 * r2


@njit(cache=True, _nrt=False, inline="always")
def _point_velocity(s: State, sc: Scratch, it: np.ndarray, b: int, x0: float, x1: float, x2: float) -> tuple[float, float, float]:
    """Velocity [m/s] of block b's material point at world x: a free block's from the iterate ``it``
    (nb, 6: v world, omega body), a driven block's from the state (its velocity over the step)."""
    p = s.position[b]
    r0, r1, r2 = x0 - p[0], x1 - p[1], x2 - p[2]
    if sc.block_damped[b]:
        rt = sc.rotation[b]
        wb0, wb1, wb2 = it[b, 3], it[b, 4], it[b, 5]
        w0 = rt[0, 0] * wb0 + rt[0, 1] * wb1 + rt[0, 2] * wb2
        w1 = rt[1, 0] * wb0 + rt[1, 1] * wb1 + rt[1, 2] * wb2
        w2 = rt[2, 0] * wb0 + rt[2, 1] * wb1 + rt[2, 2] * wb2
        return it[b, 0] + w1 * r2 - w2 * r1, it[b, 1] + w2 * r0 - w0 * r2, it[b, 2] + w0 * r1 - w1 * r0
    v = s.velocity[b]
    w = sc.omega_world[b]
    return v[0] + w[1] * r2 - w[2] * r1, v[1] + w[2] * r0 - w[0] * r2, v[2] + w[0] * r1 - w[1] * r0


@njit(cache=True, _nrt=False, inline="always")
def _add_coupling(
    out: np.ndarray, s: State, b: int, x0: float, x1: float, x2: float, cn: float, cs: float,
    n0: float, n1: float, n2: float, u0: float, u1: float, u2: float,
) -> None:
    """out[b] += J^T C u: the force C u at world point x and its moment about block b's centroid."""
    un = (cn - cs) * (n0 * u0 + n1 * u1 + n2 * u2)
    w0 = cs * u0 + un * n0
    w1 = cs * u1 + un * n1
    w2 = cs * u2 + un * n2
    p = s.position[b]
    r0, r1, r2 = x0 - p[0], x1 - p[1], x2 - p[2]
    out[b, 0] += w0
    out[b, 1] += w1
    out[b, 2] += w2
    out[b, 3] += r1 * w2 - r2 * w1
    out[b, 4] += r2 * w0 - r0 * w2
    out[b, 5] += r0 * w1 - r1 * w0


@njit(cache=True, _nrt=False, inline="always")
def _pair_range(m: ModelArrays, s: State, i: int) -> tuple[bool, int, int, int, int, int]:
    """(EDGE pair, block a, block b, first and last + 1 tracked index, split) of pair i: a FACE
    pair's dashpots are its sub-contacts track[k0:k1], acting on a for k < split and on b from
    split on (kernels.blend); an EDGE pair's is the pair itself (k = 0)."""
    if s.pair_kind[i] == PAIR_EDGE:
        return True, s.pair_a[i], s.pair_b[i], 0, 1, 1
    a = m.face_block[s.pair_owner_face[i]]
    b = m.face_block[s.pair_target_face[i]]
    return False, a, b, s.pair_track_start[i], s.pair_track_stop[i], s.pair_track_split[i]


@njit(cache=True, _nrt=False, inline="always")
def _dashpot(s: State, sc: Scratch, i: int, k: int, edge: bool) -> tuple[float, float, float, float, float, float, float, float]:
    """(c_n, c_s [N s/m], point x (world) [m], unit normal n) of the dashpot of sub-contact k or of
    EDGE pair i; c_n = 0: inactive."""
    if edge:
        return (
            sc.pair_dashpot_cn[i], sc.pair_dashpot_cs[i], sc.pair_point[i, 0], sc.pair_point[i, 1], sc.pair_point[i, 2],
            s.pair_normal[i, 0], s.pair_normal[i, 1], s.pair_normal[i, 2],
        )
    return (
        sc.dashpot_cn[k], sc.dashpot_cs[k], sc.contact_point[k, 0], sc.contact_point[k, 1], sc.contact_point[k, 2],
        sc.dashpot_normal[k, 0], sc.dashpot_normal[k, 1], sc.dashpot_normal[k, 2],
    )


@njit(cache=True, _nrt=False)
def mark_damped(m: ModelArrays, s: State, sc: Scratch) -> bool:
    """Flag the free blocks with an active dashpot (``sc.block_damped``) and add every dashpot's
    J^T C J to its free blocks (``sc.block_damping``). Returns whether a dashpot joins two free
    blocks (sweeps needed)."""
    nb = m.block_mass.shape[0]
    for b in range(nb):
        sc.block_damped[b] = False
        for i in range(6):
            for j in range(6):
                sc.block_damping[b, i, j] = 0.0
    coupled = False
    for i in range(s.pair_count[0]):
        edge, a, b, k0, k1, split = _pair_range(m, s, i)
        for k in range(k0, k1):
            cn, cs, x0, x1, x2, n0, n1, n2 = _dashpot(s, sc, i, k, edge)
            if cn <= 0.0:
                continue
            for side in range(2):
                o = a if side == 0 else b
                if m.block_free[o]:
                    sc.block_damped[o] = True
                    p = s.position[o]
                    _add_damping(sc.block_damping[o], x0 - p[0], x1 - p[1], x2 - p[2], cn, cs, n0, n1, n2)
            coupled = coupled or (m.block_free[a] and m.block_free[b])
    return coupled


@njit(cache=True, _nrt=False)
def couple(m: ModelArrays, s: State, sc: Scratch, it: np.ndarray) -> None:
    """``sc.block_coupling`` = sum over each damped block's dashpots of J^T C u, u the partner's
    point velocity: a driven partner's over the step (state), a free partner's from the iterate
    ``it`` (nb, 6; the state's velocity for a block without dashpots)."""
    nb = m.block_mass.shape[0]
    for b in range(nb):
        for j in range(6):
            sc.block_coupling[b, j] = 0.0
    for i in range(s.pair_count[0]):
        edge, a, b, k0, k1, split = _pair_range(m, s, i)
        for k in range(k0, k1):
            cn, cs, x0, x1, x2, n0, n1, n2 = _dashpot(s, sc, i, k, edge)
            if cn <= 0.0:
                continue
            if sc.block_damped[a]:
                u0, u1, u2 = _point_velocity(s, sc, it, b, x0, x1, x2)
                _add_coupling(sc.block_coupling, s, a, x0, x1, x2, cn, cs, n0, n1, n2, u0, u1, u2)
            if sc.block_damped[b]:
                u0, u1, u2 = _point_velocity(s, sc, it, a, x0, x1, x2)
                _add_coupling(sc.block_coupling, s, b, x0, x1, x2, cn, cs, n0, n1, n2, u0, u1, u2)


@njit(cache=True, _nrt=False, inline="always")
def factor_block(m: ModelArrays, sc: Scratch, b: int, h: float, ha: float) -> None:
    """``sc.block_lhs[b]`` = Cholesky factor L (lower) of M (1 + ha) + h/2 T^T K T, K the block's
    world damping matrix and T = diag(I, R) (body angular velocity -> world)."""
    a = sc.block_lhs[b]
    k = sc.block_damping[b]
    r = sc.rotation[b]
    hh = 0.5 * h
    # T^T K T: [[K_tt, K_tr R], [R^T K_rt, R^T K_rr R]]
    for i in range(3):
        for j in range(3):
            a[i, j] = hh * k[i, j]
            a[i, 3 + j] = hh * (k[i, 3] * r[0, j] + k[i, 4] * r[1, j] + k[i, 5] * r[2, j])
            a[3 + j, i] = a[i, 3 + j]
    for i in range(3):
        for j in range(i, 3):
            acc = 0.0
            for p in range(3):
                acc += r[p, i] * (k[3 + p, 3] * r[0, j] + k[3 + p, 4] * r[1, j] + k[3 + p, 5] * r[2, j])
            a[3 + i, 3 + j] = hh * acc
            a[3 + j, 3 + i] = hh * acc
    for i in range(3):
        a[i, i] += m.block_mass[b] * (1.0 + ha)
        a[3 + i, 3 + i] += m.block_inertia[b, i] * (1.0 + ha)
    # In-place Cholesky (lower triangle).
    for j in range(6):
        d = a[j, j]
        for p in range(j):
            d -= a[j, p] * a[j, p]
        d = math.sqrt(d)
        a[j, j] = d
        for i in range(j + 1, 6):
            acc = a[i, j]
            for p in range(j):
                acc -= a[i, p] * a[j, p]
            a[i, j] = acc / d


@njit(cache=True, _nrt=False, inline="always")
def solve_block(sc: Scratch, b: int, h: float, out: np.ndarray) -> None:
    """out[b] = A^{-1} (rhs + h/2 T^T coupling) with the factor of :func:`factor_block`."""
    l = sc.block_lhs[b]
    c = sc.block_coupling[b]
    r = sc.rotation[b]
    hh = 0.5 * h
    y0 = sc.block_rhs[b, 0] + hh * c[0]
    y1 = sc.block_rhs[b, 1] + hh * c[1]
    y2 = sc.block_rhs[b, 2] + hh * c[2]
    y3 = sc.block_rhs[b, 3] + hh * (r[0, 0] * c[3] + r[1, 0] * c[4] + r[2, 0] * c[5])
    y4 = sc.block_rhs[b, 4] + hh * (r[0, 1] * c[3] + r[1, 1] * c[4] + r[2, 1] * c[5])
    y5 = sc.block_rhs[b, 5] + hh * (r[0, 2] * c[3] + r[1, 2] * c[4] + r[2, 2] * c[5])
    x = out[b]
    x[0], x[1], x[2], x[3], x[4], x[5] = y0, y1, y2, y3, y4, y5
    for i in range(6):  # L y = rhs
        acc = x[i]
        for p in range(i):
            acc -= l[i, p] * x[p]
        x[i] = acc / l[i, i]
    for i in range(5, -1, -1):  # L^T x = y
        acc = x[i]
        for p in range(i + 1, 6):
            acc -= l[p, i] * x[p]
        x[i] = acc / l[i, i]


@njit(cache=True, _nrt=False)
def sweep(m: ModelArrays, s: State, sc: Scratch, h: float, gravity_step: float) -> None:
    """Block-Jacobi sweeps of the coupled dashpots from the first solve in ``sc.block_iterate[0]``
    until converged (:data:`DASHPOT_SWEEP_TOL`); the result is left in ``sc.block_iterate[0]``."""
    nb = m.block_mass.shape[0]
    cur = 0
    converged = False
    for _ in range(DASHPOT_MAX_SWEEPS):
        src = sc.block_iterate[cur]
        dst = sc.block_iterate[1 - cur]
        couple(m, s, sc, src)
        change = 0.0
        scale = gravity_step
        for b in range(nb):
            if not sc.block_damped[b]:
                continue
            solve_block(sc, b, h, sc.block_iterate[1 - cur])
            rad = m.block_radius[b]
            dv = math.sqrt((dst[b, 0] - src[b, 0]) ** 2 + (dst[b, 1] - src[b, 1]) ** 2 + (dst[b, 2] - src[b, 2]) ** 2)
            dw = math.sqrt((dst[b, 3] - src[b, 3]) ** 2 + (dst[b, 4] - src[b, 4]) ** 2 + (dst[b, 5] - src[b, 5]) ** 2)
            change = max(change, dv + rad * dw)
            vv = math.sqrt(dst[b, 0] ** 2 + dst[b, 1] ** 2 + dst[b, 2] ** 2)
            ww = math.sqrt(dst[b, 3] ** 2 + dst[b, 4] ** 2 + dst[b, 5] ** 2)
            scale = max(scale, vv + rad * ww)
        cur = 1 - cur
        s.dashpot_sweeps[0] += 1
        if change <= DASHPOT_SWEEP_TOL * scale:
            converged = True
            break
    if not converged:
        s.dashpot_unconverged[0] += 1
    if cur == 1:
        for b in range(nb):
            for j in range(6):
                sc.block_iterate[0, b, j] = sc.block_iterate[1, b, j]


@njit(cache=True, _nrt=False, inline="always")
def _new_point_velocity(s: State, sc: Scratch, b: int, x0: float, x1: float, x2: float) -> tuple[float, float, float]:
    """Velocity [m/s] of block b's material point at world x over the step (the state's new velocities)."""
    p = s.position[b]
    r0, r1, r2 = x0 - p[0], x1 - p[1], x2 - p[2]
    rt = sc.rotation[b]
    wb = s.omega[b]
    w0 = rt[0, 0] * wb[0] + rt[0, 1] * wb[1] + rt[0, 2] * wb[2]
    w1 = rt[1, 0] * wb[0] + rt[1, 1] * wb[1] + rt[1, 2] * wb[2]
    w2 = rt[2, 0] * wb[0] + rt[2, 1] * wb[1] + rt[2, 2] * wb[2]
    v = s.velocity[b]
    return v[0] + w1 * r2 - w2 * r1, v[1] + w2 * r0 - w0 * r2, v[2] + w0 * r1 - w1 * r0


@njit(cache=True, _nrt=False, inline="always")
def _mid_relative_velocity(
    m: ModelArrays, s: State, sc: Scratch, o: int, t: int, x0: float, x1: float, x2: float, w0: float, w1: float, w2: float,
    drift: float,
) -> tuple[float, float, float]:
    """Relative velocity (o minus t) [m/s] at world x over the step from w, its value at the last
    half step: a free block's point velocity at the mid-step (the mean of old and new, as the
    kinetic energy), a driven block's its displacement over the velocity interval [t - lag, t + step
    / 2] divided by its length h (as its work, ``W_DRIVEN``): (v_last lag + v_new step / 2) / h, the
    mean of the two less ``drift`` (v_new - v_last) / 2, drift = (2 lag - h) / h."""
    uo0, uo1, uo2 = _new_point_velocity(s, sc, o, x0, x1, x2)
    ut0, ut1, ut2 = _new_point_velocity(s, sc, t, x0, x1, x2)
    v0, v1, v2 = 0.5 * (w0 + uo0 - ut0), 0.5 * (w1 + uo1 - ut1), 0.5 * (w2 + uo2 - ut2)
    for side in range(2):
        b = o if side == 0 else t
        if not m.block_free[b]:  # w had its last velocity, a driven block has no rotation
            sign = -0.5 * drift if side == 0 else 0.5 * drift
            v0 += sign * (s.velocity[b, 0] - sc.driven_velocity_last[b, 0])
            v1 += sign * (s.velocity[b, 1] - sc.driven_velocity_last[b, 1])
            v2 += sign * (s.velocity[b, 2] - sc.driven_velocity_last[b, 2])
    return v0, v1, v2


@njit(cache=True, _nrt=False)
def driven_dashpot_forces(m: ModelArrays, s: State, sc: Scratch) -> None:
    """``sc.driven_dashpot[b]``: the resultant force [N] of the SP dashpots (``sc.dashpot_force``,
    ``sc.pair_dashpot_force``, complete: after :func:`finalize` under implicit dashpots) on each
    driven block b, the part of its force whose work its dissipation counts (kernels.step)."""
    for b in range(m.block_mass.shape[0]):
        if not m.block_free[b]:
            for c in range(3):
                sc.driven_dashpot[b, c] = 0.0
    for i in range(s.pair_count[0]):
        edge, a, b, k0, k1, split = _pair_range(m, s, i)
        if m.block_free[a] and m.block_free[b]:
            continue
        for k in range(k0, k1):
            fd = sc.pair_dashpot_force[i] if edge else sc.dashpot_force[k]
            o, t = (a, b) if k < split else (b, a)  # fd acts on o, -fd on t
            for c in range(3):
                if not m.block_free[o]:
                    sc.driven_dashpot[o, c] += fd[c]
                if not m.block_free[t]:
                    sc.driven_dashpot[t, c] -= fd[c]


@njit(cache=True, _nrt=False)
def finalize(m: ModelArrays, s: State, sc: Scratch, h: float) -> float:
    """The dashpot forces at the mid-step velocities, f = -C (v_rel- + v_rel+) / 2 (the new
    velocities in the state): stored in ``sc.dashpot_force`` / ``sc.pair_dashpot_force``, with the
    contacts' forces completed (the half at v_rel+ added to ``sc.contact_force`` / ``sc.pair_force``
    and to the blocks' forces and torques and the reaction of the driven blocks). Returns the energy
    dissipated over the step, h sum_k v_mid^T C_k v_mid [J] (the work of the applied forces)."""
    e = 0.0
    drift = (2.0 * s.velocity_lag[0] - h) / h  # a driven block's velocity over the interval (_mid_relative_velocity)
    for i in range(s.pair_count[0]):
        edge, a, b, k0, k1, split = _pair_range(m, s, i)
        for k in range(k0, k1):
            cn, cs, x0, x1, x2, n0, n1, n2 = _dashpot(s, sc, i, k, edge)
            o, t = (a, b) if k < split else (b, a)
            fd = sc.pair_dashpot_force[i] if edge else sc.dashpot_force[k]
            vd = sc.pair_dashpot_velocity[i] if edge else sc.dashpot_velocity[k]
            if cn <= 0.0:
                # No implicit share; a dashpot released during the last step had its share of this
                # step applied at the last half step's velocity (forces._release_pass): its work.
                if fd[0] == 0.0 and fd[1] == 0.0 and fd[2] == 0.0:
                    continue
                vm0, vm1, vm2 = _mid_relative_velocity(m, s, sc, o, t, x0, x1, x2, vd[0], vd[1], vd[2], drift)
                e -= h * (fd[0] * vm0 + fd[1] * vm1 + fd[2] * vm2)
                continue
            fc = sc.pair_force[i] if edge else sc.contact_force[k]
            vm0, vm1, vm2 = vd[0], vd[1], vd[2]
            uo0, uo1, uo2 = _new_point_velocity(s, sc, o, x0, x1, x2)
            ut0, ut1, ut2 = _new_point_velocity(s, sc, t, x0, x1, x2)
            vp0, vp1, vp2 = uo0 - ut0, uo1 - ut1, uo2 - ut2
            pn = (cn - cs) * (n0 * vp0 + n1 * vp1 + n2 * vp2)
            g0 = -0.5 * (cs * vp0 + pn * n0)  # -C v_rel+ / 2: the half not yet applied
            g1 = -0.5 * (cs * vp1 + pn * n1)
            g2 = -0.5 * (cs * vp2 + pn * n2)
            vm0, vm1, vm2 = _mid_relative_velocity(m, s, sc, o, t, x0, x1, x2, vm0, vm1, vm2, drift)
            fd[0] += g0
            fd[1] += g1
            fd[2] += g2
            fc[0] += g0
            fc[1] += g1
            fc[2] += g2
            f0, f1, f2 = fd[0], fd[1], fd[2]
            _apply(s.position, m.block_free, sc.force, sc.torque, sc.reaction, o, t, g0, g1, g2, x0, x1, x2)
            e -= h * (f0 * vm0 + f1 * vm1 + f2 * vm2)
    return e
