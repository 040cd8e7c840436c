"""Initial state: poses, velocities and the contacts at t = 0 (bonded where touching)."""

from __future__ import annotations

import numpy as np

from .kernels.detect import detect, point_in_target, update_rotations
from .kernels.layout import ENERGY_COUNT, FAILED_NONE, Scratch, State
from .model import Model

__all__ = ["initial_state"]


def initial_state(model: Model, *, check_overlap: bool = True) -> tuple[State, Scratch]:
    """State at t = 0 with contacts detected; joints touching at the start are bonded.

    Raises:
        ValueError: two blocks overlap at the start (names both and the depth).
    """
    m = model.arrays
    nb, n_pts, nv = model.block_count, model.point_count, m.vertex_local.shape[0]
    s = State(
        clock=np.zeros(6),
        step=np.zeros(1, dtype=np.int64),
        position=model.position0.copy(),
        quaternion=model.quaternion0.copy(),
        velocity=model.velocity0.copy(),
        omega=model.omega0.copy(),
        point_partner=np.full(n_pts, -1, dtype=np.int64),
        point_target_face=np.full(n_pts, -1, dtype=np.int64),
        point_shear=np.zeros((n_pts, 3)),
        point_normal_force=np.zeros(n_pts),
        point_bonded=np.zeros(n_pts, dtype=np.bool_),
        point_failed=np.full(n_pts, FAILED_NONE, dtype=np.int64),
        energy=np.zeros(ENERGY_COUNT),
        track=np.zeros(n_pts, dtype=np.int64),
        track_count=np.zeros(1, dtype=np.int64),
        moved=np.zeros(nb),
    )
    sc = Scratch(
        rotation=np.zeros((nb, 3, 3)),
        force=np.zeros((nb, 3)),
        torque=np.zeros((nb, 3)),
        world_vertex=np.zeros((nv, 3)),
        aabb=np.zeros((nb, 6)),
        seen=np.zeros(n_pts, dtype=np.int64),
        prev_partner=np.full(n_pts, -1, dtype=np.int64),
        passes=np.zeros(1, dtype=np.int64),
        sums=np.zeros(8),
        ground_velocity=np.zeros(3),
        body_acc=np.zeros(3),
        omega_world=np.zeros((nb, 3)),
        point_tmp=np.zeros(4),
        dashpot_force=np.zeros((n_pts, 3)),
        dashpot_point=np.zeros((n_pts, 3)),
        velocity_mid=np.zeros((nb, 3)),
        omega_mid=np.zeros((nb, 3)),
    )
    update_rotations(m, s, sc)
    detect(m, s, sc)
    depth = -sc.sums[5]
    if check_overlap and depth > m.edge_tol:
        a, b = int(sc.sums[6]), int(sc.sums[7])
        raise ValueError(
            f"blocks {model.block_names[a]!r} and {model.block_names[b]!r} overlap by {depth:.4g} m at the "
            f"start (tolerance {m.edge_tol:.3g} m); move them apart so that they at most touch"
        )
    tmp = np.zeros(4)
    for k in range(int(s.track_count[0])):
        p = int(s.track[k])
        t = int(s.point_partner[p])
        gap = point_in_target(m, s, sc, p, t, int(s.point_target_face[p]), tmp)
        touching = abs(gap) <= m.edge_tol and tmp[3] <= m.edge_tol
        s.point_bonded[p] = touching and m.mat_bonded[m.block_group[m.point_block[p]], m.block_group[t]]
    return s, sc
