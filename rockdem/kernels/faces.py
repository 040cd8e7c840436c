"""Face-to-face sub-contacts: how much of a point's tributary cell a partner face covers, and where.

An owner face (carrying the interface points) is pressed against a target face of another block.
The owner face coordinates (u, w) map affinely onto the target face coordinates (u', w') by the
projection along the target normal; the height of an owner-plane point above the target plane is
affine too. A point's *effective area* is the part of its tributary cell that the target polygon
covers (the cell clipped by the target's edge lines); its force acts at the point itself when the
cell is covered (the paper's interface-point quadrature, §3.3); a partly covered cell's force
moves from the point (or the nearest covered point) towards the deepest covered point, as far as
that is deeper and the cell uncovered (nothing on a flat joint; all the way where an edge of the
other block crosses a tilted cell). The
area varies continuously as the blocks slide, so a sub-contact's force fades out smoothly as it
leaves its partner instead of switching a full spring on or off; and an edge lying across a
narrow face (a tilted block landing on a wall top) is held where it actually crosses the face.
See ``docs/contacts.md``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .layout import ModelArrays, Scratch, State
from .polygon import clip_edge, clip_halfplane, deepest_point, nearest_on_polygon, polygon_area

INSIDE_TOL = 1e-10
"""[m] a cell vertex this close outside a target edge counts as inside (round-off of flush joints)."""

DEPTH_TIE = 1.0
"""The least depth band of a covered cell's deepest point, in touching tolerances: the vertices
this close in depth to the deepest share it, so that on a cell pressed flat it slides along the
cell as its ends' depths cross instead of jumping from end to end (docs/contacts.md section 2)."""

DEPTH_BLEND = 0.1
"""Covered-cell vertices within this share of the cell's depth range of the deepest share its
deepest point (:func:`rockdem.kernels.polygon.deepest_point`)."""

OFF_BLEND = 10.0
"""A point off its target polygon by this many touching tolerances has its force at the deepest
covered point of its cell (the blend towards it starts as the point leaves the polygon)."""

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


@njit(cache=True, _nrt=False, inline="always")
def _rot(r: np.ndarray, v: np.ndarray) -> tuple[float, float, float]:
    return (
        r[0, 0] * v[0] + r[0, 1] * v[1] + r[0, 2] * v[2],
        r[1, 0] * v[0] + r[1, 1] * v[1] + r[1, 2] * v[2],
        r[2, 0] * v[0] + r[2, 1] * v[1] + r[2, 2] * v[2],
    )


@njit(cache=True, _nrt=False, inline="always")
def face_map(m: ModelArrays, s: State, sc: Scratch, fo: int, ft: int) -> FaceMap:
    """The map from owner face ``fo`` to target face ``ft`` at the current poses."""
    return face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position, fo, ft)


@njit(cache=True, _nrt=False, inline="always")
def face_map_arrays(
    face_block: np.ndarray, face_origin: np.ndarray, face_u: np.ndarray, face_w: np.ndarray, face_normal: np.ndarray,
    rotation: np.ndarray, position: np.ndarray, fo: int, ft: int,
) -> FaceMap:
    """:func:`face_map` from the arrays it reads (call this one inside compiled loops: an inlined
    function taking the model or state tuples makes Numba count references to all their arrays)."""
    o = face_block[fo]
    t = face_block[ft]
    ro = rotation[o]
    rt = rotation[t]
    ox, oy, oz = _rot(ro, face_origin[fo])
    ox += position[o, 0]
    oy += position[o, 1]
    oz += position[o, 2]
    eux, euy, euz = _rot(ro, face_u[fo])
    ewx, ewy, ewz = _rot(ro, face_w[fo])
    px, py, pz = _rot(rt, face_origin[ft])
    px += position[t, 0]
    py += position[t, 1]
    pz += position[t, 2]
    fux, fuy, fuz = _rot(rt, face_u[ft])
    fwx, fwy, fwz = _rot(rt, face_w[ft])
    nx, ny, nz = _rot(rt, face_normal[ft])
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


