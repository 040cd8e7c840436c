"""Which face of a FACE pair carries its sub-contacts: the owner's points, the target's, or a blend.

The owner face (the smaller one, :mod:`rockdem.kernels.detect`) carries the paper's interface
points (§3.3). That quadrature misses the support where the *target's* edge or corner presses into
the middle of the owner face: a brick tipping over the edge of the course below, whose edge lies
under the middle of the brick (on the boundary between two of its cells), or a wedge of two equal
bed faces. There the target's points are the ones that penetrate.

The *clarity* c = sep_o - sep_t [m] says which: sep_o is the separation of the target's block from
the owner face's plane (the least over its vertices, negative when a vertex is below the plane),
sep_t that of the owner's block from the target face's plane. c > 0: the target's block penetrates
the owner face more clearly than the other way round. The target's points carry the share
lambda(c) (a smoothstep from 0 at BLEND_LOW to 1 at BLEND_HIGH tracking tolerances) and the owner's
points 1 - lambda: on a flat joint, a block on a foundation or a block rocking on its own edge
(c <= 0) nothing changes.

A weight that depends on the configuration is only energy-consistent if its own gradient is
applied: with U_o, U_t the normal spring energies of the two quadratures at full share, the contact
energy is U = (1 - lambda) U_o + lambda U_t, whose gradient adds -(U_t - U_o) lambda'(c) grad c to
the two sets of spring forces. grad sep_o is a unit force pair along the owner face's normal at the
target's deepest vertex (and likewise for sep_t), so the correction is two small force pairs
(:func:`blend_forces`). Switching the owner outright at a detection instead changed the stored
energy of a loaded contact in one step (a discretised parapet under El Centro x 5 created 2.8 % of
its energy). The shear springs, whose extension is a history and not a function of the pose, follow
a side's share as they follow a cell's cover (forces.cover_change): a growing share scales the
extension so that the spring keeps its energy, a shrinking one dissipates what it holds less
(forces._law_range).
"""

from __future__ import annotations

import numpy as np
from numba import njit

BLEND_LOW = 0.1
"""Clarity (in tracking tolerances) below which the owner's points alone carry the pair."""

BLEND_HIGH = 1.0
"""Clarity (in tracking tolerances) above which the target's points alone carry the pair."""

TRACK_MARGIN = 0.05
"""The target's points are tracked (and a detection is asked for) once the clarity is within this
many tracking tolerances of BLEND_LOW, so that they are in place before their share grows."""


@njit(cache=True, _nrt=False)
def face_clearance(
    face_normal: np.ndarray, face_offset: np.ndarray, face_block: np.ndarray, block_vertex_start: np.ndarray,
    vertex_local: np.ndarray, rotation: np.ndarray, position: np.ndarray, f: int, other: int,
) -> tuple[float, float, float, float, float, float, float]:
    """Separation [m] of block ``other`` from the plane of face ``f`` (the least over its vertices
    of n . (x - c) - offset; negative: that vertex is below the plane), that vertex (world) and the
    face's world normal n.

    The normal is taken into the other block's frame once (n_l = R^T n), so that each vertex costs
    one dot product with its local coordinates (n . (R v + x_other - c) = n_l . v + n . (x_other - c))
    instead of its rotation to the world: the unbonded face pairs of a settled wall call this twice per
    pair at every step (forces._blend)."""
    b = face_block[f]
    r = rotation[b]
    fn = face_normal[f]
    n0 = r[0, 0] * fn[0] + r[0, 1] * fn[1] + r[0, 2] * fn[2]
    n1 = r[1, 0] * fn[0] + r[1, 1] * fn[1] + r[1, 2] * fn[2]
    n2 = r[2, 0] * fn[0] + r[2, 1] * fn[1] + r[2, 2] * fn[2]
    ro = rotation[other]
    l0 = ro[0, 0] * n0 + ro[1, 0] * n1 + ro[2, 0] * n2
    l1 = ro[0, 1] * n0 + ro[1, 1] * n1 + ro[2, 1] * n2
    l2 = ro[0, 2] * n0 + ro[1, 2] * n1 + ro[2, 2] * n2
    base = (n0 * (position[other, 0] - position[b, 0]) + n1 * (position[other, 1] - position[b, 1])
            + n2 * (position[other, 2] - position[b, 2]) - face_offset[f])
    best = np.inf
    arg = block_vertex_start[other]
    for v in range(block_vertex_start[other], block_vertex_start[other + 1]):
        d = l0 * vertex_local[v, 0] + l1 * vertex_local[v, 1] + l2 * vertex_local[v, 2]
        if d < best:
            best, arg = d, v
    vl = vertex_local[arg]
    x0 = ro[0, 0] * vl[0] + ro[0, 1] * vl[1] + ro[0, 2] * vl[2] + position[other, 0]
    x1 = ro[1, 0] * vl[0] + ro[1, 1] * vl[1] + ro[1, 2] * vl[2] + position[other, 1]
    x2 = ro[2, 0] * vl[0] + ro[2, 1] * vl[1] + ro[2, 2] * vl[2] + position[other, 2]
    return best + base, x0, x1, x2, n0, n1, n2


@njit(cache=True, _nrt=False, inline="always")
def blend_weight(clarity: float, tol: float) -> tuple[float, float]:
    """Share lambda of the target's points and d lambda / d clarity [1/m] (smoothstep)."""
    lo = BLEND_LOW * tol
    hi = BLEND_HIGH * tol
    x = (clarity - lo) / (hi - lo)
    if x <= 0.0:
        return 0.0, 0.0
    if x >= 1.0:
        return 1.0, 0.0
    return x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x) / (hi - lo)


@njit(cache=True, _nrt=False, inline="always")
def tracks_target(clarity: float, tol: float) -> bool:
    """Whether the target's points must be tracked at this clarity."""
    return clarity > (BLEND_LOW - TRACK_MARGIN) * tol
