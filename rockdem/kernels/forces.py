"""Contact forces: the sub-contacts of face pairs and the point contacts of edge pairs (paper §3).

Each contact's force (spring, dashpot and transition corrections, :mod:`rockdem.kernels.contact`)
is stored with its point of application, per sub-contact in ``sc.contact_force`` /
``sc.contact_point`` and per edge pair in ``sc.pair_force`` / ``sc.pair_point``, and then added to
the blocks by :func:`accumulate` in the fixed pair order (so results do not depend on how the
contacts were computed).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .contact import (
    coulomb_limit,
    dashpot_onset_share,
    dashpot_release_share,
    drop_dissipation,
    ramp_overlap,
    release_shear,
    shear_increment,
    slip_dissipation,
    spring_energy,
)
from .blend import blend_weight, face_clearance, tracks_target
from .detect import edge_contact
from .faces import anchored_overlap, cell_above, crossing_lines, cut_cell, face_map_arrays
from .layout import (
    DASHPOTS_IMPLICIT,
    E_BOND,
    E_FRICTION,
    FAILED_NONE,
    FAILED_SHEAR,
    FAILED_TENSION,
    LAW_CHUNKS,
    PAIR_EDGE,
    SLOTS,
    STIFFENING_AT_START,
    ModelArrays,
    Scratch,
    State,
)
from .prefetch import prefetch
from .series import interpolate
from .variants import rebind


@njit(cache=True, _nrt=False, inline="always")
def has_dashpots(m: ModelArrays) -> bool:
    """Whether any pair of joint groups has SP damping (beta > 0); without, no block is damped and
    the passes over the contacts below are skipped."""
    for i in range(m.mat_beta.shape[0]):
        for j in range(m.mat_beta.shape[1]):
            if m.mat_beta[i, j] > 0.0:
                return True
    return False


@njit(cache=True, _nrt=False, inline="always")
def _relative_velocity_arrays(
    position: np.ndarray, velocity: np.ndarray, omega_world: np.ndarray, o: int, t: int, c0: float, c1: float, c2: float
) -> tuple[float, float, float]:
    r0, r1, r2 = c0 - position[o, 0], c1 - position[o, 1], c2 - position[o, 2]
    q0, q1, q2 = c0 - position[t, 0], c1 - position[t, 1], c2 - position[t, 2]
    v0 = velocity[o, 0] + omega_world[o, 1] * r2 - omega_world[o, 2] * r1 - (velocity[t, 0] + omega_world[t, 1] * q2 - omega_world[t, 2] * q1)
    v1 = velocity[o, 1] + omega_world[o, 2] * r0 - omega_world[o, 0] * r2 - (velocity[t, 1] + omega_world[t, 2] * q0 - omega_world[t, 0] * q2)
    v2 = velocity[o, 2] + omega_world[o, 0] * r1 - omega_world[o, 1] * r0 - (velocity[t, 2] + omega_world[t, 0] * q1 - omega_world[t, 1] * q0)
    return v0, v1, v2


CORNER_RESOLUTION = 0.3
"""Largest omega dt / 2 of a landing corner's stiffened spring (kernels.forces.corner_stiffening):
the impact resolution of :data:`rockdem.timestep.DEFAULT_RESOLUTION`, an impact of at least ~5 steps."""


@njit(cache=True, _nrt=False, inline="always")
def flexibility(rot: np.ndarray, inv_mass: float, inv_inertia: np.ndarray, r0: float, r1: float, r2: float, d0: float, d1: float, d2: float) -> float:
    """1/m + sum_j (r x d)_j^2 / I_j [1/kg] of a block at arm r [m] along unit d, inertia in its
    principal frame (``rot`` body -> world; 0 for driven blocks: inv_mass 0)."""
    if inv_mass == 0.0:
        return 0.0
    c0 = r1 * d2 - r2 * d1
    c1 = r2 * d0 - r0 * d2
    c2 = r0 * d1 - r1 * d0
    out = inv_mass
    for j in range(3):
        cj = rot[0, j] * c0 + rot[1, j] * c1 + rot[2, j] * c2
        out += cj * cj * inv_inertia[j]
    return out


@njit(cache=True, _nrt=False, inline="always")
def _neighbour_gap(m: ModelArrays, p: int, fo: int, h0: float, hu: float, hw: float) -> float:
    """The smaller gap [m] above the target plane of the two face corners next to point p's corner
    on face ``fo`` (gap h0 + hu u + hw w at face point (u, w) in the face map of fo on its partner)."""
    c = m.point_corner[p]
    c0 = m.face_corner_start[fo]
    n = m.face_corner_start[fo + 1] - c0
    a = c0 + (c - c0 + n - 1) % n
    b = c0 + (c - c0 + 1) % n
    return min(h0 + hu * m.face_corner_uw[a, 0] + hw * m.face_corner_uw[a, 1],
               h0 + hu * m.face_corner_uw[b, 0] + hw * m.face_corner_uw[b, 1])


@njit(cache=True, _nrt=False, inline="always")
def _rise(m: ModelArrays, p: int, fo: int, h0: float, hu: float, hw: float) -> float:
    """How much higher [m] above the target plane the lower of the two face corners next to point
    p's corner stands than that corner (0 or less: an edge or the face comes down with it)."""
    return _neighbour_gap(m, p, fo, h0, hu, hw) - (h0 + hu * m.point_node[p, 0] + hw * m.point_node[p, 1])


@njit(cache=True, _nrt=False, inline="always")
def landing_corner(m: ModelArrays, p: int, fo: int, ft: int, h0: float, hu: float, hw: float) -> float:
    """Area factor [-] of point p of face ``fo`` if its corner landed now on face ``ft`` (face map
    gaps h0 + hu u + hw w [m] of fo on ft): 1 + (F - 1) S(g / tol), F = min(A_fo, A_ft) / A_p
    (at least 1), g how much higher than the corner its lower neighbouring face corner stands
    above the target plane, S the smoothstep on [0, 1], tol the tracking tolerance; 1 for a point
    that is not on a corner of its face (see :func:`corner_stiffening`)."""
    if m.point_corner[p] < 0 or m.point_area[p] <= 0.0:
        return 1.0
    g = _rise(m, p, fo, h0, hu, hw) / m.contact_tol
    if g <= 0.0:
        return 1.0
    g = min(g, 1.0)
    full = max(1.0, min(m.face_area[fo], m.face_area[ft]) / m.point_area[p])
    return 1.0 + (full - 1.0) * g * g * (3.0 - 2.0 * g)


@njit(cache=True, _nrt=False)
def _classify_corner(
    m: ModelArrays, s: State, sc: Scratch, i: int, p: int, j: int, fo: int, ft: int, o: int, t: int, h0: float, hu: float,
    hw: float, before: float, x0: float, x1: float, x2: float, n0: float, n1: float, n2: float,
) -> float:
    """The factor of :func:`corner_stiffening` for a corner sub-contact that was not compressed at
    the last step (stored in ``s.slot_stiffening``); out of line, off the joint law's hot path."""
    f = 1.0
    d = before / m.contact_tol
    if d < 1.0 and s.dashpots[0] == DASHPOTS_IMPLICIT and not s.pair_from_edge[i]:
        f = landing_corner(m, p, fo, ft, h0, hu, hw)
        if f > 1.0:
            flex = flexibility(sc.rotation[o], m.block_inv_mass[o], m.block_inv_inertia[o], x0 - s.position[o, 0],
                               x1 - s.position[o, 1], x2 - s.position[o, 2], n0, n1, n2)
            flex += flexibility(sc.rotation[t], m.block_inv_mass[t], m.block_inv_inertia[t], x0 - s.position[t, 0],
                                x1 - s.position[t, 1], x2 - s.position[t, 2], n0, n1, n2)
            w = 2.0 * CORNER_RESOLUTION / s.dt_coarse[0]
            k = m.mat_kn[m.block_group[o], m.block_group[t]] * m.point_area[p]
            if k * flex > 0.0:
                f = max(1.0, min(f, w * w / (k * flex)))
            d = max(d, 0.0)
            f = 1.0 + (f - 1.0) * (1.0 - d * d * (3.0 - 2.0 * d))
    s.slot_stiffening[p, j] = f
    return f


@njit(cache=True, _nrt=False)
def _corner_ends(m: ModelArrays, s: State, p: int, j: int, fo: int, h0: float, hu: float, hw: float) -> bool:
    """Whether a landed corner's stiffening ends now: a neighbouring face corner came down to the
    target plane (:func:`corner_stiffening`); resets ``s.slot_stiffening`` then."""
    if _neighbour_gap(m, p, fo, h0, hu, hw) > 0.0:
        return False
    s.slot_stiffening[p, j] = 1.0
    return True


