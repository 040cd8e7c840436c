"""Results as an xarray Dataset: building, saving to NetCDF, CSV export, loading.

Variables (dims; units in each variable's ``units`` attribute):
  block_position (time, block, xyz) [m]        centroid
  block_quaternion (time, block, quat)         body principal frame -> world (w, x, y, z)
  block_velocity, block_angular_velocity (time, block, xyz) [m/s], [rad/s] (world)
  block_displacement (time, block, xyz) [m]    centroid displacement from t = 0, relative to the
                                               ground (attr ``reference``; see below)
  block_displacement_absolute (time, block, xyz) [m]  the same in the model's fixed frame
  block_rotation (time, block, xyz) [rad]      rotation vector of R(t) R_ref^T (world); R_ref is the
                                               orientation before any initial tilt
  rocking_angle (time, block) [rad]            block_rotation . rocking_axis
  monitor_displacement (time, monitor, xyz) [m] from the monitor's reference (untilted) position,
                                               relative to the ground (attr ``reference``)
  monitor_displacement_absolute (time, monitor, xyz) [m]  the same in the model's fixed frame
  ground_displacement (time, xyz) [m]          displacement of the ground: the blocks added with
                                               driven="ground" (zero without a ground motion)
  contacts_active / _bonded / _failed_tension / _failed_shear (time) [-]  sub-contact counts
  base_reaction (time, xyz) [N]                force of the driven blocks on the free blocks
  driven_reaction (time, driven_block, xyz) [N] the same, per driven block (foundation, rods, ...)
  energy_* and work_* (time) [J], energy_balance_error (time) [J], energy_balance_error_relative
  static: block_mass, block_free, block_group, block_name (block); the geometry for plots and
  VTK: vertex_local (vertex, xyz) [m] in the body frames, face_vertex (corner) global vertex ids,
  face_corner_start (face+1), block_face_start (block+1), point_count (block).
Attributes: dt, steps, runtime_s, rocking_axis, gravity, alpha, beta, displacement_reference, ...;
with ``damping.beta = "auto"`` or ``"critical"`` also how beta was chosen: beta_mode, beta_pairs,
beta_how, and for "auto" beta_target_restitution, beta_target_value, beta_achieved_e_a,
beta_iterations, beta_search_beta / beta_search_e_a (every probe run), beta_search_time_s
(:meth:`rockdem.beta_choice.BetaChoice.attrs`).

Response displacements are relative to the ground by default. Under an earthquake applied as
foundation motion (``mode="foundation"``) the ground-following blocks move with the record's
displacement, which can be far larger than the response (a two-block wall under Nahanni: 145 mm of
table motion); ``block_displacement`` and ``monitor_displacement`` subtract ``ground_displacement``
(attrs ``reference = "ground"``), and the ``*_absolute`` variables keep the motion in the model's
fixed frame. Without a moving ground (free rocking, pushover, inertial-mode earthquakes, whose
model frame moves with the ground) both are equal (``reference = "fixed frame"``). Rotations are
unaffected by a translating ground. A command-line summary of peak displacements should read
``monitor_displacement`` and print its ``reference`` attribute.
"""

from __future__ import annotations

import os
import uuid
from pathlib import Path
from typing import Mapping

import numpy as np
import xarray as xr

from .kernels.layout import COUNT_NAMES, E_POTENTIAL, ENERGY_NAMES, Records
from .kernels.rotation import quats_to_matrices, rotation_vector
from .model import Model

