"""Initial state: poses, velocities and the contacts at t = 0 (bonded where touching)."""

from __future__ import annotations

import numpy as np

from ._warn import warn_user
from .kernels.detect import bond_touching, detect, update_rotations
from .kernels.layout import ENERGY_COUNT, FAILED_NONE, LAW_CHUNKS, SLOTS, Scratch, State
from .model import Model

__all__ = ["initial_state", "grow_buffers"]


def _pair_arrays(count: int) -> dict[str, np.ndarray]:
    i64 = np.int64
    return {
        "pair_a": np.zeros(count, dtype=i64),
        "pair_b": np.zeros(count, dtype=i64),
        "pair_kind": np.zeros(count, dtype=i64),
        "pair_owner_face": np.zeros(count, dtype=i64),
        "pair_target_face": np.zeros(count, dtype=i64),
        "pair_track_start": np.zeros(count, dtype=i64),
        "pair_track_split": np.zeros(count, dtype=i64),
        "pair_track_stop": np.zeros(count, dtype=i64),
        "pair_edge_a": np.zeros(count, dtype=i64),
        "pair_edge_b": np.zeros(count, dtype=i64),
        "pair_normal": np.zeros((count, 3)),
        "pair_shear": np.zeros((count, 3)),
        "pair_normal_force": np.zeros(count),
        "pair_overlap": np.zeros(count),
        "pair_set": np.zeros(count),
        "pair_from_edge": np.zeros(count, dtype=np.bool_),
    }


def _scratch_pairs(count: int) -> dict[str, np.ndarray]:
    i64 = np.int64
    return {
        "pair_force": np.zeros((count, 3)),
        "pair_point": np.zeros((count, 3)),
        "pair_dashpot_force": np.zeros((count, 3)),
        "pair_dashpot_cn": np.zeros(count),
        "pair_dashpot_cs": np.zeros(count),
        "pair_dashpot_velocity": np.zeros((count, 3)),
        "pair_weight": np.zeros(count),
        "pair_bonded": np.zeros(count, dtype=np.bool_),
        "pair_asks_detection": np.zeros(count, dtype=np.bool_),
        "pair_handover": np.full(count, -1.0),
        "side_force": np.zeros((count, 2, 3)),
        "side_moment": np.zeros((count, 2, 3)),
        "side_elastic": np.zeros((count, 2)),
        "side_friction": np.zeros((count, 2)),
        "side_bond": np.zeros((count, 2)),
        "side_active": np.zeros((count, 2), dtype=i64),
        "side_released": np.zeros((count, 2), dtype=i64),
        "side_failed": np.zeros((count, 2), dtype=i64),
        "side_touch": np.full((count, 2), np.inf),
        "side_impacting": np.zeros((count, 2), dtype=np.bool_),
        "blend_force_owner": np.zeros((count, 3)),
        "blend_point_owner": np.zeros((count, 3)),
        "blend_force_target": np.zeros((count, 3)),
        "blend_point_target": np.zeros((count, 3)),
        "prev_pair_a": np.zeros(count, dtype=i64),
        "prev_pair_b": np.zeros(count, dtype=i64),
        "prev_pair_kind": np.zeros(count, dtype=i64),
        "prev_pair_owner_face": np.zeros(count, dtype=i64),
        "prev_pair_target_face": np.zeros(count, dtype=i64),
        "prev_pair_edge_a": np.zeros(count, dtype=i64),
        "prev_pair_edge_b": np.zeros(count, dtype=i64),
        "prev_pair_shear": np.zeros((count, 3)),
        "prev_pair_normal": np.zeros((count, 3)),
        "prev_pair_normal_force": np.zeros(count),
        "prev_pair_overlap": np.zeros(count),
        "prev_pair_set": np.zeros(count),
        "prev_pair_weight": np.zeros(count),
        "prev_pair_key": np.zeros(count, dtype=i64),
        "prev_pair_index": np.zeros(count, dtype=i64),
        "prev_pair_kept": np.zeros(count, dtype=np.bool_),
    }


def _scratch_candidates(count: int) -> dict[str, np.ndarray]:
    i64 = np.int64
    return {
        "cand_code": np.zeros(count, dtype=i64),
        "cand_partner": np.zeros(count, dtype=i64),
        "cand_face": np.zeros(count, dtype=i64),
        "cand_slot": np.zeros(count, dtype=i64),
    }