@njit(cache=True, _nrt=False)
def corner_stiffening(
    m: ModelArrays, s: State, sc: Scratch, i: int, p: int, j: int, fo: int, ft: int, o: int, t: int, h0: float, hu: float,
    hw: float, depth: float, before: float, x0: float, x1: float, x2: float, n0: float, n1: float, n2: float,
) -> float:
    """Area factor [-] of sub-contact (point p, slot j) of face ``fo`` (block o) pressed on face
    ``ft`` (block t) at world point x along n: a corner that lands alone (a vertex-face contact)
    is as stiff as the smaller of the two faces landing flat, as far as the step resolves it; any
    other sub-contact 1. Returns the factor, or minus the factor that ended at this step (then 1
    applies).

    Decided when the contact forms (``s.slot_stiffening``): while the sub-contact was not
    compressed at the last step it gets 1 + (f - 1) (1 - S(d / tol)), f = :func:`landing_corner`
    (F for a corner whose neighbouring face corners stand a tolerance higher, 1 for an edge
    landing, with no jump between the two) capped so that the spring's frequency
    sqrt(kn A f (flex_o + flex_t)) stays within 2 CORNER_RESOLUTION / dt (the impact lasts at least
    ~5 steps, :func:`flexibility` at x along n), d = ``before`` [m] its depth at the last step as its
    motion gives it (u_n + v_n dt, <= 0 for a corner that arrives from above the plane), S the
    smoothstep on [0, 1], tol the tracking tolerance: a corner that comes to press at depth (the
    partner's edge sliding over it, its cover switching on) is not a landing and is not stiffened.
    It is kept while the contact stays compressed, until a neighbouring face corner comes down to
    the target plane while it still presses (``depth`` [m] > 0: the block came down onto an edge
    or its face, the corner is no longer alone), when it ends: the caller books the energy its
    springs held beyond the cell's own as dissipated. Sub-contacts of a pair that was a pressed
    EDGE pair at the last detection (``s.pair_from_edge[i]``) continue that contact and are not
    stiffened (as landing corners, 0.18 mm deep, they held 12.8 J where the edge spring had held
    1.7 J). Bonded sub-contacts are never stiffened, nor any with explicit dashpots (whose step is
    bounded by Belytschko's factor, not the resolution). A corner touching at the start
    (STIFFENING_AT_START, kernels.detect.bond_touching) is decided at the first pass as one that
    arrives at its start depth: the sign of a round-off overlap chose before (a column released
    on one corner: three of its four corners unstiffened, 2026-12-08)."""
    if s.slot_area[p, j] == 0.0 or s.slot_overlap[p, j] <= 0.0 or s.slot_stiffening[p, j] == STIFFENING_AT_START:
        # Decided at the step it presses (still open: nothing acts, the bound uses landing_corner),
        # or at the first pass for a corner touching at the start (its overlap is round-off's).
        if depth <= 0.0:
            return 1.0
        return _classify_corner(m, s, sc, i, p, j, fo, ft, o, t, h0, hu, hw, before, x0, x1, x2, n0, n1, n2)
    f = s.slot_stiffening[p, j]
    if f > 1.0 and depth > 0.0 and _corner_ends(m, s, p, j, fo, h0, hu, hw):
        return -f
    return f


@njit(cache=True, _nrt=False, inline="always")
def cover_change(
    slot_set: np.ndarray, p: int, j: int, un: float, un_prev: float, area: float, prev_area: float, kn: float,
    deepened: float, areas: bool, ks: float, us_sq: float,
) -> tuple[float, float, float]:
    """Overlap [m] of an unbonded partly covered sub-contact whose cover changed in the last step,
    the energy [J] dissipated and the factor on its shear extension: its overlap ``un`` is measured
    from its set ``slot_set[p, j]`` [m], and the cover changed it by ``deepened`` [m] at the present
    pose (the cover weight of :func:`rockdem.kernels.faces.partly_covered`) and, with ``areas``, its
    effective area from ``prev_area`` to ``area`` [m^2]; ``us_sq`` [m^2]: its shear extension squared.

    The cover moves without work, so it must not load the springs: an overlap it deepens raises the
    set by as much (the spring keeps its energy), one it makes shallower lowers the set first and
    releases the rest (dissipated, returned). Compressed at both steps, a growing area keeps both
    springs' energies: the set rises so that kn A u^2 / 2 is that of the last area, and the shear
    extension is scaled so that ks A u_s^2 / 2 is (the factor returned); a shrinking one lowers the
    set first, as far as it keeps kn A u^2 / 2, and loses the rest and ks u_s^2 (A_prev - A) / 2.
    The set follows the overlap down, to 0 once it opens.
    (Without the shear's part a corner of a random hull sinking into a face at 3 m/s, its cell's
    cover growing fivefold, gained 3.6 J of shear spring energy without work, docs/contacts.md section 5.)"""
    st = slot_set[p, j]
    e = 0.0
    shear_factor = 1.0
    if deepened > 0.0 and un > 0.0:
        r = min(deepened, un)
        st += r
        un -= r
    elif deepened < 0.0:
        r = min(-deepened, st)
        st -= r
        un += r
        before = un - deepened - r  # the overlap the old cover gave (> un)
        if before > 0.0:
            e = 0.5 * kn * area * (before * before - max(un, 0.0) ** 2)
    if areas and un > 0.0 and un_prev > 0.0 and prev_area > 0.0 and area > 0.0:
        if area > prev_area:
            shear_factor = math.sqrt(prev_area / area)
            kept = un * shear_factor
            st += un - kept
            un = kept
        elif area < prev_area:
            # The set comes down first, so that kn A u^2 / 2 is that of the last area (a cover
            # sliding to and fro gives back what it took: a one-way set sank a parapet's brick 4 mm
            # into the one below as its blended pair's cover moved at every vibration); the rest,
            # and the shear spring's share, is dissipated.
            before = un
            un = min(un * math.sqrt(prev_area / area), un + st)
            st -= un - before
            e += 0.5 * kn * (prev_area * before * before - area * un * un) + 0.5 * ks * us_sq * (prev_area - area)
    elif st > 0.0 and un < 0.0:
        st = max(st + un, 0.0)  # opened: the set comes down to the geometric overlap st + un, or 0
    slot_set[p, j] = st
    return un, e, shear_factor


@njit(cache=True, _nrt=False, inline="always")
def _store(force: np.ndarray, point: np.ndarray, k: int, f0: float, f1: float, f2: float, x0: float, x1: float, x2: float) -> None:
    """Contact k's force (on its first block) and point of application."""
    force[k, 0] = f0
    force[k, 1] = f1
    force[k, 2] = f2
    point[k, 0] = x0
    point[k, 1] = x1
    point[k, 2] = x2


@njit(cache=True, _nrt=False, inline="always")
def _apply_resultant(
    position: np.ndarray, free: np.ndarray, force: np.ndarray, torque: np.ndarray, reaction: np.ndarray,
    o: int, t: int, f0: float, f1: float, f2: float, m0: float, m1: float, m2: float,
) -> None:
    """Resultant f of a set of contact forces on block o, with moment m about o's centroid: f and m
    on o, -f and -(m + (x_o - x_t) x f) on t; the reaction of driven blocks."""
    if f0 == 0.0 and f1 == 0.0 and f2 == 0.0 and m0 == 0.0 and m1 == 0.0 and m2 == 0.0:
        return
    d0, d1, d2 = position[o, 0] - position[t, 0], position[o, 1] - position[t, 1], position[o, 2] - position[t, 2]
    force[o, 0] += f0
    force[o, 1] += f1
    force[o, 2] += f2
    force[t, 0] -= f0
    force[t, 1] -= f1
    force[t, 2] -= f2
    torque[o, 0] += m0
    torque[o, 1] += m1
    torque[o, 2] += m2
    torque[t, 0] -= m0 + d1 * f2 - d2 * f1
    torque[t, 1] -= m1 + d2 * f0 - d0 * f2
    torque[t, 2] -= m2 + d0 * f1 - d1 * f0
    if free[o] and not free[t]:
        reaction[0] += f0
        reaction[1] += f1
        reaction[2] += f2
    elif free[t] and not free[o]:
        reaction[0] -= f0
        reaction[1] -= f1
        reaction[2] -= f2


@njit(cache=True, _nrt=False, inline="always")
def _apply(
    position: np.ndarray, free: np.ndarray, force: np.ndarray, torque: np.ndarray, reaction: np.ndarray,
    o: int, t: int, f0: float, f1: float, f2: float, c0: float, c1: float, c2: float,
) -> None:
    """Force f on block o and -f on block t, both at world point c; the reaction of driven blocks."""
    r0, r1, r2 = c0 - position[o, 0], c1 - position[o, 1], c2 - position[o, 2]
    _apply_resultant(position, free, force, torque, reaction, o, t, f0, f1, f2, r1 * f2 - r2 * f1, r2 * f0 - r0 * f2, r0 * f1 - r1 * f0)


@njit(cache=True, _nrt=False)
def accumulate(m: ModelArrays, s: State, sc: Scratch) -> None:
    """Add the forces of the edge pairs and the blend forces of the face pairs to their two blocks
    (and to the reaction of driven blocks), in pair order. (The face pairs' sub-contacts were added
    by :func:`_law_range`, per pair side, and released ones by :func:`_release_pass`.)"""
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            f = sc.pair_force[i]
            c = sc.pair_point[i]
            _apply(s.position, m.block_free, sc.force, sc.torque, sc.reaction, s.pair_a[i], s.pair_b[i], f[0], f[1], f[2], c[0], c[1], c[2])
            continue
        a = m.face_block[s.pair_owner_face[i]]
        b = m.face_block[s.pair_target_face[i]]
        if sc.pair_weight[i] > 0.0 and sc.pair_weight[i] < 1.0:
            f = sc.blend_force_owner[i]
            c = sc.blend_point_owner[i]
            _apply(s.position, m.block_free, sc.force, sc.torque, sc.reaction, a, b, f[0], f[1], f[2], c[0], c[1], c[2])
            f = sc.blend_force_target[i]
            c = sc.blend_point_target[i]
            _apply(s.position, m.block_free, sc.force, sc.torque, sc.reaction, b, a, f[0], f[1], f[2], c[0], c[1], c[2])


