"""The interfaces of a model and the critical SP damping of each joint group pair (paper Eq. 1-4, §2.2).

An *interface* is a pair of facing faces of two blocks, at least one free: outward normals
antiparallel within 10 deg, at most a gap apart at their closest (touching joints, or the few
millimetres between a one-sided façade and its return walls) and an overlap of positive area A,
in the reference (untilted) pose.

**Critical impact of an interface.** A face of area A landing flat on its partner compresses all
its sub-contact springs at once (faces of a block facing the same direction and the same partner
group strike together and their areas add up: a façade's inner face on both return walls): the edge impact of DeJong (paper Eq. 1, omega_e = sqrt(2 k_s / m_b),
two corner springs k_s each carrying half the joint) with the model's own springs, k_s = kn A / 2:

    omega = sqrt(kn A / m),   m = m_1 m_2 / (m_1 + m_2)  (two free blocks),  m = m_free (on a driven one).

For a block B x L x H on a rigid base with kn = E / H this is omega_e = sqrt(E / (rho H^2)); two equal
stacked blocks give m / 2, the sqrt 2 of DeJong's stacked blocks (§2.2); a façade striking its return
walls gives the return walls' end faces' area, its own horizontally stacked impact (§2.2). The
paper's Eq. 2 writes k_s = k_j B / 2 with k_j = E B / H; with k_j = kn A the stiffness of the joint,
each corner spring is k_j / 2, and the extra factor B [m] of Eq. 2 makes Eq. 3's omega_e smaller by
sqrt(B / 1 m) (and its beta larger by 1 / sqrt(B / 1 m): the façade's two-sided 0.0047 s is
0.0016 s here, the parapet's 0.00305 s is 0.0015 s).

**Strike by one row across a gap.** Faces that start apart (a one-sided façade 4 mm in front of its
return walls) while the block stands on a support (faces touching in another direction) do not
land flat: the block rocks about its base and closes the gap with the edge row
of interface points farthest from the pivot (the façade's top points) while the rest is still
open. The impact force is orders of magnitude above the base friction mu m g, so during the strike
the block is free, and the row of area A_r at r from the centre of mass meets an effective mass

    1 / m_eff = 1 / m + (r x n) . I^-1 (r x n)     (plus the same term of a free partner),
    omega = sqrt(kn A_r / m_eff).

For the §4.2 façade (top row A_r = A / 2, 1 / m_eff = (1 / m)(1 + 3 H^2 / (B^2 + H^2))) this is
1.40 sqrt(kn A / m); the recorded strike's undamped contact time gives 1.39. For such faces omega is
the larger of this and the flat landing; rows are the points along each edge of the convex hull of
the interface's points. Touching faces keep the flat landing (all their rows are in contact at once:
the paper's edge impact). Per group pair the largest omega over its interfaces gives

    beta = 2 zeta / omega    (Eq. 4 with alpha = 0; zeta = 1 is critical damping).

A pair with no interface at the start (blocks that only meet when something falls) takes a free block
of the pair landing on its largest face; a pair of two driven groups never acts (beta = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from .beta_choice import PairBeta
from .geometry import Polyhedron, _clip, _inside_2d, _polygon_area
from .kernels.rotation import quats_to_matrices

__all__ = ["Body", "FaceContact", "GAP_FRACTION", "face_contacts", "model_bodies", "critical_pair_betas", "critical_betas"]

GAP_FRACTION = 0.1
"""Largest gap between two facing faces that still makes an interface, as a fraction of the
smaller of the two blocks' smallest dimensions (a façade 0.11 m thick: 11 mm; Shawa et al.'s 4 mm
gap to the return walls is inside it)."""

PARALLEL_TOL_DEG = 2.0
"""Faces of one block striking together: outward normals parallel within this angle [deg]."""

FACING_TOL_DEG = 10.0
"""Facing faces: outward normals antiparallel within this angle [deg] (a façade leaned outward on a
sloped foundation still strikes its vertical return walls: it turns parallel to them on the way)."""


@dataclass(frozen=True)
class Body:
    """A block as the interface search sees it.

    Attributes:
        name: block name. group: its joint-material group.
        poly: its geometry in the reference (untilted) pose [m].
        mass: [kg]. free: False for driven blocks.
        centre: (3,) centre of mass [m]. inertia: (3, 3) inertia tensor about it, world axes [kg m^2].
        points: (k, 3) interface points [m], point_areas: (k,) their tributary areas [m^2],
            point_faces: (k,) the index of each point's face in ``poly.faces`` (empty: none known,
            the strike of a gap interface is then not computed).
    """

    name: str
    group: str
    poly: Polyhedron
    mass: float
    free: bool
    centre: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    inertia: NDArray[np.float64] = field(default_factory=lambda: np.zeros((3, 3)))
    points: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    point_areas: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    point_faces: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


@dataclass(frozen=True)
class FaceContact:
    """Two facing faces of bodies ``a`` and ``b`` (indices into the body list).

    Attributes:
        normal: (3,) outward unit normal of a's face (from a towards b).
        area: overlap area of the two faces [m^2].
        gap: closest distance of b's face from a's face plane [m] (negative: overlapping).
        face_a, face_b: the two faces, indices into ``poly.faces`` of a and b.
    """

    a: int
    b: int
    normal: NDArray[np.float64]
    area: float
    gap: float
    face_a: int = -1
    face_b: int = -1


def _face_frames(poly: Polyhedron) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    """(vertices (k, 3), outward normal (3,), plane offset) of every face."""
    return [(poly.vertices[f], poly.normals[i], float(poly.offsets[i])) for i, f in enumerate(poly.faces)]


def _plane_axes(n: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit axes (u, w) of a plane of unit normal n (3,), with u x w = n."""
    u = np.cross(n, np.eye(3)[int(np.argmin(np.abs(n)))])
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def _thinnest(bodies: Sequence[Body]) -> NDArray[np.float64]:
    """(nb,) each block's smallest dimension along the axes [m] (reference pose)."""
    return np.array([float(np.ptp(b.poly.vertices, axis=0).min()) for b in bodies])