@njit(cache=True, _nrt=False, inline="always")
def _quad_to_target(
    cell_vertex: np.ndarray, c0: int, fm: FaceMap
) -> tuple[float, float, float, float, float, float, float, float]:
    """The four vertices ``cell_vertex[c0:c0 + 4]`` of a cell in the target face's coordinates:
    (u'_0, w'_0, ..., u'_3, w'_3) [m] (the arithmetic of :func:`_cell_to_target`)."""
    return (
        fm.m00 * cell_vertex[c0, 0] + fm.m01 * cell_vertex[c0, 1] + fm.t0,
        fm.m10 * cell_vertex[c0, 0] + fm.m11 * cell_vertex[c0, 1] + fm.t1,
        fm.m00 * cell_vertex[c0 + 1, 0] + fm.m01 * cell_vertex[c0 + 1, 1] + fm.t0,
        fm.m10 * cell_vertex[c0 + 1, 0] + fm.m11 * cell_vertex[c0 + 1, 1] + fm.t1,
        fm.m00 * cell_vertex[c0 + 2, 0] + fm.m01 * cell_vertex[c0 + 2, 1] + fm.t0,
        fm.m10 * cell_vertex[c0 + 2, 0] + fm.m11 * cell_vertex[c0 + 2, 1] + fm.t1,
        fm.m00 * cell_vertex[c0 + 3, 0] + fm.m01 * cell_vertex[c0 + 3, 1] + fm.t0,
        fm.m10 * cell_vertex[c0 + 3, 0] + fm.m11 * cell_vertex[c0 + 3, 1] + fm.t1,
    )


@njit(cache=True, _nrt=False, inline="always")
def _quad_distances(
    a0: float, b0: float, a1: float, b1: float, a2: float, b2: float, a3: float, b3: float, lu: float, lw: float, lo: float,
) -> tuple[float, float, float, float]:
    """Signed distances lu u' + lw w' - lo of a quad's four vertices (u'_k, w'_k) = (a_k, b_k) from a
    target edge line (> 0: outside; the arithmetic of :func:`rockdem.kernels.polygon.clip_halfplane`)."""
    return lu * a0 + lw * b0 - lo, lu * a1 + lw * b1 - lo, lu * a2 + lw * b2 - lo, lu * a3 + lw * b3 - lo


COVER_FULL = 1
COVER_NONE = 0
COVER_PART = -1


ALL_LINES = -1
"""Line mask of :func:`covered` that tests every edge line of the target face."""

MASK_LINES = 62
"""Faces with more edge lines than this are tested line by line (:func:`crossing_lines` masks
only up to this many)."""


@njit(cache=True, _nrt=False, inline="always")
def crossing_lines(
    corner_start: np.ndarray, corner_uw: np.ndarray, line_start: np.ndarray, line: np.ndarray,
    fo: int, ft: int, fm: FaceMap,
) -> int:
    """Which edge lines of target face ``ft`` cross owner face ``fo`` (mapped by ``fm``): a bit mask
    (bit i: line ``line_start[ft] + i``) for :func:`covered`, or -2 when one line leaves the whole
    owner face outside (no cell covered).

    Every cell lies in its face, and a line's signed distance is affine, so a line that leaves all
    the face's corners inside (within INSIDE_TOL) leaves every cell inside: only the crossing lines
    need testing per cell (none for a flush joint, one where a head joint crosses a bed joint), with
    the same answer as testing them all. ALL_LINES for faces with more than MASK_LINES lines.
    A line's distance is affine in the owner's (u, w), so it is one affine function of the corners'
    face coordinates ``corner_uw`` (no mapped copy of them is made).
    """
    l0 = line_start[ft]
    nl = line_start[ft + 1] - l0
    if nl > MASK_LINES:
        return ALL_LINES
    c0 = corner_start[fo]
    c1 = corner_start[fo + 1]
    mask = 0
    for i in range(nl):
        lu = line[l0 + i, 0]
        lw = line[l0 + i, 1]
        # d(u, w) = lu u' + lw w' - lo with (u', w') the target coordinates of owner point (u, w).
        du = lu * fm.m00 + lw * fm.m10
        dw = lu * fm.m01 + lw * fm.m11
        d0 = lu * fm.t0 + lw * fm.t1 - line[l0 + i, 2]
        hi = low = du * corner_uw[c0, 0] + dw * corner_uw[c0, 1] + d0
        for c in range(c0 + 1, c1):
            d = du * corner_uw[c, 0] + dw * corner_uw[c, 1] + d0
            hi = max(hi, d)
            low = min(low, d)
        if low > INSIDE_TOL:
            mask = -2
            break
        if hi > INSIDE_TOL:
            mask |= 1 << i
    return mask