def _allocate(model: Model) -> tuple[State, Scratch]:
    m = model.arrays
    nb, n_pts, nv = model.block_count, model.point_count, m.vertex_local.shape[0]
    pairs = max(64, 16 * nb)
    cands = SLOTS * n_pts + 64
    one = np.zeros(1)
    s = State(
        time=one.copy(),
        dt=one.copy(),
        dt_prev=one.copy(),
        velocity_lag=one.copy(),  # 0: the initial velocities are those at t = 0 (a half step's update first)
        dt_min=one.copy(),
        safety=one.copy(),
        resolution=one.copy(),
        dt_coarse=one.copy(),
        refinement=np.ones(1),
        impact_window=one.copy(),
        impact_speed=np.full(1, np.inf),
        refine_until=one.copy(),
        refine_limit=one.copy(),
        refined_time=one.copy(),
        dashpots=np.zeros(1, dtype=np.int64),
        dashpot_sweeps=np.zeros(1, dtype=np.int64),
        dashpot_unconverged=np.zeros(1, dtype=np.int64),
        step=np.zeros(1, dtype=np.int64),
        slot_updates=np.zeros(1, dtype=np.int64),
        position=model.position0.copy(),
        quaternion=model.quaternion0.copy(),
        velocity=model.velocity0.copy(),
        omega=model.omega0.copy(),
        slot_partner=np.full((n_pts, SLOTS), -1, dtype=np.int64),
        slot_face=np.full((n_pts, SLOTS), -1, dtype=np.int64),
        slot_shear=np.zeros((n_pts, SLOTS, 3)),
        slot_normal_force=np.zeros((n_pts, SLOTS)),
        slot_area=np.zeros((n_pts, SLOTS)),
        slot_overlap=np.zeros((n_pts, SLOTS)),
        slot_set=np.zeros((n_pts, SLOTS)),
        slot_cover=np.zeros((n_pts, SLOTS)),
        slot_anchor=np.zeros((n_pts, SLOTS, 2)),
        slot_deepest=np.zeros((n_pts, SLOTS, 2)),
        slot_bonded=np.zeros((n_pts, SLOTS), dtype=np.bool_),
        slot_stiffening=np.ones((n_pts, SLOTS)),
        point_failed=np.full(n_pts, FAILED_NONE, dtype=np.int64),
        energy=np.zeros(ENERGY_COUNT),
        track=np.zeros(SLOTS * n_pts, dtype=np.int64),
        track_count=np.zeros(1, dtype=np.int64),
        pair_count=np.zeros(1, dtype=np.int64),
        moved=np.zeros(nb),
        fell_off=np.full(nb, -1.0),
        **_pair_arrays(pairs),
    )
    sc = Scratch(
        rotation=np.zeros((nb, 3, 3)),
        force=np.zeros((nb, 3)),
        torque=np.zeros((nb, 3)),
        world_vertex=np.zeros((nv, 3)),
        aabb=np.zeros((nb, 6)),
        seen=np.zeros(SLOTS * n_pts, dtype=np.int64),
        passes=np.zeros(1, dtype=np.int64),
        elastic_energy=one.copy(),
        active_count=np.zeros(1, dtype=np.int64),
        reaction=np.zeros(3),
        min_separation=one.copy(),
        min_pair=np.full(2, -1, dtype=np.int64),
        overflow=np.zeros(1, dtype=np.int64),
        ground_velocity=np.zeros(3),
        body_acc=np.zeros(3),
        driven_velocity=np.zeros(3),
        omega_world=np.zeros((nb, 3)),
        contact_force=np.zeros((SLOTS * n_pts, 3)),
        contact_point=np.zeros((SLOTS * n_pts, 3)),
        dashpot_force=np.zeros((SLOTS * n_pts, 3)),
        dashpot_cn=np.zeros(SLOTS * n_pts),
        dashpot_cs=np.zeros(SLOTS * n_pts),
        dashpot_normal=np.zeros((SLOTS * n_pts, 3)),
        dashpot_velocity=np.zeros((SLOTS * n_pts, 3)),
        track_area=np.zeros(SLOTS * n_pts),
        track_point_u=np.zeros(SLOTS * n_pts),
        track_point_w=np.zeros(SLOTS * n_pts),
        track_depth_shift=np.zeros(SLOTS * n_pts),
        pending=np.zeros(SLOTS * n_pts, dtype=np.int64),
        pending_pair=np.zeros(SLOTS * n_pts, dtype=np.int64),
        release_overlap=np.zeros(SLOTS * n_pts),
        release_area=np.zeros(SLOTS * n_pts),
        track_released=np.zeros(SLOTS * n_pts, dtype=np.bool_),
        track_failed=np.zeros(SLOTS * n_pts, dtype=np.int64),
        velocity_mid=np.zeros((nb, 3)),
        omega_mid=np.zeros((nb, 3)),
        block_damping=np.zeros((nb, 6, 6)),
        block_coupling=np.zeros((nb, 6)),
        block_lhs=np.zeros((nb, 6, 6)),
        block_rhs=np.zeros((nb, 6)),
        block_iterate=np.zeros((2, nb, 6)),
        block_damped=np.zeros(nb, dtype=np.bool_),
        driven_velocity_last=np.zeros((nb, 3)),
        driven_force_last=np.zeros((nb, 3)),
        driven_dashpot=np.zeros((nb, 3)),
        poly=np.zeros((2, 32, 2)),
        chunk_poly=np.zeros((LAW_CHUNKS, 2, 32, 2)),
        touch_time=np.full(1, np.inf),
        impacting=np.zeros(1, dtype=np.bool_),
        prev_pair_count=np.zeros(1, dtype=np.int64),
        energy_scale=one.copy(),
        lost_block=np.full(1, -1, dtype=np.int64),
        sweep_order=np.zeros(nb, dtype=np.int64),
        bound_stiffness=np.zeros(nb),
        bound_beta=np.zeros(nb),
        **_scratch_pairs(pairs),
        **_scratch_candidates(cands),
    )
    return s, sc