@njit(cache=True, _nrt=False, inline="always")
def _faces(s: State, i: int, side: int) -> tuple[int, int]:
    """(face whose points press, face they press on) of FACE pair i: the owner's points on the
    target (side 0) or the target's points on the owner (side 1, kernels.blend)."""
    if side == 0:
        return s.pair_owner_face[i], s.pair_target_face[i]
    return s.pair_target_face[i], s.pair_owner_face[i]


@njit(cache=True, _nrt=False)
def _hand_over_face(m: ModelArrays, s: State, sc: Scratch, i: int, a: int, b: int, budget: float) -> bool:
    """After the first law pass of FACE pair i (blocks a, b), formed at this detection from an
    EDGE pair whose normal spring held ``budget`` [J] (0 unloaded): whether the pass must run again.

    The contact changes representation under load (a cube tipping over a foundation's edge held
    by its edge, then by its face's sub-contacts); the face springs start with no more energy than
    the edge spring held, as :func:`rockdem.kernels.detect.hand_over_edge` does the other way. If
    their overlaps would hold more, each compressed sub-contact starts unloaded at a *set*
    (``s.slot_set``, followed down as it opens) that scales its overlap by sqrt(budget / held),
    its slot is reset to new (but for its overlap: it continues the edge's contact, and is not
    ramped in as a contact closing in the step) and True is returned; otherwise what they hold
    less is booked as dissipated. Before 2026-11-28 the edge's energy was booked as dissipated and the face springs
    started loaded: a frictionless cube sliding over a foundation's edge gained 0.25 J in one step
    (its sub-contacts 0.1-0.27 mm deep under the edge). A pair whose slots carry history (not new
    at this detection) books the budget as dissipated, as before. A FACE pair whose faces changed
    at this detection under load, or none of whose springs went on, is handed over alike, every
    slot of it new (detect._narrow releases those a face kept): a random hull pressed 2.8 mm into
    another changed its carrying faces, and the new face's five points started loaded with 52 J
    where the released ones held 6 J."""
    kn = m.mat_kn[m.block_group[a], m.block_group[b]]
    held = 0.0
    for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
        code = s.track[k]
        p = code // SLOTS
        j = code - SLOTS * p
        if s.slot_bonded[p, j] or s.slot_set[p, j] != 0.0:
            sc.side_friction[i, 0] += budget  # not new: handed over as before
            return False
        u = s.slot_overlap[p, j]
        if u > 0.0:
            held += 0.5 * kn * s.slot_area[p, j] * u * u
    if held <= budget:
        sc.side_friction[i, 0] += budget - held
        return False
    f = 1.0 - math.sqrt(budget / held)
    for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
        code = s.track[k]
        p = code // SLOTS
        j = code - SLOTS * p
        u = max(s.slot_overlap[p, j], 0.0)
        s.slot_set[p, j] = f * u
        s.slot_overlap[p, j] = u - f * u  # pressed at the last step (the edge's contact goes on): no closing ramp
        s.slot_area[p, j] = 0.0
        s.slot_cover[p, j] = 0.0
        s.slot_stiffening[p, j] = 1.0
        s.slot_normal_force[p, j] = 0.0
        s.slot_shear[p, j, 0] = 0.0
        s.slot_shear[p, j, 1] = 0.0
        s.slot_shear[p, j, 2] = 0.0
    return True


@njit(cache=True, _nrt=False, inline="always")
def _law_pair(m: ModelArrays, s: State, sc: Scratch, i: int, dt: float, implicit: bool, dashpots: bool, buf: np.ndarray) -> None:
    """The cover and joint law of the sub-contacts of FACE pair i (``buf``: a (2, 32, 2) polygon
    buffer of the calling thread's own). Writes only pair i's entries: its sub-contacts' slots,
    forces and flags (``sc.track_released``, ``sc.track_failed``), its ``sc.pair_handover`` and
    per side the resultant, energies and counts (``sc.side_*``) that :func:`_gather` adds up in
    pair order, so that pairs may run in parallel with the serial answer bit for bit.

    Performance note: the joint law (:func:`_law_range`) calls only small inlined functions and
    makes no array views. A call to a compiled function, or an inlined one with loops of its own
    (a clipping, a quadrature), anywhere in it stops Numba from pruning the reference counting of
    every array it touches, which made it ten times slower: such rare work is done out of line.
    The law is inlined by Numba at a single call site: a compiled call that passes the model,
    state and scratch tuples unpacks some 900 array fields per pair side (about 4,500
    instructions), which made the 1000-brick wall's force pass 2.2x slower wherever LLVM chose not
    to inline it (2.5 against 1.16 ms per step, measured on the corner-stiffening branch).
    """
    fa = s.pair_owner_face[i]
    fb = s.pair_target_face[i]
    a = m.face_block[fa]
    b = m.face_block[fb]
    split = s.pair_track_split[i]
    stop = s.pair_track_stop[i]
    budget = sc.pair_handover[i]
    sc.pair_handover[i] = -1.0
    # A pair formed from an EDGE pair runs its law twice at its first pass when its
    # sub-contacts would hold more than the edge spring held (_hand_over_face).
    for _ in range(2):
        lam_prev = sc.pair_weight[i]  # the target's share at the last law pass (-1: not known)
        lam, dlam = _blend(m, s, sc, i, fa, fb, a, b, split)
        # The owner's points on the target face, then (while the pair may blend) the target's on
        # the owner face: one call site, so that the inlined joint law is compiled once.
        u_owner = 0.0
        for side in range(2 if split < stop else 1):
            if side == 0:
                k0, k1, fo, ft, o, t, wgt, blending = s.pair_track_start[i], split, fa, fb, a, b, 1.0 - lam, split < stop
                wgt_prev = 1.0 - lam_prev if lam_prev >= 0.0 else -1.0
            else:
                k0, k1, fo, ft, o, t, wgt, blending = split, stop, fb, fa, b, a, lam, True
                wgt_prev = lam_prev
            u_side = _law_range(m, s, sc, i, side, k0, k1, fo, ft, o, t, wgt, wgt_prev, blending, dt, implicit, dashpots, buf)
            if side == 0:
                u_owner = u_side
            elif dlam != 0.0:
                # The weight's own energy gradient: sc.blend_* hold the unit force pairs of grad c.
                g = (u_side - u_owner) * dlam
                for c in range(3):
                    sc.blend_force_owner[i, c] *= g
                    sc.blend_force_target[i, c] *= g
        if budget < 0.0 or not _hand_over_face(m, s, sc, i, a, b, budget):
            break
        budget = -1.0


PREFETCH_AHEAD = 2
"""The joint law asks for the cache lines of the face pair this many pairs ahead
(:func:`_prefetch_pair`)."""


@njit(cache=True, _nrt=False, inline="always")
def _prefetch_pair(m: ModelArrays, s: State, sc: Scratch, q: int) -> None:
    """Ask for the cache lines that the law of FACE pair q reads first: its blocks' poses and
    velocities, its faces' frames, lines, corners and vertices, and its first sub-contact's point
    and slot entries (kernels.prefetch: a hint, no value changes). The settled 1000-brick wall's
    law, all pairs in order, took 127 to 171 ns per sub-contact with it against 209 to 270 without,
    alternating in a slow phase of the machine (docs/performance.md)."""
    if s.pair_track_start[q] == s.pair_track_stop[q]:  # (an EDGE pair, or nothing tracked)
        return
    p = s.track[s.pair_track_start[q]] // SLOTS
    fo = s.pair_owner_face[q]
    ft = s.pair_target_face[q]
    ba = m.face_block[fo]
    bb = m.face_block[ft]
    # Written out pair by pair: the same prefetches as loops over the two blocks and faces gained
    # nothing (the loop's layout, docs/performance.md).
    prefetch(sc.rotation, (ba, 0, 0))
    prefetch(sc.rotation, (bb, 0, 0))
    prefetch(s.position, (ba, 0))
    prefetch(s.position, (bb, 0))
    prefetch(s.velocity, (ba, 0))
    prefetch(s.velocity, (bb, 0))
    prefetch(sc.omega_world, (ba, 0))
    prefetch(sc.omega_world, (bb, 0))
    prefetch(m.vertex_local, (m.block_vertex_start[ba], 0))
    prefetch(m.vertex_local, (m.block_vertex_start[bb], 0))
    prefetch(m.face_origin, (fo, 0))
    prefetch(m.face_origin, (ft, 0))
    prefetch(m.face_u, (fo, 0))
    prefetch(m.face_u, (ft, 0))
    prefetch(m.face_w, (fo, 0))
    prefetch(m.face_w, (ft, 0))
    prefetch(m.face_normal, (fo, 0))
    prefetch(m.face_normal, (ft, 0))
    prefetch(m.face_line, (m.face_line_start[ft], 0))
    prefetch(m.face_corner_uw, (m.face_corner_start[fo], 0))
    prefetch(m.point_node, (p, 0))
    prefetch(m.point_area, (p,))
    prefetch(m.point_corner, (p,))
    prefetch(m.point_cell_start, (p,))
    prefetch(s.slot_overlap, (p, 0))
    prefetch(s.slot_area, (p, 0))
    prefetch(s.slot_set, (p, 0))
    prefetch(s.slot_bonded, (p, 0))
    prefetch(s.slot_shear, (p, 0, 0))
    prefetch(s.slot_cover, (p, 0))
    prefetch(s.slot_anchor, (p, 0, 0))
    prefetch(s.slot_deepest, (p, 0, 0))
    prefetch(s.slot_normal_force, (p, 0))


