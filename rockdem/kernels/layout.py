"""Flat struct-of-arrays layouts passed into the kernels (NamedTuples pass into Numba and pickle).

Index conventions: ``block_*_start`` arrays have length count+1 (CSR style); the faces of block b
are ``block_face_start[b]:block_face_start[b+1]``, and likewise for vertices, face edges and face
points. Body frames are principal frames with the origin at the centroid.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# Point failure modes (persistent: a point that failed keeps its mode for reporting).
FAILED_NONE = 0
FAILED_TENSION = 1
FAILED_SHEAR = 2

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
    block_face_start: np.ndarray  # (nb+1,)
    face_normal: np.ndarray  # (nf, 3) outward unit normal, body frame
    face_offset: np.ndarray  # (nf,) [m]: normal . x <= offset inside
    face_area: np.ndarray  # (nf,) [m^2]
    face_edge_start: np.ndarray  # (nf+1,)
    edge_normal: np.ndarray  # (ne, 3) in-plane outward normal of a face edge, body frame
    edge_offset: np.ndarray  # (ne,) [m]
    face_point_start: np.ndarray  # (nf+1,)
    point_local: np.ndarray  # (np, 3) [m], body frame
    point_area: np.ndarray  # (np,) [m^2]
    point_block: np.ndarray  # (np,) int64
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
    contact_tol: float  # [m] gap within which points are tracked between detections
    edge_tol: float  # [m] tolerance of the point-in-face test


class State(NamedTuple):
    """Everything that changes during a run (arrays mutated in place by the kernels)."""

    clock: np.ndarray  # (2,) [time s, dt s]
    step: np.ndarray  # (1,) int64 steps taken
    position: np.ndarray  # (nb, 3) [m] centroid
    quaternion: np.ndarray  # (nb, 4) body -> world
    velocity: np.ndarray  # (nb, 3) [m/s] at the last half step
    omega: np.ndarray  # (nb, 3) [rad/s] body frame, last half step
    point_partner: np.ndarray  # (np,) int64 target block, -1 none
    point_target_face: np.ndarray  # (np,) int64
    point_shear: np.ndarray  # (np, 3) [N] elastic shear force on the point's block, world
    point_normal_force: np.ndarray  # (np,) [N] elastic normal force (compression > 0)
    point_bonded: np.ndarray  # (np,) bool
    point_failed: np.ndarray  # (np,) int64 FAILED_*
    energy: np.ndarray  # (ENERGY_COUNT,) [J] accumulated dissipation and work
    track: np.ndarray  # (np,) int64 tracked point ids
    track_count: np.ndarray  # (1,) int64
    moved: np.ndarray  # (nb,) [m] displacement bound since the last detection


class Scratch(NamedTuple):
    """Per-step work arrays (no meaning between steps)."""

    rotation: np.ndarray  # (nb, 3, 3)
    force: np.ndarray  # (nb, 3) [N] world
    torque: np.ndarray  # (nb, 3) [N m] world, about the centroid
    world_vertex: np.ndarray  # (nv, 3)
    aabb: np.ndarray  # (nb, 6)
    seen: np.ndarray  # (np,) int64 detection pass that claimed the point
    prev_partner: np.ndarray  # (np,) int64 partner before the current detection pass
    passes: np.ndarray  # (1,) int64
    sums: np.ndarray  # (8,) [0] elastic energy, [1] active count, [2:5] reaction, [5] min pair separation, [6:8] pair
    ground_velocity: np.ndarray  # (3,) [m/s]
    body_acc: np.ndarray  # (3,) [m/s^2]
    omega_world: np.ndarray  # (nb, 3) [rad/s]
    point_tmp: np.ndarray  # (4,)
    dashpot_force: np.ndarray  # (np, 3) [N] SP dashpot force on the point's block, per tracked slot
    dashpot_point: np.ndarray  # (np, 3) [m] contact point of that dashpot, world
    velocity_mid: np.ndarray  # (nb, 3) [m/s] step mid-point velocity
    omega_mid: np.ndarray  # (nb, 3) [rad/s] step mid-point angular velocity, world


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
        np.zeros(count),
        np.zeros((count, blocks, 3)),
        np.zeros((count, blocks, 4)),
        np.zeros((count, blocks, 3)),
        np.zeros((count, blocks, 3)),
        np.zeros((count, ENERGY_COUNT)),
        np.zeros((count, 4), dtype=np.int64),
        np.zeros((count, 3)),
        np.zeros((count, driven, 3)),
    )