@njit(cache=True, _nrt=False, inline="always")
def covered(
    cell_start: np.ndarray, cell_vertex: np.ndarray, line_start: np.ndarray, line: np.ndarray,
    p: int, ft: int, fm: FaceMap, grow: float, mask: int,
) -> int:
    """Whether the target polygon (grown by ``grow``) covers the cell of point p wholly
    (COVER_FULL), not at all because one of its edge lines leaves the cell outside (COVER_NONE), or
    in part (COVER_PART, to be clipped by :func:`partly_covered`). Only the lines of ``mask``
    (:func:`crossing_lines`, or ALL_LINES) are tested."""
    full = True
    none = False
    c0 = cell_start[p]
    nv = cell_start[p + 1] - c0
    l0 = line_start[ft]
    if nv == 4:  # the usual rectangular cell: its corners mapped once
        a0, b0, a1, b1, a2, b2, a3, b3 = _quad_to_target(cell_vertex, c0, fm)
        for li in range(l0, line_start[ft + 1]):
            if mask != ALL_LINES and not (mask >> (li - l0)) & 1:
                continue
            lo = line[li, 2] + grow
            d0, d1, d2, d3 = _quad_distances(a0, b0, a1, b1, a2, b2, a3, b3, line[li, 0], line[li, 1], lo)
            if max(max(d0, d1), max(d2, d3)) > INSIDE_TOL:
                full = False
                none = none or min(min(d0, d1), min(d2, d3)) >= -INSIDE_TOL
    else:
        for li in range(l0, line_start[ft + 1]):
            if mask != ALL_LINES and not (mask >> (li - l0)) & 1:
                continue
            lu = line[li, 0]
            lw = line[li, 1]
            lo = line[li, 2] + grow
            low = np.inf
            for k in range(c0, c0 + nv):
                cu = cell_vertex[k, 0]
                cw = cell_vertex[k, 1]
                d = lu * (fm.m00 * cu + fm.m01 * cw + fm.t0) + lw * (fm.m10 * cu + fm.m11 * cw + fm.t1) - lo
                if d > INSIDE_TOL:
                    full = False
                low = min(low, d)
            none = none or low >= -INSIDE_TOL
    if none:
        return COVER_NONE
    return COVER_FULL if full else COVER_PART


@njit(cache=True, _nrt=False, inline="always")
def _cell_to_target(cell_start: np.ndarray, cell_vertex: np.ndarray, buf: np.ndarray, p: int, fm: FaceMap) -> int:
    """Cell p's polygon in the target face's coordinates into ``buf[0]``; returns its vertex count."""
    c0 = cell_start[p]
    nv = cell_start[p + 1] - c0
    for k in range(nv):
        cu = cell_vertex[c0 + k, 0]
        cw = cell_vertex[c0 + k, 1]
        buf[0, k, 0] = fm.m00 * cu + fm.m01 * cw + fm.t0
        buf[0, k, 1] = fm.m10 * cu + fm.m11 * cw + fm.t1
    return nv


@njit(cache=True, _nrt=False, inline="always")
def anchored_overlap(
    fm: FaceMap, nu: float, nw: float, au: float, aw: float, eu: float, ew: float, cover_w: float, touch_tol: float,
) -> float:
    """Overlap [m] of point (nu, nw)'s cell at the pose of ``fm``, measured as :func:`partly_covered`
    measures it, with its cover weight w, anchor q = (au, aw) and deepest covered point d = (eu, ew)
    (owner face coordinates [m]) kept: u_q + w phi(g), or the point's own overlap where w is 0
    (q and d are then not read). With those of the last step: how deep the cell would be now had
    its cover not moved."""
    if cover_w == 0.0:
        return -(fm.h0 + fm.hu * nu + fm.hw * nw)
    uq = -(fm.h0 + fm.hu * au + fm.hw * aw)
    g = -(fm.hu * (eu - au) + fm.hw * (ew - aw))
    if g <= 0.0:
        return uq
    return uq + cover_w * (g * g / (2.0 * touch_tol) if g < touch_tol else g - 0.5 * touch_tol)