@njit(cache=True, _nrt=False)
def _law_pairs(
    m: ModelArrays, s: State, sc: Scratch, first: int, last: int, dt: float, implicit: bool, dashpots: bool, buf: np.ndarray
) -> None:
    """:func:`_law_pair` for FACE pairs first..last - 1, in order (``buf`` as there), asking for the
    data of the pair :data:`PREFETCH_AHEAD` ahead as it goes. The joint law is compiled here once,
    for the serial and the parallel pass alike; its callers hold copies of this code that Numba
    optimized again inside them, slower on the 1000-brick wall, so a run loads this function's
    own code first and every call runs it (:func:`rockdem.simulation._load_law_first`)."""
    for i in range(first, last):
        if i + PREFETCH_AHEAD < last:
            _prefetch_pair(m, s, sc, i + PREFETCH_AHEAD)
        if s.pair_kind[i] != PAIR_EDGE:
            _law_pair(m, s, sc, i, dt, implicit, dashpots, buf)


@njit(cache=True, _nrt=False, inline="always")
def _law_pass(m: ModelArrays, s: State, sc: Scratch, dt: float, implicit: bool, dashpots: bool) -> None:
    """The joint law of every FACE pair (:func:`_law_pairs`), on the calling thread."""
    n = s.pair_count[0]
    # min(n, 0), not a literal 0: Numba would compile the law a second time for Literal[int](0),
    # beside the int64 bounds of the parallel pass (two minutes more at its first use).
    _law_pairs(m, s, sc, min(n, 0), n, dt, implicit, dashpots, sc.poly)


@intrinsic
def _stack_address(typingctx: Any, value: Any) -> Any:
    """(value) -> uintp: the address of a copy of ``value`` (a tuple of arrays) on the calling
    function's stack, valid until it returns."""

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        return builder.ptrtoint(cgutils.alloca_once_value(builder, args[0]), context.get_value_type(types.uintp))

    return types.uintp(value), codegen


@intrinsic
def _type_of(typingctx: Any, value: Any) -> Any:
    """(value) -> its type, as a value that costs nothing (for :func:`_load_at`)."""

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        return context.get_dummy_value()

    return types.TypeRef(value)(value), codegen


@intrinsic
def _load_at(typingctx: Any, address: Any, like: Any) -> Any:
    """(address, type) -> the value of that type stored at ``address`` by :func:`_stack_address`."""
    ty = like.instance_type

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        return builder.load(builder.inttoptr(args[0], context.get_value_type(ty).as_pointer()))

    return ty(address, like), codegen


@njit(cache=True, _nrt=False)
def _law_chunk(pm: int, ps: int, psc: int, tm: Any, ts: Any, tsc: Any, first: int, last: int, dt: float,
               implicit: bool, dashpots: bool, chunk: int) -> None:
    """:func:`_law_pairs` for pairs first..last - 1 of chunk ``chunk``, on the model, state and
    scratch stored at addresses pm, ps, psc (of types tm, ts, tsc) by :func:`_law_pass_parallel`."""
    sc = _load_at(psc, tsc)
    _law_pairs(_load_at(pm, tm), _load_at(ps, ts), sc, first, last, dt, implicit, dashpots, sc.chunk_poly[chunk])


@njit(cache=True, _nrt=False, parallel=True)
def _law_pass_parallel(m: ModelArrays, s: State, sc: Scratch, dt: float, implicit: bool, dashpots: bool) -> None:
    """:func:`_law_pass` over LAW_CHUNKS fixed chunks of the pairs on Numba's threads (the same
    answer on any number of threads: every pair writes only its own entries). Each chunk is one
    call of the compiled :func:`_law_pairs`: the law inlined into the loop of a ``parallel=True``
    function lost its writes to the state's arrays (Numba 0.68's parfor passes took them for dead
    code).

    The model, state and scratch enter the parallel region as three addresses, not as tuples:
    Numba unpacks tuples that enter a parallel region into one gufunc argument per array, and
    its compile time grows steeply with their number (their 200 arrays took 15 to 20 minutes to
    compile on a slow machine; benchmarks/parfor_tuple_compile.py). The copies they point to live
    on this function's stack for the whole parallel loop."""
    n = s.pair_count[0]
    per = (n + LAW_CHUNKS - 1) // LAW_CHUNKS
    pm, ps, psc = _stack_address(m), _stack_address(s), _stack_address(sc)
    tm, ts, tsc = _type_of(m), _type_of(s), _type_of(sc)
    for chunk in numba.prange(LAW_CHUNKS):
        _law_chunk(pm, ps, psc, tm, ts, tsc, min(n, chunk * per), min(n, (chunk + 1) * per), dt, implicit, dashpots, chunk)