def _ccw(v: NDArray[np.float64], u: NDArray[np.float64], w: NDArray[np.float64]) -> NDArray[np.float64]:
    """(k, 2) counter-clockwise polygon of the face vertices v (k, 3) in the plane coordinates (u, w)."""
    q = np.column_stack((v @ u, v @ w))
    return q if _polygon_area(q) > 0 else q[::-1]


def _overlap(va: NDArray[np.float64], vb: NDArray[np.float64], n: NDArray[np.float64]) -> float:
    """Area [m^2] of the overlap of two facing convex polygons (k, 3), projected on the plane of normal n."""
    u, w = _plane_axes(n)
    clipped = _clip(_ccw(va, u, w), _ccw(vb, u, w))  # b's face runs counter-clockwise about -n: reoriented
    return abs(_polygon_area(clipped)) if len(clipped) >= 3 else 0.0


def face_contacts(bodies: Sequence[Body], *, gap_fraction: float = GAP_FRACTION) -> list[FaceContact]:
    """Every pair of facing faces of two bodies, at least one free (see the module docstring).

    Args:
        bodies: the blocks in their reference pose.
        gap_fraction: largest gap between the face planes, as a fraction of the smaller of the two
            bodies' smallest dimensions [-].

    Returns:
        One :class:`FaceContact` per facing face pair with a positive overlap area.
    """
    if not gap_fraction >= 0:
        raise ValueError(f"gap_fraction must be >= 0, got {gap_fraction!r}")
    lo = np.array([b.poly.vertices.min(axis=0) for b in bodies])
    hi = np.array([b.poly.vertices.max(axis=0) for b in bodies])
    thin = _thinnest(bodies)
    free = np.array([b.free for b in bodies], dtype=bool)
    cos_tol = math.cos(math.radians(FACING_TOL_DEG))
    frames = [_face_frames(b.poly) for b in bodies]
    out: list[FaceContact] = []
    for i in range(len(bodies)):
        j = np.arange(i + 1, len(bodies))
        limit = gap_fraction * np.minimum(thin[i], thin[j])
        near = np.all((lo[j] <= hi[i] + limit[:, None]) & (hi[j] >= lo[i] - limit[:, None]), axis=1)
        near &= free[i] | free[j]
        for jj, lim in zip(j[near], limit[near]):
            for fa, (va, na, oa) in enumerate(frames[i]):
                for fb, (vb, nb, _) in enumerate(frames[jj]):
                    if na @ nb > -cos_tol:
                        continue
                    gap = float(np.min(vb @ na)) - oa  # closest approach (the mean for parallel faces)
                    if abs(gap) > lim:
                        continue
                    area = _overlap(va, vb, na)
                    if area > 1e-12 * max(thin[i], thin[jj]) ** 2:
                        out.append(FaceContact(i, int(jj), na.copy(), area, gap, fa, fb))
    return out


