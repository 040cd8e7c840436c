"""Contact detection: bounding-box broad phase, separating-axis narrow phase, sub-contact slots.

For each pair of blocks whose bounding boxes (grown by the tracking tolerance) overlap, every
candidate separating axis is tried: the face normals of both blocks and the cross products of
their edge directions. The axis of largest separation decides (face axes win ties):

* separation above the tolerance: the blocks are apart, no contact;
* a face normal: a FACE pair. Its reference face is that face; the *incident* face is the face of
  the other block most opposed to it. The smaller of the two (tie: lower block id) is the *owner*:
  its interface points whose tributary cells the other (*target*) face covers, within the
  tolerance, become sub-contacts (:mod:`rockdem.kernels.faces`);
* an edge x edge axis: an EDGE pair, one point contact between the two edges (crossing edges,
  ridge on ridge).

A point holds up to ``SLOTS`` partners at once (a point on the line where two partner faces meet
covers both). A slot keeps its history (shear, bond) while its partner block stays the same;
a slot whose partner is gone is released (a bond torn off counts as a tension failure, stored
shear energy as friction). Tracked sub-contacts are listed pair by pair in the pair order, which
is fixed by the broad phase, so the force accumulation order (and the results) are deterministic.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .blend import face_clearance, tracks_target
from .contact import spring_energy
from .faces import anchored_overlap, cover, face_map
from .layout import (
    E_BOND,
    E_FRICTION,
    FAILED_SHEAR,
    FAILED_TENSION,
    PAIR_EDGE,
    PAIR_FACE,
    SLOTS,
    STIFFENING_AT_START,
    ModelArrays,
    Scratch,
    State,
)
from .polygon import segment_closest
from .rotation import quat_to_matrix
from .sort import sort_indices

EDGE_AXIS_BIAS = 1e-3
"""An edge x edge axis must separate by more than the best face axis plus this fraction of the
tracking tolerance to be chosen (face axes win ties: an edge resting on a face is a face contact)."""

EDGE_AXIS_MARGIN = 0.5
"""... and plus this fraction of the face axis' overlap: an edge lying across a face, whose edge
axes nearly match the face normal, stays a face contact (its sub-contacts hold it where it crosses
the face), while crossing edges, whose face axes overlap far more than their edge axis, are
edge-edge contacts. Without the margin a tilting edge flips between the two representations.
An EDGE pair keeps its edge axis without the margin (:func:`separating_axes`, ``was_edge``): with
it, two random convex blocks whose edges crossed (edge axis 0.49 mm deep, the small face's 0.72)
turned into a face contact on the 3.4 cm^2 face as they pressed, whose points missed the crossing;
the 5.6 kg block went on at 1.7 m/s, 2.2 mm deep the face pair tracked no point, and it passed
through the other (21 mm, the run stopped). The margin applies only to edge axes within
EDGE_MARGIN_ANGLE of the face normal."""

EDGE_MARGIN_ANGLE = 10.0
"""[deg] EDGE_AXIS_MARGIN holds only for edge axes this close to the best face axis (an edge lying
across a face, the case it is for). An edge axis further off is another contact, which wins when it
overlaps less: a hull's corner sliding past the edge of a 21 cm^2 face, its face pair's one point
0.35 mm outside that face and so without area, went 7.8 mm into the other block without a force
while the edge axis (27 degrees off, 6.8 mm) lost to the face axis (7.8 mm) by the margin; its face
springs then switched on with 11 J."""

_EDGE_MARGIN_COS = math.cos(math.radians(EDGE_MARGIN_ANGLE))


@njit(cache=True, _nrt=False)
def update_rotations(m: ModelArrays, s: State, sc: Scratch) -> None:
    """Rotation matrices of every block from its quaternion."""
    for b in range(m.block_mass.shape[0]):
        quat_to_matrix(s.quaternion[b], sc.rotation[b])


@njit(cache=True, _nrt=False)
def _block_world_vertices(m: ModelArrays, s: State, sc: Scratch, b: int) -> None:
    """``sc.world_vertex`` of block b's vertices at its current pose (rotation current)."""
    r = sc.rotation[b]
    for v in range(m.block_vertex_start[b], m.block_vertex_start[b + 1]):
        for i in range(3):
            sc.world_vertex[v, i] = (r[i, 0] * m.vertex_local[v, 0] + r[i, 1] * m.vertex_local[v, 1]
                                     + r[i, 2] * m.vertex_local[v, 2] + s.position[b, i])


@njit(cache=True, _nrt=False)
def _world_vertices(m: ModelArrays, s: State, sc: Scratch) -> None:
    """World vertices of every block and their bounding boxes grown by the tracking tolerance."""
    for b in range(m.block_mass.shape[0]):
        _block_world_vertices(m, s, sc, b)
        for i in range(3):
            sc.aabb[b, i] = np.inf
            sc.aabb[b, 3 + i] = -np.inf
        for v in range(m.block_vertex_start[b], m.block_vertex_start[b + 1]):
            for i in range(3):
                sc.aabb[b, i] = min(sc.aabb[b, i], sc.world_vertex[v, i])
                sc.aabb[b, 3 + i] = max(sc.aabb[b, 3 + i], sc.world_vertex[v, i])
        for i in range(3):
            sc.aabb[b, i] -= m.contact_tol
            sc.aabb[b, 3 + i] += m.contact_tol


@njit(cache=True, _nrt=False, inline="always")
def _extent(wv: np.ndarray, v0: int, v1: int, ax: float, ay: float, az: float) -> tuple[float, float]:
    lo = np.inf
    hi = -np.inf
    for v in range(v0, v1):
        x = ax * wv[v, 0] + ay * wv[v, 1] + az * wv[v, 2]
        lo = min(lo, x)
        hi = max(hi, x)
    return lo, hi


@njit(cache=True, _nrt=False)
def separating_axes(
    m: ModelArrays, s: State, sc: Scratch, a: int, b: int, faces: bool = True, was_edge: bool = False
) -> tuple[float, int, int, int, int, int, float, float, float]:
    """Best separating axis of blocks a and b (world vertices must be current).

    Returns (separation [m], kind, reference block, reference face, direction id of a, direction id
    of b, axis x, y, z). For a face axis the axis is the reference face's world normal; for an
    edge axis it points from b towards a. With ``faces`` False, the best edge axis (kind PAIR_FACE
    and separation -inf when the blocks have no edge axis, all their edges parallel). ``was_edge``:
    the pair is an EDGE pair (or was one at the last detection); its edge axis then keeps winning
    while it separates more than the best face axis plus EDGE_AXIS_BIAS tolerances, without
    EDGE_AXIS_MARGIN: the margin keeps a face contact from flipping to an edge contact, and would
    otherwise turn two crossing edges into a face contact as they press (EDGE_AXIS_MARGIN). The
    margin holds only for edge axes within EDGE_MARGIN_ANGLE of the best face axis.
    """
    best = -np.inf
    kind = PAIR_FACE
    ref = -1
    rface = -1
    da = -1
    db = -1
    nx = ny = nz = 0.0
    wv = sc.world_vertex
    for side in range(2 if faces else 0):
        r_, o_ = (a, b) if side == 0 else (b, a)
        rr = sc.rotation[r_]
        for f in range(m.block_face_start[r_], m.block_face_start[r_ + 1]):
            fn = m.face_normal[f]
            n0 = rr[0, 0] * fn[0] + rr[0, 1] * fn[1] + rr[0, 2] * fn[2]
            n1 = rr[1, 0] * fn[0] + rr[1, 1] * fn[1] + rr[1, 2] * fn[2]
            n2 = rr[2, 0] * fn[0] + rr[2, 1] * fn[1] + rr[2, 2] * fn[2]
            d = n0 * s.position[r_, 0] + n1 * s.position[r_, 1] + n2 * s.position[r_, 2] + m.face_offset[f]
            lo, _ = _extent(wv, m.block_vertex_start[o_], m.block_vertex_start[o_ + 1], n0, n1, n2)
            if lo - d > best:
                best, ref, rface = lo - d, r_, f
                nx, ny, nz = n0, n1, n2
    bias = 0.0 if not faces else EDGE_AXIS_BIAS * m.contact_tol + 1e-12
    margin = 0.0 if not faces or was_edge else EDGE_AXIS_MARGIN * max(-best, 0.0)
    fx, fy, fz = nx, ny, nz  # the best face axis
    ra = sc.rotation[a]
    rb = sc.rotation[b]
    for i in range(m.block_dir_start[a], m.block_dir_start[a + 1]):
        di = m.dir_local[i]
        a0 = ra[0, 0] * di[0] + ra[0, 1] * di[1] + ra[0, 2] * di[2]
        a1 = ra[1, 0] * di[0] + ra[1, 1] * di[1] + ra[1, 2] * di[2]
        a2 = ra[2, 0] * di[0] + ra[2, 1] * di[1] + ra[2, 2] * di[2]
        for j in range(m.block_dir_start[b], m.block_dir_start[b + 1]):
            dj = m.dir_local[j]
            b0 = rb[0, 0] * dj[0] + rb[0, 1] * dj[1] + rb[0, 2] * dj[2]
            b1 = rb[1, 0] * dj[0] + rb[1, 1] * dj[1] + rb[1, 2] * dj[2]
            b2 = rb[2, 0] * dj[0] + rb[2, 1] * dj[1] + rb[2, 2] * dj[2]
            l0, l1, l2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
            ln = math.sqrt(l0 * l0 + l1 * l1 + l2 * l2)
            if ln < 1e-6:
                continue
            l0, l1, l2 = l0 / ln, l1 / ln, l2 / ln
            alo, ahi = _extent(wv, m.block_vertex_start[a], m.block_vertex_start[a + 1], l0, l1, l2)
            blo, bhi = _extent(wv, m.block_vertex_start[b], m.block_vertex_start[b + 1], l0, l1, l2)
            s1 = alo - bhi  # a on the + side
            s2 = blo - ahi  # a on the - side
            sep = max(s1, s2)
            if sep > best + bias + (margin if abs(l0 * fx + l1 * fy + l2 * fz) >= _EDGE_MARGIN_COS else 0.0):
                best, kind, da, db = sep, PAIR_EDGE, i, j
                bias = margin = 0.0
                sign = 1.0 if s1 >= s2 else -1.0
                nx, ny, nz = sign * l0, sign * l1, sign * l2
    return best, kind, ref, rface, da, db, nx, ny, nz


@njit(cache=True, _nrt=False)
def _supporting_edge(m: ModelArrays, sc: Scratch, blk: int, i: int, nx: float, ny: float, nz: float, lowest: bool) -> int:
    """The edge of ``blk`` parallel to its edge direction ``i`` furthest along -n (``lowest``) or +n."""
    r = sc.rotation[blk]
    dl = m.dir_local[i]
    e0 = r[0, 0] * dl[0] + r[0, 1] * dl[1] + r[0, 2] * dl[2]
    e1 = r[1, 0] * dl[0] + r[1, 1] * dl[1] + r[1, 2] * dl[2]
    e2 = r[2, 0] * dl[0] + r[2, 1] * dl[1] + r[2, 2] * dl[2]
    best = np.inf
    out = -1
    for e in range(m.block_edge_start[blk], m.block_edge_start[blk + 1]):
        v0 = m.edge_vertex[e, 0]
        v1 = m.edge_vertex[e, 1]
        d0 = sc.world_vertex[v1, 0] - sc.world_vertex[v0, 0]
        d1 = sc.world_vertex[v1, 1] - sc.world_vertex[v0, 1]
        d2 = sc.world_vertex[v1, 2] - sc.world_vertex[v0, 2]
        ln = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if abs(d0 * e0 + d1 * e1 + d2 * e2) < (1.0 - 1e-6) * ln:
            continue
        h = 0.5 * (
            nx * (sc.world_vertex[v0, 0] + sc.world_vertex[v1, 0])
            + ny * (sc.world_vertex[v0, 1] + sc.world_vertex[v1, 1])
            + nz * (sc.world_vertex[v0, 2] + sc.world_vertex[v1, 2])
        )
        key = h if lowest else -h
        if key < best:
            best, out = key, e
    return out


INCIDENT_KEEP = 0.1
"""The incident face of the last detection is kept while its deepest vertex (along the reference
normal) is within this many tracking tolerances of the deepest vertex of the face the rule would
choose now, and every corner of that face near the reference face (below the level of
:func:`_incident_face`) is a corner of the kept face too: a block rocking on the edge between two of
its faces (both reach the same depth) keeps the face carrying its sub-contacts (each switch
re-represents a loaded contact), while a face landing flat takes over as soon as it reaches deeper,
or as soon as a corner the kept face lacks comes within the tolerance (it is about to press: it
must be tracked before it does, and only the incident face carries sub-contacts). Without that
rule a brick pivoting down onto its bed face kept its end face (they share the pivot edge) until
the bed face's far edge was 0.29 mm into the ground, and its sub-contacts switched on there with
15 J at once; until 2026-11-30 the rule asked only for *all* the corners of the most opposed face
within the tolerance, and a wedge pivoting on a vertex of a face standing upright kept that face
while the next corner of its inclined face came down onto the ground, untracked, 0.49 mm deep in
22 steps, whose spring then switched on with 25 J (12 % of the run's energy scale). (A hysteresis
in angle instead, 0.05 in cosine, kept the rounded-edge facet of a toppling façade while its
0.8 m face swung 0.12 m into the ground.)"""


@njit(cache=True, _nrt=False)
def _previous_pair(m: ModelArrays, sc: Scratch, a: int, b: int) -> int:
    """Index of pair (a, b) at the previous detection, -1 if it was not a pair (binary search)."""
    key = a * m.block_mass.shape[0] + b
    lo = 0
    hi = sc.prev_pair_count[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if sc.prev_pair_key[sc.prev_pair_index[mid]] < key:
            lo = mid + 1
        else:
            hi = mid
    if lo < sc.prev_pair_count[0] and sc.prev_pair_key[sc.prev_pair_index[lo]] == key:
        return sc.prev_pair_index[lo]
    return -1


@njit(cache=True, _nrt=False, inline="always")
def _facing(r: np.ndarray, fn: np.ndarray, nx: float, ny: float, nz: float) -> float:
    return (
        (r[0, 0] * fn[0] + r[0, 1] * fn[1] + r[0, 2] * fn[2]) * nx
        + (r[1, 0] * fn[0] + r[1, 1] * fn[1] + r[1, 2] * fn[2]) * ny
        + (r[2, 0] * fn[0] + r[2, 1] * fn[1] + r[2, 2] * fn[2]) * nz
    )


@njit(cache=True, _nrt=False)
def _face_span(m: ModelArrays, sc: Scratch, f: int, nx: float, ny: float, nz: float) -> tuple[float, float]:
    """Lowest and highest position of face f's corners along the world direction n [m] (world
    vertices current)."""
    low = np.inf
    high = -np.inf
    for c in range(m.face_corner_start[f], m.face_corner_start[f + 1]):
        v = m.face_corner[c]
        h = nx * sc.world_vertex[v, 0] + ny * sc.world_vertex[v, 1] + nz * sc.world_vertex[v, 2]
        low = min(low, h)
        high = max(high, h)
    return low, high


@njit(cache=True, _nrt=False)
def _incident_face(
    m: ModelArrays, sc: Scratch, blk: int, nx: float, ny: float, nz: float, previous: int, tol: float, plane: float
) -> int:
    """The incident face of ``blk`` against a reference face whose plane lies at ``plane`` [m]
    along the world direction n (n points from the reference face towards blk). Of the faces of blk
    at its deepest vertex along -n, the one with the largest part *near* the reference face, below
    ``level = max(deepest, plane) + tol`` along n (pressing, or about to; the most opposed to n
    among those with as large a part, :func:`_widest_face`); or ``previous`` (a face of blk, or -1)
    while it reaches as deep along -n as that face, within INCIDENT_KEEP tolerances ``tol``, and
    has every corner of that face below ``level``. So a block landing on a vertex, rocking on an
    edge or landing flat is carried by the face most nearly parallel to the reference face (the
    longest strip near an edge, the whole face), and a small facet at a vertex (a chipped corner, a
    hull's sliver) carries the contact only while no face beside it comes nearer the reference
    over a larger area: a box's edge landing whose end was chipped off by a 3.5 mm^2 facet, the
    most opposed face at the deepest vertex, pressed on that facet's points alone and sank 52 mm,
    half the box, before 2026-12-01. (Nor need the face most opposed to n among all touch: a 4 cm^2
    face 0.3 degrees from the ground's plane held no point within the tolerance while the vertex
    beside it, on a 47 cm^2 face, landed.)"""
    v = _deepest_vertex(m, sc, blk, nx, ny, nz)
    deepest = nx * sc.world_vertex[v, 0] + ny * sc.world_vertex[v, 1] + nz * sc.world_vertex[v, 2]
    level = max(deepest, plane) + tol
    out = _widest_face(m, sc, blk, nx, ny, nz, v, level)
    if out < 0:  # a vertex that is no face's corner (not in a hull rockdem builds): all faces
        out = _most_opposed(m, sc, blk, nx, ny, nz)
    if previous >= 0 and previous != out:
        low, _ = _face_span(m, sc, out, nx, ny, nz)
        if _face_span(m, sc, previous, nx, ny, nz)[0] <= low + INCIDENT_KEEP * tol and _near_corners_shared(m, sc, out, previous, nx, ny, nz, level):
            return previous
    return out


@njit(cache=True, _nrt=False)
def _submerged_area(m: ModelArrays, sc: Scratch, g: int, nx: float, ny: float, nz: float, level: float) -> float:
    """Area [m^2] of the part of face g below ``level`` along the world direction n [m] (world
    vertices current): the face polygon clipped by that plane, in its own coordinates. (Clipped
    and summed as it goes, not in the scratch's polygon buffer of :mod:`.polygon`: a face may
    have more corners than that buffer, sized for cells, holds.)"""
    c0 = m.face_corner_start[g]
    nc = m.face_corner_start[g + 1] - c0
    wv = sc.world_vertex
    cross = 0.0
    fu = fw = pu = pw = 0.0
    started = False
    for k in range(nc):
        a = m.face_corner[c0 + k]
        b = m.face_corner[c0 + (k + 1) % nc]
        ha = nx * wv[a, 0] + ny * wv[a, 1] + nz * wv[a, 2] - level
        hb = nx * wv[b, 0] + ny * wv[b, 1] + nz * wv[b, 2] - level
        for out in range(2):  # the corner a if below, then the crossing of edge a-b if any
            if out == 0:
                if ha >= 0.0:
                    continue
                qu, qw = m.face_corner_uw[c0 + k, 0], m.face_corner_uw[c0 + k, 1]
            else:
                if (ha < 0.0) == (hb < 0.0):
                    continue
                r = ha / (ha - hb)
                j = (k + 1) % nc
                qu = m.face_corner_uw[c0 + k, 0] + r * (m.face_corner_uw[c0 + j, 0] - m.face_corner_uw[c0 + k, 0])
                qw = m.face_corner_uw[c0 + k, 1] + r * (m.face_corner_uw[c0 + j, 1] - m.face_corner_uw[c0 + k, 1])
            if started:
                cross += pu * qw - qu * pw
            else:
                fu, fw, started = qu, qw, True
            pu, pw = qu, qw
    if started:
        cross += pu * fw - fu * pw
    return 0.5 * abs(cross)


@njit(cache=True, _nrt=False)
def _widest_face(m: ModelArrays, sc: Scratch, blk: int, nx: float, ny: float, nz: float, v: int, level: float) -> int:
    """Of the faces of ``blk`` with corner v (global id), the one with the largest part below
    ``level`` along the world direction n [m] (:func:`_submerged_area`; world vertices current); of
    those with as large a part, the most opposed to n. -1 if v is no face's corner."""
    r = sc.rotation[blk]
    best = -1.0
    lowest = np.inf
    out = -1
    for g in range(m.block_face_start[blk], m.block_face_start[blk + 1]):
        if not _has_corner(m, g, v):
            continue
        area = _submerged_area(m, sc, g, nx, ny, nz, level)
        c = _facing(r, m.face_normal[g], nx, ny, nz)
        if area > best or (area == best and c < lowest):
            best, lowest, out = area, c, g
    return out


@njit(cache=True, _nrt=False, inline="always")
def _most_opposed(m: ModelArrays, sc: Scratch, blk: int, nx: float, ny: float, nz: float) -> int:
    """The face of ``blk`` most opposed to the world direction n."""
    r = sc.rotation[blk]
    lowest = np.inf
    out = -1
    for g in range(m.block_face_start[blk], m.block_face_start[blk + 1]):
        c = _facing(r, m.face_normal[g], nx, ny, nz)
        if c < lowest:
            lowest, out = c, g
    return out


@njit(cache=True, _nrt=False, inline="always")
def _deepest_vertex(m: ModelArrays, sc: Scratch, blk: int, nx: float, ny: float, nz: float) -> int:
    """Global id of the vertex of ``blk`` furthest along the world direction -n (world vertices current)."""
    low = np.inf
    out = -1
    for v in range(m.block_vertex_start[blk], m.block_vertex_start[blk + 1]):
        h = nx * sc.world_vertex[v, 0] + ny * sc.world_vertex[v, 1] + nz * sc.world_vertex[v, 2]
        if h < low:
            low, out = h, v
    return out


@njit(cache=True, _nrt=False, inline="always")
def _has_corner(m: ModelArrays, f: int, v: int) -> bool:
    """Whether vertex v (global id) is a corner of face f."""
    for c in range(m.face_corner_start[f], m.face_corner_start[f + 1]):
        if m.face_corner[c] == v:
            return True
    return False


@njit(cache=True, _nrt=False)
def _near_corners_shared(
    m: ModelArrays, sc: Scratch, f: int, g: int, nx: float, ny: float, nz: float, level: float
) -> bool:
    """Whether every corner of face f below ``level`` along the world direction n [m] (world
    vertices current) is a corner of face g."""
    for c in range(m.face_corner_start[f], m.face_corner_start[f + 1]):
        v = m.face_corner[c]
        if nx * sc.world_vertex[v, 0] + ny * sc.world_vertex[v, 1] + nz * sc.world_vertex[v, 2] < level:
            if not _has_corner(m, g, v):
                return False
    return True


@njit(cache=True, _nrt=False)
def edge_pairs_changed(m: ModelArrays, s: State, sc: Scratch) -> bool:
    """Whether an EDGE pair's best separating axis is no longer its edge pair (rotations current).

    An EDGE pair tracks one edge-edge contact; the blocks' faces are not tracked while it lasts. A
    pair classified EDGE at a detection with a gap below the tracking tolerance can turn face to
    face before the next detection (blocks may close the whole tolerance between two): its face
    sub-contacts then switched on at depth at that detection (two offset bricks under an
    earthquake: 0.13 mm, 2.4 J of spring energy in one step). Called every step; the caller
    detects again when this is true, so the pair becomes a FACE pair (or another EDGE pair) as soon as
    :func:`separating_axes` would choose it, as every detection would (one whose face pair would
    track no point stays EDGE there, :func:`_narrow`, and is detected again at every step while
    so: that check made here, inlined into the step, made every step of a single rocking block 8 %
    slower). Cost: one separating-axis test per EDGE pair per step (there are none in a flat
    assembly)."""
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] != PAIR_EDGE:
            continue
        a = s.pair_a[i]
        b = s.pair_b[i]
        _block_world_vertices(m, s, sc, a)
        _block_world_vertices(m, s, sc, b)
        _, kind, _, _, da, db, nx, ny, nz = separating_axes(m, s, sc, a, b, True, True)
        if kind != PAIR_EDGE:
            return True
        if (_supporting_edge(m, sc, a, da, nx, ny, nz, True) != s.pair_edge_a[i]
                or _supporting_edge(m, sc, b, db, nx, ny, nz, False) != s.pair_edge_b[i]):
            return True
    return False


@njit(cache=True, _nrt=False, inline="always")
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


@njit(cache=True, _nrt=False, inline="always")
def _edge_geometry(
    m: ModelArrays, s: State, sc: Scratch, a: int, b: int, ea: int, eb: int, m0: float, m1: float, m2: float,
) -> tuple[float, float, float, float, float, float, float]:
    """Geometry of edge ea of block a on edge eb of block b (rotations current): (overlap [m], unit
    normal from b to a, contact point [m], world). The normal is the cross product of the two
    edges, oriented like the last normal m (taken when the edges are parallel); the overlap is
    measured along it between the closest points of the two edge segments, and the contact point
    is their midpoint."""
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
    if cn > EDGE_PARALLEL_SIN * la * lb:
        n0, n1, n2 = c0 / cn, c1 / cn, c2 / cn
        if n0 * m0 + n1 * m1 + n2 * m2 < 0.0:
            n0, n1, n2 = -n0, -n1, -n2
    else:
        n0, n1, n2 = m0, m1, m2
    un = -(n0 * (qa0 - qb0) + n1 * (qa1 - qb1) + n2 * (qa2 - qb2))
    return un, n0, n1, n2, 0.5 * (qa0 + qb0), 0.5 * (qa1 + qb1), 0.5 * (qa2 + qb2)


@njit(cache=True, _nrt=False)
def edge_contact(m: ModelArrays, s: State, sc: Scratch, i: int) -> tuple[float, float, float, float, float, float, float]:
    """Geometry of EDGE pair i (rotations current): (overlap [m], unit normal from b to a, contact
    point [m], world). The normal is the cross product of the two edges, oriented like the pair's
    last normal (which it replaces in ``s.pair_normal``); the overlap is measured along it between
    the closest points of the two edge segments, and the contact point is their midpoint."""
    un, n0, n1, n2, x0, x1, x2 = _edge_geometry(
        m, s, sc, s.pair_a[i], s.pair_b[i], s.pair_edge_a[i], s.pair_edge_b[i], s.pair_normal[i, 0], s.pair_normal[i, 1],
        s.pair_normal[i, 2],
    )
    s.pair_normal[i, 0] = n0
    s.pair_normal[i, 1] = n1
    s.pair_normal[i, 2] = n2
    return un, n0, n1, n2, x0, x1, x2


@njit(cache=True, _nrt=False, inline="always")
def _prev_edge_area(edge_area: np.ndarray, sc: Scratch, k: int) -> float:
    """Contact area [m^2] of the previous detection's EDGE pair k: the smaller of its two edges'
    (the area its stiffness kn A_e and its energies use)."""
    return min(edge_area[sc.prev_pair_edge_a[k]], edge_area[sc.prev_pair_edge_b[k]])


@njit(cache=True, _nrt=False)
def _prev_edge_energy_now(m: ModelArrays, s: State, sc: Scratch, k: int, kn: float) -> float:
    """Normal spring energy kn A_e (u - set)^2 / 2 [J] that the previous detection's EDGE pair k
    would hold at the present pose (u its edges' overlap now, its set followed down as its law
    does; ``kn`` [Pa/m]: its two blocks' normal stiffness): what it hands over to the pair that
    replaces it, or what is dissipated when it is lost. Its energy at its last law pass is a step
    old, and the leapfrog has since turned part of it into motion: a cube rebounding at 5 m/s off
    the ground on its edge, whose edge spring gave up 3.4 J per step, handed its face sub-contacts
    the last step's 42.5 J, and the balance rose by 5.1 J (0.7 % of the scale) in that step;
    0.8 J with the energy now (edge_on_wall, 2026-11-29)."""
    un, _, _, _, _, _, _ = _edge_geometry(
        m, s, sc, sc.prev_pair_a[k], sc.prev_pair_b[k], sc.prev_pair_edge_a[k], sc.prev_pair_edge_b[k],
        sc.prev_pair_normal[k, 0], sc.prev_pair_normal[k, 1], sc.prev_pair_normal[k, 2],
    )
    st = sc.prev_pair_set[k]
    if st > 0.0:
        un -= min(st, max(un, 0.0))
    if un <= 0.0:
        return 0.0
    return 0.5 * kn * _prev_edge_area(m.edge_area, sc, k) * un * un


@njit(cache=True, _nrt=False)
def _pair_touching(m: ModelArrays, s: State, a: int, b: int) -> tuple[bool, bool]:
    """Whether a face sub-contact between blocks a and b is in contact (covered at its last law
    pass and compressed, or held at a set, ``s.slot_set``: an overlap taken as its new zero,
    unloaded), and whether one is bonded."""
    touching = False
    bonded = False
    for side in range(2):
        blk, oth = (a, b) if side == 0 else (b, a)
        for p in range(m.face_point_start[m.block_face_start[blk]], m.face_point_start[m.block_face_start[blk + 1]]):
            for k in range(SLOTS):
                if s.slot_partner[p, k] == oth:
                    covered = s.slot_area[p, k] > 0.0  # (an uncovered slot keeps its set, unused)
                    touching = touching or (covered and (s.slot_set[p, k] > 0.0 or s.slot_normal_force[p, k] > 0.0))
                    bonded = bonded or s.slot_bonded[p, k]
    return touching, bonded


@njit(cache=True, _nrt=False)
def _release_face_slots(m: ModelArrays, s: State, a: int, b: int) -> None:
    """Release every face sub-contact slot between blocks a and b (:func:`release_slot`)."""
    for side in range(2):
        blk, oth = (a, b) if side == 0 else (b, a)
        for p in range(m.face_point_start[m.block_face_start[blk]], m.face_point_start[m.block_face_start[blk + 1]]):
            for k in range(SLOTS):
                if s.slot_partner[p, k] == oth:
                    release_slot(m, s, p, k)


@njit(cache=True, _nrt=False)
def _pair_face_energy(m: ModelArrays, s: State, sc: Scratch, a: int, b: int) -> float:
    """Elastic energy [J] that the compressed normal springs of the face sub-contacts between
    blocks a and b would hold at the present pose (rotations current), which is taken from them
    (their normal force is zeroed, so releasing them books only their shear springs): each spring
    kn A (u - set)^2 / 2 with its last area A, u its overlap now as its law measures it
    (:func:`rockdem.kernels.faces.anchored_overlap` with its last cover weight, anchor and deepest
    vertex; the point's own overlap without cover weight). Its energy at its last law pass is a
    step old: a cube sliding off a wall top onto its edge, its face springs unloading, handed its
    edge spring their last step's 38.7 J where they held 36.8 J, and the balance rose by 1.35 J
    (0.19 % of the scale) in that step (edge_on_wall, 2026-11-29). Cost: the two blocks' points."""
    e = 0.0
    for side in range(2):
        blk, oth = (a, b) if side == 0 else (b, a)
        gb, go = m.block_group[blk], m.block_group[oth]
        for f in range(m.block_face_start[blk], m.block_face_start[blk + 1]):
            for p in range(m.face_point_start[f], m.face_point_start[f + 1]):
                for k in range(SLOTS):
                    if s.slot_partner[p, k] == oth and s.slot_normal_force[p, k] > 0.0 and s.slot_area[p, k] > 0.0:
                        un = anchored_overlap(
                            face_map(m, s, sc, f, s.slot_face[p, k]), m.point_node[p, 0], m.point_node[p, 1],
                            s.slot_anchor[p, k, 0], s.slot_anchor[p, k, 1], s.slot_deepest[p, k, 0], s.slot_deepest[p, k, 1],
                            s.slot_cover[p, k], m.touch_tol) - s.slot_set[p, k]
                        if un > 0.0:
                            e += 0.5 * m.mat_kn[gb, go] * s.slot_area[p, k] * un * un
                        s.slot_normal_force[p, k] = 0.0
    return e


@njit(cache=True, _nrt=False)
def hand_over_edge(m: ModelArrays, s: State, sc: Scratch, i: int, k: int) -> None:
    """Start the spring of EDGE pair i, new at this detection (k: the pair's index at the previous
    detection, -1 if none), with no more elastic energy than the same two blocks' contact held.

    A contact changes representation under load: three partly covered face sub-contacts of a cube
    tilting across a wall top (10.3 J) become one edge-edge contact 0.57 mm deep (21.8 J at kn A_e);
    booking the first as dissipated and starting the second from its geometry created 11.5 J (and
    23 J in the ledger). So the normal spring energy E of the previous representation (face
    sub-contacts' or another edge pair's) is handed over: an edge spring that would hold more than E
    at its overlap u starts unloaded at the *set* u - sqrt(2 E / kn A_e) (``s.pair_set``, which
    follows the overlap down as the blocks part, so no energy appears later either); one that holds
    less takes what it holds and the rest is dissipated (booked as friction). A pair new to the two
    blocks (E = 0) found overlapping starts unloaded at its overlap, which the one-step look-ahead
    of detection keeps within a fraction of the tracking tolerance."""
    a = s.pair_a[i]
    b = s.pair_b[i]
    ga, gb = m.block_group[a], m.block_group[b]
    kna = m.mat_kn[ga, gb] * min(m.edge_area[s.pair_edge_a[i]], m.edge_area[s.pair_edge_b[i]])
    budget = 0.0
    if k >= 0:
        if sc.prev_pair_kind[k] == PAIR_EDGE:
            budget = _prev_edge_energy_now(m, s, sc, k, m.mat_kn[ga, gb])
            sc.prev_pair_normal_force[k] = 0.0  # handed over, not released
        else:
            budget = _pair_face_energy(m, s, sc, a, b)
    un = edge_contact(m, s, sc, i)[0]
    held = 0.5 * kna * un * un if un > 0.0 else 0.0
    if held <= budget:
        s.pair_set[i] = 0.0
        s.energy[E_FRICTION] += budget - held
    else:
        s.pair_set[i] = un - math.sqrt(2.0 * budget / kna)
    s.pair_overlap[i] = un - s.pair_set[i]
    s.pair_normal_force[i] = kna * s.pair_overlap[i] if s.pair_overlap[i] > 0.0 else 0.0


@njit(cache=True, _nrt=False)
def _narrow(m: ModelArrays, s: State, sc: Scratch, a: int, b: int, ncand: int) -> int:
    """Narrow phase of pair (a, b), a < b: adds a pair and its candidate sub-contacts; returns the
    new candidate count."""
    prev = _previous_pair(m, sc, a, b)
    was_edge = prev >= 0 and sc.prev_pair_kind[prev] == PAIR_EDGE
    sep, kind, ref, rface, da, db, nx, ny, nz = separating_axes(m, s, sc, a, b, True, was_edge)
    if sep < sc.min_separation[0]:
        sc.min_separation[0] = sep
        sc.min_pair[0] = a
        sc.min_pair[1] = b
    if sep > m.contact_tol:
        return ncand
    i = s.pair_count[0]
    if i >= s.pair_a.shape[0]:
        sc.overflow[0] += 1
        return ncand
    keep = -1
    fo = ft = -1
    both = False
    split = stop = ncand
    if kind == PAIR_FACE:
        oth = b if ref == a else a
        if prev >= 0 and sc.prev_pair_kind[prev] == PAIR_FACE:
            for f in (sc.prev_pair_owner_face[prev], sc.prev_pair_target_face[prev]):
                if m.face_block[f] == oth:
                    keep = f
        fo, ft, both = _face_roles(m, s, sc, ref, rface, oth, nx, ny, nz, keep)
        split = _face_candidates(m, s, sc, fo, ft, ncand)
        stop = _face_candidates(m, s, sc, ft, fo, split) if both else split
        if stop == ncand:
            # The face pair the axes chose covers none of its points: the contact lies off both
            # faces (edges crossing beyond a small face). Its best edge axis carries it instead.
            esep, ekind, _, _, eda, edb, enx, eny, enz = separating_axes(m, s, sc, a, b, False)
            if ekind == PAIR_EDGE and esep <= m.contact_tol and _edges_cross(m, sc, a, b, eda, edb, enx, eny, enz):
                kind, da, db, nx, ny, nz = PAIR_EDGE, eda, edb, enx, eny, enz
    s.pair_count[0] = i + 1
    s.pair_a[i] = a
    s.pair_b[i] = b
    s.pair_kind[i] = kind
    s.pair_track_start[i] = ncand
    s.pair_track_split[i] = ncand
    s.pair_track_stop[i] = ncand
    s.pair_from_edge[i] = False
    if kind == PAIR_EDGE:
        ea = _supporting_edge(m, sc, a, da, nx, ny, nz, True)
        eb = _supporting_edge(m, sc, b, db, nx, ny, nz, False)
        s.pair_edge_a[i] = ea
        s.pair_edge_b[i] = eb
        s.pair_normal[i, 0] = nx
        s.pair_normal[i, 1] = ny
        s.pair_normal[i, 2] = nz
        s.pair_shear[i, :] = 0.0
        s.pair_normal_force[i] = 0.0
        k = prev  # carry the history of the same edge contact
        if k >= 0 and sc.prev_pair_kind[k] == PAIR_EDGE and sc.prev_pair_edge_a[k] == ea and sc.prev_pair_edge_b[k] == eb:
            sc.prev_pair_kept[k] = True
            for c in range(3):
                s.pair_shear[i, c] = sc.prev_pair_shear[k, c]
            s.pair_normal_force[i] = sc.prev_pair_normal_force[k]
            s.pair_overlap[i] = sc.prev_pair_overlap[k]
            s.pair_set[i] = sc.prev_pair_set[k]
        else:
            hand_over_edge(m, s, sc, i, k)
        return ncand
    s.pair_from_edge[i] = prev >= 0 and sc.prev_pair_kind[prev] == PAIR_EDGE and sc.prev_pair_normal_force[prev] > 0.0
    sc.pair_handover[i] = -1.0
    if prev >= 0 and sc.prev_pair_kind[prev] == PAIR_EDGE:
        # The edge spring's energy goes to the face sub-contacts at their first law pass
        # (forces._hand_over_face), not to the released edges' dissipation. An unloaded edge
        # spring (its overlap taken into its set at its own hand-over) hands over none: the face
        # springs start unloaded at their overlaps.
        sc.pair_handover[i] = _prev_edge_energy_now(m, s, sc, prev, m.mat_kn[m.block_group[a], m.block_group[b]])
        sc.prev_pair_normal_force[prev] = 0.0
    sc.pair_weight[i] = -1.0  # (a new pair's share at its last law pass is not known)
    if prev >= 0 and sc.prev_pair_kind[prev] == PAIR_FACE:  # (an EDGE pair turned FACE hands over, above)
        sc.prev_pair_kept[prev] = True
        po, pt = sc.prev_pair_owner_face[prev], sc.prev_pair_target_face[prev]
        changed = not ((fo == po and ft == pt) or (fo == pt and ft == po))
        # The same faces carry on: the target's share at the last law pass, for the cover's change
        # of a cell whose area holds that share (forces._law_range); the owner and target may swap.
        w = sc.prev_pair_weight[prev]
        if fo == po and ft == pt:
            sc.pair_weight[i] = w
        elif not changed and w >= 0.0:
            sc.pair_weight[i] = 1.0 - w
        fresh = not _has_slots(m, s, fo, m.face_block[ft]) and not (both and _has_slots(m, s, ft, m.face_block[fo]))
        if changed or fresh:
            # Other faces carry the contact now, or none of its springs goes on: the new faces'
            # points, found pressed, would start loaded. The new springs start with no more than
            # the pair's springs hold now (forces._hand_over_face), as for an EDGE pair turned
            # FACE: those springs are released with only their shear energy booked, the ones a
            # new face keeps too (they restart, so that what a kept spring held is not booked
            # twice, by the hand-over and by its cover's change); a pair held at its sets,
            # unloaded, hands over nothing, and its new springs start unloaded at their depths.
            # A pair with a bonded slot whose faces change keeps its slots and is not handed over
            # (its new points start loaded, as before 2026-12-01), unless none of them has a slot.
            touching, bonded = _pair_touching(m, s, a, b)
            if touching and (fresh or not bonded):
                sc.pair_handover[i] = _pair_face_energy(m, s, sc, a, b)
                s.pair_from_edge[i] = True
                if not fresh:
                    _release_face_slots(m, s, a, b)
    s.pair_owner_face[i] = fo
    s.pair_target_face[i] = ft
    s.pair_track_split[i] = split  # (the candidates were added above)
    s.pair_track_stop[i] = stop
    return stop


@njit(cache=True, _nrt=False)
def _edges_cross(m: ModelArrays, sc: Scratch, a: int, b: int, da: int, db: int, nx: float, ny: float, nz: float) -> bool:
    """Whether the supporting edges of blocks a and b along the edge axis n (their edge directions
    da and db) cross: the closest points of the two segments lie inside both, so that n is the
    normal of an edge-edge contact (world vertices current). Along an edge axis that is not the
    normal of a face of the blocks' Minkowski difference the supporting edges need not meet: a
    hull's edge on the ground paired with the ground's edge 2 m away along an axis 0.6 degrees from
    the vertical measured 20 mm of overlap between them, and its spring, applied half way, created
    energy as the hull turned."""
    ea = _supporting_edge(m, sc, a, da, nx, ny, nz, True)
    eb = _supporting_edge(m, sc, b, db, nx, ny, nz, False)
    if ea < 0 or eb < 0:
        return False
    wv = sc.world_vertex
    p, q = m.edge_vertex[ea, 0], m.edge_vertex[ea, 1]
    u, w = m.edge_vertex[eb, 0], m.edge_vertex[eb, 1]
    sa, sb = segment_closest(
        wv[p, 0], wv[p, 1], wv[p, 2], wv[q, 0] - wv[p, 0], wv[q, 1] - wv[p, 1], wv[q, 2] - wv[p, 2],
        wv[u, 0], wv[u, 1], wv[u, 2], wv[w, 0] - wv[u, 0], wv[w, 1] - wv[u, 1], wv[w, 2] - wv[u, 2],
    )
    return 0.0 < sa < 1.0 and 0.0 < sb < 1.0


@njit(cache=True, _nrt=False)
def _has_slots(m: ModelArrays, s: State, f: int, partner: int) -> bool:
    """Whether a point of face f has a slot for block ``partner``."""
    for p in range(m.face_point_start[f], m.face_point_start[f + 1]):
        for k in range(SLOTS):
            if s.slot_partner[p, k] == partner:
                return True
    return False


@njit(cache=True, _nrt=False)
def _face_roles(
    m: ModelArrays, s: State, sc: Scratch, ref: int, rface: int, oth: int, nx: float, ny: float, nz: float, keep: int
) -> tuple[int, int, bool]:
    """The owner face, the target face and whether the target's points are tracked too
    (:func:`blend.tracks_target`) of a FACE pair whose reference face ``rface`` of block ``ref``
    won the separating axes along the world normal n against block ``oth``; ``keep``: oth's face
    of the same pair at the last detection (-1 none), kept as incident face while it reaches as
    deep (:func:`_incident_face`)."""
    c0 = m.face_corner[m.face_corner_start[rface]]  # the reference face's plane along n
    plane = nx * sc.world_vertex[c0, 0] + ny * sc.world_vertex[c0, 1] + nz * sc.world_vertex[c0, 2]
    iface = _incident_face(m, sc, oth, nx, ny, nz, keep, m.contact_tol, plane)
    ar = m.face_area[rface]
    ai = m.face_area[iface]
    # The smaller face owns the points (tie: the lower block id).
    if ai < ar * (1.0 - 1e-9) or (ar >= ai * (1.0 - 1e-9) and oth < ref):
        fo, ft = iface, rface
    else:
        fo, ft = rface, iface
    a_o = m.face_block[fo]
    a_t = m.face_block[ft]
    sep_o = face_clearance(m.face_normal, m.face_offset, m.face_block, m.block_vertex_start, m.vertex_local, sc.rotation, s.position, fo, a_t)[0]
    sep_t = face_clearance(m.face_normal, m.face_offset, m.face_block, m.block_vertex_start, m.vertex_local, sc.rotation, s.position, ft, a_o)[0]
    return fo, ft, tracks_target(sep_o - sep_t, m.contact_tol)


@njit(cache=True, _nrt=False)
def _face_candidates(m: ModelArrays, s: State, sc: Scratch, fo: int, ft: int, ncand: int) -> int:
    """Add the points of face ``fo`` whose cells face ``ft`` covers within the tracking tolerance
    as candidate sub-contacts; returns the new candidate count."""
    fm = face_map(m, s, sc, fo, ft)
    if abs(fm.det) < 1e-9:
        return ncand
    partner = m.face_block[ft]
    for p in range(m.face_point_start[fo], m.face_point_start[fo + 1]):
        area, yu, yw, shift = cover(m, sc, p, ft, fm, m.contact_tol)
        if area <= 0.0:
            continue
        if fm.h0 + fm.hu * yu + fm.hw * yw - shift > m.contact_tol:
            continue
        if ncand >= sc.cand_code.shape[0]:
            sc.overflow[0] += 1
            break
        sc.cand_code[ncand] = p
        sc.cand_partner[ncand] = partner
        sc.cand_face[ncand] = ft
        ncand += 1
    return ncand


@njit(cache=True, _nrt=False)
def release_slot(m: ModelArrays, s: State, p: int, k: int) -> None:
    """Forget slot k of point p: a bond torn off counts as a tension failure; the energy still
    stored in its springs is dissipated (bond energy for a bond, friction otherwise)."""
    t = s.slot_partner[p, k]
    if t < 0:
        return
    go = m.block_group[m.point_block[p]]
    gt = m.block_group[t]
    area = s.slot_area[p, k]
    e = 0.0
    if area > 0.0:
        ks = m.mat_ks[go, gt] * area
        sh = s.slot_shear[p, k]
        e += 0.5 * ks * (sh[0] * sh[0] + sh[1] * sh[1] + sh[2] * sh[2])
        e += spring_energy(s.slot_normal_force[p, k], m.mat_kn[go, gt] * area)
    if s.slot_bonded[p, k]:
        s.slot_bonded[p, k] = False
        s.point_failed[p] = FAILED_TENSION
        s.energy[E_BOND] += e
    else:
        s.energy[E_FRICTION] += e
    s.slot_partner[p, k] = -1
    s.slot_face[p, k] = -1
    s.slot_shear[p, k, :] = 0.0
    s.slot_normal_force[p, k] = 0.0
    s.slot_area[p, k] = 0.0
    s.slot_overlap[p, k] = 0.0
    s.slot_set[p, k] = 0.0
    s.slot_cover[p, k] = 0.0
    s.slot_stiffening[p, k] = 1.0


@njit(cache=True, _nrt=False)
def _assign_slots(m: ModelArrays, s: State, sc: Scratch, ncand: int) -> None:
    """Give each candidate a slot of its point (its old one for the same partner), release the
    slots not found again, and list the tracked sub-contacts pair by pair."""
    passid = sc.passes[0]
    for c in range(ncand):
        p = sc.cand_code[c]
        sc.cand_slot[c] = -1
        for k in range(SLOTS):
            if s.slot_partner[p, k] == sc.cand_partner[c] and sc.seen[SLOTS * p + k] != passid:
                sc.cand_slot[c] = k
                sc.seen[SLOTS * p + k] = passid
                if s.slot_face[p, k] != sc.cand_face[c]:
                    # Another face of the same partner: a new joint plane, the shear spring restarts
                    # (its energy is dissipated) and a bond is sheared off.
                    go, gt = m.block_group[m.point_block[p]], m.block_group[sc.cand_partner[c]]
                    sh = s.slot_shear[p, k]
                    e = 0.5 * m.mat_ks[go, gt] * s.slot_area[p, k] * (sh[0] * sh[0] + sh[1] * sh[1] + sh[2] * sh[2])
                    if s.slot_bonded[p, k]:
                        s.slot_bonded[p, k] = False
                        s.point_failed[p] = FAILED_SHEAR
                        s.energy[E_BOND] += e
                    else:
                        s.energy[E_FRICTION] += e
                    s.slot_face[p, k] = sc.cand_face[c]
                    s.slot_shear[p, k, :] = 0.0
                break
    for p in range(m.point_block.shape[0]):
        for k in range(SLOTS):
            if s.slot_partner[p, k] >= 0 and sc.seen[SLOTS * p + k] != passid:
                release_slot(m, s, p, k)
    for c in range(ncand):
        if sc.cand_slot[c] >= 0:
            continue
        p = sc.cand_code[c]
        for k in range(SLOTS):
            if s.slot_partner[p, k] < 0 and sc.seen[SLOTS * p + k] != passid:
                s.slot_partner[p, k] = sc.cand_partner[c]
                s.slot_face[p, k] = sc.cand_face[c]
                s.slot_shear[p, k, :] = 0.0
                s.slot_normal_force[p, k] = 0.0
                s.slot_area[p, k] = 0.0
                s.slot_overlap[p, k] = 0.0
                s.slot_set[p, k] = 0.0
                s.slot_cover[p, k] = 0.0
                s.slot_stiffening[p, k] = 1.0
                sc.seen[SLOTS * p + k] = passid
                sc.cand_slot[c] = k
                break
    n = 0
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] != PAIR_FACE:
            continue
        c0 = s.pair_track_start[i]
        cm = s.pair_track_split[i]
        c1 = s.pair_track_stop[i]
        s.pair_track_start[i] = n
        bonded = True
        for c in range(c0, c1):
            if c == cm:
                s.pair_track_split[i] = n
            if sc.cand_slot[c] >= 0:
                code = SLOTS * sc.cand_code[c] + sc.cand_slot[c]
                s.track[n] = code
                bonded = bonded and s.slot_bonded[sc.cand_code[c], sc.cand_slot[c]]
                n += 1
        if cm >= c1:
            s.pair_track_split[i] = n
        s.pair_track_stop[i] = n
        sc.pair_bonded[i] = bonded and n > s.pair_track_start[i]
    s.track_count[0] = n