@njit(cache=True, _nrt=False)
def _gather(m: ModelArrays, s: State, sc: Scratch) -> tuple[float, int, float, float, int]:
    """Add up, in pair order, what :func:`_law_pair` left per pair side: the resultants on the two
    blocks, the energies and counts, the failed bonds (``s.point_failed``), the sub-contacts that
    opened during the last step (listed in ``sc.pending`` for :func:`_release_pass`), the
    detections asked for (:func:`_blend`) and the soonest impact predicted (``sc.touch_time``).

    Returns (elastic energy, active count, friction and bond energy dissipated, opened count)."""
    elastic = 0.0
    active = 0
    e_fric = 0.0
    e_bond = 0.0
    nrel = 0
    touch = np.inf
    impacting = False
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            continue
        a = m.face_block[s.pair_owner_face[i]]
        b = m.face_block[s.pair_target_face[i]]
        if sc.pair_asks_detection[i]:
            sc.pair_asks_detection[i] = False
            s.moved[a] = max(s.moved[a], m.contact_tol)
            s.moved[b] = max(s.moved[b], m.contact_tol)
        split = s.pair_track_split[i]
        for side in range(2 if split < s.pair_track_stop[i] else 1):
            o, t = (a, b) if side == 0 else (b, a)
            elastic += sc.side_elastic[i, side]
            active += sc.side_active[i, side]
            e_fric += sc.side_friction[i, side]
            e_bond += sc.side_bond[i, side]
            touch = min(touch, sc.side_touch[i, side])
            impacting = impacting or sc.side_impacting[i, side]
            f = sc.side_force[i, side]
            q = sc.side_moment[i, side]
            _apply_resultant(s.position, m.block_free, sc.force, sc.torque, sc.reaction, o, t, f[0], f[1], f[2], q[0], q[1], q[2])
            if sc.side_failed[i, side] == 0 and sc.side_released[i, side] == 0:
                continue
            k0, k1 = (s.pair_track_start[i], split) if side == 0 else (split, s.pair_track_stop[i])
            for k in range(k0, k1):
                if sc.track_failed[k] != FAILED_NONE:
                    s.point_failed[s.track[k] // SLOTS] = sc.track_failed[k]
                    sc.track_failed[k] = FAILED_NONE
                if sc.track_released[k]:
                    sc.track_released[k] = False
                    sc.pending[nrel] = k
                    sc.pending_pair[nrel] = i
                    nrel += 1
    sc.touch_time[0] = touch
    sc.impacting[0] = impacting
    return elastic, active, e_fric, e_bond, nrel


@njit(cache=True, _nrt=False, inline="always")
def _closing_bound(m: ModelArrays, s: State, sc: Scratch, o: int, t: int) -> float:
    """Upper bound [m/s] of the relative speed of any two points of blocks o and t:
    |v_o - v_t| + |omega_o| R_o + |omega_t| R_t (R the blocks' radii)."""
    wo = sc.omega_world[o]
    wt = sc.omega_world[t]
    dv = math.sqrt((s.velocity[o, 0] - s.velocity[t, 0]) ** 2 + (s.velocity[o, 1] - s.velocity[t, 1]) ** 2
                   + (s.velocity[o, 2] - s.velocity[t, 2]) ** 2)
    return (dv + math.sqrt(wo[0] ** 2 + wo[1] ** 2 + wo[2] ** 2) * m.block_radius[o]
            + math.sqrt(wt[0] ** 2 + wt[1] ** 2 + wt[2] ** 2) * m.block_radius[t])


@njit(cache=True, _nrt=False)
def _open_cell_touch(
    m: ModelArrays, s: State, sc: Scratch, p: int, ft: int, o: int, t: int, fm: Any, mask: int, buf: np.ndarray,
    impact_speed: float,
) -> float:
    """Time [s] until the open, unbonded cell of point p, wholly above face ft's plane (the joint
    law skips it: faces.cell_above), touches the part of it that face ft covers,
    at its present closing speed, if that speed exceeds ``impact_speed``; +inf otherwise. A face
    landing across its partner's edge is seen by these cells only (docs/dashpots.md). Out of line,
    called only while a partly covered pair may close that fast (:func:`_closing_bound`)."""
    area, yu, yw, shift, _, _, _, _, _ = cut_cell(
        m.point_cell_start, m.cell_vertex, m.face_line_start, m.face_line, buf,
        m.point_node[p, 0], m.point_node[p, 1], m.point_area[p], m.touch_tol, p, ft, fm, 0.0, mask,
        True, m.face_area[ft] / (m.face_point_start[ft + 1] - m.face_point_start[ft]),
    )
    if area <= 0.0:
        return np.inf
    un = -(fm.h0 + fm.hu * yu + fm.hw * yw) + shift
    if un >= 0.0:
        return np.inf
    x0 = fm.ox + yu * fm.eux + yw * fm.ewx + 0.5 * un * fm.nx
    x1 = fm.oy + yu * fm.euy + yw * fm.ewy + 0.5 * un * fm.ny
    x2 = fm.oz + yu * fm.euz + yw * fm.ewz + 0.5 * un * fm.nz
    v0, v1, v2 = _relative_velocity_arrays(s.position, s.velocity, sc.omega_world, o, t, x0, x1, x2)
    vn = v0 * fm.nx + v1 * fm.ny + v2 * fm.nz
    return un / vn if vn < -impact_speed else np.inf


@njit(cache=True, _nrt=False, inline="always")
def _law_range(
    m: ModelArrays, s: State, sc: Scratch, i: int, side: int, k0: int, k1: int, fo: int, ft: int, o: int, t: int,
    wgt: float, wgt_prev: float, blending: bool, dt: float, implicit: bool, dashpots: bool, buf: np.ndarray,
) -> float:
    """The joint law of sub-contacts track[k0:k1] of FACE pair i: points of face ``fo`` (block o)
    pressed on face ``ft`` (block t), carrying the share ``wgt`` (kernels.blend; ``blending``
    False: the whole pair, wgt 1); ``wgt_prev``: the share their areas held at the last law pass
    (1 for the whole pair, -1 not known). With ``implicit`` dashpots (:mod:`rockdem.kernels.implicit`) only
    half the dashpot force at the last half step's velocity is applied here and each active
    dashpot is stored (``sc.dashpot_*``) for the velocity solve. Leaves the side's resultant on
    block o (moment about its centroid), energies and counts in ``sc.side_*[i, side]``; returns
    the normal springs' energy at full share [J]."""
    elastic = 0.0
    active = 0
    e_fric = 0.0
    e_bond = 0.0
    u_side = 0.0
    released = 0
    failed = 0
    touch = np.inf
    impacting = False
    impact_speed = s.impact_speed[0]
    # The dynamic overlap of an impact at the impact speed, v / omega_max (the window is one
    # period 2 pi / omega_max of the stiffest contact): five static overlaps g / omega_max^2.
    impact_depth = impact_speed * s.impact_window[0] / (2.0 * math.pi) if s.impact_window[0] > 0.0 else np.inf
    sf0 = sf1 = sf2 = sm0 = sm1 = sm2 = 0.0
    # How the side's share moved since the last law pass (1: not at all, or not known).
    share = (wgt if blending else 1.0) / wgt_prev if wgt_prev > 0.0 else 1.0
    fm = face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position, fo, ft)
    # The cover of each cell (its effective area and force point, kernels.faces): the target's edge
    # lines that cross the owner face are found once for the pair; with none every cell is wholly
    # covered (a flush joint), with one leaving the face outside none is (faces at right angles too).
    mask = -2 if abs(fm.det) < 1e-9 else crossing_lines(m.face_corner_start, m.face_corner_uw, m.face_line_start, m.face_line, fo, ft, fm)
    go = m.block_group[o]
    gt = m.block_group[t]
    kn = m.mat_kn[go, gt]
    ks = m.mat_ks[go, gt]
    beta = m.mat_beta[go, gt]
    n0, n1, n2 = fm.nx, fm.ny, fm.nz
    cut = mask != 0 and mask != -2  # cells are clipped by the target's edge lines (cut_cell)
    # Open cells above the target's plane are skipped unclipped; while the pair may close faster
    # than an impact, each is clipped to predict its touch (_open_cell_touch).
    landing = cut and impact_speed < np.inf and _closing_bound(m, s, sc, o, t) > impact_speed
    for k in range(k0, k1):
        code = s.track[k]
        p = code // SLOTS
        j = code - SLOTS * p
        cover_w = 0.0
        au = aw = eu = ew = 0.0
        if mask == 0:
            full_area, yu, yw, shift = m.point_area[p], m.point_node[p, 0], m.point_node[p, 1], 0.0
        elif mask == -2:
            full_area, yu, yw, shift = 0.0, m.point_node[p, 0], m.point_node[p, 1], 0.0
        elif not s.slot_bonded[p, j] and (s.slot_overlap[p, j] <= 0.0 or s.slot_area[p, j] == 0.0) and cell_above(
                m.point_cell_start, m.cell_vertex, p, fm.h0, fm.hu, fm.hw):
            # Unbonded, open at the last step and wholly above the target plane: it stays open
            # whatever its cover (faces.cell_above; no call of faces.cut_cell).
            full_area, yu, yw, shift = 0.0, m.point_node[p, 0], m.point_node[p, 1], 0.0
        else:
            unbonded = not s.slot_bonded[p, j]
            full_area, yu, yw, shift, cover_w, au, aw, eu, ew = cut_cell(
                m.point_cell_start, m.cell_vertex, m.face_line_start, m.face_line, buf,
                m.point_node[p, 0], m.point_node[p, 1], m.point_area[p], m.touch_tol, p, ft, fm, 0.0, mask,
                unbonded, m.face_area[ft] / (m.face_point_start[ft + 1] - m.face_point_start[ft]),
            )
        shift -= s.slot_set[p, j]  # an unbonded sub-contact's set (below): its overlap is measured from it
        if dashpots:
            sc.dashpot_cn[k] = 0.0
            sc.dashpot_force[k, 0] = 0.0
            sc.dashpot_force[k, 1] = 0.0
            sc.dashpot_force[k, 2] = 0.0
            sc.contact_force[k, 0] = 0.0
            sc.contact_force[k, 1] = 0.0
            sc.contact_force[k, 2] = 0.0
        if full_area == 0.0 and s.slot_area[p, j] == 0.0 and not s.slot_bonded[p, j]:
            # Uncovered now and at the last step, unbonded: nothing acts (the opened case below,
            # without computing what it does not use).
            s.slot_overlap[p, j] = min(-(fm.h0 + fm.hu * yu + fm.hw * yw) + shift, 0.0)
            s.slot_shear[p, j, 0] = 0.0
            s.slot_shear[p, j, 1] = 0.0
            s.slot_shear[p, j, 2] = 0.0
            s.slot_normal_force[p, j] = 0.0
            if landing:
                touch = min(touch, _open_cell_touch(m, s, sc, p, ft, o, t, fm, mask, buf, impact_speed))
            continue
        un = -(fm.h0 + fm.hu * yu + fm.hw * yw) + shift
        # Contact point: midway between the owner-plane point and the target plane.
        x0 = fm.ox + yu * fm.eux + yw * fm.ewx + 0.5 * un * n0
        x1 = fm.oy + yu * fm.euy + yw * fm.ewy + 0.5 * un * n1
        x2 = fm.oz + yu * fm.euz + yw * fm.ewz + 0.5 * un * n2
        v0, v1, v2 = _relative_velocity_arrays(s.position, s.velocity, sc.omega_world, o, t, x0, x1, x2)
        vn = v0 * n0 + v1 * n1 + v2 * n2  # > 0: separating
        # A corner that landed alone is stiffened (vertex-face contact): its springs, dashpots and
        # energies use the stiffened area, its Coulomb strength the cell's own area.
        stiff = 1.0
        ended = 1.0
        if m.point_corner[p] >= 0 and not s.slot_bonded[p, j]:  # (the rest out of line: the hot loop stays lean)
            stiff = corner_stiffening(m, s, sc, i, p, j, fo, ft, o, t, fm.h0, fm.hu, fm.hw, un, un + vn * s.dt_prev[0], x0, x1, x2, n0, n1, n2)
            if stiff < 0.0:
                ended = -stiff
                stiff = 1.0
        area = full_area * stiff
        if blending:  # this side's share (kernels.blend); 0 switches it off
            area *= wgt
        if ended > 1.0:
            # The stiffening ended under load: the energy its springs held beyond the cell's own is
            # dissipated (counted with the contacts' friction). The leapfrog's work identity makes
            # the spring energy of a stiffness k that acted up to the last step k u_prev u_now / 2
            # at the switch (sum of F_n (x_n+1 - x_n-1) / 2 telescopes to the product), so that is
            # what the stiffening leaves: with u_now^2 a parapet's face slapping down booked 275 J
            # (balance +1.0 %), with u_prev^2 196 J (-1.2 %), with the product 232 J.
            u_held = max(s.slot_overlap[p, j], 0.0) * max(un, 0.0)
            e_fric += 0.5 * s.slot_area[p, j] * (1.0 - 1.0 / ended) * (
                kn * u_held + ks * (s.slot_shear[p, j, 0] ** 2 + s.slot_shear[p, j, 1] ** 2 + s.slot_shear[p, j, 2] ** 2))
        un_prev = s.slot_overlap[p, j]
        us0, us1, us2 = s.slot_shear[p, j, 0], s.slot_shear[p, j, 1], s.slot_shear[p, j, 2]
        bonded = s.slot_bonded[p, j]
        prev_area = s.slot_area[p, j]
        if not bonded and (cut or s.slot_set[p, j] > 0.0):
            # A partly covered cell whose cover slides under load: the spring kn A u^2 / 2 would
            # gain or lose energy without work, as its area changes (kn u^2 dA / 2) and as its
            # cover weight w moves its overlap u = u_p + w phi(g) at a fixed pose (kernels.faces;
            # a cube on a foundation sliding away under it, frictionless, gained 0.05 J of its
            # 0.05 J scale as the foundation's edge passed under its cell boundary, before
            # 2026-11-28). It keeps its energy as the area grows or w deepens it (its overlap is
            # measured from a set, s.slot_set, which follows the overlap down as it opens) and
            # what it holds less as they shrink it is dissipated (an ended stiffening is booked
            # above: the areas are compared at the same factor). Inside a blend the areas are
            # compared at the same share too: the share's own change is the blend weight's, whose
            # energy gradient is applied (kernels.blend); a cell's cover changing while it carries a
            # share is this rule's (a random hull's corner sinking into a face carried by the target
            # face's points, its cut cell's area shrinking, created 16 J of a pile's 300 J, before
            # 2026-12-07). A pair new at this detection (share not known) inside a blend counts w's only.
            # (A wholly covered cell has a set when its pair took over from an edge, _hand_over_face.)
            # The cover deepens the cell by the overlap now less the overlap it would have now with
            # the last step's cover weight, anchor and deepest vertex (faces.anchored_overlap): the
            # anchor, the nearest covered point of a cell whose point is off the target, slides with
            # the target's edge (a two-block wall's crack, wedged open 0.1 rad, its points on the
            # face's ends just off the other block: 0.67 J of its 38 J scale created in one impact,
            # before 2026-11-29, when only w's change was counted).
            # (Both by the same formula, so that an unmoved cover deepens nothing, bit for bit; a
            # cell without cover weight is measured at its point.)
            un_cover = un
            deepened = 0.0
            if prev_area > 0.0:
                nu, nw = m.point_node[p, 0], m.point_node[p, 1]
                deepened = anchored_overlap(fm, nu, nw, au, aw, eu, ew, cover_w, m.touch_tol) - anchored_overlap(
                    fm, nu, nw, s.slot_anchor[p, j, 0], s.slot_anchor[p, j, 1], s.slot_deepest[p, j, 0],
                    s.slot_deepest[p, j, 1], s.slot_cover[p, j], m.touch_tol)
            area_then = prev_area / ended * share  # at the factor and share of this step
            un, e_set, shear_factor = cover_change(s.slot_set, p, j, un, un_prev, area, area_then, kn, deepened,
                                        cut and (wgt_prev > 0.0 or (wgt_prev < 0.0 and not blending)), ks,
                                        us0 * us0 + us1 * us1 + us2 * us2)
            us0 *= shear_factor
            us1 *= shear_factor
            us2 *= shear_factor
            shift += un - un_cover
            e_fric += e_set
        # Stored only when they change: a settled joint's lines of these arrays stay clean and are not
        # written back (the 1000-brick wall's working set is larger than the caches).
        if s.slot_cover[p, j] != cover_w:
            s.slot_cover[p, j] = cover_w
        if cover_w > 0.0:
            s.slot_anchor[p, j, 0] = au
            s.slot_anchor[p, j, 1] = aw
            s.slot_deepest[p, j, 0] = eu
            s.slot_deepest[p, j, 1] = ew
        s.slot_overlap[p, j] = un if area > 0.0 else min(un, 0.0)
        if s.slot_area[p, j] != area:
            s.slot_area[p, j] = area
        vs0, vs1, vs2 = v0 - vn * n0, v1 - vn * n1, v2 - vn * n2
        kna = kn * area
        ksa = ks * area
        fn = kna * un
        opened = area <= 0.0 or (un <= 0.0 and not bonded)
        if not opened and bonded and fn < -m.mat_tension[go, gt] * area:
            # Tension cut-off: the bond fails and the point opens.
            e_bond += spring_energy(fn, kna) + 0.5 * ksa * (us0 * us0 + us1 * us1 + us2 * us2)
            s.slot_bonded[p, j] = False
            sc.track_failed[k] = FAILED_TENSION
            failed += 1
            opened = True
            bonded = False
            prev_area = 0.0  # its energy is counted
        if opened:
            if vn < -impact_speed and un < 0.0 and area > 0.0 and not bonded:
                # An impact ahead: when this open covered cell touches at its closing speed (the
                # step is refined around impacts, kernels.step.advance). A pressed one opens no
                # window: the joints of a settling wall vibrate at closing speeds far above it.
                touch = min(touch, -un / -vn)
            # Not in contact: the stored shear energy is lost (friction), a bond slid off breaks.
            e = 0.5 * ks * prev_area * (us0 * us0 + us1 * us1 + us2 * us2)
            if bonded:
                e_bond += e + (spring_energy(s.slot_normal_force[p, j], kn * prev_area) if prev_area > 0.0 else 0.0)
                s.slot_bonded[p, j] = False
                sc.track_failed[k] = FAILED_SHEAR if un > 0.0 else FAILED_TENSION
                failed += 1
            elif area > 0.0 and un_prev > 0.0 and prev_area > 0.0:
                # Opened during the last step: its release is computed apart (release pass), its
                # shear extension kept until then.
                sc.track_released[k] = True
                sc.release_overlap[k] = un_prev
                sc.release_area[k] = prev_area
                # Where and how large it is now (only the release pass reads these: written here,
                # not for every sub-contact at every step).
                sc.track_area[k] = area
                sc.track_point_u[k] = yu
                sc.track_point_w[k] = yw
                sc.track_depth_shift[k] = shift
                released += 1
                s.slot_normal_force[p, j] = 0.0
                continue
            else:
                e_fric += e
            s.slot_shear[p, j, 0] = 0.0
            s.slot_shear[p, j, 1] = 0.0
            s.slot_shear[p, j, 2] = 0.0
            s.slot_normal_force[p, j] = 0.0
            continue
        # An unbonded contact that closed during the last step: its springs act since the crossing
        # (a fraction of the step) and its impulse is completed (contact.ramp_overlap).
        ramp = 1.0
        since = dt
        closing = not bonded and un_prev <= 0.0 and vn < 0.0
        if closing:
            since = min(un / (-vn * dt), 1.0) * dt
            ramp = ramp_overlap(un, un_prev, vn, dt) / un
        f_applied = fn * ramp
        if share > 1.0:
            # The side's share grew (kernels.blend): the shear spring keeps its energy, as for a
            # growing cover (cover_change), its extension scaled; ...
            f = 1.0 / math.sqrt(share)
            us0 *= f
            us1 *= f
            us2 *= f
        elif share < 1.0:
            # ... as it shrinks, what the spring holds less is dissipated. (The normal springs'
            # share moves with the weight's energy gradient instead; with the shear springs' energy
            # in that gradient a block 5 mm past a support's edge rested on the barrier it raises.)
            e_fric += 0.5 * ks * area * (1.0 / share - 1.0) * (us0 * us0 + us1 * us1 + us2 * us2)
        us0, us1, us2, e0_du, e0_sq, du_sq = shear_increment(us0, us1, us2, n0, n1, n2, vs0, vs1, vs2, since)
        if bonded:
            fmax = coulomb_limit(m.mat_cohesion[go, gt], m.mat_tan_friction[go, gt], area, fn)
        else:
            fmax = coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], area / stiff, fn)
        trial_sq = ksa * ksa * (us0 * us0 + us1 * us1 + us2 * us2)
        slipping = trial_sq > fmax * fmax  # |trial force| > fmax (>= 0), without its square root
        gone = False
        if slipping:
            trial = math.sqrt(trial_sq)
            e_fric += slip_dissipation(ksa, fmax / trial, e0_du, e0_sq, du_sq)
            if bonded:
                # Shear failure: drop to the residual strength; the released energy is the bond's.
                s.slot_bonded[p, j] = False
                sc.track_failed[k] = FAILED_SHEAR
                failed += 1
                fres = min(coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], area, fn), fmax)
                e_bond += drop_dissipation(fmax, fres, ksa)
                fmax = fres
                if un <= 0.0:  # held only by the bond: it opens
                    e_bond += spring_energy(fn, kna) + spring_energy(fmax, ksa)
                    gone = True
            f = fmax / trial if trial > 0.0 else 0.0
            us0 *= f
            us1 *= f
            us2 *= f
        if gone:
            us0 = us1 = us2 = fn = 0.0
        s.slot_shear[p, j, 0] = us0
        s.slot_shear[p, j, 1] = us1
        s.slot_shear[p, j, 2] = us2
        s.slot_normal_force[p, j] = fn
        if gone:
            continue
        elastic += 0.5 * (fn * un + ksa * (us0 * us0 + us1 * us1 + us2 * us2))  # the springs' energies (shear after any slip)
        # A pressed unbonded sub-contact moving at an impact speed, deeper than an impact's
        # dynamic overlap at that speed (impact_depth): an impact goes on (an open impact window
        # lasts until it ends, kernels.step.advance). Blocks resting, rolling or sliding on one
        # another press far less deep at such speeds.
        impacting = impacting or (abs(vn) > impact_speed and un > impact_depth and not bonded)
        if blending:
            u_side += 0.5 * kn * full_area * stiff * un * un
        active += 1
        # Stiffness-proportional dashpots on the active sub-contact (paper Eq. 4, alpha = 0 part).
        # Rayleigh SP damping follows the tangent stiffness: no shear dashpot while slipping.
        fdn = -beta * kna * vn
        bs = 0.0 if slipping else beta * ksa
        if implicit and beta > 0.0:
            # Implicit dashpots (kernels.implicit): half the force at the last half step's velocity
            # now, the other half at the new velocity in the velocity solve. A contact that closed
            # during the last step has its dashpot from the crossing on.
            onset = dashpot_onset_share(since, s.velocity_lag[0] + 0.5 * s.dt[0]) if closing else 1.0
            sc.dashpot_cn[k] = onset * beta * kna
            sc.dashpot_cs[k] = onset * bs
            sc.dashpot_normal[k, 0] = n0
            sc.dashpot_normal[k, 1] = n1
            sc.dashpot_normal[k, 2] = n2
            sc.dashpot_velocity[k, 0] = v0
            sc.dashpot_velocity[k, 1] = v1
            sc.dashpot_velocity[k, 2] = v2
            fdn *= 0.5 * onset
            bs *= 0.5 * onset
        d0 = fdn * n0 - bs * vs0
        d1 = fdn * n1 - bs * vs1
        d2 = fdn * n2 - bs * vs2
        fs = ksa * ramp
        f0 = f_applied * n0 + fs * us0 + d0
        f1 = f_applied * n1 + fs * us1 + d1
        f2 = f_applied * n2 + fs * us2 + d2
        if dashpots:  # read by the dashpot passes only (kernels.implicit, step.dashpot_work)
            sc.dashpot_force[k, 0] = d0
            sc.dashpot_force[k, 1] = d1
            sc.dashpot_force[k, 2] = d2
            _store(sc.contact_force, sc.contact_point, k, f0, f1, f2, x0, x1, x2)
        # The range's resultant on block o and its moment about o's centroid, applied once below.
        r0, r1, r2 = x0 - s.position[o, 0], x1 - s.position[o, 1], x2 - s.position[o, 2]
        sf0 += f0
        sf1 += f1
        sf2 += f2
        sm0 += r1 * f2 - r2 * f1
        sm1 += r2 * f0 - r0 * f2
        sm2 += r0 * f1 - r1 * f0
    sc.side_force[i, side, 0] = sf0
    sc.side_force[i, side, 1] = sf1
    sc.side_force[i, side, 2] = sf2
    sc.side_moment[i, side, 0] = sm0
    sc.side_moment[i, side, 1] = sm1
    sc.side_moment[i, side, 2] = sm2
    sc.side_elastic[i, side] = elastic
    sc.side_active[i, side] = active
    sc.side_friction[i, side] = e_fric
    sc.side_bond[i, side] = e_bond
    sc.side_released[i, side] = released
    sc.side_failed[i, side] = failed
    sc.side_touch[i, side] = touch
    sc.side_impacting[i, side] = impacting
    return u_side