@njit(cache=True, _nrt=False, inline="always")
def partly_covered(
    cell_start: np.ndarray, cell_vertex: np.ndarray, line_start: np.ndarray, line: np.ndarray, buf: np.ndarray,
    nu: float, nw: float, point_area: float, touch_tol: float, p: int, ft: int, fm: FaceMap, grow: float,
    lumped: bool, target_cell_area: float, mask: int,
) -> tuple[float, float, float, float, float, float, float, float, float]:
    """Effective area, force point (u, w), depth shift, cover weight, anchor (u, w) and deepest
    covered vertex (u, w) of a cell the target polygon does not wholly cover (clipped by the
    target's edge lines in ``mask``, :func:`crossing_lines`); points in owner face coordinates [m].

    The force point: from the point p (or the nearest covered point q when p is off the target)
    towards the deepest covered point d (:func:`rockdem.kernels.polygon.deepest_point`: the mean of
    the covered vertices near the deepest, continuous as they cross), by w phi'(g): w the cover
    weight (how much of the cell is uncovered relative to COVER_BLEND, or how far p is off the
    target), g = u_d - u_p how much deeper d is, phi the ramp smoothed over tau = touch_tol (phi(g) = g^2 / (2 tau) below tau,
    g - tau / 2 above, phi' = min(g / tau, 1)). The overlap of the sub-contact is
    u = u_p + w phi(g), whose gradient in the blocks' motion is exactly a unit normal force at that
    point (for fixed w, q and d): the spring is then the gradient of its energy kn A u^2 / 2 and
    conserves energy as the block rocks. (The overlap at the force point, u_p + w phi'(g) g, is
    deeper by up to w tau / 2, and made a block tipping over an edge gain energy.) Returns the shift
    u - overlap at the force point (<= 0), the cover weight w [-], the anchor (p, or q when p is
    off the target) and d (:func:`anchored_overlap` gives u from them). As the cover
    slides, w, the anchor and d move, and with them u at a fixed pose, which the joint law treats
    as a cover change (:func:`rockdem.kernels.forces.cover_change`, :func:`anchored_overlap`).

    With ``lumped`` (unbonded sub-contacts) the effective area is the cell area times the fraction
    of the cell's *overlapping* part (below the target plane) that the target covers: a tilted
    corner or edge landing near the partner's edge is as stiff as the same corner landing in the
    middle of the face (the paper's interface point carries its whole tributary area), and the
    stiffness still falls continuously to zero as the overlapping part leaves the partner. Where the
    whole cell overlaps (a flat joint) this is the covered area itself. The lumped area is at most
    ``target_cell_area`` [m^2] (the mean cell of the target face) or the covered area, whichever is
    larger: a big cell whose sliver presses on a small face (a wall face on a 20 mm rod) is as stiff
    as the small face's own interface point, as an EDGE pair is as stiff as the smaller side's.
    """
    nv = _cell_to_target(cell_start, cell_vertex, buf, p, fm)
    xu = fm.m00 * nu + fm.m01 * nw + fm.t0
    xw = fm.m10 * nu + fm.m11 * nw + fm.t1
    node_in = True
    n = nv
    cur = 0  # the buffer holding the current polygon
    l0 = line_start[ft]
    for li in range(l0, line_start[ft + 1]):
        if mask != ALL_LINES and not (mask >> (li - l0)) & 1:
            continue
        lu = line[li, 0]
        lw = line[li, 1]
        lo = line[li, 2] + grow
        worst = -np.inf
        for k in range(n):
            worst = max(worst, lu * buf[cur, k, 0] + lw * buf[cur, k, 1] - lo)
        if worst > INSIDE_TOL and n >= 3:
            if lu * xu + lw * xw - lo > INSIDE_TOL:
                node_in = False
            n = clip_halfplane(buf, cur, n, lu, lw, lo)
            cur = 1 - cur
    return _cover_tail(
        cell_start, cell_vertex, buf, cur, n, xu, xw, node_in, nu, nw, point_area, touch_tol, p, fm, lumped, target_cell_area,
    )


