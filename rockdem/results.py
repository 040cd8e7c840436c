"""Results as an xarray Dataset: building, saving to NetCDF, CSV export, loading.

Coordinates: ``time`` [s]; ``block``: the block names, so that ``ds.sel(block="wall")`` selects a
block by name; ``block_id`` (block): the integer ids, indexed too: ``ds.sel(block_id=1)`` or
``ds.isel(block=1)`` (the id is the position); ``monitor`` and ``driven_block`` names. Results
written before the names became the coordinate hold the ids in ``block`` (positional access with
``.values[:, b]`` and ``isel`` works for both).

Variables (dims; units in each variable's ``units`` attribute):
  block_position (time, block, xyz) [m]        centroid
  block_quaternion (time, block, quat)         body principal frame -> world (w, x, y, z)
  block_velocity, block_angular_velocity (time, block, xyz) [m/s], [rad/s] (world)
  block_displacement (time, block, xyz) [m]    centroid displacement from t = 0, relative to the
                                               ground (attr ``reference``; see below)
  block_displacement_absolute (time, block, xyz) [m]  the same in the model's fixed frame
  block_position_reference (block, xyz) [m]    centroid in the reference pose (before any initial tilt)
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

import csv
import os
import sys
import uuid
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, NamedTuple

import numpy as np
import xarray as xr

if TYPE_CHECKING:
    import pandas as pd

from .kernels.layout import (
    COUNT_NAMES,
    E_DAMPING_MASS,
    E_DAMPING_STIFFNESS,
    E_BOND,
    E_ELASTIC,
    E_FRICTION,
    E_KINETIC,
    E_LOCAL_DAMPING,
    E_POTENTIAL,
    ENERGY_NAMES,
    W_BODY,
    W_DRIVEN,
    Records,
)

from .kernels.rotation import quats_to_matrices, rotation_vector
from .model import Model


class _DaskWhenImported:
    """xarray's record of dask as a duck-array library (``xarray.namedarray.pycompat``), resolved
    lazily: its array type is ``dask.array.Array`` once something has imported ``dask.array``, and
    none before (no dask array can exist then). xarray itself imports ``dask.array`` to build its
    first Variable wherever dask is installed, to test each new array against that type: 0.2 to
    0.7 s of a warm ``rockdem run`` of 2 s, in runs that never see a dask array. The module, its
    version and availability are xarray's own record, made at their first use."""

    def __init__(self, record: Any) -> None:
        self._record = record
        self._resolved: Any = None

    @property
    def type(self) -> tuple[type, ...]:
        array = getattr(sys.modules.get("dask.array"), "Array", None)
        return (array,) if isinstance(array, type) else ()

    def _real(self) -> Any:
        if self._resolved is None:
            self._resolved = self._record("dask")
        return self._resolved

    @property
    def module(self) -> Any:
        return self._real().module

    @property
    def version(self) -> Any:
        return self._real().version

    @property
    def available(self) -> bool:
        return bool(self._real().available)


def _defer_dask_type() -> None:
    """Install :class:`_DaskWhenImported` in xarray's cache of duck-array libraries, unless xarray
    has made its own record already or keeps it elsewhere (another xarray version: nothing done)."""
    try:
        from xarray.namedarray import pycompat
        cache = pycompat._cached_duck_array_modules
        record = pycompat.DuckArrayModule
    except (ImportError, AttributeError):
        return
    if isinstance(cache, dict) and "dask" not in cache:
        cache["dask"] = _DaskWhenImported(record)


def _lazy_dask_collection_test() -> None:
    """Let xarray's test "is this a dask collection?" (``xarray.namedarray.utils``, behind
    ``is_duck_dask_array``) answer no without importing dask (0.07 s of a warm ``rockdem run``)
    for an object without ``__dask_graph__``, which dask's own test answers no first; other objects
    go to xarray's test. Nothing done where xarray keeps the test elsewhere."""
    try:
        from xarray.namedarray import utils
        xarray_test = utils.is_dask_collection
    except (ImportError, AttributeError):
        return
    if getattr(xarray_test, "_rockdem_lazy", False):
        return

    def is_dask_collection(x: object) -> bool:
        return hasattr(x, "__dask_graph__") and bool(xarray_test(x))

    is_dask_collection._rockdem_lazy = True  # type: ignore[attr-defined]
    utils.is_dask_collection = is_dask_collection


