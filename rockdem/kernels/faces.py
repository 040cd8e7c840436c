"""Face-to-face sub-contacts: how much of a point's tributary cell a partner face covers, and where.

An owner face (carrying the interface points) is pressed against a target face of another block.
The owner face coordinates (u, w) map affinely onto the target face coordinates (u', w') by the
projection along the target normal; the height of an owner-plane point above the target plane is
affine too. A point's *effective area* is the part of its tributary cell that the target polygon
covers (the cell clipped by the target's edge lines); its force acts at the point itself when the
cell is covered (the paper's interface-point quadrature, §3.3); a partly covered cell's force
moves from the point (or the nearest covered point) towards the deepest covered vertex, as far as
that is deeper and the cell uncovered (nothing on a flat joint; all the way where an edge of the
other block crosses a tilted cell). The
area varies continuously as the blocks slide, so a sub-contact's force fades out smoothly as it
leaves its partner instead of switching a full spring on or off; and an edge lying across a
narrow face (a tilted block landing on a wall top) is held where it actually crosses the face.
See ``docs/contacts.md``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from .layout import ModelArrays, Scratch, State
from .polygon import clip_halfplane, deepest_vertex, nearest_on_polygon, polygon_area

INSIDE_TOL = 1e-10
"""[m] a cell vertex this close outside a target edge counts as inside (round-off of flush joints)."""

DEPTH_TIE = 1e-7
"""[m] covered-cell vertices this close to the deepest count as equally deep."""

COVER_BLEND = 0.05
"""A cell covered to more than 1 - COVER_BLEND of its area keeps its force at its point (it moves
there continuously as the cover grows)."""


class FaceMap(NamedTuple):
    """Owner face -> target face map at the current poses (world frame).

    Owner face point (u, w) is X = origin + u eu + w ew; its projection on the target face has
    target coordinates (m00 u + m01 w + t0, m10 u + m11 w + t1) and its height above the target
    plane is h0 + hu u + hw w [m] (negative: overlap).
    """

    ox: float
    oy: float
    oz: float
    eux: float
    euy: float
    euz: float
    ewx: float
    ewy: float
    ewz: float
    nx: float
    ny: float
    nz: float
    m00: float
    m01: float
    m10: float
    m11: float
    t0: float
    t1: float
    h0: float
    hu: float
    hw: float
    det: float


@njit(cache=True, inline="always")
def _rot(r: np.ndarray, v: np.ndarray) -> tuple[float, float, float]:
    return (
        r[0, 0] * v[0] + r[0, 1] * v[1] + r[0, 2] * v[2],
        r[1, 0] * v[0] + r[1, 1] * v[1] + r[1, 2] * v[2],
        r[2, 0] * v[0] + r[2, 1] * v[1] + r[2, 2] * v[2],
    )


@njit(cache=True)
def face_map(m: ModelArrays, s: State, sc: Scratch, fo: int, ft: int) -> FaceMap:
    """The map from owner face ``fo`` to target face ``ft`` at the current poses."""
    o = m.face_block[fo]
    t = m.face_block[ft]
    ro = sc.rotation[o]
    rt = sc.rotation[t]
    ox, oy, oz = _rot(ro, m.face_origin[fo])
    ox += s.position[o, 0]
    oy += s.position[o, 1]
    oz += s.position[o, 2]
    eux, euy, euz = _rot(ro, m.face_u[fo])
    ewx, ewy, ewz = _rot(ro, m.face_w[fo])
    px, py, pz = _rot(rt, m.face_origin[ft])
    px += s.position[t, 0]
    py += s.position[t, 1]
    pz += s.position[t, 2]
    fux, fuy, fuz = _rot(rt, m.face_u[ft])
    fwx, fwy, fwz = _rot(rt, m.face_w[ft])
    nx, ny, nz = _rot(rt, m.face_normal[ft])
    dx, dy, dz = ox - px, oy - py, oz - pz
    m00 = eux * fux + euy * fuy + euz * fuz
    m01 = ewx * fux + ewy * fuy + ewz * fuz
    m10 = eux * fwx + euy * fwy + euz * fwz
    m11 = ewx * fwx + ewy * fwy + ewz * fwz
    return FaceMap(
        ox, oy, oz, eux, euy, euz, ewx, ewy, ewz, nx, ny, nz,
        m00, m01, m10, m11,
        dx * fux + dy * fuy + dz * fuz,
        dx * fwx + dy * fwy + dz * fwz,
        dx * nx + dy * ny + dz * nz,
        eux * nx + euy * ny + euz * nz,
        ewx * nx + ewy * ny + ewz * nz,
        m00 * m11 - m01 * m10,
    )


@njit(cache=True)
def cover(m: ModelArrays, sc: Scratch, p: int, ft: int, fm: FaceMap, grow: float) -> tuple[float, float, float]:
    """Effective area [m^2] of point p against target face ``ft`` (its cell clipped by the target
    polygon grown by ``grow`` [m]) and where its force acts, (u, w) in owner face coordinates.

    Returns (0, u, w) when the cell is not covered at all.
    """
    c0 = m.point_cell_start[p]
    nv = m.point_cell_start[p + 1] - c0
    a = sc.poly_a
    for k in range(nv):
        cu = m.cell_vertex[c0 + k, 0]
        cw = m.cell_vertex[c0 + k, 1]
        a[k, 0] = fm.m00 * cu + fm.m01 * cw + fm.t0
        a[k, 1] = fm.m10 * cu + fm.m11 * cw + fm.t1
    l0 = m.face_line_start[ft]
    l1 = m.face_line_start[ft + 1]
    nu = m.point_node[p, 0]
    nw = m.point_node[p, 1]
    xu = fm.m00 * nu + fm.m01 * nw + fm.t0
    xw = fm.m10 * nu + fm.m11 * nw + fm.t1
    clipped = False
    node_in = True
    n = nv
    src = sc.poly_a
    dst = sc.poly_b
    for li in range(l0, l1):
        lu = m.face_line[li, 0]
        lw = m.face_line[li, 1]
        lo = m.face_line[li, 2] + grow
        worst = -np.inf
        for k in range(n):
            worst = max(worst, lu * src[k, 0] + lw * src[k, 1] - lo)
        if worst <= INSIDE_TOL:
            continue
        if lu * xu + lw * xw - lo > INSIDE_TOL:
            node_in = False
        n = clip_halfplane(src, n, lu, lw, lo, dst)
        clipped = True
        src, dst = dst, src
        if n < 3:
            return 0.0, nu, nw
    if not clipped:
        return m.point_area[p], nu, nw
    area = abs(polygon_area(src, n)) / abs(fm.det)
    # The force point of a partly covered cell: from the point itself (or the nearest covered point
    # when the point is off the target) towards the deepest covered vertex, as far as that vertex is
    # deeper (relative to the touching tolerance) and the cell is uncovered (relative to
    # COVER_BLEND). On a flat joint nothing moves; where an edge of the other block crosses the cell
    # (a tilted block on the edge of a narrower one) the cell is held on that edge.
    if node_in:
        nu_, nw_ = xu, xw
    else:
        nu_, nw_ = nearest_on_polygon(src, n, xu, xw)
    inv = 1.0 / fm.det
    gu = inv * (fm.hu * fm.m11 - fm.hw * fm.m10)  # height above the target plane in target coordinates
    gw = inv * (-fm.hu * fm.m01 + fm.hw * fm.m00)
    du_, dw_ = deepest_vertex(src, n, 0.0, gu, gw, nu_, nw_, DEPTH_TIE)
    gain = gu * (nu_ - du_) + gw * (nw_ - dw_)
    uncovered = 1.0 - area / m.point_area[p]
    wgt = min(max(gain / m.touch_tol, 0.0), 1.0) * min(max(uncovered / COVER_BLEND, 0.0), 1.0)
    if node_in and wgt == 0.0:
        return area, nu, nw
    yu = nu_ + wgt * (du_ - nu_)
    yw = nw_ + wgt * (dw_ - nw_)
    # back to owner coordinates
    du, dw = yu - fm.t0, yw - fm.t1
    return area, inv * (fm.m11 * du - fm.m01 * dw), inv * (-fm.m10 * du + fm.m00 * dw)