__all__ = ["build_dataset", "block_eta", "ground_blocks", "save", "load", "export_csv"]

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
    ground = ground_blocks(model)
    u_ground = np.zeros((len(t), 3))
    if ground.size:
        u_ground = rec.position[:, ground[0]] - model.position0[ground[0]]  # they translate together
    moving = bool(np.any(u_ground != 0.0))
    ref = "ground" if moving else "fixed frame"
    rel_note = ("relative to the ground (the blocks added with driven='ground'); absolute in the *_absolute "
                "variable" if moving else "no moving ground: equal to the *_absolute variable")
    abs_note = "in the model's fixed frame (inertial-mode earthquakes: a frame moving with the ground)"
    u_abs = rec.position - model.position0[None]
    ds["ground_displacement"] = (("time", "xyz"), u_ground, {"units": "m", "note": "driven='ground' blocks"})
    ds["block_displacement"] = (xyz, u_abs - u_ground[:, None], {"units": "m", "reference": ref, "note": rel_note})
    ds["block_displacement_absolute"] = (xyz, u_abs, {"units": "m", "reference": "fixed frame", "note": abs_note})
    ds["block_rotation"] = (xyz, rotvec, {"units": "rad"})
    ds["rocking_angle"] = (("time", "block"), rotvec @ axis, {"units": "rad", "axis": axis.tolist()})
    names = list(monitors)
    mdisp = np.zeros((len(t), len(names), 3))
    for k, name in enumerate(names):
        b, p_ref = monitors[name]  # point given in the reference (untilted) configuration
        arm = p_ref - model.position_ref[b]
        mdisp[:, k] = np.einsum("tij,j->ti", rel_ref[:, b], arm) + rec.position[:, b] - p_ref
    ds = ds.assign_coords(monitor=np.array(names, dtype=object) if names else np.zeros(0, dtype=object))
    mon = ("time", "monitor", "xyz")
    ds["monitor_displacement"] = (mon, mdisp - u_ground[:, None], {"units": "m", "reference": ref, "note": rel_note})
    ds["monitor_displacement_absolute"] = (mon, mdisp, {"units": "m", "reference": "fixed frame", "note": abs_note})
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
            "displacement_reference": ref,
        }
    )
    if model.beta_choice is not None:
        ds.attrs.update(model.beta_choice.attrs())
    return ds


def ground_blocks(model: Model) -> np.ndarray:
    """Ids of the driven blocks that follow the model's ground motion (``driven="ground"``)."""
    m = model.arrays
    if m.ground_motion < 0:
        return np.zeros(0, dtype=np.int64)
    return np.flatnonzero((m.block_motion == m.ground_motion) & ~m.block_free.astype(bool))


def block_eta(model: Model) -> np.ndarray:
    """Instability (slenderness) angle of each free block about its base edges [rad], NaN for
    driven blocks, at the reference (untilted) pose: atan(horizontal distance from the centroid to
    the nearer edge of the base contact face along the rocking direction / height of the centroid
    above the base). The base face is the block's lowest vertices, so a reduced (chamfered) base
    gives the angle about the pivot the block actually rocks on, as :meth:`ModelBuilder.tilt` uses.
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
        z = v @ up
        size = float(np.ptp(v, axis=0).max())
        base = v[z <= z.min() + 1e-9 * size]  # the base contact face (vertices relative to the centroid)
        height = -float(z.min())
        half = min(float(np.max(base @ d)), -float(np.min(base @ d)))
        if height > 0 and half > 0:
            out[b] = float(np.arctan2(half, height))
    return out


def _version() -> str:
    from . import __version__

    return __version__


def save(ds: xr.Dataset, path: str | Path) -> Path:
    """Write a result to NetCDF (compressed); returns the path.

    The file is written under a temporary name in the same folder, then renamed over ``path``: an
    interrupted save (a second Ctrl-C, a full disk) leaves the previous file, or none, never a
    truncated one. An existing symbolic link at ``path`` is replaced by the file, not written
    through.

    Raises:
        ValueError: ``path`` is a folder.
    """
    p = Path(path)
    if p.is_dir() and not p.is_symlink():
        raise ValueError(f"cannot save the result to {p}: it is a folder; give a file name such as {p / 'result.nc'}")
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
    tmp = p.with_name(f".{p.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.part")
    try:
        out.to_netcdf(tmp, encoding=enc)
        os.replace(tmp, p)  # atomic on one file system; replaces a link at p, not its target
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
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
    contact counts, base reaction and energies (one column each, units in the header).

    With a moving ground the displacement columns are relative to it (``top.ux rel. ground [m]``)
    and the ground's own displacement follows (``ground.ux [m]``)."""
    cols: dict[str, np.ndarray] = {"time [s]": ds.time.values}
    moving = ds.monitor_displacement.attrs.get("reference") == "ground"
    rel = " rel. ground" if moving else ""
    for b in range(ds.sizes["block"]):
        if not bool(ds.block_free[b]):
            continue
        name = str(ds.block_name.values[b])
        cols[f"{name}.rocking_angle [rad]"] = ds.rocking_angle.values[:, b]
        for i, ax in enumerate("xyz"):
            cols[f"{name}.u{ax}{rel} [m]"] = ds.block_displacement.values[:, b, i]
    for k, mname in enumerate(ds.monitor.values):
        for i, ax in enumerate("xyz"):
            cols[f"{mname}.u{ax}{rel} [m]"] = ds.monitor_displacement.values[:, k, i]
    if moving:
        for i, ax in enumerate("xyz"):
            cols[f"ground.u{ax} [m]"] = ds.ground_displacement.values[:, i]
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