@dataclass
class _Impact:
    """The faces of free block ``block`` facing blocks of ``group`` in one direction: they strike together."""

    block: int
    group: str
    normal: NDArray[np.float64]
    area: float
    partners: list[int]
    contacts: list[FaceContact] = field(default_factory=list)


def _sorted_pair(a: str, b: str) -> tuple[str, str]:
    return (a, b) if a <= b else (b, a)


def _impacts(bodies: Sequence[Body], contacts: Sequence[FaceContact]) -> list[_Impact]:
    """Facing faces grouped per free block, direction and partner group: a façade's inner face
    strikes both return walls at once (the areas add up), a brick lands on the two bricks below."""
    cos_tol = math.cos(math.radians(PARALLEL_TOL_DEG))
    out: list[_Impact] = []
    for c in contacts:
        for own, other, n in ((c.a, c.b, c.normal), (c.b, c.a, -c.normal)):
            if not bodies[own].free:
                continue
            group = bodies[other].group
            for imp in out:
                if imp.block == own and imp.group == group and float(imp.normal @ n) > cos_tol:
                    imp.area += c.area
                    if other not in imp.partners:
                        imp.partners.append(other)
                    imp.contacts.append(c)
                    break
            else:
                out.append(_Impact(own, group, n, c.area, [other], [c]))
    return out


TOUCH_FRACTION = 1e-3
"""Facing faces further apart than this fraction of the smaller of the two blocks' smallest
dimensions (reference pose) are *apart*; closer ones touch. Faces apart from their partner while the
block touches a support in another direction strike by one edge row (module docstring)."""


def _rocks_into(imp: _Impact, own_contacts: Sequence[FaceContact], thin: NDArray[np.float64]) -> bool:
    """Whether the impact's faces start apart from their partners while the block touches another
    face in another direction (its support): rocking on that support closes the gap row by row.
    ``own_contacts``: the facing faces of the impact's block; ``thin``: (nb,) each block's smallest
    dimension [m]."""
    def apart(c: FaceContact) -> bool:
        return c.gap > TOUCH_FRACTION * min(thin[c.a], thin[c.b])
    if not any(apart(c) for c in imp.contacts):
        return False
    cos_tol = math.cos(math.radians(PARALLEL_TOL_DEG))
    return any(not apart(c) and abs(float(c.normal @ imp.normal)) < cos_tol for c in own_contacts)


def _rows(q: NDArray[np.float64], tol: float) -> list[NDArray[np.int64]]:
    """The points (indices) of each edge of the convex hull of the 2D points q (k, 2): the rows
    that strike first when the face tilts about the opposite side."""
    centred = q - q.mean(axis=0)
    if len(q) >= 3 and np.linalg.matrix_rank(centred, tol=tol) == 2:
        from scipy.spatial import ConvexHull  # noqa: PLC0415 - only for gap interfaces

        outward = ConvexHull(q).equations[:, :2]
    else:  # one point, or points on a line: its two ends
        d = np.linalg.svd(centred)[2][0] if len(q) > 1 else np.array([1.0, 0.0])
        outward = np.array([d, -d])
    rows = {tuple(np.flatnonzero(q @ d >= (q @ d).max() - tol)) for d in outward}
    return [np.array(r, dtype=np.int64) for r in sorted(rows)]