@njit(cache=True, _nrt=False)
def detect(m: ModelArrays, s: State, sc: Scratch) -> None:
    """Rebuild the pairs and the tracked sub-contacts at the current poses (rotations current).

    Also leaves the smallest pair separation (the deepest overlap when negative) and its blocks in
    ``sc.min_separation`` and ``sc.min_pair`` for the start-of-run overlap check, and counts
    buffer overflows in ``sc.overflow`` (the caller enlarges the buffers and detects again).
    """
    nb = m.block_mass.shape[0]
    _world_vertices(m, s, sc)
    sc.passes[0] += 1
    npair = s.pair_count[0]
    for i in range(npair):
        if sc.pair_handover[i] >= 0.0:  # detected again before its law pass (buffers enlarged): dissipated
            s.energy[E_FRICTION] += sc.pair_handover[i]
            sc.pair_handover[i] = -1.0
    sc.prev_pair_count[0] = npair
    for i in range(npair):
        sc.prev_pair_a[i] = s.pair_a[i]
        sc.prev_pair_b[i] = s.pair_b[i]
        sc.prev_pair_kind[i] = s.pair_kind[i]
        sc.prev_pair_owner_face[i] = s.pair_owner_face[i]
        sc.prev_pair_target_face[i] = s.pair_target_face[i]
        sc.prev_pair_edge_a[i] = s.pair_edge_a[i]
        sc.prev_pair_edge_b[i] = s.pair_edge_b[i]
        sc.prev_pair_normal_force[i] = s.pair_normal_force[i]
        sc.prev_pair_overlap[i] = s.pair_overlap[i]
        sc.prev_pair_set[i] = s.pair_set[i]
        sc.prev_pair_weight[i] = sc.pair_weight[i]
        for k in range(3):
            sc.prev_pair_shear[i, k] = s.pair_shear[i, k]
            sc.prev_pair_normal[i, k] = s.pair_normal[i, k]
        sc.prev_pair_kept[i] = False
        sc.prev_pair_key[i] = s.pair_a[i] * nb + s.pair_b[i]
    sort_indices(sc.prev_pair_key, sc.prev_pair_index, npair)
    s.pair_count[0] = 0
    sc.min_separation[0] = np.inf
    sc.min_pair[0] = -1
    sc.min_pair[1] = -1
    sc.overflow[0] = 0
    ncand = 0
    order = sc.sweep_order
    sort_indices(sc.aabb[:, 0], order, nb)
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
            ncand = _narrow(m, s, sc, lo, hi, ncand)
    _release_lost_edges(m, s, sc)
    _assign_slots(m, s, sc, ncand)
    for b in range(nb):
        s.moved[b] = 0.0