def grow_buffers(s: State, sc: Scratch) -> tuple[State, Scratch]:
    """Double the pair and candidate buffers (after a detection reported an overflow)."""
    pairs = 2 * s.pair_a.shape[0]
    cands = 2 * sc.cand_code.shape[0]
    new_pairs = _pair_arrays(pairs)
    for name, arr in new_pairs.items():
        old = getattr(s, name)
        arr[: old.shape[0]] = old
    new_scr = _scratch_pairs(pairs)
    for name, arr in new_scr.items():
        old = getattr(sc, name)
        arr[: old.shape[0]] = old
    return s._replace(**new_pairs), sc._replace(**new_scr, **_scratch_candidates(cands))


def detect_all(model: Model, s: State, sc: Scratch) -> tuple[State, Scratch]:
    """Contact detection at the current state, enlarging the buffers until everything fits."""
    m = model.arrays
    update_rotations(m, s, sc)
    while True:
        detect(m, s, sc)
        if sc.overflow[0] == 0:
            return s, sc
        s, sc = grow_buffers(s, sc)


START_OVERLAP_SHARE = 0.1
"""An overlap at the start above this share of the contact tolerance is warned about (the
springs start loaded); above the tolerance itself it is refused."""


def initial_state(model: Model, *, check_overlap: bool = True) -> tuple[State, Scratch]:
    """State at t = 0 with contacts detected; joints touching at the start are bonded.

    Raises:
        ValueError: two blocks overlap at the start (names both and the depth).
    """
    m = model.arrays
    s, sc = _allocate(model)
    s, sc = detect_all(model, s, sc)
    depth = -float(sc.min_separation[0])
    if check_overlap and depth > START_OVERLAP_SHARE * m.touch_tol:
        a, b = (model.block_names[int(v)] for v in sc.min_pair)
        if depth > m.touch_tol:
            raise ValueError(f"blocks {a!r} and {b!r} overlap by {depth:.4g} m at the start (more than the touching tolerance, {m.touch_tol:.3g} m); "
                             "move them apart so that they at most touch")
        warn_user(
            f"blocks {a!r} and {b!r} overlap by {depth:.3g} m at the start: their joint springs start compressed by that "
            "much and release its energy at the first steps (a 0.3 m cube sunk 0.3 mm into the ground on kn = 5e9 Pa/m "
            "jumps 39 mm); move them apart so that they at most touch"
        )
    bond_touching(m, s, sc)
    return s, sc
