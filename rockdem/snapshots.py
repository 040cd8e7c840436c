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
  point_bonded (contact_time, point) int8       1 bonded, 0 not, -1 where no partner
  point_failed (contact_time, point) int8       0 intact, 1 failed in tension, 2 failed in shear
                                                (persistent: kept after the point loses its partner)
  static: point_block (point), point_area (point) [m^2], point_local (point, xyz) [m] (body frame)

Size: 24 + 4 + 8 + 8 + 1 + 1 = 46 bytes per point per snapshot (before NetCDF compression).
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .kernels.layout import State
from .kernels.rotation import quats_to_matrices
from .model import Model

__all__ = ["ContactSnapshots", "BYTES_PER_POINT"]

BYTES_PER_POINT = 46
"""Bytes stored per interface point per contact snapshot (uncompressed)."""


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
        self.rows: list[tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []

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
        rot = quats_to_matrices(state.quaternion)[m.point_block]  # (np, 3, 3)
        pos = np.einsum("pij,pj->pi", rot, m.point_local) + state.position[m.point_block]
        # A point may press on two partners (slots); report the slot carrying the larger force.
        slots = state.slot_partner
        k = np.argmax(np.where(slots >= 0, np.abs(state.slot_normal_force) + 1e-300, -1.0), axis=1)
        rows = np.arange(len(k))
        partner = slots[rows, k].astype(np.int32)
        has = partner >= 0
        normal = np.where(has, state.slot_normal_force.sum(axis=1), np.nan)
        ks = m.mat_ks[m.block_group[m.point_block][:, None], m.block_group[np.maximum(slots, 0)]]
        shear_force = (ks * state.slot_area)[..., None] * state.slot_shear  # (np, slots, 3) [N]
        shear = np.where(has, np.linalg.norm(shear_force.sum(axis=1), axis=1), np.nan)
        bonded = np.where(has, state.slot_bonded.any(axis=1).astype(np.int8), np.int8(-1)).astype(np.int8)
        failed = state.point_failed.astype(np.int8)
        self.rows.append((t, pos, partner, normal, shear, bonded, failed))
        # Skip snapshot times already passed (a chunk may overshoot by one step).
        self.count = int(math.floor(t / self.interval + 1e-9)) + 1

    def attach(self, ds: xr.Dataset) -> xr.Dataset:
        """Add the snapshots and ``point_block``, ``point_area`` to a result (unchanged if off)."""
        if self.interval is None:
            return ds
        m = self.model.arrays
        n = len(self.rows)
        cols = list(zip(*self.rows)) if n else [np.zeros(0)] + [np.zeros((0, m.point_area.shape[0]))] * 6
        t, pos, partner, normal, shear, bonded, failed = (np.asarray(c) for c in cols)
        if not n:
            pos = np.zeros((0, m.point_area.shape[0], 3))
        tp = ("contact_time", "point")
        ds = ds.assign_coords(contact_time=("contact_time", t.astype(float), {"units": "s"}))
        ds["point_position"] = (tp + ("xyz",), pos, {"units": "m"})
        ds["point_partner"] = (tp, partner.astype(np.int32), {"units": "1", "note": "-1: no partner"})
        ds["point_normal_force"] = (tp, normal.astype(float), {"units": "N", "note": "compression > 0"})
        ds["point_shear_force"] = (tp, shear.astype(float), {"units": "N"})
        ds["point_bonded"] = (tp, bonded.astype(np.int8), {"units": "1", "note": "1 bonded, 0 not, -1 no partner"})
        ds["point_failed"] = (
            tp, failed.astype(np.int8), {"units": "1", "note": "0 intact, 1 failed in tension, 2 failed in shear"}
        )
        ds["point_block"] = ("point", m.point_block.astype(np.int32))
        ds["point_local"] = (("point", "xyz"), m.point_local, {"units": "m", "note": "body frame of point_block"})
        ds["point_area"] = ("point", m.point_area, {"units": "m^2"})
        ds.attrs["contact_interval"] = float(self.interval)
        return ds
