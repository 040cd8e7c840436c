"""Flatten block geometry into the kernels' arrays (body frames, CSR layout).

Called once by :meth:`rockdem.model.ModelBuilder.finalize`: vertices, faces with their 2D frames
and polygon edge lines, edges and edge directions, and the interface points with their tributary
cells (see :class:`rockdem.kernels.layout.ModelArrays` for the meaning of each array).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import NDArray

from .geometry import Polyhedron, face_grid

__all__ = ["BlockFrame", "flatten_geometry"]


@dataclass(frozen=True)
class BlockFrame:
    """A block's geometry and its principal body frame.

    Attributes:
        poly: the block at its initial pose [m].
        centroid: (3,) [m]. rotation: (3, 3) body -> world (columns: principal axes).
        points: interface points per face (across, along).
    """

    poly: Polyhedron
    centroid: NDArray[np.float64]
    rotation: NDArray[np.float64]
    points: tuple[int, int]


def _edges(faces: Sequence[NDArray[np.int64]]) -> list[tuple[int, int]]:
    """Unique edges (i < j) of a polyhedron from its face rings, in first-seen order."""
    seen: dict[tuple[int, int], None] = {}
    for f in faces:
        for j in range(len(f)):
            a, b = int(f[j]), int(f[(j + 1) % len(f)])
            seen.setdefault((min(a, b), max(a, b)), None)
    return list(seen)


def _directions(local: NDArray[np.float64], edges: list[tuple[int, int]]) -> NDArray[np.float64]:
    """Unit edge directions with parallel edges merged (the SAT's edge x edge axes)."""
    out: list[NDArray[np.float64]] = []
    for i, j in edges:
        d = local[j] - local[i]
        d = d / np.linalg.norm(d)
        if all(abs(abs(float(d @ u)) - 1.0) > 1e-9 for u in out):
            out.append(d)
    return np.array(out)


def flatten_geometry(blocks: Sequence[BlockFrame]) -> dict[str, NDArray]:
    """Kernel arrays of the block geometry (keys are :class:`ModelArrays` field names)."""
    vloc: list[NDArray[np.float64]] = []
    vstart, fstart, estart, dstart = [0], [0], [0], [0]
    edge_vertex, edge_area, dirs = [], [], []
    fblock, fnorm, foff, farea, forig, fu, fw = [], [], [], [], [], [], []
    cstart, corner, corner_uw, lstart, lines = [0], [], [], [0], []
    pstart, ploc, parea, pblock, pface, pnode, pcorner = [0], [], [], [], [], [], []
    cellstart, cellv = [0], []
    for b, blk in enumerate(blocks):
        rot, cen = blk.rotation, blk.centroid
        local = (blk.poly.vertices - cen) @ rot
        base_v = vstart[-1]
        vloc.append(local)
        vstart.append(base_v + len(local))
        face_of_edge: dict[tuple[int, int], list[int]] = {}
        per_point_area: list[float] = []
        for k, fverts in enumerate(blk.poly.faces):
            g = face_grid(blk.poly, k, *blk.points)
            fid = len(fnorm)
            fblock.append(b)
            fnorm.append(blk.poly.normals[k] @ rot)
            forig.append((g.origin - cen) @ rot)
            fu.append(g.u @ rot)
            fw.append(g.w @ rot)
            foff.append(float(fnorm[-1] @ forig[-1]))
            farea.append(float(g.areas.sum()))
            per_point_area.append(float(g.areas.sum()) / len(g.areas))
            corner.extend(int(v) + base_v for v in fverts)
            cstart.append(len(corner))
            q = np.column_stack(((blk.poly.vertices[fverts] - g.origin) @ g.u, (blk.poly.vertices[fverts] - g.origin) @ g.w))
            corner_uw.append(q)
            for j in range(len(q)):
                e = q[(j + 1) % len(q)] - q[j]
                nrm = np.array([e[1], -e[0]]) / np.hypot(e[0], e[1])  # outward for a CCW ring
                lines.append((nrm[0], nrm[1], float(nrm @ q[j])))
                a_, b_ = int(fverts[j]), int(fverts[(j + 1) % len(fverts)])
                face_of_edge.setdefault((min(a_, b_), max(a_, b_)), []).append(k)
            lstart.append(len(lines))
            ploc.append((g.points - cen) @ rot)
            parea.append(g.areas)
            pblock.append(np.full(len(g.areas), b))
            pface.append(np.full(len(g.areas), fid))
            pnode.append(g.nodes)
            # The point that sits on a corner of its face (a block vertex): a vertex-face contact there
            # is stiffened (kernels.forces, docs/contacts.md).
            gap = np.linalg.norm(g.nodes[:, None, :] - q[None, :, :], axis=2)  # (points, corners) [m]
            near = np.argmin(gap, axis=1)
            on = gap[np.arange(len(near)), near] <= 1e-9 * max(float(np.ptp(q)), 1e-300)
            pcorner.append(np.where(on, cstart[-2] + near, -1))
            for cell in g.cells:
                cellv.extend(cell)
                cellstart.append(len(cellv))
            pstart.append(pstart[-1] + len(g.areas))
        fstart.append(fstart[-1] + len(blk.poly.faces))
        edges = _edges(blk.poly.faces)
        for i, j in edges:
            edge_vertex.append((i + base_v, j + base_v))
            adj = face_of_edge.get((i, j), [])
            edge_area.append(float(np.mean([per_point_area[k] for k in adj])) if adj else float(np.mean(per_point_area)))
        estart.append(len(edge_vertex))
        d = _directions(local, edges)
        dirs.append(d)
        dstart.append(dstart[-1] + len(d))
    i64 = np.int64
    return {
        "block_vertex_start": np.array(vstart, dtype=i64),
        "vertex_local": np.concatenate(vloc),
        "block_edge_start": np.array(estart, dtype=i64),
        "edge_vertex": np.array(edge_vertex, dtype=i64).reshape(-1, 2),
        "edge_area": np.array(edge_area),
        "block_dir_start": np.array(dstart, dtype=i64),
        "dir_local": np.concatenate(dirs),
        "block_face_start": np.array(fstart, dtype=i64),
        "face_block": np.array(fblock, dtype=i64),
        "face_normal": np.array(fnorm),
        "face_offset": np.array(foff),
        "face_area": np.array(farea),
        "face_origin": np.array(forig),
        "face_u": np.array(fu),
        "face_w": np.array(fw),
        "face_corner_start": np.array(cstart, dtype=i64),
        "face_corner": np.array(corner, dtype=i64),
        "face_corner_uw": np.concatenate(corner_uw),
        "face_line_start": np.array(lstart, dtype=i64),
        "face_line": np.array(lines),
        "face_point_start": np.array(pstart, dtype=i64),
        "point_local": np.concatenate(ploc),
        "point_area": np.concatenate(parea),
        "point_block": np.concatenate(pblock).astype(i64),
        "point_face": np.concatenate(pface).astype(i64),
        "point_node": np.concatenate(pnode),
        "point_corner": np.concatenate(pcorner).astype(i64),
        "point_cell_start": np.array(cellstart, dtype=i64),
        "cell_vertex": np.array(cellv).reshape(-1, 2),
    }