@njit(cache=True, _nrt=False, inline="always")
def _cover_tail(
    cell_start: np.ndarray, cell_vertex: np.ndarray, buf: np.ndarray, cur: int, n: int, xu: float, xw: float,
    node_in: bool, nu: float, nw: float, point_area: float, touch_tol: float, p: int, fm: FaceMap, lumped: bool,
    target_cell_area: float,
) -> tuple[float, float, float, float, float, float, float, float, float]:
    """:func:`partly_covered` from the cell's covered part ``buf[cur, :n]`` (target coordinates)
    on: point (nu, nw) maps to (xu, xw), inside the target when ``node_in``."""
    area = abs(polygon_area(buf, cur, n)) / abs(fm.det) if n >= 3 else 0.0
    yu, yw = nu, nw
    shift = 0.0
    cover_w = 0.0
    au, aw, eu, ew = nu, nw, nu, nw
    if area > 0.0:
        # The force point of a partly covered cell: from the point itself (or the nearest covered
        # point when the point is off the target) towards the deepest covered point, as far as that
        # point is deeper (relative to the touching tolerance) and the cell is uncovered (relative
        # to COVER_BLEND). On a flat joint nothing moves; where an edge of the other block crosses
        # the cell (a tilted block on the edge of a narrower one) the cell is held on that edge.
        if node_in:
            nu_, nw_ = xu, xw
        else:
            nu_, nw_ = nearest_on_polygon(buf, cur, n, xu, xw)
        inv = 1.0 / fm.det
        gu = inv * (fm.hu * fm.m11 - fm.hw * fm.m10)  # height above the target plane in target coordinates
        gw = inv * (-fm.hu * fm.m01 + fm.hw * fm.m00)
        du_, dw_ = deepest_point(buf, cur, n, gu, gw, DEPTH_BLEND, DEPTH_TIE * touch_tol)
        gain = gu * (nu_ - du_) + gw * (nw_ - dw_)
        uncovered = 1.0 - area / point_area
        # A point off the target is no interface point of this contact any more: the farther off
        # (relative to the tracking tolerance, 10 touch_tol), the more the force goes to the deepest
        # covered vertex however little of the cell is uncovered (an edge lying across the
        # target's boundary is held where it crosses it).
        off = 0.0 if node_in else math.hypot(nu_ - xu, nw_ - xw) / (OFF_BLEND * touch_tol)
        cover_w = min(max(uncovered / COVER_BLEND, off, 0.0), 1.0)
        slope = min(max(gain / touch_tol, 0.0), 1.0)
        wgt = slope * cover_w
        if gain > 0.0:  # u_p + w phi(g) minus the overlap at the force point, u_p + w phi'(g) g
            shift = -cover_w * min(gain, touch_tol) ** 2 / (2.0 * touch_tol)
        if not (node_in and wgt == 0.0):
            tu = nu_ + wgt * (du_ - nu_) - fm.t0
            tw = nw_ + wgt * (dw_ - nw_) - fm.t1
            yu = inv * (fm.m11 * tu - fm.m01 * tw)  # back to owner coordinates
            yw = inv * (-fm.m10 * tu + fm.m00 * tw)
        if not node_in:
            au = inv * (fm.m11 * (nu_ - fm.t0) - fm.m01 * (nw_ - fm.t1))
            aw = inv * (-fm.m10 * (nu_ - fm.t0) + fm.m00 * (nw_ - fm.t1))
        eu = inv * (fm.m11 * (du_ - fm.t0) - fm.m01 * (dw_ - fm.t1))
        ew = inv * (-fm.m10 * (du_ - fm.t0) + fm.m00 * (dw_ - fm.t1))
        if lumped and _straddles(cell_start, cell_vertex, p, fm):
            # (A cell wholly on one side of the target plane has the lumped area of its covered part.)
            area = max(area, min(_lumped_area(cell_start, cell_vertex, buf, cur, n, point_area, area, p, fm, gu, gw), target_cell_area))
    return area, yu, yw, shift, cover_w, au, aw, eu, ew


