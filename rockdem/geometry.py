"""Convex polyhedral block geometry: hulls, faces, mass properties and interface points.

Everything here is plain NumPy/SciPy and runs once, when a model is built. Units are SI: lengths in
metres, density in kg/m^3, mass in kg, inertia in kg*m^2. Boxes are built directly; other shapes go
through Qhull (``scipy.spatial``, imported only then: a quarter of a warm ``rockdem run``).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "Polyhedron",
    "MassProperties",
    "convex_hull",
    "box",
    "mass_properties",
    "face_points",
    "FaceGrid",
    "face_grid",
    "MAX_FACE_POINTS",
]

_REL_TOL = 1e-9

MAX_FACE_POINTS = 10_000
"""Most interface points on one face (across x along); the paper uses 2 to 15 across."""

MAX_LENGTH = 1e6
"""Largest side of a box [m] (larger values are unit mistakes or overflow the mass properties)."""


@dataclass(frozen=True)
class Polyhedron:
    """A convex polyhedron.

    Attributes:
        vertices: (n, 3) vertex coordinates [m].
        faces: one int array per face, vertex indices counter-clockwise seen from outside.
        normals: (f, 3) outward unit normals.
        offsets: (f,) plane offsets, ``normals[i] @ x <= offsets[i]`` for every point x inside.
    """

    vertices: NDArray[np.float64]
    faces: tuple[NDArray[np.int64], ...]
    normals: NDArray[np.float64]
    offsets: NDArray[np.float64]

    @property
    def size(self) -> float:
        """Diameter of the vertex set [m]."""
        v = self.vertices
        return float(np.max(np.linalg.norm(v[:, None, :] - v[None, :, :], axis=-1)))

    def transformed(self, rotation: ArrayLike, translation: ArrayLike) -> "Polyhedron":
        """Return the polyhedron moved rigidly: x -> R x + t."""
        r = np.asarray(rotation, dtype=float)
        t = np.asarray(translation, dtype=float)
        normals = self.normals @ r.T
        vertices = self.vertices @ r.T + t
        offsets = self.offsets + normals @ t
        return Polyhedron(vertices, self.faces, normals, offsets)

    def contains(self, points: ArrayLike, tol: float = 0.0) -> NDArray[np.bool_]:
        """Whether points (m, 3) lie inside (within ``tol`` metres of) the polyhedron."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        return np.all(p @ self.normals.T - self.offsets <= tol, axis=1)


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of a homogeneous solid.

    Attributes:
        volume: [m^3].
        mass: [kg].
        centroid: (3,) [m].
        inertia: (3, 3) inertia tensor about the centroid, world axes [kg m^2].
    """

    volume: float
    mass: float
    centroid: NDArray[np.float64]
    inertia: NDArray[np.float64]


MIN_THICKNESS = 1e-5
"""A block thinner than this share of its size (across one of its faces) is refused by :func:`convex_hull`."""


def convex_hull(vertices: ArrayLike, *, name: str = "block") -> Polyhedron:
    """Build a convex polyhedron from its vertices.

    Coplanar hull triangles are merged into polygonal faces. Every given vertex must be a corner of
    the hull: a vertex inside the hull means the intended shape is not convex, which rockdem refuses
    (split such a shape into convex blocks).

    Args:
        vertices: (n, 3) coordinates [m], n >= 4, not all coplanar.
        name: used in error messages.

    Raises:
        ValueError: degenerate (flat, collinear, too few points) or non-convex vertex sets.
    """
    try:
        v = np.asarray(vertices, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: vertices must be an (n, 3) array of numbers [m], got {vertices!r}"[:300]) from None
    if v.ndim != 2 or v.shape[1] != 3 or v.shape[0] < 4:
        raise ValueError(f"{name}: vertices must be an (n, 3) array with n >= 4, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name}: vertices contain NaN or infinite values")
    scale = float(np.max(np.ptp(v, axis=0)))
    if scale <= 0.0:
        raise ValueError(f"{name}: all vertices coincide; give a block of positive size")
    from scipy.spatial import ConvexHull, QhullError  # noqa: PLC0415 - only for shapes other than boxes

    try:
        hull = ConvexHull(v)
    except QhullError as exc:
        raise ValueError(
            f"{name}: vertices are flat or degenerate (zero volume); give a block with positive "
            "extent in all three directions"
        ) from exc
    tol = 1e-7 * scale
    # Width across each facet's plane: a block thinner than MIN_THICKNESS of its size (a slab 1e-9 m
    # thick passed every other test) would need a timestep so small that its run never ends.
    width = float(np.min(np.ptp(v @ hull.equations[:, :3].T, axis=0)))
    if width < MIN_THICKNESS * scale:
        raise ValueError(
            f"{name}: the block is {width:.3g} m thin across one of its faces, {width / scale:.2g} of its size "
            f"({scale:.3g} m); blocks thinner than {MIN_THICKNESS:g} of their size are refused (their timestep would be "
            "vanishingly small): give a thicker block")
    # Group hull triangles by plane.
    planes: list[tuple[NDArray[np.float64], float, set[int]]] = []
    for simplex, eq in zip(hull.simplices, hull.equations):
        n, d = eq[:3], -eq[3]
        for pn, pd, verts in planes:
            if np.dot(pn, n) > 1.0 - 1e-9 and abs(pd - d) < tol:
                verts.update(int(i) for i in simplex)
                break
        else:
            planes.append((n.copy(), float(d), {int(i) for i in simplex}))
    # Each plane: all input vertices lying on it (catches coplanar points qhull dropped).
    hull_idx = set(int(i) for i in hull.vertices)
    for i in range(len(v)):
        if i in hull_idx:
            continue
        dist = min(float(pd - pn @ v[i]) for pn, pd, _ in planes)
        if dist > tol:
            raise ValueError(
                f"{name}: vertex {i} at {v[i].tolist()} lies inside the convex hull of the others, "
                "so the block is not convex. rockdem blocks are convex polyhedra: split the shape "
                "into convex blocks."
            )
    # Keep only hull vertices, renumbered.
    keep = sorted(hull_idx)
    renum = {old: new for new, old in enumerate(keep)}
    verts = v[keep]
    faces = []
    normals = []
    offsets = []
    for pn, pd, ids in planes:
        ids_new = np.array([renum[i] for i in ids if i in renum])
        pts = verts[ids_new]
        c = pts.mean(axis=0)
        a = pts[0] - c
        a = a - pn * (pn @ a)
        a /= np.linalg.norm(a)
        b = np.cross(pn, a)
        # The face's outline: the convex hull of its points in its plane, counter-clockwise seen from
        # outside. A point inside it (a vertex raised 1e-8 to 1e-5 m above a face's middle, merged
        # into that face within the tolerance) is no corner: sorted by angle with the others, it cut
        # the outline, and a 1 m cube weighed 3.7 % too little.
        xy = np.column_stack([(pts - c) @ a, (pts - c) @ b])
        try:
            order = ids_new[ConvexHull(xy).vertices]
        except QhullError:  # collinear points: _drop_collinear below reports the face as a line
            order = ids_new[np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))]
        # Drop vertices collinear with their neighbours (they are not face corners).
        order = _drop_collinear(verts, order, tol)
        if len(order) < 3:  # a sliver thinner than the tolerance: its narrow faces collapse to lines
            raise ValueError(
                f"{name}: vertices are flat or degenerate (a face collapses to a line within {tol:.3g} m, 1e-7 of "
                f"the block's size); give a block with a positive extent in all three directions")
        faces.append(order.astype(np.int64))
        normals.append(pn / np.linalg.norm(pn))
        offsets.append(pd)
    used = sorted({int(i) for f in faces for i in f})  # a vertex that is no face's corner (inside a face) is dropped
    if len(used) < len(verts):
        renum2 = {old: new for new, old in enumerate(used)}
        verts = verts[used]
        faces = [np.array([renum2[int(i)] for i in f], dtype=np.int64) for f in faces]
    return Polyhedron(verts, tuple(faces), np.array(normals), np.array(offsets))


def _drop_collinear(v: NDArray[np.float64], order: NDArray[np.int64], tol: float) -> NDArray[np.int64]:
    keep = []
    k = len(order)
    for j in range(k):
        p0, p1, p2 = v[order[j - 1]], v[order[j]], v[order[(j + 1) % k]]
        e1, e2 = p1 - p0, p2 - p1
        if np.linalg.norm(np.cross(e1, e2)) > tol * (np.linalg.norm(e1) + np.linalg.norm(e2) + 1e-300):
            keep.append(order[j])
    return np.array(keep, dtype=np.int64)


_BOX_PLANES = ((2, -1.0), (1, -1.0), (0, 1.0), (0, -1.0), (1, 1.0), (2, 1.0))
"""(axis, outward sign) of a box's faces, in the order Qhull gives them (-z, -y, +x, -x, +y, +z)."""