@njit(cache=True, _nrt=False)
def _blend(m: ModelArrays, s: State, sc: Scratch, i: int, fa: int, fb: int, a: int, b: int, split: int) -> tuple[float, float]:
    """Share lambda of the target face's points of FACE pair i and d lambda / d clarity
    (:mod:`rockdem.kernels.blend`); leaves in ``sc.blend_*`` the unit force pairs of -grad c
    (scaled by (U_t - U_o) lambda' once the spring energies are known) and asks for a detection
    when the target's points are needed but not tracked."""
    sc.pair_weight[i] = 0.0
    if sc.pair_bonded[i] or s.pair_track_start[i] == s.pair_track_stop[i]:
        return 0.0, 0.0  # a joint (flush) or nothing tracked: the detection tracks what comes near
    sep_o, v0, v1, v2, na0, na1, na2 = face_clearance(
        m.face_normal, m.face_offset, m.face_block, m.block_vertex_start, m.vertex_local, sc.rotation, s.position, fa, b
    )
    sep_t, w0, w1, w2, nb0, nb1, nb2 = face_clearance(
        m.face_normal, m.face_offset, m.face_block, m.block_vertex_start, m.vertex_local, sc.rotation, s.position, fb, a
    )
    clarity = sep_o - sep_t
    if split == s.pair_track_stop[i]:
        if tracks_target(clarity, m.contact_tol):  # not tracked yet: detect at the next step (_gather)
            sc.pair_asks_detection[i] = True
        return 0.0, 0.0
    lam, dlam = blend_weight(clarity, m.contact_tol)
    sc.pair_weight[i] = lam
    # -grad c = -grad sep_o + grad sep_t: sep_o grows with the target's vertex v moving out of the
    # owner face along n_o (a unit force n_o on the target's block at v, -n_o on the owner's);
    # sep_t likewise with the owner's vertex w along n_t.
    sc.blend_force_owner[i, 0] = na0
    sc.blend_force_owner[i, 1] = na1
    sc.blend_force_owner[i, 2] = na2
    sc.blend_point_owner[i, 0] = v0
    sc.blend_point_owner[i, 1] = v1
    sc.blend_point_owner[i, 2] = v2
    sc.blend_force_target[i, 0] = -nb0
    sc.blend_force_target[i, 1] = -nb1
    sc.blend_force_target[i, 2] = -nb2
    sc.blend_point_target[i, 0] = w0
    sc.blend_point_target[i, 1] = w1
    sc.blend_point_target[i, 2] = w2
    return lam, dlam


