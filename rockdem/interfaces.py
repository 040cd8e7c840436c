"""The interfaces of a model and the critical SP damping of each joint group pair (paper Eq. 1-4, §2.2).

An *interface* is a pair of facing faces of two blocks, at least one free: antiparallel outward
normals, planes at most a gap apart (touching joints, or the few millimetres between a one-sided
façade and its return walls) and an overlap of positive area A, in the reference (untilted) pose.

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
0.0016 s here, the parapet's 0.00305 s is 0.0015 s). The rotational mode of a rocking impact is
slower than this translational one (for the façade on its return walls by H^2 / (B^2 + H^2)), so
omega is the highest impact frequency of the pair, the paper's choice (§2.2: it affects the timestep
the least). Per group pair the largest omega over its interfaces gives

    beta = 2 zeta / omega    (Eq. 4 with alpha = 0; zeta = 1 is critical damping).

A pair with no interface at the start (blocks that only meet when something falls) takes a free block
of the pair landing on its largest face; a pair of two driven groups never acts (beta = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from .beta_choice import PairBeta
from .geometry import Polyhedron, _clip, _polygon_area
from .kernels.rotation import quats_to_matrices

__all__ = ["Body", "FaceContact", "GAP_FRACTION", "face_contacts", "model_bodies", "critical_pair_betas", "critical_betas"]

GAP_FRACTION = 0.1
"""Largest gap between two facing faces that still makes an interface, as a fraction of the
smaller of the two blocks' smallest dimensions (a façade 0.11 m thick: 11 mm; Shawa et al.'s 4 mm
gap to the return walls is inside it)."""

PARALLEL_TOL_DEG = 2.0
"""Facing faces: outward normals antiparallel within this angle [deg]."""


@dataclass(frozen=True)
class Body:
    """A block as the interface search sees it.

    Attributes:
        name: block name. group: its joint-material group.
        poly: its geometry in the reference (untilted) pose [m].
        mass: [kg]. free: False for driven blocks.
    """

    name: str
    group: str
    poly: Polyhedron
    mass: float
    free: bool


@dataclass(frozen=True)
class FaceContact:
    """Two facing faces of bodies ``a`` and ``b`` (indices into the body list).

    Attributes:
        normal: (3,) outward unit normal of a's face (from a towards b).
        area: overlap area of the two faces [m^2].
        gap: distance between the two face planes [m] (negative: overlapping).
    """

    a: int
    b: int
    normal: NDArray[np.float64]
    area: float
    gap: float


def _face_frames(poly: Polyhedron) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    """(vertices (k, 3), outward normal (3,), plane offset) of every face."""
    return [(poly.vertices[f], poly.normals[i], float(poly.offsets[i])) for i, f in enumerate(poly.faces)]


def _overlap(va: NDArray[np.float64], vb: NDArray[np.float64], n: NDArray[np.float64]) -> float:
    """Area [m^2] of the overlap of two facing convex polygons (k, 3), projected on the plane of normal n."""
    u = va[1] - va[0]
    u = u - n * (n @ u)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    pa = np.column_stack((va @ u, va @ w))
    pb = np.column_stack((vb @ u, vb @ w))
    if _polygon_area(pa) < 0:
        pa = pa[::-1]
    if _polygon_area(pb) < 0:  # b's face runs counter-clockwise about -n
        pb = pb[::-1]
    clipped = _clip(pa, pb)
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
    thin = (hi - lo).min(axis=1)
    free = np.array([b.free for b in bodies], dtype=bool)
    cos_tol = math.cos(math.radians(PARALLEL_TOL_DEG))
    frames = [_face_frames(b.poly) for b in bodies]
    out: list[FaceContact] = []
    for i in range(len(bodies)):
        j = np.arange(i + 1, len(bodies))
        limit = gap_fraction * np.minimum(thin[i], thin[j])
        near = np.all((lo[j] <= hi[i] + limit[:, None]) & (hi[j] >= lo[i] - limit[:, None]), axis=1)
        near &= free[i] | free[j]
        for jj, lim in zip(j[near], limit[near]):
            for va, na, oa in frames[i]:
                for vb, nb, _ in frames[jj]:
                    if na @ nb > -cos_tol:
                        continue
                    gap = float(np.mean(vb @ na)) - oa
                    if abs(gap) > lim:
                        continue
                    area = _overlap(va, vb, na)
                    if area > 1e-12 * max(thin[i], thin[jj]) ** 2:
                        out.append(FaceContact(i, int(jj), na.copy(), area, gap))
    return out


@dataclass
class _Impact:
    """The faces of free block ``block`` facing blocks of ``group`` in one direction: they strike together."""

    block: int
    group: str
    normal: NDArray[np.float64]
    area: float
    partners: list[int]


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
                    break
            else:
                out.append(_Impact(own, group, n, c.area, [other]))
    return out


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
        out.append(Body(model.block_names[b], model.group_names[int(m.block_group[b])], poly,
                        float(m.block_mass[b]), bool(m.block_free[b])))
    return out


def _largest_face(poly: Polyhedron) -> float:
    return max(abs(_polygon_area(np.column_stack(_plane_coords(poly.vertices[f], poly.normals[k])))) for k, f in enumerate(poly.faces))


def _plane_coords(v: NDArray[np.float64], n: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    u = v[1] - v[0]
    u = u - n * (n @ u)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    return v @ u, v @ w


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
    best: dict[tuple[str, str], tuple[float, float, float, float, tuple[str, str]]] = {}
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
        omega = math.sqrt(k * imp.area / mass)
        if key not in best or omega > best[key][0]:
            best[key] = (omega, imp.area, mass, k, (own.name, " + ".join(p.name for p in partners)))
    groups = sorted({b.group for b in bodies})
    out: dict[tuple[str, str], PairBeta] = {}
    for i, ga in enumerate(groups):
        for gb in groups[i:]:
            key = (ga, gb)  # groups are sorted
            members = [b for b in bodies if b.group in key]
            free = [b for b in members if b.free]
            if key in best:
                omega, area, mass, k, names = best[key]
                how = (f"omega = sqrt(kn A / m) = sqrt({k:.4g} Pa/m x {area:.4g} m^2 / {mass:.4g} kg) = {omega:.5g} rad/s "
                       f"({names[0]} on {names[1]}); beta = 2 zeta / omega, zeta = {damping_ratio:g}")
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