_BOX_FACES = ((0, 2, 6, 4), (0, 4, 5, 1), (4, 6, 7, 5), (0, 1, 3, 2), (2, 3, 7, 6), (1, 5, 7, 3))
"""A box's faces: indices of its vertices (vertex 4 sx + 2 sy + sz at the corner with signs s of
(x, y, z), 0 for -1, 1 for +1), counter-clockwise seen from outside, each from its lowest index.
:func:`convex_hull` gives the same faces in the same order, but starts some of them at another
vertex, depending on the round-off of Qhull's normals (eight variants over random boxes)."""


def box(b: float, l: float, h: float, *, center: ArrayLike = (0.0, 0.0, 0.0), name: str = "box") -> Polyhedron:
    """Rectangular box of width ``b`` (x), length ``l`` (y) and height ``h`` (z) [m], centred at ``center``."""
    for field, val in (("b (width, x)", b), ("l (length, y)", l), ("h (height, z)", h)):
        if isinstance(val, bool) or not isinstance(val, numbers.Real) or not np.isfinite(val) or not 0.0 < val <= MAX_LENGTH:
            raise ValueError(f"{name}: {field} must be a positive length in metres (at most {MAX_LENGTH:g}), got {val!r}")
    try:
        c = np.asarray(center, dtype=float)
    except (TypeError, ValueError):
        c = np.full(0, np.nan)
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise ValueError(f"{name}: center must be a finite point (x, y, z) [m], got {center!r}")
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    vertices = c + 0.5 * signs * np.array([b, l, h])
    normals = np.zeros((6, 3))
    for k, (axis, side) in enumerate(_BOX_PLANES):
        normals[k, axis] = side
    offsets = np.array([normals[k] @ vertices[f[0]] for k, f in enumerate(_BOX_FACES)])
    return Polyhedron(vertices, tuple(np.array(f, dtype=np.int64) for f in _BOX_FACES), normals, offsets)