@njit(cache=True, _nrt=False, inline="always")
def _slipped(ks_area: float, us0: float, us1: float, us2: float, cap: float) -> bool:
    """Whether a shear spring of stiffness ``ks_area`` [N/m] with elastic extension us [m], left by
    the last step, was slipping there: its force is at that step's Coulomb limit ``cap`` [N] (the
    slip step scales the extension to it; a sticking spring stays below it)."""
    return ks_area * math.sqrt(us0 * us0 + us1 * us1 + us2 * us2) >= (1.0 - 1e-9) * cap


@njit(cache=True, _nrt=False, inline="always")
def _released_dashpot(
    fd: np.ndarray, vd: np.ndarray, c: float, kn: float, ks: float, v0: float, v1: float, v2: float,
    vn: float, n0: float, n1: float, n2: float,
) -> tuple[float, float, float]:
    """Force [N] of a dashpot at its first step out of contact (implicit dashpots):
    -c (kn v_n n + ks v_s), c [s m^2 or s] beta x its share of the step (x the area for a
    sub-contact), at the relative velocity v [m/s] (normal part vn along n); stored with that
    velocity in ``fd``, ``vd`` (3,) for the work of :func:`rockdem.kernels.implicit.finalize`.
    ``ks`` is 0 for a contact that slipped at its last step in contact, which had no shear dashpot
    (:func:`_slipped`): a negative share of one it never had pushed a sliding contact along its
    sliding (a cube landing at 6 m/s on a foundation gained 15 J of its 972 J, booked as negative
    damping, before 2026-11-28)."""
    vs0, vs1, vs2 = v0 - vn * n0, v1 - vn * n1, v2 - vn * n2
    d0 = -c * (kn * vn * n0 + ks * vs0)
    d1 = -c * (kn * vn * n1 + ks * vs1)
    d2 = -c * (kn * vn * n2 + ks * vs2)
    fd[0], fd[1], fd[2] = d0, d1, d2
    vd[0], vd[1], vd[2] = v0, v1, v2
    return d0, d1, d2


@njit(cache=True, _nrt=False)
def _release_pass(m: ModelArrays, s: State, sc: Scratch, nrel: int, dt: float) -> float:
    """Sub-contacts that opened during the last step (listed by :func:`_law_pass`): complete the
    impulses of the normal ramp and of the capped shear force up to the opening time
    (:func:`contact.ramp_overlap`, :func:`contact.release_shear`); returns the friction energy."""
    e_fric = 0.0
    for q in range(nrel):
        k = sc.pending[q]
        i = sc.pending_pair[q]
        un_prev = sc.release_overlap[k]
        prev_area = sc.release_area[k]
        fo, ft = _faces(s, i, 0 if k < s.pair_track_split[i] else 1)
        fm = face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position, fo, ft)
        o = m.face_block[fo]
        t = m.face_block[ft]
        go = m.block_group[o]
        gt = m.block_group[t]
        kn = m.mat_kn[go, gt]
        ks = m.mat_ks[go, gt]
        p = s.track[k] // SLOTS
        j = s.track[k] - SLOTS * p
        area = sc.track_area[k]
        yu = sc.track_point_u[k]
        yw = sc.track_point_w[k]
        un = -(fm.h0 + fm.hu * yu + fm.hw * yw) + sc.track_depth_shift[k]
        n0, n1, n2 = fm.nx, fm.ny, fm.nz
        x0 = fm.ox + yu * fm.eux + yw * fm.ewx + 0.5 * un * n0
        x1 = fm.oy + yu * fm.euy + yw * fm.ewy + 0.5 * un * n1
        x2 = fm.oz + yu * fm.euz + yw * fm.ewz + 0.5 * un * n2
        v0, v1, v2 = _relative_velocity_arrays(s.position, s.velocity, sc.omega_world, o, t, x0, x1, x2)
        vn = v0 * n0 + v1 * n1 + v2 * n2
        fnc = kn * area * ramp_overlap(un, un_prev, vn, dt)
        c0, c1, c2, d = release_shear(
            s.slot_shear[p, j, 0], s.slot_shear[p, j, 1], s.slot_shear[p, j, 2], ks * prev_area,
            m.mat_res_tan_friction[go, gt] * kn * prev_area, un_prev, vn, v0 - vn * n0, v1 - vn * n1, v2 - vn * n2, dt,
        )
        e_fric += d
        if s.dashpots[0] == DASHPOTS_IMPLICIT and vn > 0.0 and m.mat_beta[go, gt] > 0.0:
            # Implicit dashpots: the dashpot acted until the opening; its share of this velocity step
            # (negative: the last step applied it past the opening), at the last half step's velocity.
            c = m.mat_beta[go, gt] * dashpot_release_share(un, vn, dt) * prev_area
            # the last step's Coulomb limit, as _law_range computed it (a stiffened corner's on its cell's area)
            cap = coulomb_limit(m.mat_res_cohesion[go, gt], m.mat_res_tan_friction[go, gt], prev_area / max(s.slot_stiffening[p, j], 1.0),
                                kn * prev_area * un_prev)
            slid = _slipped(ks * prev_area, s.slot_shear[p, j, 0], s.slot_shear[p, j, 1], s.slot_shear[p, j, 2], cap)
            d0, d1, d2 = _released_dashpot(sc.dashpot_force[k], sc.dashpot_velocity[k], c, kn, 0.0 if slid else ks,
                                           v0, v1, v2, vn, n0, n1, n2)
            c0 += d0
            c1 += d1
            c2 += d2
        _store(sc.contact_force, sc.contact_point, k, fnc * n0 + c0, fnc * n1 + c1, fnc * n2 + c2, x0, x1, x2)
        _apply(s.position, m.block_free, sc.force, sc.torque, sc.reaction, o, t, fnc * n0 + c0, fnc * n1 + c1, fnc * n2 + c2, x0, x1, x2)
        s.slot_shear[p, j, 0] = 0.0
        s.slot_shear[p, j, 1] = 0.0
        s.slot_shear[p, j, 2] = 0.0
    return e_fric


