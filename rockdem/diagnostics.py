"""Independent geometric checks of a result: interpenetration of blocks by separating axes.

This module re-derives the block geometry from a result Dataset (vertices in the body frames,
faces, recorded poses) and measures, in plain NumPy and without any code of the engine, how deep
the blocks overlap. For two convex polyhedra the penetration depth (the shortest translation that
separates them) is the smallest interval overlap over the candidate axes: the face normals of both
blocks and the cross products of their edge directions (the normals of the faces of the Minkowski
difference). A positive smallest overlap means the interiors intersect by that depth [m].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from .kernels.rotation import quats_to_matrices

__all__ = ["BlockShape", "block_shapes", "penetration_depth", "Interpenetration", "max_interpenetration"]


@dataclass(frozen=True)
class BlockShape:
    """One block's convex geometry in its body frame.

    Attributes:
        vertices: (n, 3) vertex coordinates [m].
        normals: (f, 3) outward unit face normals.
        edges: (e, 3) unit edge directions, one per direction (parallel edges merged).
        radius: largest vertex distance from the body origin [m].
        size: smallest extent of the vertex set along its face normals [m] (its thickness).
    """

    vertices: NDArray[np.float64]
    normals: NDArray[np.float64]
    edges: NDArray[np.float64]
    radius: float
    size: float


def block_shapes(ds: xr.Dataset) -> list[BlockShape]:
    """Geometry of every block of a result (see :mod:`rockdem.results` for the stored arrays)."""
    vl = ds.vertex_local.values
    vstart = ds.block_vertex_start.values
    fstart = ds.block_face_start.values
    corner = ds.face_vertex.values
    cstart = ds.face_corner_start.values
    shapes = []
    for b in range(ds.sizes["block"]):
        v = vl[vstart[b] : vstart[b + 1]]
        normals, dirs = [], []
        for f in range(fstart[b], fstart[b + 1]):
            ids = corner[cstart[f] : cstart[f + 1]]
            p = vl[ids]
            n = np.cross(p[1] - p[0], p[2] - p[0])
            for k in range(2, len(p)):  # a robust normal: largest cross product of the fan
                c = np.cross(p[k - 1] - p[0], p[k] - p[0])
                if np.linalg.norm(c) > np.linalg.norm(n):
                    n = c
            n /= np.linalg.norm(n)
            if (p.mean(axis=0) - v.mean(axis=0)) @ n < 0:
                n = -n
            normals.append(n)
            e = np.roll(p, -1, axis=0) - p
            dirs.extend(e / np.linalg.norm(e, axis=1, keepdims=True))
        uniq: list[NDArray[np.float64]] = []
        for d in dirs:
            if all(abs(abs(float(d @ u)) - 1.0) > 1e-9 for u in uniq):
                uniq.append(d)
        nrm = np.array(normals)
        extent = np.array([np.ptp(v @ n) for n in nrm])
        shapes.append(BlockShape(v, nrm, np.array(uniq), float(np.max(np.linalg.norm(v, axis=1))), float(extent.min())))
    return shapes


def penetration_depth(
    va: NDArray[np.float64], na: NDArray[np.float64], ea: NDArray[np.float64],
    vb: NDArray[np.float64], nb: NDArray[np.float64], eb: NDArray[np.float64],
) -> float:
    """Penetration depth [m] of two convex polyhedra in world coordinates (<= 0: apart or touching).

    Args:
        va, vb: (n, 3) world vertices; na, nb: (f, 3) world face normals; ea, eb: (e, 3) world
            edge directions.
    """
    cross = np.cross(ea[:, None, :], eb[None, :, :]).reshape(-1, 3)
    ln = np.linalg.norm(cross, axis=1)
    cross = cross[ln > 1e-9] / ln[ln > 1e-9, None]
    axes = np.vstack([na, nb, cross])
    pa = va @ axes.T
    pb = vb @ axes.T
    overlap = np.minimum(pa.max(axis=0) - pb.min(axis=0), pb.max(axis=0) - pa.min(axis=0))
    return float(overlap.min())


@dataclass(frozen=True)
class Interpenetration:
    """Largest interpenetration found in a result.

    Attributes:
        depth: penetration depth [m] (<= 0 when no two blocks overlap).
        relative: depth over the smaller block's thickness (its smallest dimension).
        time: when it occurred [s].
        blocks: the two block names.
        per_frame: (T,) the largest depth of each checked frame [m].
    """

    depth: float
    relative: float
    time: float
    blocks: tuple[str, str]
    per_frame: NDArray[np.float64]


def max_interpenetration(ds: xr.Dataset, *, frames: slice | NDArray[np.int64] | None = None) -> Interpenetration:
    """Largest interpenetration between any two blocks over the recorded frames (default all).

    Pairs are pre-selected by bounding spheres; each candidate pair is tested on every separating
    axis (face normals and edge x edge), so the depth is exact for convex blocks.
    """
    shapes = block_shapes(ds)
    idx = np.arange(ds.sizes["time"])[frames] if frames is not None else np.arange(ds.sizes["time"])
    pos = ds.block_position.values[idx]
    rot = quats_to_matrices(ds.block_quaternion.values[idx])
    names = [str(n) for n in ds.block_name.values]
    free = ds.block_free.values.astype(bool)
    radius = np.array([s.radius for s in shapes])
    per_frame = np.full(len(idx), -np.inf)
    best = (-np.inf, 0.0, 0, 0, 0.0)
    nb = len(shapes)
    for k in range(len(idx)):
        p = pos[k]
        dist = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=-1)
        close = np.argwhere(np.triu(dist <= radius[:, None] + radius[None, :], 1))
        for a, b in close:
            if not (free[a] or free[b]):
                continue
            ra, rb = rot[k, a], rot[k, b]
            d = penetration_depth(
                shapes[a].vertices @ ra.T + p[a], shapes[a].normals @ ra.T, shapes[a].edges @ ra.T,
                shapes[b].vertices @ rb.T + p[b], shapes[b].normals @ rb.T, shapes[b].edges @ rb.T,
            )
            per_frame[k] = max(per_frame[k], d)
            size = min(shapes[a].size, shapes[b].size)
            if d / size > best[0]:
                best = (d / size, d, int(a), int(b), float(ds.time.values[idx[k]]))
        if nb < 2:
            per_frame[k] = 0.0
    rel, depth, a, b, t = best
    if not np.isfinite(rel):
        return Interpenetration(0.0, 0.0, float("nan"), ("", ""), per_frame)
    return Interpenetration(depth, rel, t, (names[a], names[b]), per_frame)