def mass_properties(poly: Polyhedron, density: float) -> MassProperties:
    """Volume, mass, centroid and inertia tensor by the divergence theorem (tetrahedra fan).

    Each face is fanned into triangles which, with a reference point, form signed tetrahedra whose
    volume, first and second moments are summed exactly.
    """
    if isinstance(density, bool) or not isinstance(density, numbers.Real) or not (np.isfinite(density) and density > 0):
        raise ValueError(f"density must be a positive number [kg/m^3], got {density!r}")
    v = poly.vertices
    ref = v.mean(axis=0)
    vol = 0.0
    first = np.zeros(3)
    second = np.zeros((3, 3))
    for f in poly.faces:
        a = v[f[0]] - ref
        for j in range(1, len(f) - 1):
            b = v[f[j]] - ref
            c = v[f[j + 1]] - ref
            det = float(np.dot(a, np.cross(b, c)))
            vol += det / 6.0
            s = a + b + c
            first += det / 24.0 * s
            second += det / 120.0 * (np.outer(a, a) + np.outer(b, b) + np.outer(c, c) + np.outer(s, s))
    centroid_rel = first / vol
    cov = second - vol * np.outer(centroid_rel, centroid_rel)
    inertia = density * (np.trace(cov) * np.eye(3) - cov)
    return MassProperties(vol, density * vol, ref + centroid_rel, 0.5 * (inertia + inertia.T))


def _polygon_area(p: NDArray[np.float64]) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _clip(poly: NDArray[np.float64], clipper: NDArray[np.float64]) -> NDArray[np.float64]:
    """Sutherland-Hodgman clip of 2D polygon ``poly`` by convex CCW polygon ``clipper``."""
    out = poly
    n = len(clipper)
    for i in range(n):
        if len(out) == 0:
            break
        out = _clip_line(out, clipper[i], clipper[(i + 1) % n] - clipper[i])
    return out


def _clip_line(poly: NDArray[np.float64], a: NDArray[np.float64], e: NDArray[np.float64]) -> NDArray[np.float64]:
    """The part of 2D polygon ``poly`` on the left of the line through ``a`` along ``e`` (or on it)."""
    out_list = []
    side = e[0] * (poly[:, 1] - a[1]) - e[1] * (poly[:, 0] - a[0])
    m = len(poly)
    for j in range(m):
        cur, nxt = poly[j], poly[(j + 1) % m]
        sc, sn = side[j], side[(j + 1) % m]
        if sc >= 0:
            out_list.append(cur)
        if (sc >= 0) != (sn >= 0):
            t = sc / (sc - sn)
            out_list.append(cur + t * (nxt - cur))
    return np.array(out_list) if out_list else np.zeros((0, 2))