@njit(cache=True, _nrt=False)
def _edge_pair(m: ModelArrays, s: State, sc: Scratch, i: int, dt: float) -> tuple[float, int, float]:
    """Force of the point contact of EDGE pair i (edge of block a on edge of block b); returns
    (elastic energy, active count, friction energy dissipated).

    Stiffness: kn A_e and ks A_e with A_e the smaller of the two edges' ``edge_area`` (the mean
    tributary area of the interface points of the faces meeting at the edge): an edge-edge contact
    is as stiff as one interface point of the coarser-discretised side would be.
    """
    a = s.pair_a[i]
    b = s.pair_b[i]
    ea = s.pair_edge_a[i]
    eb = s.pair_edge_b[i]
    sc.pair_dashpot_force[i, :] = 0.0
    sc.pair_dashpot_cn[i] = 0.0
    sc.pair_force[i, :] = 0.0
    un, n0, n1, n2, x0, x1, x2 = edge_contact(m, s, sc, i)
    st = s.pair_set[i]
    if st > 0.0:  # unloaded at overlap st (detect.hand_over_edge); follows the overlap down
        st = min(st, max(un, 0.0))
        s.pair_set[i] = st
        un -= st
    ga = m.block_group[a]
    gb = m.block_group[b]
    area = min(m.edge_area[ea], m.edge_area[eb])
    kna = m.mat_kn[ga, gb] * area
    ksa = m.mat_ks[ga, gb] * area
    us0, us1, us2 = s.pair_shear[i, 0], s.pair_shear[i, 1], s.pair_shear[i, 2]
    un_prev = s.pair_overlap[i]
    s.pair_overlap[i] = un
    v0, v1, v2 = _relative_velocity_arrays(s.position, s.velocity, sc.omega_world, a, b, x0, x1, x2)
    vn = v0 * n0 + v1 * n1 + v2 * n2
    vs0, vs1, vs2 = v0 - vn * n0, v1 - vn * n1, v2 - vn * n2
    if un <= 0.0:
        e = 0.5 * ksa * (us0 * us0 + us1 * us1 + us2 * us2)
        if un_prev > 0.0:
            fnc = kna * ramp_overlap(un, un_prev, vn, dt)
            c0, c1, c2, e = release_shear(us0, us1, us2, ksa, m.mat_res_tan_friction[ga, gb] * kna, un_prev, vn, vs0, vs1, vs2, dt)
            if s.dashpots[0] == DASHPOTS_IMPLICIT and vn > 0.0 and m.mat_beta[ga, gb] > 0.0:  # as in _release_pass
                c = m.mat_beta[ga, gb] * dashpot_release_share(un, vn, dt)
                slid = _slipped(ksa, us0, us1, us2, coulomb_limit(m.mat_res_cohesion[ga, gb], m.mat_res_tan_friction[ga, gb], area, kna * un_prev))
                d0, d1, d2 = _released_dashpot(sc.pair_dashpot_force[i], sc.pair_dashpot_velocity[i], c, kna, 0.0 if slid else ksa,
                                               v0, v1, v2, vn, n0, n1, n2)
                c0 += d0
                c1 += d1
                c2 += d2
            _store(sc.pair_force, sc.pair_point, i, fnc * n0 + c0, fnc * n1 + c1, fnc * n2 + c2, x0, x1, x2)
        s.pair_shear[i, 0] = 0.0
        s.pair_shear[i, 1] = 0.0
        s.pair_shear[i, 2] = 0.0
        s.pair_normal_force[i] = 0.0
        return 0.0, 0, e
    ramp = 1.0
    since = dt
    closing = un_prev <= 0.0 and vn < 0.0
    if closing:
        since = min(un / (-vn * dt), 1.0) * dt
        ramp = ramp_overlap(un, un_prev, vn, dt) / un
    fn = kna * un
    f_applied = fn * ramp
    us0, us1, us2, e0_du, e0_sq, du_sq = shear_increment(us0, us1, us2, n0, n1, n2, vs0, vs1, vs2, since)
    trial = ksa * math.sqrt(us0 * us0 + us1 * us1 + us2 * us2)
    fmax = coulomb_limit(m.mat_res_cohesion[ga, gb], m.mat_res_tan_friction[ga, gb], area, fn)
    e_fric = 0.0
    slipping = trial > fmax
    if slipping:
        e_fric = slip_dissipation(ksa, fmax / trial, e0_du, e0_sq, du_sq)
        f = fmax / trial
        us0 *= f
        us1 *= f
        us2 *= f
    s.pair_shear[i, 0] = us0
    s.pair_shear[i, 1] = us1
    s.pair_shear[i, 2] = us2
    s.pair_normal_force[i] = fn
    beta = m.mat_beta[ga, gb]
    fdn = -beta * kna * vn
    bs = 0.0 if slipping else beta * ksa
    if s.dashpots[0] == DASHPOTS_IMPLICIT and beta > 0.0:  # as in _law_range
        onset = dashpot_onset_share(since, s.velocity_lag[0] + 0.5 * s.dt[0]) if closing else 1.0
        sc.pair_dashpot_cn[i] = onset * beta * kna
        sc.pair_dashpot_cs[i] = onset * bs
        sc.pair_dashpot_velocity[i, 0] = v0
        sc.pair_dashpot_velocity[i, 1] = v1
        sc.pair_dashpot_velocity[i, 2] = v2
        fdn *= 0.5 * onset
        bs *= 0.5 * onset
    d0, d1, d2 = fdn * n0 - bs * vs0, fdn * n1 - bs * vs1, fdn * n2 - bs * vs2
    sc.pair_dashpot_force[i, 0] = d0
    sc.pair_dashpot_force[i, 1] = d1
    sc.pair_dashpot_force[i, 2] = d2
    fs = ksa * ramp
    _store(sc.pair_force, sc.pair_point, i, f_applied * n0 + fs * us0 + d0, f_applied * n1 + fs * us1 + d1, f_applied * n2 + fs * us2 + d2, x0, x1, x2)
    return spring_energy(fn, kna) + spring_energy(min(trial, fmax), ksa), 1, e_fric


@njit(cache=True, _nrt=False, inline="always")
def compute_forces(m: ModelArrays, s: State, sc: Scratch, t: float, dt: float) -> None:
    """Forces and torques on every block at the current poses (joint law of paper §3); ``t`` [s] is
    the time at which body loads (inertial earthquake loading) are sampled, ``dt`` [s] the step
    just taken. (:data:`compute_forces_parallel`: the same with the face pairs' law on Numba's
    threads, the same answer bit for bit.)"""
    nb = m.block_mass.shape[0]
    sc.force[:] = 0.0
    sc.torque[:] = 0.0
    sc.reaction[:] = 0.0
    interpolate(m.body_time, m.body_acceleration, 0, m.body_time.shape[0], t, sc.body_acc)
    for b in range(nb):
        r = sc.rotation[b]
        for i in range(3):
            sc.omega_world[b, i] = r[i, 0] * s.omega[b, 0] + r[i, 1] * s.omega[b, 1] + r[i, 2] * s.omega[b, 2]
        if m.block_free[b]:
            for i in range(3):
                sc.force[b, i] = m.block_mass[b] * (m.gravity[i] + sc.body_acc[i])
    _law_pass(m, s, sc, dt, s.dashpots[0] == DASHPOTS_IMPLICIT, has_dashpots(m))
    elastic, active, e_fric, e_bond, nrel = _gather(m, s, sc)
    if nrel > 0:
        e_fric += _release_pass(m, s, sc, nrel, dt)
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            el, ac, ef = _edge_pair(m, s, sc, i, dt)
            elastic += el
            active += ac
            e_fric += ef
    accumulate(m, s, sc)
    sc.elastic_energy[0] = elastic
    sc.active_count[0] = active
    s.energy[E_FRICTION] += e_fric
    s.energy[E_BOND] += e_bond




compute_forces_parallel = njit(cache=True, _nrt=False, inline="always")(
    rebind(getattr(compute_forces, "py_func", compute_forces), "compute_forces_parallel", _law_pass=_law_pass_parallel)
)
"""(m, s, sc, t, dt) -> None: :func:`compute_forces` with :func:`_law_pass_parallel`."""