_defer_dask_type()
_lazy_dask_collection_test()

__all__ = [
    "EnergyCheck",
    "energy_check",
    "build_dataset",
    "damping_attrs",
    "block_eta",
    "block_thickness",
    "Pivot",
    "rocking_pivots",
    "ground_blocks",
    "reference_rotations",
    "rocking_angles",
    "ground_displacement",
    "monitor_displacements",
    "save",
    "load",
    "export_csv",
    "contact_table",
    "write_contact_table",
    "with_block_index",
]

class EnergyCheck(NamedTuple):
    """Energy checks of a run [J].

    Attributes:
        created: the largest rise of the mechanical energy (kinetic + potential + elastic) beyond the
            work done on the model since any earlier frame: energy the engine created (0 for a sound run:
            dissipation only ever lowers it).
        balance_error: mechanical + dissipated energy - work at the last frame, less its initial value:
            positive when energy was created or a dissipation term was booked in excess.
        scale: the run's energy scale, the largest kinetic + elastic + |potential| + dissipated +
            |work| reached (as ``energy_balance_error_relative`` divides by).
    """

    created: float
    balance_error: float
    scale: float


def energy_balance(energy: np.ndarray) -> tuple[np.ndarray, float]:
    """The energy balance error (T,) [J] of recorded energies ``energy`` (T >= 1, len(ENERGY_NAMES))
    [J] (columns in the order of :data:`ENERGY_NAMES`, ``Records.energy``): kinetic + potential +
    elastic + dissipated - work, less its initial value; and the run's energy scale [J], the
    largest kinetic + elastic + |potential change| + dissipated + |work| (as the result's
    ``energy_balance_error_relative`` divides by)."""
    e = np.asarray(energy, dtype=float)
    work = e[:, W_DRIVEN] + e[:, W_BODY]
    lost = sum(e[:, k] for k in (E_DAMPING_MASS, E_DAMPING_STIFFNESS, E_FRICTION, E_BOND, E_LOCAL_DAMPING))
    total = e[:, E_KINETIC] + e[:, E_POTENTIAL] + e[:, E_ELASTIC] - work + lost
    scale = e[:, E_KINETIC] + e[:, E_ELASTIC] + np.abs(e[:, E_POTENTIAL] - e[0, E_POTENTIAL]) + lost + np.abs(work)
    return total - total[0], float(np.max(scale))


def energy_check(energy: np.ndarray) -> EnergyCheck:
    """:class:`EnergyCheck` of recorded energies ``energy`` (T, len(ENERGY_NAMES)) [J], columns in the
    order of :data:`ENERGY_NAMES` (``Records.energy``)."""
    e = np.asarray(energy, dtype=float)
    if len(e) == 0:
        return EnergyCheck(0.0, 0.0, 0.0)
    net = e[:, E_KINETIC] + e[:, E_POTENTIAL] + e[:, E_ELASTIC] - e[:, W_DRIVEN] - e[:, W_BODY]
    created = float(np.max(net - np.minimum.accumulate(net)))
    err, scale = energy_balance(e)
    return EnergyCheck(created, float(err[-1]), scale)