@njit(cache=True, _nrt=False)
def _release_lost_edges(m: ModelArrays, s: State, sc: Scratch) -> None:
    """Edge contacts of the previous detection not found again: their stored spring energy is
    dissipated (friction)."""
    for k in range(sc.prev_pair_count[0]):
        if sc.prev_pair_kind[k] != PAIR_EDGE or sc.prev_pair_kept[k]:
            continue
        a = sc.prev_pair_a[k]
        b = sc.prev_pair_b[k]
        area = _prev_edge_area(m.edge_area, sc, k)
        g0, g1 = m.block_group[a], m.block_group[b]
        sh = sc.prev_pair_shear[k]
        e = 0.5 * m.mat_ks[g0, g1] * area * (sh[0] * sh[0] + sh[1] * sh[1] + sh[2] * sh[2])
        if sc.prev_pair_normal_force[k] > 0.0:  # (0: handed over, or open)
            e += _prev_edge_energy_now(m, s, sc, k, m.mat_kn[g0, g1])
        s.energy[E_FRICTION] += e


@njit(cache=True, _nrt=False)
def bond_touching(m: ModelArrays, s: State, sc: Scratch) -> None:
    """At the start: the effective area and overlap of every tracked sub-contact, bonded where its
    cell is covered and its gap is within ``m.touch_tol`` and the two groups' material bonds
    (``m.mat_bonded``); a FACE pair whose sub-contacts are all bonded is a joint
    (``sc.pair_bonded``, no blending). An unbonded corner sub-contact touching is marked
    STIFFENING_AT_START (its corner stiffening decided at the first law pass)."""
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] != PAIR_FACE:
            continue
        k0 = s.pair_track_start[i]
        k1 = s.pair_track_stop[i]
        for k in range(k0, k1):
            # The owner's points on the target face; the target's (kernels.blend) on the owner face.
            fo, ft = s.pair_owner_face[i], s.pair_target_face[i]
            if k >= s.pair_track_split[i]:
                fo, ft = ft, fo
            fm = face_map(m, s, sc, fo, ft)
            if abs(fm.det) < 1e-9:
                continue
            p = s.track[k] // SLOTS
            j = s.track[k] - SLOTS * p
            area, yu, yw, shift = cover(m, sc, p, ft, fm, 0.0)
            gap = fm.h0 + fm.hu * yu + fm.hw * yw - shift
            touching = area > 0.0 and abs(gap) <= m.touch_tol
            s.slot_bonded[p, j] = touching and m.mat_bonded[m.block_group[m.point_block[p]], m.block_group[s.slot_partner[p, j]]]
            s.slot_area[p, j] = area
            s.slot_overlap[p, j] = -gap
            if touching and not s.slot_bonded[p, j] and m.point_corner[p] >= 0:
                # A corner resting alone at the start is a landing at its start depth, whichever
                # sign the round-off gives its overlap (kernels.forces.corner_stiffening).
                s.slot_stiffening[p, j] = STIFFENING_AT_START
        joint = k1 > k0
        for k in range(k0, k1):
            p = s.track[k] // SLOTS
            joint = joint and s.slot_bonded[p, s.track[k] - SLOTS * p]
        sc.pair_bonded[i] = joint