def _split_at_corners(
    node: NDArray[np.float64], cell: NDArray[np.float64], corners: list[NDArray[np.float64]], tol: float
) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """(node, cell) pairs that give each face corner in ``cell`` a point of its own: the cell is
    split among its node and those corners by their Voronoi regions (each part convex, the parts
    sum to the cell). Without corners, the cell as it is."""
    if not corners:
        return [(node, cell)]
    gens = [node, *corners]
    out = []
    for i, g in enumerate(gens):
        part = cell
        for j, h in enumerate(gens):
            if j != i and len(part):
                d = h - g
                part = _clip_line(part, 0.5 * (g + h), np.array([-d[1], d[0]]))
        if len(part) >= 3 and abs(_polygon_area(part)) > tol * tol:
            out.append((g if i > 0 or _inside_2d(g, part, tol) else _polygon_centroid(part), part))
    return out


def _min_area_rect_axes(p2: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit axis (2,) of the minimum-area bounding rectangle of a convex polygon (rotating calipers)."""
    best, best_axis = np.inf, np.array([1.0, 0.0])
    for i in range(len(p2)):
        e = p2[(i + 1) % len(p2)] - p2[i]
        ln = np.linalg.norm(e)
        if ln == 0.0:
            continue
        u = e / ln
        w = np.array([-u[1], u[0]])
        area = np.ptp(p2 @ u) * np.ptp(p2 @ w)
        if area < best * (1.0 - 1e-12):
            best, best_axis = area, u
    return best_axis


@dataclass(frozen=True)
class FaceGrid:
    """Interface points of one face with their tributary cells, in the face's own 2D frame.

    A point x of the face plane has face coordinates (x - origin) . u, (x - origin) . w.

    Attributes:
        origin: (3,) a point of the face (its vertex centroid) [m].
        u: (3,) unit in-plane axis "across" (the shorter side of the minimum bounding rectangle).
        w: (3,) unit in-plane axis "along" (w = normal x u).
        points: (k, 3) interface points [m].
        nodes: (k, 2) the points in face coordinates [m].
        areas: (k,) tributary areas [m^2] (they sum to the face area).
        cells: per point, the tributary cell (its grid rectangle clipped to the face polygon) as a
            (c, 2) counter-clockwise polygon in face coordinates [m].
    """

    origin: NDArray[np.float64]
    u: NDArray[np.float64]
    w: NDArray[np.float64]
    points: NDArray[np.float64]
    nodes: NDArray[np.float64]
    areas: NDArray[np.float64]
    cells: tuple[NDArray[np.float64], ...]


def face_grid(poly: Polyhedron, face: int, n_across: int, n_along: int) -> FaceGrid:
    """Interface integration points of one face, their tributary cells and areas.

    The face's minimum-area bounding rectangle defines two axes: "across" (the shorter side, the
    wall thickness for a bed face) and "along" (the longer side). ``n_across x n_along`` nodes are
    spread evenly over the rectangle *including its edges*, so that 2 x 2 puts the points at the
    corners of a rectangular face (3DEC's minimal sub-contacts, the paper's "2 contact points").
    Each node's tributary cell (half cells at the ends, the trapezoidal rule) is clipped to the
    face polygon; its clipped area is the point's area, so the areas sum exactly to the face area.
    A node outside a non-rectangular face is moved to its clipped cell's centroid, and (with at
    least 2 x 2 nodes) every corner of the face that is not a node gets a point of its own, with
    the part of its cell nearer to it than to the cell's node (a block landing on that corner is
    held there; a rectangle's corners are nodes already). The cells are
    what the contact law clips against a partner face (see ``docs/contacts.md``): the force of a
    point is carried by the part of its cell that the partner covers.
    """
    for what, n in (("across", n_across), ("along", n_along)):
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
            raise ValueError(f"interface points: the count {what} must be an integer >= 1, got {n!r}")
    if n_across * n_along > MAX_FACE_POINTS:
        raise ValueError(
            f"interface points: {n_across} x {n_along} per face exceed the limit of {MAX_FACE_POINTS} "
            "(the paper uses 2 to 15 across)"
        )
    if isinstance(face, bool) or not isinstance(face, numbers.Integral) or not 0 <= face < len(poly.faces):
        raise ValueError(f"interface points: face must be an index in [0, {len(poly.faces)}), got {face!r}")
    v = poly.vertices[poly.faces[face]]
    n = poly.normals[face]
    c = v.mean(axis=0)
    ax = v[1] - v[0]
    ax = ax - n * (n @ ax)
    ax /= np.linalg.norm(ax)
    ay = np.cross(n, ax)
    p2 = np.column_stack(((v - c) @ ax, (v - c) @ ay))
    u = _min_area_rect_axes(p2)
    if np.ptp(p2 @ u) > np.ptp(p2 @ np.array([-u[1], u[0]])):  # make u the short side ("across")
        u = np.array([-u[1], u[0]])
    u3 = u[0] * ax + u[1] * ay
    w3 = np.cross(n, u3)
    q2 = np.column_stack(((v - c) @ u3, (v - c) @ w3))  # face polygon in (u, w), counter-clockwise
    su, sw = q2[:, 0], q2[:, 1]
    nodes, areas, cells = [], [], []
    gu = _nodes(su.min(), su.max(), n_across)
    gw = _nodes(sw.min(), sw.max(), n_along)
    size = max(np.ptp(su), np.ptp(sw))
    grid = []  # (node, clipped cell) of each grid cell with an area
    for (ucen, ulo, uhi) in gu:
        for (wcen, wlo, whi) in gw:
            cell = np.array([[ulo, wlo], [uhi, wlo], [uhi, whi], [ulo, whi]])
            clipped = _clip(cell, q2)
            if len(clipped) < 3:
                continue
            area = abs(_polygon_area(clipped))
            if area <= _REL_TOL * size * size:
                continue
            node = np.array([ucen, wcen])
            if not _inside_2d(node, q2, 1e-9 * size):
                node = _polygon_centroid(clipped)
            grid.append((node, _drop_duplicates(clipped, 1e-12 * size)))
    # With nodes on the face's edges (2 or more each way), every face corner gets a point (a corner
    # that lands alone must be held there): a corner that is no node takes the part of the cell it
    # lies in that is nearer to it than to the cell's node. (One node across or along is a line
    # of points the user chose.)
    free = [c for c in range(len(q2)) if all(np.max(np.abs(q2[c] - node)) > 1e-9 * size for node, _ in grid)]
    if n_across < 2 or n_along < 2:
        free = []
    for node, clipped in grid:
        mine = [c for c in free if _inside_2d(q2[c], clipped, 1e-9 * size)]
        free = [c for c in free if c not in mine]
        for pt, part in _split_at_corners(node, clipped, [q2[c] for c in mine], np.sqrt(_REL_TOL) * size):
            nodes.append(pt)
            areas.append(abs(_polygon_area(part)))
            cells.append(part if part is clipped else _drop_duplicates(part, 1e-12 * size))
    nodes_a = np.array(nodes)
    points = c + nodes_a[:, :1] * u3 + nodes_a[:, 1:] * w3
    return FaceGrid(c, u3, w3, points, nodes_a, np.array(areas), tuple(cells))


def face_points(
    poly: Polyhedron, face: int, n_across: int, n_along: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Interface points (k, 3) [m] of one face and their tributary areas (k,) [m^2] (see :func:`face_grid`)."""
    g = face_grid(poly, face, n_across, n_along)
    return g.points, g.areas


