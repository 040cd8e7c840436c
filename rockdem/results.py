"""Results as an xarray Dataset: building, saving to NetCDF, CSV export, loading.

Variables (dims; units in each variable's ``units`` attribute):
  block_position (time, block, xyz) [m]        centroid
  block_quaternion (time, block, quat)         body principal frame -> world (w, x, y, z)
  block_velocity, block_angular_velocity (time, block, xyz) [m/s], [rad/s] (world)
  block_displacement (time, block, xyz) [m]    centroid displacement from t = 0
  block_rotation (time, block, xyz) [rad]      rotation vector of R(t) R_ref^T (world); R_ref is the
                                               orientation before any initial tilt
  rocking_angle (time, block) [rad]            block_rotation . rocking_axis
  monitor_displacement (time, monitor, xyz) [m] from the monitor's reference (untilted) position
  contacts_active / _bonded / _failed_tension / _failed_shear (time) [-]  sub-contact counts
  base_reaction (time, xyz) [N]                force of the driven blocks on the free blocks
  driven_reaction (time, driven_block, xyz) [N] the same, per driven block (foundation, rods, ...)
  energy_* and work_* (time) [J], energy_balance_error (time) [J], energy_balance_error_relative
  static: block_mass, block_free, block_group, block_name (block); the geometry for plots and
  VTK: vertex_local (vertex, xyz) [m] in the body frames, face_vertex (corner) global vertex ids,
  face_corner_start (face+1), block_face_start (block+1), point_count (block).
Attributes: dt, steps, runtime_s, rocking_axis, gravity, alpha, beta, ...
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np
import xarray as xr

from .kernels.layout import COUNT_NAMES, E_POTENTIAL, ENERGY_NAMES, Records
from .kernels.rotation import quats_to_matrices, rotation_vector
from .model import Model

__all__ = ["build_dataset", "block_eta", "save", "load", "export_csv"]

_DISSIPATED = (
    "energy_damping_mass",
    "energy_damping_stiffness",
    "energy_friction",
    "energy_bond",
    "energy_local_damping",
)


def build_dataset(
    model: Model,
    rec: Records,
    *,
    monitors: Mapping[str, tuple[int, np.ndarray]],
    attrs: Mapping[str, object],
) -> xr.Dataset:
    """Assemble the recorded frames and the model's static data into a Dataset."""
    t = rec.time
    r = quats_to_matrices(rec.quaternion)  # (T, nb, 3, 3)
    rref = quats_to_matrices(model.quaternion_ref)
    rel_ref = np.einsum("tbij,bkj->tbik", r, rref)  # rotation since the untilted reference
    rotvec = rotation_vector(rel_ref)
    axis = model.rocking_axis
    ds = xr.Dataset(coords={"time": ("time", t, {"units": "s"}), "block": np.arange(model.block_count)})
    xyz = ("time", "block", "xyz")
    ds["block_position"] = (xyz, rec.position, {"units": "m"})
    ds["block_quaternion"] = (("time", "block", "quat"), rec.quaternion, {"units": "1"})
    ds["block_velocity"] = (xyz, rec.velocity, {"units": "m/s"})
    ds["block_angular_velocity"] = (xyz, rec.omega, {"units": "rad/s"})
    ds["block_displacement"] = (xyz, rec.position - model.position0[None], {"units": "m"})
    ds["block_rotation"] = (xyz, rotvec, {"units": "rad"})
    ds["rocking_angle"] = (("time", "block"), rotvec @ axis, {"units": "rad", "axis": axis.tolist()})
    names = list(monitors)
    mdisp = np.zeros((len(t), len(names), 3))
    for k, name in enumerate(names):
        b, p_ref = monitors[name]  # point given in the reference (untilted) configuration
        arm = p_ref - model.position_ref[b]
        mdisp[:, k] = np.einsum("tij,j->ti", rel_ref[:, b], arm) + rec.position[:, b] - p_ref
    ds = ds.assign_coords(monitor=np.array(names, dtype=object) if names else np.zeros(0, dtype=object))
    ds["monitor_displacement"] = (("time", "monitor", "xyz"), mdisp, {"units": "m"})
    for k, name in enumerate(COUNT_NAMES):
        ds[name] = ("time", rec.counts[:, k], {"units": "1"})
    ds["base_reaction"] = (("time", "xyz"), rec.reaction, {"units": "N"})
    driven = np.flatnonzero(~model.arrays.block_free.astype(bool))
    ds = ds.assign_coords(driven_block=("driven_block", np.array([model.block_names[b] for b in driven], dtype=object)))
    ds["driven_reaction"] = (
        ("time", "driven_block", "xyz"),
        rec.driven_reaction,
        {"units": "N", "note": "contact force of each driven block on the free blocks"},
    )
    energy = rec.energy.copy()
    if len(t):
        energy[:, E_POTENTIAL] -= energy[0, E_POTENTIAL]
    for k, name in enumerate(ENERGY_NAMES):
        ds[name] = ("time", energy[:, k], {"units": "J"})
    total = ds.energy_kinetic + ds.energy_potential + ds.energy_elastic + sum(ds[n] for n in _DISSIPATED)
    work = ds.work_driven + ds.work_body
    err = total - work - (total[0] - work[0] if len(t) else 0.0)
    scale = (
        ds.energy_kinetic + ds.energy_elastic + abs(ds.energy_potential) + sum(ds[n] for n in _DISSIPATED)
        + abs(work)
    ).max() if len(t) else 1.0
    ds["energy_balance_error"] = ("time", err.values, {"units": "J"})
    ds["energy_balance_error_relative"] = (
        "time",
        err.values / max(float(scale), 1e-300),
        {"units": "1", "note": "error / max over time of (kinetic + elastic + |potential| + dissipated + |work|)"},
    )
    m = model.arrays
    ds["block_eta"] = ("block", block_eta(model), {"units": "rad", "note": "instability angle about the base edge"})
    ds["block_mass"] = ("block", m.block_mass, {"units": "kg"})
    ds["block_free"] = ("block", m.block_free)
    ds["block_group"] = ("block", np.array([model.group_names[g] for g in m.block_group], dtype=object))
    ds["block_name"] = ("block", np.array(model.block_names, dtype=object))
    ds["position0"] = (("block", "xyz"), model.position0, {"units": "m"})
    ds["quaternion0"] = (("block", "quat"), model.quaternion0)
    ds["vertex_local"] = (("vertex", "xyz"), m.vertex_local, {"units": "m"})
    ds["block_vertex_start"] = ("block_p1", m.block_vertex_start)
    corners = [f for faces in model.faces for f in faces]
    ds["face_vertex"] = ("corner", np.concatenate(corners).astype(np.int64))
    ds["face_corner_start"] = ("face_p1", np.cumsum([0] + [len(f) for f in corners]).astype(np.int64))
    ds["block_face_start"] = ("block_p1", m.block_face_start)
    ds.attrs.update({k: v for k, v in attrs.items()})
    ds.attrs.update(
        {
            "rocking_axis": axis.tolist(),
            "gravity": m.gravity.tolist(),
            "alpha": model.damping.alpha,
            "beta": model.damping.beta,
            "alpha_relative": int(model.damping.alpha_relative),
            "local_damping": model.damping.local,
            "point_count": model.point_count,
            "contact_tolerance": m.contact_tol,
            "rockdem_version": _version(),
        }
    )
    return ds