def _row_strike(bodies: Sequence[Body], imp: _Impact) -> tuple[float, float] | None:
    """(area A [m^2], effective mass m [kg]) of the stiffest single-row strike of an impact's faces.

    The interface points of the smaller face of each facing pair that lie on the other face (within
    half a cell) carry the contact with their tributary areas (scaled down to the pair's overlap
    area where they exceed it). A block rocking about another interface (its base) closes the gap
    with one edge row of these points first; during the strike
    its base friction (mu m g) is far below the impact force, so the block is free and the row's
    effective mass is 1 / m_eff = 1 / m + (r x n) . I^-1 (r x n) (r from the centre of mass to the
    row's centroid; plus the same term of a single free partner, or 1 / M of several).
    None when no points are known.
    """
    own = bodies[imp.block]
    n = imp.normal
    u, w = _plane_axes(n)
    pts, areas, owner = [], [], []
    for c in imp.contacts:
        faces = [(bodies[c.a], c.face_a, bodies[c.b], c.face_b), (bodies[c.b], c.face_b, bodies[c.a], c.face_a)]
        faces.sort(key=lambda f: abs(_polygon_area(_ccw(f[0].poly.vertices[f[0].poly.faces[f[1]]], u, w))))  # the smaller face's points
        carrier, face, other, other_face = faces[0]
        sel = np.flatnonzero(carrier.point_faces == face)
        if len(sel) == 0:
            return None
        poly = _ccw(other.poly.vertices[other.poly.faces[other_face]], u, w)
        on = [i for i in sel  # within half a cell of the other face: its cell is (mostly) covered
              if _inside_2d(np.array([carrier.points[i] @ u, carrier.points[i] @ w]), poly, 0.5 * math.sqrt(carrier.point_areas[i]))]
        if not on:
            continue
        a = carrier.point_areas[on]
        pts.append(carrier.points[on])
        areas.append(a * min(1.0, c.area / a.sum()))
        owner += [c.b if c.a == imp.block else c.a] * len(on)
    if not pts:
        return None
    p, a, part = np.vstack(pts), np.concatenate(areas), np.array(owner)
    size = float(np.ptp(p, axis=0).max()) or 1.0

    def flexibility(body: Body, r: NDArray[np.float64]) -> float:
        arm = np.cross(r - body.centre, n)
        return 1.0 / body.mass + float(arm @ np.linalg.solve(body.inertia, arm))

    best: tuple[float, float] | None = None
    for row in _rows(np.column_stack((p @ u, p @ w)), 1e-6 * size):
        area = float(a[row].sum())
        r = (a[row] @ p[row]) / area
        flex = flexibility(own, r)
        struck = [bodies[j] for j in np.unique(part[row])]
        if all(b.free for b in struck):
            flex += flexibility(struck[0], r) if len(struck) == 1 else 1.0 / sum(b.mass for b in struck)
        if best is None or area * flex > best[0] / best[1]:
            best = (area, 1.0 / flex)
    return best


def model_bodies(model) -> list[Body]:  # noqa: ANN001 - a rockdem.model.Model (imported lazily by callers)
    """The blocks of a finalized :class:`~rockdem.model.Model` in their reference (untilted) pose."""
    m = model.arrays
    rot = quats_to_matrices(model.quaternion_ref)
    out = []
    for b in range(model.block_count):
        start = int(m.block_vertex_start[b])
        v = m.vertex_local[start : int(m.block_vertex_start[b + 1])] @ rot[b].T + model.position_ref[b]
        faces = tuple(np.asarray(f, dtype=np.int64) - start for f in model.faces[b])
        normals = []
        for f in faces:
            p = v[f]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            for k in range(3, len(p)):  # Newell-like: the largest triangle normal of the fan
                c = np.cross(p[k - 1] - p[0], p[k] - p[0])
                if np.linalg.norm(c) > np.linalg.norm(n):
                    n = c
            normals.append(n / np.linalg.norm(n))
        nrm = np.array(normals)
        offsets = np.array([nrm[k] @ v[f[0]] for k, f in enumerate(faces)])
        poly = Polyhedron(v, faces, nrm, offsets)
        pts = np.flatnonzero(m.point_block == b)
        out.append(Body(model.block_names[b], model.group_names[int(m.block_group[b])], poly,
                        float(m.block_mass[b]), bool(m.block_free[b]), centre=np.array(model.position_ref[b], dtype=float),
                        inertia=rot[b] @ np.diag(m.block_inertia[b]) @ rot[b].T,
                        points=m.point_local[pts] @ rot[b].T + model.position_ref[b], point_areas=m.point_area[pts].copy(),
                        point_faces=m.point_face[pts] - int(m.block_face_start[b])))
    return out


def _largest_face(poly: Polyhedron) -> float:
    return max(abs(_polygon_area(_ccw(poly.vertices[f], *_plane_axes(poly.normals[k])))) for k, f in enumerate(poly.faces))