def _drop_duplicates(p: NDArray[np.float64], tol: float) -> NDArray[np.float64]:
    """Remove consecutive (cyclically) coincident vertices of a polygon."""
    keep = [i for i in range(len(p)) if np.max(np.abs(p[i] - p[i - 1])) > tol]
    return p[keep] if len(keep) >= 3 else p


def _nodes(lo: float, hi: float, k: int) -> list[tuple[float, float, float]]:
    if k == 1:
        return [(0.5 * (lo + hi), lo, hi)]
    x = np.linspace(lo, hi, k)
    h = (hi - lo) / (k - 1)
    return [(float(xi), max(lo, xi - 0.5 * h), min(hi, xi + 0.5 * h)) for xi in x]


def _inside_2d(p: NDArray[np.float64], poly: NDArray[np.float64], tol: float) -> bool:
    n = len(poly)
    for i in range(n):
        a, b = poly[i], poly[(i + 1) % n]
        e = b - a
        ln = np.hypot(e[0], e[1])
        if e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0]) < -tol * ln:
            return False
    return True


def _polygon_centroid(p: NDArray[np.float64]) -> NDArray[np.float64]:
    x, y = p[:, 0], p[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    a = 0.5 * cross.sum()
    return np.array([((x + np.roll(x, -1)) * cross).sum(), ((y + np.roll(y, -1)) * cross).sum()]) / (6.0 * a)