def block_eta(model: Model) -> np.ndarray:
    """Instability (slenderness) angle of each free block about its base edges [rad], NaN for
    driven blocks: atan(horizontal distance from the centroid to the nearer base edge along the
    rocking direction / height of the centroid above the base), at the reference pose.
    The rocking direction is rocking_axis x up (up opposes gravity)."""
    m = model.arrays
    g = m.gravity
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    d = np.cross(model.rocking_axis, up)
    out = np.full(model.block_count, np.nan)
    if np.linalg.norm(d) == 0:
        return out
    d /= np.linalg.norm(d)
    rref = quats_to_matrices(model.quaternion_ref)
    for b in np.flatnonzero(m.block_free):
        v = m.vertex_local[m.block_vertex_start[b] : m.block_vertex_start[b + 1]] @ rref[b].T
        height = -float(np.min(v @ up))
        half = min(float(np.max(v @ d)), -float(np.min(v @ d)))
        if height > 0 and half > 0:
            out[b] = float(np.arctan2(half, height))
    return out


def _version() -> str:
    from . import __version__

    return __version__


def save(ds: xr.Dataset, path: str | Path) -> Path:
    """Write a result to NetCDF (compressed); returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    enc = {
        name: {"zlib": True, "complevel": 4}
        for name, var in ds.data_vars.items()
        if var.dtype.kind in "fiu" and var.ndim > 0
    }
    out = ds.copy()
    for name in ("block_group", "block_name"):
        out[name] = out[name].astype(str)
    for coord in ("monitor", "driven_block"):
        if coord in out.coords:
            out = out.assign_coords({coord: out[coord].astype(str)})
    out["block_free"] = out["block_free"].astype(np.int8)
    out.to_netcdf(p, encoding=enc)
    return p


def load(path: str | Path) -> xr.Dataset:
    """Read a result written by :func:`save`."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"no result file at {p}")
    ds = xr.load_dataset(p)
    ds["block_free"] = ds["block_free"].astype(bool)
    return ds


def export_csv(ds: xr.Dataset, path: str | Path) -> Path:
    """Histories as one CSV table: time, per-block rocking angle and displacement, monitors,
    contact counts, base reaction and energies (one column each, units in the header)."""
    cols: dict[str, np.ndarray] = {"time [s]": ds.time.values}
    for b in range(ds.sizes["block"]):
        if not bool(ds.block_free[b]):
            continue
        name = str(ds.block_name.values[b])
        cols[f"{name}.rocking_angle [rad]"] = ds.rocking_angle.values[:, b]
        for i, ax in enumerate("xyz"):
            cols[f"{name}.u{ax} [m]"] = ds.block_displacement.values[:, b, i]
    for k, mname in enumerate(ds.monitor.values):
        for i, ax in enumerate("xyz"):
            cols[f"{mname}.u{ax} [m]"] = ds.monitor_displacement.values[:, k, i]
    for name in COUNT_NAMES:
        cols[f"{name} [-]"] = ds[name].values
    for i, ax in enumerate("xyz"):
        cols[f"base_reaction_{ax} [N]"] = ds.base_reaction.values[:, i]
    for name in ENERGY_NAMES + ("energy_balance_error",):
        cols[f"{name} [J]"] = ds[name].values
    import pandas as pd

    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(cols).to_csv(p, index=False)
    return p
