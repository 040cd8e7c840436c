"""Flat struct-of-arrays layouts passed into the kernels (NamedTuples pass into Numba and pickle).

Index conventions: ``*_start`` arrays have length count+1 (CSR style); the faces of block b are
``block_face_start[b]:block_face_start[b+1]``, and likewise for vertices, edges, edge directions,
face corners, face edge lines, face points and point cell vertices. Body frames are principal
frames with the origin at the centroid. Every face has a 2D frame (origin, u "across", w "along",
with u, w, normal right-handed); "face coordinates" are (u, w) in it.

Contacts (see ``docs/contacts.md``): a *pair* is two blocks found close by the narrow phase. A
FACE pair carries sub-contacts: interface points of its *owner* face, each with one of the two
*slots* of its point, pressed against the *target* face of the other block. An EDGE pair is one
point contact between an edge of each block. Slot k of point p is the contact code ``2 p + k``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# Point failure modes (persistent: a point that failed keeps its mode for reporting).
FAILED_NONE = 0
FAILED_TENSION = 1
FAILED_SHEAR = 2

# Kinds of pairs.
PAIR_FACE = 0
PAIR_EDGE = 1

LAW_CHUNKS = 64
"""Fixed chunks of the face pairs in the parallel law pass (kernels.forces), each with its own
polygon buffer (``Scratch.chunk_poly``): the work splits over up to this many threads, and the
answer does not depend on how many there are."""

SLOTS = 2
"""Partners a point can hold at once (a point on the shared edge of two faces of its partners)."""

STIFFENING_AT_START = 0.0
"""``State.slot_stiffening`` of an unbonded corner sub-contact touching at the start: its factor is
decided at the first law pass as for a corner arriving at its start depth (kernels.forces.corner_stiffening),
whatever the sign of a round-off overlap."""

# How the SP dashpots are integrated (State.dashpots).
DASHPOTS_IMPLICIT = 0  # trapezoidal in the damping: stable at the undamped step (kernels.implicit)
DASHPOTS_EXPLICIT = 1  # on the last half step's velocities, Belytschko-reduced step (3DEC's scheme)

# Status returned by the stepping loop.
STATUS_DONE = 0
STATUS_GROW = 1  # the pair or candidate buffers are full: enlarge them and continue
STATUS_DIVERGED = 2  # energy balance broken or a non-finite state
STATUS_LOST = 3  # a free block fell through its support or flew away (left the model's extent through its bottom or top)

# Energy accumulator slots (State.energy) and recorded energy columns.
E_KINETIC = 0
E_POTENTIAL = 1
E_ELASTIC = 2
E_DAMPING_MASS = 3
E_DAMPING_STIFFNESS = 4
E_FRICTION = 5
E_BOND = 6
E_LOCAL_DAMPING = 7
W_DRIVEN = 8
W_BODY = 9
ENERGY_COUNT = 10
ENERGY_NAMES = (
    "energy_kinetic",
    "energy_potential",
    "energy_elastic",
    "energy_damping_mass",
    "energy_damping_stiffness",
    "energy_friction",
    "energy_bond",
    "energy_local_damping",
    "work_driven",
    "work_body",
)

# Recorded contact counts.
COUNT_ACTIVE = 0
COUNT_BONDED = 1
COUNT_FAILED_TENSION = 2
COUNT_FAILED_SHEAR = 3
COUNT_NAMES = ("contacts_active", "contacts_bonded", "contacts_failed_tension", "contacts_failed_shear")


class ModelArrays(NamedTuple):
    """Constant model data: geometry, mass, materials, damping, prescribed kinematics."""

    block_mass: np.ndarray  # (nb,) [kg]
    block_inv_mass: np.ndarray  # (nb,) [1/kg], 0 for driven blocks
    block_inertia: np.ndarray  # (nb, 3) principal moments [kg m^2]
    block_inv_inertia: np.ndarray  # (nb, 3), 0 for driven blocks
    block_free: np.ndarray  # (nb,) bool
    block_motion: np.ndarray  # (nb,) int64: motion table of a driven block, -1 = fixed
    block_group: np.ndarray  # (nb,) int64
    block_radius: np.ndarray  # (nb,) [m] largest vertex distance from the centroid
    block_vertex_start: np.ndarray  # (nb+1,)
    vertex_local: np.ndarray  # (nv, 3) [m], body frame
    block_edge_start: np.ndarray  # (nb+1,)
    edge_vertex: np.ndarray  # (ne, 2) int64 global vertex ids of each edge
    edge_area: np.ndarray  # (ne,) [m^2] contact area of an edge-edge contact on this edge
    block_dir_start: np.ndarray  # (nb+1,)
    dir_local: np.ndarray  # (nd, 3) unit edge directions of each block, parallel edges merged
    block_face_start: np.ndarray  # (nb+1,)
    face_block: np.ndarray  # (nf,) int64
    face_normal: np.ndarray  # (nf, 3) outward unit normal, body frame
    face_offset: np.ndarray  # (nf,) [m]: normal . x <= offset inside
    face_area: np.ndarray  # (nf,) [m^2]
    face_origin: np.ndarray  # (nf, 3) [m] origin of the face frame (a point of the face), body frame
    face_u: np.ndarray  # (nf, 3) unit axis "across" of the face frame, body frame
    face_w: np.ndarray  # (nf, 3) unit axis "along" of the face frame, body frame
    face_corner_start: np.ndarray  # (nf+1,)
    face_corner: np.ndarray  # (nc,) global vertex ids, counter-clockwise seen from outside
    face_corner_uw: np.ndarray  # (nc, 2) [m] those corners in face coordinates (u, w)
    face_line_start: np.ndarray  # (nf+1,)
    face_line: np.ndarray  # (nl, 3) polygon edges in face coordinates: lu u + lw w <= lo inside
    face_point_start: np.ndarray  # (nf+1,)
    point_local: np.ndarray  # (np, 3) [m], body frame
    point_area: np.ndarray  # (np,) [m^2] tributary area (cell area)
    point_block: np.ndarray  # (np,) int64
    point_face: np.ndarray  # (np,) int64
    point_node: np.ndarray  # (np, 2) [m] the point in face coordinates
    point_corner: np.ndarray  # (np,) int64 index into face_corner of the block vertex the point sits on, -1 none
    point_cell_start: np.ndarray  # (np+1,)
    cell_vertex: np.ndarray  # (ncv, 2) [m] tributary cell polygons in face coordinates (CCW)
    mat_kn: np.ndarray  # (ng, ng) [Pa/m]
    mat_ks: np.ndarray  # (ng, ng) [Pa/m]
    mat_cohesion: np.ndarray  # (ng, ng) [Pa]
    mat_tension: np.ndarray  # (ng, ng) [Pa]
    mat_tan_friction: np.ndarray  # (ng, ng)
    mat_res_cohesion: np.ndarray  # (ng, ng) [Pa]
    mat_res_tan_friction: np.ndarray  # (ng, ng)
    mat_beta: np.ndarray  # (ng, ng) [s]
    mat_bonded: np.ndarray  # (ng, ng) bool: joints in contact at the start are bonded
    gravity: np.ndarray  # (3,) [m/s^2]
    alpha: float  # mass-proportional damping [1/s]
    alpha_relative: bool  # MP damping on velocities relative to the ground motion
    local_damping: float  # Cundall local damping coefficient [-]
    motion_start: np.ndarray  # (nm+1,)
    motion_time: np.ndarray  # (N,) [s]
    motion_velocity: np.ndarray  # (N, 3) [m/s]
    ground_motion: int  # motion table of the ground, -1 = none
    body_time: np.ndarray  # (M,) [s]
    body_acceleration: np.ndarray  # (M, 3) [m/s^2] applied to free blocks (inertial loading)
    contact_tol: float  # [m] gap within which contacts are tracked between detections
    touch_tol: float  # [m] gap within which joints count as touching at the start (bonded)
    extent_low: np.ndarray  # (3,) [m] lower corner of the model's extent (a free block leaving it is lost)
    extent_high: np.ndarray  # (3,) [m] upper corner
    support_low: np.ndarray  # (2,) [m] plan (x, y) footprint of the driven blocks at the start, lower corner
    support_high: np.ndarray  # (2,) [m] upper corner (low > high: no driven blocks)


class State(NamedTuple):
    """Everything that changes during a run (arrays mutated in place by the kernels)."""

    time: np.ndarray  # (1,) [s]
    dt: np.ndarray  # (1,) [s] step to take next
    dt_prev: np.ndarray  # (1,) [s] step just taken
    velocity_lag: np.ndarray  # (1,) [s] how long before ``time`` the velocities hold: half the step just
    # taken (leapfrog), 0 at a fresh start (the initial velocities are those at t = 0)
    dt_min: np.ndarray  # (1,) [s] smallest step used so far
    safety: np.ndarray  # (1,) fraction of the stable bound used when the step is lowered
    resolution: np.ndarray  # (1,) largest omega_max dt / 2 when the step is lowered (impact resolution)
    dt_coarse: np.ndarray  # (1,) [s] the step outside impact windows (lowered, never raised, by the bounds)
    refinement: np.ndarray  # (1,) the step inside an impact window is dt_coarse / refinement (1: no windows)
    impact_window: np.ndarray  # (1,) [s] a window opens this long before a predicted impact (0: never; step.IMPACT_AFTER)
    impact_speed: np.ndarray  # (1,) [m/s] closing speed above which an unbonded sub-contact's touch is an impact
    refine_until: np.ndarray  # (1,) [s] end of the present impact window (<= time: none)
    refine_limit: np.ndarray  # (1,) [s] latest end of the present window (kernels.step.IMPACT_LONGEST after its touch)
    refined_time: np.ndarray  # (1,) [s] simulated time spent in impact windows so far
    dashpots: np.ndarray  # (1,) int64 DASHPOTS_IMPLICIT or DASHPOTS_EXPLICIT
    dashpot_sweeps: np.ndarray  # (1,) int64 Jacobi sweeps of the implicit dashpots of coupled free blocks so far
    dashpot_unconverged: np.ndarray  # (1,) int64 steps whose sweeps stopped at DASHPOT_MAX_SWEEPS
    step: np.ndarray  # (1,) int64 steps taken
    slot_updates: np.ndarray  # (1,) int64 tracked sub-contacts summed over the steps taken (work done)
    position: np.ndarray  # (nb, 3) [m] centroid
    quaternion: np.ndarray  # (nb, 4) body -> world
    velocity: np.ndarray  # (nb, 3) [m/s] at time - velocity_lag (the last half step)
    omega: np.ndarray  # (nb, 3) [rad/s] body frame, last half step
    slot_partner: np.ndarray  # (np, SLOTS) int64 partner block, -1 none
    slot_face: np.ndarray  # (np, SLOTS) int64 target face
    slot_shear: np.ndarray  # (np, SLOTS, 3) [m] elastic shear displacement, world (owner rel. target)
    slot_normal_force: np.ndarray  # (np, SLOTS) [N] elastic normal force (compression > 0)
    slot_area: np.ndarray  # (np, SLOTS) [m^2] effective area: the cell area the partner covers
    slot_overlap: np.ndarray  # (np, SLOTS) [m] normal overlap at the last force pass (> 0 compression), less slot_set
    slot_set: np.ndarray  # (np, SLOTS) [m] overlap at which an unbonded sub-contact's spring is unloaded (>= 0:
    # forces.cover_change, its cover grew under load; forces._hand_over_face, it took over from an edge spring)
    slot_cover: np.ndarray  # (np, SLOTS) [-] cover weight of a partly covered cell at the last force pass
    # (kernels.faces.partly_covered; 0 wholly covered): its change at a pose is a cover change (forces.cover_change)
    slot_anchor: np.ndarray  # (np, SLOTS, 2) [m] (u, w) owner face coordinates of the point a partly covered
    # cell's overlap is measured at (its own, or the nearest covered one), at the last force pass where slot_cover > 0
    slot_deepest: np.ndarray  # (np, SLOTS, 2) [m] (u, w) its deepest covered point, likewise
    slot_bonded: np.ndarray  # (np, SLOTS) bool
    slot_stiffening: np.ndarray  # (np, SLOTS) [-] area factor of a corner that landed alone (vertex-face contact), 1 otherwise
    # (STIFFENING_AT_START: to be decided at the first law pass)
    point_failed: np.ndarray  # (np,) int64 FAILED_*
    energy: np.ndarray  # (ENERGY_COUNT,) [J] accumulated dissipation and work
    track: np.ndarray  # (SLOTS np,) int64 contact codes 2 p + k, grouped by pair
    track_count: np.ndarray  # (1,) int64
    pair_count: np.ndarray  # (1,) int64
    pair_a: np.ndarray  # (P,) int64 block a < b
    pair_b: np.ndarray  # (P,) int64
    pair_kind: np.ndarray  # (P,) int64 PAIR_FACE or PAIR_EDGE
    pair_owner_face: np.ndarray  # (P,) int64 FACE: face whose points carry the sub-contacts
    pair_target_face: np.ndarray  # (P,) int64 FACE: face they press on
    pair_track_start: np.ndarray  # (P,) int64 FACE: its sub-contacts are track[start:stop], the owner
    # face's points pressed on the target face in [start, split), the target face's points pressed on
    # the owner face in [split, stop) (tracked only while the pair may blend, kernels.blend)
    pair_track_split: np.ndarray  # (P,) int64
    pair_track_stop: np.ndarray  # (P,) int64
    pair_edge_a: np.ndarray  # (P,) int64 EDGE: edge of block a
    pair_edge_b: np.ndarray  # (P,) int64 EDGE: edge of block b
    pair_normal: np.ndarray  # (P, 3) EDGE: contact normal, world, pointing from b to a
    pair_shear: np.ndarray  # (P, 3) [m] EDGE: elastic shear displacement of a relative to b
    pair_normal_force: np.ndarray  # (P,) [N] EDGE: elastic normal force
    pair_overlap: np.ndarray  # (P,) [m] EDGE: overlap at the last force pass, less pair_set
    pair_from_edge: np.ndarray  # (P,) bool FACE: formed at this detection from a pressed EDGE pair of the
    # same blocks, or from a pressed FACE pair on other faces (its sub-contacts continue that contact: none is
    # a landing corner)
    pair_set: np.ndarray  # (P,) [m] EDGE: overlap at which the edge spring is unloaded (>= 0; see
    # detect.hand_over_edge: a pair formed overlapping starts with no more energy than it replaces)
    moved: np.ndarray  # (nb,) [m] displacement bound since the last detection
    fell_off: np.ndarray  # (nb,) [s] time a free block fell off the edge of the supports, -1: it did not


class Scratch(NamedTuple):
    """Per-step work arrays (no meaning between steps, except the detection buffers)."""

    rotation: np.ndarray  # (nb, 3, 3)
    force: np.ndarray  # (nb, 3) [N] world
    torque: np.ndarray  # (nb, 3) [N m] world, about the centroid
    world_vertex: np.ndarray  # (nv, 3)
    aabb: np.ndarray  # (nb, 6)
    seen: np.ndarray  # (SLOTS np,) int64 detection pass that confirmed the slot
    passes: np.ndarray  # (1,) int64
    elastic_energy: np.ndarray  # (1,) [J] stored in the contact springs at the last force pass
    active_count: np.ndarray  # (1,) int64 contacts in compression (or bonded) at the last force pass
    reaction: np.ndarray  # (3,) [N] force of the driven blocks on the free blocks
    min_separation: np.ndarray  # (1,) [m] smallest pair separation at the last detection (< 0: overlap)
    min_pair: np.ndarray  # (2,) int64 the two blocks of that pair
    overflow: np.ndarray  # (1,) int64 > 0: the pair or candidate buffers were too small
    ground_velocity: np.ndarray  # (3,) [m/s]
    body_acc: np.ndarray  # (3,) [m/s^2]
    driven_velocity: np.ndarray  # (3,) [m/s] prescribed velocity of the driven block being integrated
    omega_world: np.ndarray  # (nb, 3) [rad/s]
    # Per tracked sub-contact, written only where some joint has SP dashpots (read by their passes):
    contact_force: np.ndarray  # (SLOTS np, 3) [N] force of each tracked sub-contact on its owner, world
    contact_point: np.ndarray  # (SLOTS np, 3) [m] its point of application, world
    dashpot_force: np.ndarray  # (SLOTS np, 3) [N] the SP dashpot part of that force
    dashpot_cn: np.ndarray  # (SLOTS np,) [N s/m] normal dashpot beta kn A of an active sub-contact, 0 inactive
    dashpot_cs: np.ndarray  # (SLOTS np,) [N s/m] shear dashpot beta ks A (0 while slipping)
    dashpot_normal: np.ndarray  # (SLOTS np, 3) its unit normal, world (into the block the force acts on)
    dashpot_velocity: np.ndarray  # (SLOTS np, 3) [m/s] relative velocity at the last half step (owner minus target)
    track_area: np.ndarray  # (SLOTS np,) [m^2] effective area of a tracked sub-contact that opened during the last step (for the release pass; not written for the others)
    track_point_u: np.ndarray  # (SLOTS np,) [m] its force point, owner face coordinate u
    track_point_w: np.ndarray  # (SLOTS np,) [m] ... and w
    track_depth_shift: np.ndarray  # (SLOTS np,) [m] overlap at the force point minus its overlap (<= 0, faces.partly_covered)
    pending: np.ndarray  # (SLOTS np,) int64 tracked sub-contacts left for a later pass
    pending_pair: np.ndarray  # (SLOTS np,) int64 their pairs
    release_overlap: np.ndarray  # (SLOTS np,) [m] per tracked sub-contact that opened during the last step: its overlap then
    release_area: np.ndarray  # (SLOTS np,) [m^2] ... and its area then
    track_released: np.ndarray  # (SLOTS np,) bool it opened during the last step (from the law pass to its gather)
    track_failed: np.ndarray  # (SLOTS np,) int64 FAILED_* of its bond failing at this step (law pass to gather)
    pair_force: np.ndarray  # (P, 3) [N] EDGE pairs: force on block a
    pair_point: np.ndarray  # (P, 3) [m] its point of application
    pair_dashpot_force: np.ndarray  # (P, 3) [N] EDGE pairs: the SP dashpot part
    pair_dashpot_cn: np.ndarray  # (P,) [N s/m] EDGE pairs: normal dashpot, 0 inactive
    pair_dashpot_cs: np.ndarray  # (P,) [N s/m] EDGE pairs: shear dashpot
    pair_dashpot_velocity: np.ndarray  # (P, 3) [m/s] EDGE pairs: relative velocity of a to b at the last half step
    pair_weight: np.ndarray  # (P,) FACE: share of the target face's points (kernels.blend), the owner's 1 - it;
    # from a detection to the pair's law pass the share it had at its last law pass (-1: a new pair)
    pair_bonded: np.ndarray  # (P,) bool FACE: every sub-contact was bonded at the last detection (weight 0)
    pair_asks_detection: np.ndarray  # (P,) bool FACE: its target's points are needed but not tracked (law pass to gather)
    pair_handover: np.ndarray  # (P,) [J] FACE formed at this detection from an EDGE pair, or from a FACE pair
    # on other faces: the normal spring energy it held (0 unloaded), for the first law pass
    # (forces._hand_over_face); -1 none
    # FACE pairs per side (0: the owner's points, 1: the target's), from the law pass to its gather:
    side_force: np.ndarray  # (P, 2, 3) [N] resultant of the side's sub-contact forces on its pressing block
    side_moment: np.ndarray  # (P, 2, 3) [N m] their moment about that block's centroid
    side_elastic: np.ndarray  # (P, 2) [J] spring energy
    side_friction: np.ndarray  # (P, 2) [J] friction dissipated at this step
    side_bond: np.ndarray  # (P, 2) [J] bond energy released at this step
    side_active: np.ndarray  # (P, 2) int64 active sub-contacts
    side_released: np.ndarray  # (P, 2) int64 sub-contacts that opened during the last step
    side_failed: np.ndarray  # (P, 2) int64 bonds that failed at this step
    side_touch: np.ndarray  # (P, 2) [s] soonest impact predicted on the side (an open sub-contact's gap / closing speed), inf none
    side_impacting: np.ndarray  # (P, 2) bool a pressed unbonded sub-contact of the side moves at an impact speed, deeper than an impact (step.IMPACT_TAIL)
    blend_force_owner: np.ndarray  # (P, 3) [N] FACE: the weight's energy-gradient force on the owner's block ...
    blend_point_owner: np.ndarray  # (P, 3) [m] ... at this point (minus it on the target's block)
    blend_force_target: np.ndarray  # (P, 3) [N] ... and on the target's block
    blend_point_target: np.ndarray  # (P, 3) [m] ... at this point (minus it on the owner's block)
    velocity_mid: np.ndarray  # (nb, 3) [m/s] step mid-point velocity
    block_damping: np.ndarray  # (nb, 6, 6) implicit dashpots: sum of J^T C J over a block's dashpots, world
    # (force, torque) x (velocity, angular velocity) [N s/m, N s, N m s]
    block_coupling: np.ndarray  # (nb, 6) [N, N m] implicit dashpots: sum of J^T C u over its dashpots, u the
    # partner's point velocity (world force and torque)
    block_lhs: np.ndarray  # (nb, 6, 6) implicit dashpots: Cholesky factor of the block's velocity equations
    block_rhs: np.ndarray  # (nb, 6) their right-hand side without the partners' coupling
    block_iterate: np.ndarray  # (2, nb, 6) velocity (world) and angular velocity (body) iterates (Jacobi sweeps)
    block_damped: np.ndarray  # (nb,) bool the block has an active dashpot this step
    driven_velocity_last: np.ndarray  # (nb, 3) [m/s] a driven block's velocity over the last step (implicit dashpots, driven work)
    driven_force_last: np.ndarray  # (nb, 3) [N] the force on a driven block at the last step, less its dashpots' (driven work)
    driven_dashpot: np.ndarray  # (nb, 3) [N] the SP dashpots' resultant force on a driven block at this step
    omega_mid: np.ndarray  # (nb, 3) [rad/s] step mid-point angular velocity, world
    poly: np.ndarray  # (2, 32, 2) two polygon buffers for clipping (source and destination alternate)
    chunk_poly: np.ndarray  # (LAW_CHUNKS, 2, 32, 2) the same for each chunk of the parallel law pass
    cand_code: np.ndarray  # (C,) int64 detection: candidate point p (slot assigned later)
    cand_partner: np.ndarray  # (C,) int64
    cand_face: np.ndarray  # (C,) int64 target face
    cand_slot: np.ndarray  # (C,) int64 slot given to the candidate, -1 none
    touch_time: np.ndarray  # (1,) [s] soonest impact predicted at the last force pass (side_touch's least), inf none
    impacting: np.ndarray  # (1,) bool any side_impacting at the last force pass: an impact is going on
    prev_pair_count: np.ndarray  # (1,) int64 previous detection's pairs (for edge-contact history)
    prev_pair_a: np.ndarray  # (P,) int64
    prev_pair_b: np.ndarray  # (P,) int64
    prev_pair_kind: np.ndarray  # (P,) int64
    prev_pair_owner_face: np.ndarray  # (P,) int64
    prev_pair_target_face: np.ndarray  # (P,) int64
    prev_pair_edge_a: np.ndarray  # (P,) int64
    prev_pair_edge_b: np.ndarray  # (P,) int64
    prev_pair_shear: np.ndarray  # (P, 3)
    prev_pair_normal: np.ndarray  # (P, 3)
    prev_pair_normal_force: np.ndarray  # (P,)
    prev_pair_overlap: np.ndarray  # (P,)
    prev_pair_set: np.ndarray  # (P,)
    prev_pair_weight: np.ndarray  # (P,) pair_weight at the last law pass (-1: not known)
    prev_pair_key: np.ndarray  # (P,) int64 key a nb + b of each previous pair
    prev_pair_index: np.ndarray  # (P,) int64 the previous pairs in ascending key order
    prev_pair_kept: np.ndarray  # (P,) bool the previous pair was found again, as the same contact
    energy_scale: np.ndarray  # (1,) [J] largest energy scale recorded so far (divergence check)
    lost_block: np.ndarray  # (1,) int64 block that diverged or left the extent, -1 none
    sweep_order: np.ndarray  # (nb,) int64 detection: blocks in ascending order of their lowest x
    bound_stiffness: np.ndarray  # (nb,) [1/s^2] contact_bound: each block's row-sum stiffness over its mass
    bound_beta: np.ndarray  # (nb,) [s] contact_bound: the largest beta of its contacts


class Records(NamedTuple):
    """Preallocated outputs filled by the kernel at the record interval."""

    time: np.ndarray  # (R,)
    position: np.ndarray  # (R, nb, 3)
    quaternion: np.ndarray  # (R, nb, 4)
    velocity: np.ndarray  # (R, nb, 3)
    omega: np.ndarray  # (R, nb, 3) world frame
    energy: np.ndarray  # (R, ENERGY_COUNT)
    counts: np.ndarray  # (R, 4)
    reaction: np.ndarray  # (R, 3) [N] force of driven blocks on free blocks
    driven_reaction: np.ndarray  # (R, nd, 3) [N] force of each driven block on the free blocks


def new_records(count: int, blocks: int, driven: int = 0) -> Records:
    """Zeroed record arrays for ``count`` frames, ``blocks`` blocks of which ``driven`` driven."""
    return Records(
        time=np.zeros(count),
        position=np.zeros((count, blocks, 3)),
        quaternion=np.zeros((count, blocks, 4)),
        velocity=np.zeros((count, blocks, 3)),
        omega=np.zeros((count, blocks, 3)),
        energy=np.zeros((count, ENERGY_COUNT)),
        counts=np.zeros((count, 4), dtype=np.int64),
        reaction=np.zeros((count, 3)),
        driven_reaction=np.zeros((count, driven, 3)),
    )
