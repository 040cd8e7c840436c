"""Sub-contact snapshots taken by :func:`rockdem.simulation.simulate` at chunk boundaries.

When ``simulate(..., contact_interval=dt_c)`` is given, the state of every interface point is
copied every ``dt_c`` seconds (the loop's chunks are cut to land on these times) and added to the
result over the dims (``contact_time``, ``point``):

  contact_time (contact_time) [s]              engine clock at the snapshot
  point_position (contact_time, point, xyz) [m] world position of the point (every point)
  point_partner (contact_time, point) int32     partner block id (of the more loaded slot), -1 where none
  point_normal_force (contact_time, point) [N]  elastic normal force, summed over the point's partners
                                                (compression > 0), NaN where no partner
  point_shear_force (contact_time, point) [N]   magnitude of the elastic shear force, NaN where no partner
  point_normal (contact_time, point, xyz)       unit normal of the partner's face (of the more loaded slot),
                                                world, pointing into the point's block; NaN where no partner.
                                                The elastic normal force on the point's block is
                                                point_normal_force * point_normal
  point_shear_force_vector (contact_time, point, xyz) [N]  elastic shear force on the point's block,
                                                world (ks A u_s summed over its partners); NaN where none
  point_bonded (contact_time, point) int8       1 bonded, 0 not, -1 where no partner
  point_failed (contact_time, point) int8       0 intact, 1 failed in tension, 2 failed in shear
                                                (persistent: kept after the point loses its partner)
  static: point_block (point), point_area (point) [m^2], point_local (point, xyz) [m] (body frame)

Size: 24 + 4 + 8 + 8 + 24 + 24 + 1 + 1 = 94 bytes per point per snapshot (before NetCDF compression).
Forces are the elastic joint forces (springs), as 3DEC reports them; the SP dashpot forces are not
included. Edge-to-edge point contacts (non-conformal contacts between edges) are not in the snapshots.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .kernels.layout import State
from .kernels.rotation import quats_to_matrices
from .model import Model

__all__ = ["ContactSnapshots", "BYTES_PER_POINT"]

BYTES_PER_POINT = 94
"""Bytes stored per interface point per contact snapshot (uncompressed)."""


_VARIABLES: dict[str, tuple[tuple[str, ...], str, dict[str, str]]] = {
    # column -> (extra dims, dtype, attrs) of its ``point_*`` variable
    "position": (("xyz",), "f8", {"units": "m"}),
    "partner": ((), "i4", {"units": "1", "note": "-1: no partner"}),
    "normal_force": ((), "f8", {"units": "N", "note": "elastic, compression > 0"}),
    "shear_force": ((), "f8", {"units": "N", "note": "magnitude of the elastic shear force"}),
    "normal": (("xyz",), "f8", {"units": "1", "note": "partner face normal, world, into the point's block"}),
    "shear_force_vector": (("xyz",), "f8", {"units": "N", "note": "elastic shear force on the point's block, world"}),
    "bonded": ((), "i1", {"units": "1", "note": "1 bonded, 0 not, -1 no partner"}),
    "failed": ((), "i1", {"units": "1", "note": "0 intact, 1 failed in tension, 2 failed in shear"}),
}


class ContactSnapshots:
    """Collects per-point contact snapshots every ``interval`` seconds (no-op when ``interval`` is None).

    Args:
        model: the model being run.
        interval: time between snapshots [s], or None for none.
    """

    def __init__(self, model: Model, interval: float | None) -> None:
        if interval is not None and not (math.isfinite(interval) and interval > 0):
            raise ValueError(f"contact_interval must be a positive time [s] or None, got {interval!r}")
        self.model = model
        self.interval = interval
        self.count = 0  # snapshots taken; the next is due at count * interval
        self.rows: list[dict[str, np.ndarray | float]] = []

    def clip(self, stop: float) -> float:
        """Chunk stop time [s] cut so that it does not pass the next snapshot time."""
        if self.interval is None:
            return stop
        return min(stop, self.count * self.interval)

    def take(self, state: State) -> None:
        """Snapshot the points if the clock has reached the next snapshot time."""
        if self.interval is None:
            return
        t = float(state.time[0])
        due = self.count * self.interval
        if t < due - 1e-12 * max(1.0, due):
            return
        m = self.model.arrays
        rots = quats_to_matrices(state.quaternion)  # (nb, 3, 3)
        pos = np.einsum("pij,pj->pi", rots[m.point_block], m.point_local) + state.position[m.point_block]
        # A point may press on two partners (slots); report the slot carrying the larger force.
        slots = state.slot_partner
        k = np.argmax(np.where(slots >= 0, np.abs(state.slot_normal_force) + 1e-300, -1.0), axis=1)
        rows = np.arange(len(k))
        partner = slots[rows, k].astype(np.int32)
        has = partner >= 0
        normal = np.where(has, state.slot_normal_force.sum(axis=1), np.nan)
        ks = m.mat_ks[m.block_group[m.point_block][:, None], m.block_group[np.maximum(slots, 0)]]
        shear_force = ((ks * state.slot_area)[..., None] * state.slot_shear).sum(axis=1)  # (np, 3) [N]
        face = np.maximum(state.slot_face[rows, k], 0)
        n_world = np.einsum("pij,pj->pi", rots[m.face_block[face]], m.face_normal[face])
        self.rows.append({
            "time": t,
            "position": pos,
            "partner": partner,
            "normal_force": normal,
            "shear_force": np.where(has, np.linalg.norm(shear_force, axis=1), np.nan),
            "normal": np.where(has[:, None], n_world, np.nan),
            "shear_force_vector": np.where(has[:, None], shear_force, np.nan),
            "bonded": np.where(has, state.slot_bonded.any(axis=1).astype(np.int8), np.int8(-1)).astype(np.int8),
            "failed": state.point_failed.astype(np.int8),
        })
        # Skip snapshot times already passed (a chunk may overshoot by one step).
        self.count = int(math.floor(t / self.interval + 1e-9)) + 1

    def columns(self) -> dict[str, np.ndarray]:
        """The snapshots taken, stacked: ``time`` (S,) [s] and one (S, points, ...) array per variable."""
        n_pts = self.model.point_count
        out: dict[str, np.ndarray] = {"time": np.array([r["time"] for r in self.rows], dtype=float)}
        for name, (dims, dtype, _) in _VARIABLES.items():
            shape = (len(self.rows), n_pts) + (3,) * len(dims)
            out[name] = np.array([r[name] for r in self.rows], dtype=dtype).reshape(shape)
        return out

    def restore(self, columns: dict[str, np.ndarray], count: int) -> None:
        """Continue from snapshots saved by :meth:`columns` (a checkpoint) with ``count`` taken."""
        if not self.interval:
            return
        missing = {"time", *_VARIABLES} - set(columns)
        if missing and columns:
            raise ValueError(f"the checkpoint's contact snapshots lack {sorted(missing)}")
        n = len(columns.get("time", ()))
        self.rows = [{k: (float(v[i]) if k == "time" else v[i]) for k, v in columns.items()} for i in range(n)]
        self.count = int(count)

    def attach(self, ds: xr.Dataset) -> xr.Dataset:
        """Add the snapshots and ``point_block``, ``point_area`` to a result (unchanged if off)."""
        if self.interval is None:
            return ds
        m = self.model.arrays
        cols = self.columns()
        tp = ("contact_time", "point")
        ds = ds.assign_coords(contact_time=("contact_time", cols["time"], {"units": "s"}))
        for name, (dims, _, attrs) in _VARIABLES.items():
            ds[f"point_{name}"] = (tp + dims, cols[name], dict(attrs))
        ds["point_block"] = ("point", m.point_block.astype(np.int32))
        ds["point_local"] = (("point", "xyz"), m.point_local, {"units": "m", "note": "body frame of point_block"})
        ds["point_area"] = ("point", m.point_area, {"units": "m^2"})
        ds.attrs["contact_interval"] = float(self.interval)
        return ds