def build_dataset(
    model: Model,
    rec: Records,
    *,
    monitors: Mapping[str, tuple[int, np.ndarray]],
    attrs: Mapping[str, object],
) -> xr.Dataset:
    """Assemble the recorded frames and the model's static data into a Dataset."""
    t = rec.time
    rel_ref, rotvec = reference_rotations(model, rec.quaternion)
    axis = model.rocking_axis
    names = np.array(model.block_names, dtype=object)
    ds = xr.Dataset(coords={"time": ("time", t, {"units": "s"}), "block": ("block", names, {"note": "block name"})})
    ds = with_block_index(ds.assign_coords(block_id=("block", np.arange(model.block_count), {"note": "block id"})))
    xyz = ("time", "block", "xyz")
    ds["block_position"] = (xyz, rec.position, {"units": "m"})
    ds["block_quaternion"] = (("time", "block", "quat"), rec.quaternion, {"units": "1"})
    ds["block_velocity"] = (xyz, rec.velocity, {"units": "m/s"})
    ds["block_angular_velocity"] = (xyz, rec.omega, {"units": "rad/s"})
    u_ground = ground_displacement(model, rec.position)
    moving = bool(np.any(u_ground != 0.0))
    ref = "ground" if moving else "fixed frame"
    rel_note = ("relative to the ground (the blocks added with driven='ground'); absolute in the *_absolute "
                "variable" if moving else "no moving ground: equal to the *_absolute variable")
    abs_note = "in the model's fixed frame (inertial-mode earthquakes: a frame moving with the ground)"
    u_abs = rec.position - model.position0[None]
    ds["ground_displacement"] = (("time", "xyz"), u_ground, {"units": "m", "note": "driven='ground' blocks"})
    ds["block_displacement"] = (xyz, u_abs - u_ground[:, None], {"units": "m", "reference": ref, "note": rel_note})
    ds["block_displacement_absolute"] = (xyz, u_abs, {"units": "m", "reference": "fixed frame", "note": abs_note})
    ds["block_position_reference"] = (("block", "xyz"), model.position_ref,
                                      {"units": "m", "note": "centroid in the reference pose, before any initial tilt"})
    ds["block_rotation"] = (xyz, rotvec, {"units": "rad"})
    ds["rocking_angle"] = (("time", "block"), rocking_angles(model, rotvec), {"units": "rad", "axis": axis.tolist()})
    names = list(monitors)
    mdisp = monitor_displacements(model, rel_ref, rec.position, monitors)
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
    err, scale = energy_balance(energy) if len(t) else (np.zeros(0), 1.0)
    ds["energy_balance_error"] = ("time", err, {"units": "J"})
    ds["energy_balance_error_relative"] = (
        "time",
        err / max(scale, 1e-300),
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
            **damping_attrs(model),
            "point_count": model.point_count,
            "contact_tolerance": m.contact_tol,
            "rockdem_version": _version(),
            "displacement_reference": ref,
        }
    )
    return ds


def damping_attrs(model: Model) -> dict[str, Any]:
    """A result's damping attributes: alpha [1/s], beta [s] (the chosen one for an automatic beta),
    alpha_relative, local_damping, and how an automatic beta was chosen
    (:meth:`rockdem.beta_choice.BetaChoice.attrs`). ``build_dataset`` and the batch path's
    summary rows (:func:`rockdem.batch.frames_from_run`) both use it."""
    d = model.damping
    out: dict[str, Any] = {"alpha": d.alpha, "beta": d.beta, "alpha_relative": int(d.alpha_relative), "local_damping": d.local}
    if model.beta_choice is not None:
        out.update(model.beta_choice.attrs())
    return out


