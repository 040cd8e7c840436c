"""Contact detection: bounding-box broad phase and common-plane narrow phase (DESIGN §2).

For each candidate pair the face normals of both blocks are tried as separating axes; the axis of
largest separation is the common plane (its face is the *reference* face), and the face of the
other block most opposed to it is the *incident* face. The interface points of the smaller of the
two faces (tie: the lower block id) are the sub-contacts; they are tested against the other
(target) face: within ``contact_tol`` of its plane and inside its polygon. A point has at most one
partner; its persistent state (shear force, bond, failure) survives while the partner stays the
same. Edge-to-edge crossings (no face normal separates) are not resolved: a documented limitation.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .layout import FAILED_SHEAR, FAILED_TENSION, ModelArrays, Scratch, State
from .rotation import quat_to_matrix


@njit(cache=True)
def update_rotations(m: ModelArrays, s: State, sc: Scratch) -> None:
    """Rotation matrices of every block from its quaternion."""
    for b in range(m.block_mass.shape[0]):
        quat_to_matrix(s.quaternion[b], sc.rotation[b])


@njit(cache=True)
def _world_vertices(m: ModelArrays, s: State, sc: Scratch) -> None:
    nb = m.block_mass.shape[0]
    for b in range(nb):
        r = sc.rotation[b]
        for i in range(3):
            sc.aabb[b, i] = np.inf
            sc.aabb[b, 3 + i] = -np.inf
        for v in range(m.block_vertex_start[b], m.block_vertex_start[b + 1]):
            for i in range(3):
                x = (
                    r[i, 0] * m.vertex_local[v, 0]
                    + r[i, 1] * m.vertex_local[v, 1]
                    + r[i, 2] * m.vertex_local[v, 2]
                    + s.position[b, i]
                )
                sc.world_vertex[v, i] = x
                sc.aabb[b, i] = min(sc.aabb[b, i], x)
                sc.aabb[b, 3 + i] = max(sc.aabb[b, 3 + i], x)
        for i in range(3):
            sc.aabb[b, i] -= m.contact_tol
            sc.aabb[b, 3 + i] += m.contact_tol


@njit(cache=True)
def _face_separation(
    r: np.ndarray, pos: np.ndarray, normal: np.ndarray, offset: float, world_vertex: np.ndarray, v0: int, v1: int
) -> float:
    """Separation [m] of the vertices v0:v1 from a face (body normal, offset) of a block at (r, pos)."""
    n0 = r[0, 0] * normal[0] + r[0, 1] * normal[1] + r[0, 2] * normal[2]
    n1 = r[1, 0] * normal[0] + r[1, 1] * normal[1] + r[1, 2] * normal[2]
    n2 = r[2, 0] * normal[0] + r[2, 1] * normal[1] + r[2, 2] * normal[2]
    d = n0 * pos[0] + n1 * pos[1] + n2 * pos[2] + offset
    lo = np.inf
    for v in range(v0, v1):
        x = n0 * world_vertex[v, 0] + n1 * world_vertex[v, 1] + n2 * world_vertex[v, 2]
        lo = min(lo, x)
    return lo - d


@njit(cache=True, inline="always")
def point_in_target(
    m: ModelArrays, s: State, sc: Scratch, p: int, t: int, tf: int, out: np.ndarray
) -> float:
    """Gap of point p from face tf of block t [m] (negative = overlap) and its position in t's frame.

    ``out[:3]`` receives the point in the target body frame; ``out[3]`` the largest excursion
    outside the face polygon [m] (<= 0 inside).
    """
    o = m.point_block[p]
    ro = sc.rotation[o]
    rt = sc.rotation[t]
    pl = m.point_local[p]
    w0 = ro[0, 0] * pl[0] + ro[0, 1] * pl[1] + ro[0, 2] * pl[2] + s.position[o, 0] - s.position[t, 0]
    w1 = ro[1, 0] * pl[0] + ro[1, 1] * pl[1] + ro[1, 2] * pl[2] + s.position[o, 1] - s.position[t, 1]
    w2 = ro[2, 0] * pl[0] + ro[2, 1] * pl[1] + ro[2, 2] * pl[2] + s.position[o, 2] - s.position[t, 2]
    q0 = rt[0, 0] * w0 + rt[1, 0] * w1 + rt[2, 0] * w2
    q1 = rt[0, 1] * w0 + rt[1, 1] * w1 + rt[2, 1] * w2
    q2 = rt[0, 2] * w0 + rt[1, 2] * w1 + rt[2, 2] * w2
    out[0], out[1], out[2] = q0, q1, q2
    outside = -np.inf
    for e in range(m.face_edge_start[tf], m.face_edge_start[tf + 1]):
        d = m.edge_normal[e, 0] * q0 + m.edge_normal[e, 1] * q1 + m.edge_normal[e, 2] * q2 - m.edge_offset[e]
        outside = max(outside, d)
    out[3] = outside
    n = m.face_normal[tf]
    return n[0] * q0 + n[1] * q1 + n[2] * q2 - m.face_offset[tf]


@njit(cache=True, inline="always")
def _release(s: State, p: int) -> None:
    """Forget the partner of point p; a bond torn apart by separation counts as a tension failure."""
    if s.point_bonded[p]:
        s.point_bonded[p] = False
        s.point_failed[p] = FAILED_TENSION
    s.point_partner[p] = -1
    s.point_target_face[p] = -1
    s.point_shear[p, 0] = 0.0
    s.point_shear[p, 1] = 0.0
    s.point_shear[p, 2] = 0.0
    s.point_normal_force[p] = 0.0


@njit(cache=True, inline="always")
def _narrow(m: ModelArrays, s: State, sc: Scratch, a: int, b: int, tmp: np.ndarray) -> None:
    best = -np.inf
    ref = -1
    rface = -1
    for f in range(m.block_face_start[a], m.block_face_start[a + 1]):
        sep = _face_separation(
            sc.rotation[a], s.position[a], m.face_normal[f], m.face_offset[f], sc.world_vertex,
            m.block_vertex_start[b], m.block_vertex_start[b + 1],
        )
        if sep > best:
            best, ref, rface = sep, a, f
    for f in range(m.block_face_start[b], m.block_face_start[b + 1]):
        sep = _face_separation(
            sc.rotation[b], s.position[b], m.face_normal[f], m.face_offset[f], sc.world_vertex,
            m.block_vertex_start[a], m.block_vertex_start[a + 1],
        )
        if sep > best:
            best, ref, rface = sep, b, f
    if best < sc.sums[5]:
        sc.sums[5] = best
        sc.sums[6] = a
        sc.sums[7] = b
    if best > m.contact_tol:
        return
    oth = b if ref == a else a
    rr = sc.rotation[ref]
    ro = sc.rotation[oth]
    fr = m.face_normal[rface]
    nref0 = rr[0, 0] * fr[0] + rr[0, 1] * fr[1] + rr[0, 2] * fr[2]
    nref1 = rr[1, 0] * fr[0] + rr[1, 1] * fr[1] + rr[1, 2] * fr[2]
    nref2 = rr[2, 0] * fr[0] + rr[2, 1] * fr[1] + rr[2, 2] * fr[2]
    iface = -1
    lowest = np.inf
    for g in range(m.block_face_start[oth], m.block_face_start[oth + 1]):
        c = (
            (ro[0, 0] * m.face_normal[g, 0] + ro[0, 1] * m.face_normal[g, 1] + ro[0, 2] * m.face_normal[g, 2]) * nref0
            + (ro[1, 0] * m.face_normal[g, 0] + ro[1, 1] * m.face_normal[g, 1] + ro[1, 2] * m.face_normal[g, 2]) * nref1
            + (ro[2, 0] * m.face_normal[g, 0] + ro[2, 1] * m.face_normal[g, 1] + ro[2, 2] * m.face_normal[g, 2]) * nref2
        )
        if c < lowest:
            lowest, iface = c, g
    ar = m.face_area[rface]
    ai = m.face_area[iface]
    # The smaller face owns the points (tie: the lower block id).
    if ai < ar * (1.0 - 1e-9) or (ar >= ai * (1.0 - 1e-9) and oth < ref):
        oface, target, tface = iface, ref, rface
    else:
        oface, target, tface = rface, oth, iface
    passid = sc.passes[0]
    for p in range(m.face_point_start[oface], m.face_point_start[oface + 1]):
        gap = point_in_target(m, s, sc, p, target, tface, tmp)
        if gap > m.contact_tol or tmp[3] > m.contact_tol + max(-gap, 0.0):
            continue
        if sc.seen[p] == passid:
            # Claimed already by another pair (a point on the shared edge of two faces): the
            # previous partner keeps it, so that bonds do not flip between neighbours.
            if target == sc.prev_partner[p]:
                s.point_partner[p] = target
                s.point_target_face[p] = tface
            continue
        sc.seen[p] = passid
        s.point_partner[p] = target
        s.point_target_face[p] = tface
        s.track[s.track_count[0]] = p
        s.track_count[0] += 1


@njit(cache=True)
def detect(m: ModelArrays, s: State, sc: Scratch) -> None:
    """Rebuild the list of tracked sub-contacts at the current poses (rotations must be current).

    Also leaves the most negative pair separation (deepest overlap) and its blocks in
    ``sc.sums[5:8]`` for the start-of-run overlap check.
    """
    nb = m.block_mass.shape[0]
    _world_vertices(m, s, sc)
    sc.passes[0] += 1
    s.track_count[0] = 0
    sc.prev_partner[:] = s.point_partner
    sc.sums[5] = np.inf
    sc.sums[6] = -1
    sc.sums[7] = -1
    tmp = np.empty(4)
    order = np.argsort(sc.aabb[:, 0])
    for ii in range(nb):
        a = order[ii]
        for jj in range(ii + 1, nb):
            b = order[jj]
            if sc.aabb[b, 0] > sc.aabb[a, 3]:
                break
            if (
                sc.aabb[b, 1] > sc.aabb[a, 4]
                or sc.aabb[a, 1] > sc.aabb[b, 4]
                or sc.aabb[b, 2] > sc.aabb[a, 5]
                or sc.aabb[a, 2] > sc.aabb[b, 5]
            ):
                continue
            if not (m.block_free[a] or m.block_free[b]):
                continue
            lo, hi = (a, b) if a < b else (b, a)
            _narrow(m, s, sc, lo, hi, tmp)
    passid = sc.passes[0]
    for p in range(m.point_block.shape[0]):
        if s.point_partner[p] >= 0 and sc.seen[p] != passid:
            _release(s, p)
        elif sc.seen[p] == passid and sc.prev_partner[p] >= 0 and s.point_partner[p] != sc.prev_partner[p]:
            # Moved on to another block: a bond is sheared off, the shear spring starts anew.
            if s.point_bonded[p]:
                s.point_bonded[p] = False
                s.point_failed[p] = FAILED_SHEAR
            s.point_shear[p, 0] = 0.0
            s.point_shear[p, 1] = 0.0
            s.point_shear[p, 2] = 0.0
            s.point_normal_force[p] = 0.0
    # Sort the tracked list so that force accumulation order (and results) are deterministic.
    s.track[: s.track_count[0]].sort()
    for b in range(nb):
        s.moved[b] = 0.0