@njit(cache=True, _nrt=False, inline="always")
def _straddles(cell_start: np.ndarray, cell_vertex: np.ndarray, p: int, fm: FaceMap) -> bool:
    """Whether the cell of point p has vertices both above and below the target plane (only then
    does its lumped area differ from its covered area, :func:`_lumped_area`)."""
    above = False
    below = False
    for k in range(cell_start[p], cell_start[p + 1]):
        h = fm.h0 + fm.hu * cell_vertex[k, 0] + fm.hw * cell_vertex[k, 1]
        above = above or h > 0.0
        below = below or h < 0.0
    return above and below


@njit(cache=True, _nrt=False, inline="always")
def _lumped_area(
    cell_start: np.ndarray, cell_vertex: np.ndarray, buf: np.ndarray, cur: int, n: int, point_area: float, area: float,
    p: int, fm: FaceMap, gu: float, gw: float,
) -> float:
    """Cell area x |covered part below the target plane| / |cell part below the target plane|;
    ``buf[cur, :n]`` holds the covered part (target coordinates, overwritten), gu, gw the height
    gradient in target coordinates. Falls back to ``area`` where no part of the cell overlaps."""
    # The overlapping half-plane h < 0: gu u' + gw w' <= -(h0 - gu t0 - gw t1).
    lo = -(fm.h0 - gu * fm.t0 - gw * fm.t1)
    m = clip_halfplane(buf, cur, n, gu, gw, lo)
    covered_below = abs(polygon_area(buf, 1 - cur, m)) / abs(fm.det) if m >= 3 else 0.0
    nv = _cell_to_target(cell_start, cell_vertex, buf, p, fm)
    m = clip_halfplane(buf, 0, nv, gu, gw, lo)
    below = abs(polygon_area(buf, 1, m)) / abs(fm.det) if m >= 3 else 0.0
    if below <= 1e-12 * point_area:
        return area
    return point_area * min(covered_below / below, 1.0)


@njit(cache=True, _nrt=False, inline="always")
def cell_above(cell_start: np.ndarray, cell_vertex: np.ndarray, p: int, h0: float, hu: float, hw: float) -> bool:
    """Whether no vertex of point p's cell is below the target plane (height h0 + hu u + hw w [m] of
    the face map). The overlap is affine in the cell, so then no point of it overlaps whatever
    covers it: an unbonded sub-contact open at the last step stays open and carries nothing, and
    needs no clipping (its area is not used). In a settled wall this is about 40 % of the cut
    cells: the head faces of diagonal neighbours, overlapping the next face by a sliver of the
    settlement difference, about half of them just apart."""
    for k in range(cell_start[p], cell_start[p + 1]):
        if not h0 + hu * cell_vertex[k, 0] + hw * cell_vertex[k, 1] >= 0.0:  # (NaN: not above)
            return False
    return True


@njit(cache=True, _nrt=False, inline="always")
def _cut_quad(
    cell_start: np.ndarray, cell_vertex: np.ndarray, line: np.ndarray, li: int, buf: np.ndarray,
    nu: float, nw: float, point_area: float, touch_tol: float, p: int, fm: FaceMap, grow: float,
    lumped: bool, target_cell_area: float,
) -> tuple[float, float, float, float, float, float, float, float, float]:
    """:func:`cut_cell` of a four-vertex cell against the one target edge line ``li`` that crosses
    its face: :func:`covered` and :func:`partly_covered` in one pass, the cell's corners mapped
    once and clipped unrolled. The same arithmetic in the same order, so the same answer bit for
    bit for finite input (tests/test_contacts.py checks it on random cells, maps and lines)."""
    c0 = cell_start[p]
    a0, b0, a1, b1, a2, b2, a3, b3 = _quad_to_target(cell_vertex, c0, fm)
    lu = line[li, 0]
    lw = line[li, 1]
    lo = line[li, 2] + grow
    d0, d1, d2, d3 = _quad_distances(a0, b0, a1, b1, a2, b2, a3, b3, lu, lw, lo)
    if not max(max(d0, d1), max(d2, d3)) > INSIDE_TOL:  # (the tests of covered())
        return point_area, nu, nw, 0.0, 0.0, nu, nw, nu, nw
    if min(min(d0, d1), min(d2, d3)) >= -INSIDE_TOL:
        return 0.0, nu, nw, 0.0, 0.0, nu, nw, nu, nw
    xu = fm.m00 * nu + fm.m01 * nw + fm.t0
    xw = fm.m10 * nu + fm.m11 * nw + fm.t1
    node_in = not lu * xu + lw * xw - lo > INSIDE_TOL
    n = clip_edge(buf, 1, 0, a3, b3, d3, a0, b0, d0)
    n = clip_edge(buf, 1, n, a0, b0, d0, a1, b1, d1)
    n = clip_edge(buf, 1, n, a1, b1, d1, a2, b2, d2)
    n = clip_edge(buf, 1, n, a2, b2, d2, a3, b3, d3)
    return _cover_tail(
        cell_start, cell_vertex, buf, 1, n, xu, xw, node_in, nu, nw, point_area, touch_tol, p, fm, lumped, target_cell_area,
    )