def reference_rotations(model: Model, quaternion: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations since the untilted reference pose: matrices R(t) R_ref^T (T, nb, 3, 3) and their
    rotation vectors (T, nb, 3) [rad], from recorded quaternions (T, nb, 4). :func:`build_dataset`
    and the summary rows of studies both call this, so their values are bit-identical."""
    r = quats_to_matrices(quaternion)  # (T, nb, 3, 3)
    rref = quats_to_matrices(model.quaternion_ref)
    rel_ref = r @ np.swapaxes(rref, -1, -2)
    return rel_ref, rotation_vector(rel_ref)


def rocking_angles(model: Model, rotvec: np.ndarray) -> np.ndarray:
    """(T, nb) rotation about the model's rocking axis [rad] from rotation vectors (T, nb, 3)."""
    return rotvec @ model.rocking_axis


def ground_displacement(model: Model, position: np.ndarray) -> np.ndarray:
    """(T, 3) displacement of the ground-following driven blocks [m] (zeros without any), from
    recorded centroids (T, nb, 3): they translate together."""
    ground = ground_blocks(model)
    if not ground.size:
        return np.zeros((position.shape[0], 3))
    return position[:, ground[0]] - model.position0[ground[0]]


def monitor_displacements(
    model: Model, rel_ref: np.ndarray, position: np.ndarray, monitors: Mapping[str, tuple[int, np.ndarray]]
) -> np.ndarray:
    """(T, nm, 3) displacement of each monitor point from its reference (untilted) position, in the
    model's fixed frame [m], from the rotations of :func:`reference_rotations` and centroids (T, nb, 3)."""
    names = list(monitors)
    mdisp = np.zeros((position.shape[0], len(names), 3))
    for k, name in enumerate(names):
        b, p_ref = monitors[name]  # point given in the reference (untilted) configuration
        arm = p_ref - model.position_ref[b]
        mdisp[:, k] = np.einsum("tij,j->ti", rel_ref[:, b], arm) + position[:, b] - p_ref
    return mdisp


def ground_blocks(model: Model) -> np.ndarray:
    """Ids of the driven blocks that follow the model's ground motion (``driven="ground"``)."""
    m = model.arrays
    if m.ground_motion < 0:
        return np.zeros(0, dtype=np.int64)
    return np.flatnonzero((m.block_motion == m.ground_motion) & ~m.block_free.astype(bool))


class Pivot(NamedTuple):
    """Rigid rocking of a free block about one edge of its base (reference, untilted pose).

    Attributes:
        eta: instability angle atan(half / height) [rad].
        radius: distance R from the centroid to the pivot edge in the rocking plane [m].
        inertia: moment of inertia I_O about the pivot edge (the rocking axis through it) [kg m^2].
        mass: block mass [kg].
    """

    eta: float
    radius: float
    inertia: float
    mass: float

    @property
    def p(self) -> float:
        """Housner's frequency parameter sqrt(m g R / I_O) [rad/s] at g = 9.81 m/s^2 (sqrt(3 g / 4 R)
        for a rectangular block)."""
        return float(np.sqrt(self.mass * 9.81 * self.radius / self.inertia))


def _base(model: Model, b: int) -> tuple[float, float, float] | None:
    """(height of the centroid above the base, half base toward +d, half base toward -d) [m] of
    free block b about the rocking direction d = rocking_axis x up; None without a rocking direction."""
    m = model.arrays
    g = m.gravity
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    d = np.cross(model.rocking_axis, up)
    if np.linalg.norm(d) == 0:
        return None
    d /= np.linalg.norm(d)
    rref = quats_to_matrices(model.quaternion_ref[b])
    v = m.vertex_local[m.block_vertex_start[b] : m.block_vertex_start[b + 1]] @ rref.T
    z = v @ up
    size = float(np.ptp(v, axis=0).max())
    base = v[z <= z.min() + 1e-9 * size]  # the base contact face (vertices relative to the centroid)
    return -float(z.min()), float(np.max(base @ d)), -float(np.min(base @ d))


def block_thickness(model: Model) -> np.ndarray:
    """(nb,) smallest extent of each block along its principal axes [m]."""
    from .analysis import block_thickness_of

    return block_thickness_of(model.arrays.vertex_local, model.arrays.block_vertex_start, np.arange(model.block_count))


def block_eta(model: Model) -> np.ndarray:
    """Instability (slenderness) angle of each free block about its base edges [rad], NaN for
    driven blocks, at the reference (untilted) pose: atan(horizontal distance from the centroid to
    the nearer edge of the base contact face along the rocking direction / height of the centroid
    above the base). The base face is the block's lowest vertices, so a reduced (chamfered) base
    gives the angle about the pivot the block actually rocks on, as :meth:`ModelBuilder.tilt` uses.
    The rocking direction is rocking_axis x up (up opposes gravity)."""
    out = np.full(model.block_count, np.nan)
    for b in np.flatnonzero(model.arrays.block_free):
        base = _base(model, int(b))
        if base is None:
            return out
        height, plus, minus = base
        half = min(plus, minus)
        if height > 0 and half > 0:
            out[b] = float(np.arctan2(half, height))
    return out


def rocking_pivots(model: Model, block: int) -> tuple[Pivot, Pivot] | None:
    """The two base edges of free block ``block``: toward +d (a positive ``rocking_angle`` tips the
    block over it) and toward -d, d = rocking_axis x up; None when the block has no base to rock on."""
    base = _base(model, block)
    if base is None:
        return None
    height, plus, minus = base
    if not (height > 0 and plus > 0 and minus > 0):
        return None
    m = model.arrays
    rref = quats_to_matrices(model.quaternion_ref[block])
    i_axis = float(np.sum(m.block_inertia[block] * (rref.T @ model.rocking_axis) ** 2))
    mass = float(m.block_mass[block])
    out = []
    for half in (plus, minus):
        r = float(np.hypot(half, height))
        out.append(Pivot(float(np.arctan2(half, height)), r, i_axis + mass * r * r, mass))
    return out[0], out[1]


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
    for coord in ("block", "monitor", "driven_block"):
        if coord in out.coords and out[coord].dtype == object:
            out = out.assign_coords({coord: out[coord].astype(str)})
    out["block_free"] = out["block_free"].astype(np.int8)
    tmp = p.with_name(f".{p.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.part")
    try:
        _write_netcdf(out, tmp, enc)
        os.replace(tmp, p)  # atomic on one file system; replaces a link at p, not its target
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return p


def _write_netcdf(ds: xr.Dataset, path: Path, encoding: Mapping[str, Mapping[str, Any]]) -> None:
    """``ds.to_netcdf(path, encoding=encoding)``: the same NetCDF4 file, byte for byte, written
    through xarray's store with the lock that serialises netCDF-C and HDF5 calls across threads,
    without to_netcdf's query of the dask scheduler for a per-file lock, which imports
    ``distributed`` wherever dask is installed (0.2 s, a tenth of a warm ``rockdem run``). A
    dataset holding dask arrays (or an xarray without that lock) goes through to_netcdf."""
    from xarray.backends import NetCDF4DataStore

    try:
        from xarray.backends.netCDF4_ import NETCDF4_PYTHON_LOCK as lock
    except ImportError:
        lock = None
    if lock is None or any(v.chunks is not None for v in ds.variables.values()):
        ds.to_netcdf(path, encoding=encoding)
        return
    store = NetCDF4DataStore.open(path, mode="w", lock=lock)
    try:
        ds.dump_to_store(store, encoding=encoding, unlimited_dims=ds.encoding.get("unlimited_dims"))
    finally:
        store.close()


def load(path: str | Path) -> xr.Dataset:
    """Read a result written by :func:`save`."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"no result file at {p}")
    ds = xr.load_dataset(p)
    ds["block_free"] = ds["block_free"].astype(bool)
    return with_block_index(ds)


def with_block_index(ds: xr.Dataset) -> xr.Dataset:
    """Index the ``block_id`` coordinate (if any) so that ``ds.sel(block_id=1)`` selects by id, as
    ``ds.sel(block="wall")`` does by name (an index is not stored in NetCDF: :func:`load` adds it)."""
    if "block_id" in ds.coords and "block_id" not in ds.xindexes:
        ds = ds.set_xindex("block_id")
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
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    _write_csv(p, cols)
    return p


def _write_csv(path: Path, columns: Mapping[str, np.ndarray]) -> None:
    """Write numeric columns (n,) as a CSV table, the file ``pandas.DataFrame(columns).to_csv(path,
    index=False)`` writes, byte for byte (tested), in half its time: float64 and integers by
    ``repr`` (the shortest digits that round-trip, as NumPy formats them for pandas), other dtypes
    by NumPy's ``str``, NaN as an empty field; the header quoted where needed."""
    text = []
    for values in columns.values():
        v = np.asarray(values)
        col = list(map(repr, v.tolist())) if v.dtype == np.float64 or v.dtype.kind in "iu" else v.astype(str).tolist()
        if v.dtype.kind == "f":
            for i in np.flatnonzero(np.isnan(v)).tolist():
                col[i] = ""
        text.append(col)
    with open(path, "w", newline="", encoding="utf-8") as fh:
        csv.writer(fh, lineterminator=os.linesep).writerow(columns)
        fh.write("".join(",".join(row) + os.linesep for row in zip(*text)))


def contact_table(ds: xr.Dataset) -> "pd.DataFrame":
    """The contact snapshots of a result (run with ``contact_interval``) as one long table: a row per
    snapshot and sub-contact (interface point with a partner block).

    Columns: time [s], point, block, partner (names), x, y, z [m] (world), nx, ny, nz (unit normal of
    the partner face, into ``block``), normal_force [N] (elastic, compression > 0), shear_force [N]
    (magnitude), fnx, fny, fnz and fsx, fsy, fsz [N] (the elastic normal and shear force vectors on
    ``block``, world), bonded (bool), failed (0 intact, 1 tension, 2 shear), area [m^2] (tributary).

    Raises:
        ValueError: the result has no contact snapshots.
    """
    import pandas as pd

    if "contact_time" not in ds.coords:
        raise ValueError("the result has no contact snapshots: run it with contact_interval "
                         "([run] contact_interval = 0.05 in the case file, or --set run.contact_interval=0.05)")
    partner = ds.point_partner.values
    snap, point = np.nonzero(partner >= 0)
    names = np.asarray(ds.block_name.values, dtype=object)
    fn = ds.point_normal_force.values[snap, point]
    normal = ds.point_normal.values[snap, point] if "point_normal" in ds else np.full((snap.size, 3), np.nan)
    fs = (ds.point_shear_force_vector.values[snap, point] if "point_shear_force_vector" in ds
          else np.full((snap.size, 3), np.nan))
    pos = ds.point_position.values[snap, point]
    cols: dict[str, np.ndarray] = {
        "time": ds.contact_time.values[snap],
        "point": point,
        "block": names[ds.point_block.values[point]],
        "partner": names[partner[snap, point]],
        "x": pos[:, 0], "y": pos[:, 1], "z": pos[:, 2],
        "nx": normal[:, 0], "ny": normal[:, 1], "nz": normal[:, 2],
        "normal_force": fn,
        "shear_force": ds.point_shear_force.values[snap, point],
        "fnx": fn * normal[:, 0], "fny": fn * normal[:, 1], "fnz": fn * normal[:, 2],
        "fsx": fs[:, 0], "fsy": fs[:, 1], "fsz": fs[:, 2],
        "bonded": ds.point_bonded.values[snap, point] > 0,
        "failed": ds.point_failed.values[snap, point].astype(np.int8),
        "area": ds.point_area.values[point],
    }
    return pd.DataFrame(cols)


def _has_pyarrow() -> bool:
    import importlib.util

    return importlib.util.find_spec("pyarrow") is not None


def write_contact_table(ds: xr.Dataset, path: str | Path, fmt: str = "auto") -> Path:
    """Write :func:`contact_table` as CSV or Parquet; returns the path written.

    Args:
        path: the file; with ``fmt="auto"`` and no .csv/.parquet suffix, the suffix is chosen:
            .parquet when pyarrow is installed, else .csv.
        fmt: "auto" (by suffix, as above), "csv" or "parquet" (needs pyarrow).
    """
    p = Path(path)
    if fmt not in ("auto", "csv", "parquet"):
        raise ValueError(f"contact table format must be 'auto', 'csv' or 'parquet', got {fmt!r}")
    if fmt == "auto":
        fmt = p.suffix.lower().lstrip(".") if p.suffix.lower() in (".csv", ".parquet") else (
            "parquet" if _has_pyarrow() else "csv")
    if fmt == "parquet" and not _has_pyarrow():
        raise ValueError(f"{p}: Parquet needs pyarrow (pip install pyarrow); write a .csv instead")
    if p.suffix.lower() != f".{fmt}":
        p = p.with_name(p.name + f".{fmt}") if p.suffix.lower() not in (".csv", ".parquet") else p.with_suffix(f".{fmt}")
    table = contact_table(ds)
    p.parent.mkdir(parents=True, exist_ok=True)
    if fmt == "parquet":
        table.to_parquet(p, index=False)
    else:
        table.to_csv(p, index=False)
    return p


@xr.register_dataset_accessor("rockdem")
class ResultSummary:
    """``ds.rockdem``: a short summary of a rockdem result (the run's summary table: steps,
    timestep, peaks, energy balance, failed sub-contacts, rocking analysis), shown as text by
    ``print(ds.rockdem)`` and as a table in a notebook; ``ds.rockdem.plot(kind)`` draws one of
    :data:`rockdem.plots.PLOTS`."""

    def __init__(self, ds: xr.Dataset) -> None:
        self._ds = ds

    def lines(self) -> list[str]:
        """The summary rows (as printed by ``rockdem run``)."""
        from .run_cli import summary_lines

        return summary_lines(self._ds)

    def __repr__(self) -> str:
        name = self._ds.attrs.get("name", "")
        return f"rockdem result{' ' + str(name) if name else ''}\n" + "\n".join("  " + line for line in self.lines())

    def _repr_html_(self) -> str:
        from html import escape

        return "<b>rockdem result</b><pre>" + escape("\n".join(self.lines())) + "</pre>"

    def plot(self, kind: str = "history", **options: object) -> object:
        """A figure of :data:`rockdem.plots.PLOTS` (``"history"``, ``"energy"``, ...), shown inline."""
        from .plots import PLOTS

        if kind not in PLOTS:
            raise ValueError(f"plot kind {kind!r} unknown; use one of {sorted(PLOTS)}")
        return PLOTS[kind](self._ds, **options)