def critical_pair_betas(
    bodies: Sequence[Body],
    kn: Callable[[str, str], float],
    *,
    damping_ratio: float = 1.0,
    contacts: Sequence[FaceContact] | None = None,
    gap_fraction: float = GAP_FRACTION,
) -> dict[tuple[str, str], PairBeta]:
    """beta = 2 zeta / omega of every group pair from its own critical impact (module docstring).

    Args:
        bodies: the blocks in their reference pose.
        kn: normal stiffness [Pa/m] of a group pair, ``kn(group_a, group_b)``.
        damping_ratio: zeta at the critical impact [-] (1 = critical).
        contacts: the facing faces (default :func:`face_contacts` of ``bodies``).
        gap_fraction: passed to :func:`face_contacts`.

    Returns:
        {(group_a, group_b) sorted: PairBeta} for every pair of the bodies' groups.
    """
    if isinstance(damping_ratio, bool) or not (isinstance(damping_ratio, (int, float)) and math.isfinite(damping_ratio) and damping_ratio > 0):
        raise ValueError(f"damping.damping_ratio must be a positive number (1 = critical), got {damping_ratio!r}")
    if contacts is None:
        contacts = face_contacts(bodies, gap_fraction=gap_fraction)
    thin = _thinnest(bodies)
    by_block: dict[int, list[FaceContact]] = {}
    for c in contacts:
        by_block.setdefault(c.a, []).append(c)
        by_block.setdefault(c.b, []).append(c)
    best: dict[tuple[str, str], tuple[float, float, float, float, tuple[str, str], str]] = {}
    for imp in _impacts(bodies, contacts):
        own = bodies[imp.block]
        partners = [bodies[j] for j in imp.partners]
        if all(p.free for p in partners):  # struck blocks free: the reduced mass with all of them
            others = sum(p.mass for p in partners)
            mass = own.mass * others / (own.mass + others)
        else:
            mass = own.mass
        key = _sorted_pair(own.group, imp.group)
        k = kn(own.group, imp.group)
        omega, area, what = math.sqrt(k * imp.area / mass), imp.area, "landing flat"
        strike = _row_strike(bodies, imp) if _rocks_into(imp, by_block[imp.block], thin) else None
        if strike is not None and k * strike[0] / strike[1] > omega * omega:
            area, mass = strike
            omega, what = math.sqrt(k * area / mass), "striking with one edge row of its points (a gap closed by rocking)"
        if key not in best or omega > best[key][0]:
            best[key] = (omega, area, mass, k, (own.name, " + ".join(p.name for p in partners)), what)
    groups = sorted({b.group for b in bodies})
    out: dict[tuple[str, str], PairBeta] = {}
    for i, ga in enumerate(groups):
        for gb in groups[i:]:
            key = (ga, gb)  # groups are sorted
            members = [b for b in bodies if b.group in key]
            free = [b for b in members if b.free]
            if key in best:
                omega, area, mass, k, names, what = best[key]
                how = (f"omega = sqrt(kn A / m) = sqrt({k:.4g} Pa/m x {area:.4g} m^2 / {mass:.4g} kg) = {omega:.5g} rad/s "
                       f"({names[0]} on {names[1]}, {what}); beta = 2 zeta / omega, zeta = {damping_ratio:g}")
            elif free and (ga != gb or len(members) > 1):
                # no interface at the start: the lightest free block of the pair landing on its largest face
                blk = min(free, key=lambda x: x.mass)
                area = _largest_face(blk.poly)
                partner = gb if blk.group == ga else ga
                partner_free = any(b.free and b.group == partner and b is not blk for b in members)
                mass = blk.mass / 2.0 if partner_free else blk.mass  # an equal free partner: the reduced mass
                k = kn(ga, gb)
                omega = math.sqrt(k * area / mass)
                names = (blk.name, "")
                how = (f"no facing faces at the start: {blk.name} landing on its largest face, omega = sqrt(kn A / m) = "
                       f"sqrt({k:.4g} x {area:.4g} / {mass:.4g}) = {omega:.5g} rad/s; beta = 2 zeta / omega, zeta = {damping_ratio:g}")
            else:
                out[key] = PairBeta(key, 0.0, "no free block" if not free else "no contact possible",
                                    how="the pair never touches a free block: its beta is never used")
                continue
            out[key] = PairBeta(key, 2.0 * damping_ratio / omega, "critical", omega, area, mass, k, names, how)
    return out


def critical_betas(model, *, damping_ratio: float = 1.0, gap_fraction: float = GAP_FRACTION) -> dict[tuple[str, str], PairBeta]:  # noqa: ANN001
    """:func:`critical_pair_betas` of a finalized :class:`~rockdem.model.Model` (its materials' kn)."""
    m = model.arrays
    gi = {g: k for k, g in enumerate(model.group_names)}
    return critical_pair_betas(model_bodies(model), lambda a, b: float(m.mat_kn[gi[a], gi[b]]),
                               damping_ratio=damping_ratio, gap_fraction=gap_fraction)