@njit(cache=True, _nrt=False)
def cut_cell(
    cell_start: np.ndarray, cell_vertex: np.ndarray, line_start: np.ndarray, line: np.ndarray, buf: np.ndarray,
    nu: float, nw: float, point_area: float, touch_tol: float, p: int, ft: int, fm: FaceMap, grow: float,
    mask: int, lumped: bool, target_cell_area: float,
) -> tuple[float, float, float, float, float, float, float, float, float]:
    """Effective area, force point (u, w), depth shift, cover weight, anchor (u, w) and
    deepest covered point (u, w) (those of :func:`partly_covered`; no shift and weight, and the
    node as anchor and vertex, for a cell wholly covered or not at all) of point p's cell (node (nu, nw), area
    ``point_area``) against target face ``ft`` grown by ``grow`` [m], tested against the target
    edge lines of ``mask`` (:func:`crossing_lines`, or ALL_LINES): :func:`covered`, then
    :func:`partly_covered` (``lumped``, ``target_cell_area`` as there) where the cell is cut.
    Compiled out of line, so that the joint law's loop stays small for flush joints. (An unbonded
    cell open at the last step and wholly above the target plane, :func:`cell_above`, is not
    clipped at all: the joint law tests that first.) A four-vertex cell crossed by one line (most
    cut cells: a face sliding off its partner's edge, a wall's diagonal neighbours) takes
    :func:`_cut_quad`, the same answer bit for bit in fewer operations (settled 1000-brick wall:
    75 against 83 ns per cut cell in cache, docs/performance.md)."""
    if mask > 0 and mask & (mask - 1) == 0 and cell_start[p + 1] - cell_start[p] == 4:
        li = line_start[ft]
        while not mask & 1:
            mask >>= 1
            li += 1
        return _cut_quad(
            cell_start, cell_vertex, line, li, buf, nu, nw, point_area, touch_tol, p, fm, grow, lumped, target_cell_area,
        )
    state = covered(cell_start, cell_vertex, line_start, line, p, ft, fm, grow, mask)
    if state == COVER_FULL:
        return point_area, nu, nw, 0.0, 0.0, nu, nw, nu, nw
    if state == COVER_NONE:
        return 0.0, nu, nw, 0.0, 0.0, nu, nw, nu, nw
    return partly_covered(
        cell_start, cell_vertex, line_start, line, buf, nu, nw, point_area, touch_tol, p, ft, fm, grow,
        lumped, target_cell_area, mask,
    )


@njit(cache=True, _nrt=False, inline="always")
def cover(m: ModelArrays, sc: Scratch, p: int, ft: int, fm: FaceMap, grow: float) -> tuple[float, float, float, float]:
    """Effective area [m^2] of point p against target face ``ft`` (its cell clipped by the target
    polygon grown by ``grow`` [m]) and where its force acts, (u, w) in owner face coordinates.

    Also returns the depth shift of :func:`partly_covered` (0 for a wholly covered cell); returns
    (0, u, w, 0) when the cell is not covered at all. (The work is split into two functions
    taking only the arrays they use: Numba compiles such small functions far better than one
    taking the whole model and scratch tuples, 50 ns instead of 1 us per sub-contact.)
    """
    area, yu, yw, shift, _, _, _, _, _ = cut_cell(
        m.point_cell_start, m.cell_vertex, m.face_line_start, m.face_line, sc.poly,
        m.point_node[p, 0], m.point_node[p, 1], m.point_area[p], m.touch_tol, p, ft, fm, grow, ALL_LINES, False, np.inf,
    )
    return area, yu, yw, shift
