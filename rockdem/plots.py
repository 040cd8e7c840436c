"""Plots of results, after the figures of Galvez et al. (2022): each function takes a result
(an xarray Dataset from :func:`rockdem.simulation.simulate` or a NetCDF path) and returns a
Matplotlib figure (:class:`InlineFigure`: never shown by pyplot, displayed inline by Jupyter as the
value of a cell, without importing pyplot first).

- :func:`plot_history`: rocking angle and normalised top displacement u/B vs time (Figs. 6, 9B, 10B, 12B, 13),
  with the input motion's acceleration, velocity and displacement under them for earthquake runs;
- :func:`plot_restitution`: half-cycle peaks and apparent restitution e_a per impact with the
  e_eta and 0.95 e_eta lines (Eq. 6, Figs. 6D-F, 8C-D);
- :func:`plot_bouncing`: vertical centroid displacement with airborne phases shaded (Fig. 5A);
- :func:`plot_energy`: energy components and the balance error vs time;
- :func:`plot_capacity`: capacity curves of pushovers (Fig. 9A);
- :func:`plot_contacts`: sub-contacts in contact, bonded, failed in tension and in shear vs time;
- :func:`plot_comparison`: several results, optionally a measured CSV history, on one axis with
  the WME of each in the legend.

The CLI is ``rockdem plot RESULT.nc [MORE.nc ...] --kind KIND -o OUT.png|pdf``.
"""

from __future__ import annotations

import argparse
import csv
import functools
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import xarray as xr
from matplotlib import rc_context
from matplotlib.figure import Figure

from .analysis import (
    ground_acceleration,
    rocking_direction,
    apparent_restitution,
    bouncing,
    half_cycle_peaks,
    is_free_rocking,
    is_pushover,
    lowest_point_height,
    result_eta,
    wme,
)
from .cli import dots_per_inch, positive_float
from .kernels.rotation import axis_angle_matrix, quats_to_matrices
from .style import STYLE, InlineFigure, save_figure

__all__ = [
    "STYLE",
    "PLOTS",
    "InlineFigure",
    "load_result",
    "rocking_direction",
    "block_dimensions",
    "top_displacement",
    "ground_displacement",
    "ground_acceleration",
    "world_vertices",
    "plot_history",
    "plot_restitution",
    "plot_bouncing",
    "plot_energy",
    "plot_capacity",
    "plot_contacts",
    "plot_comparison",
    "is_pushover",
    "is_free_rocking",
    "read_history_csv",
    "save_figure",
    "register_cli",
]

Result = xr.Dataset | str | Path

_WIDTH = 7.0  # figure width [in]


def _styled(func: Callable[..., Figure]) -> Callable[..., Figure]:
    """Build the figure under :data:`STYLE` (artists read rcParams when they are created)."""

    @functools.wraps(func)
    def wrapper(*args: object, **kwargs: object) -> Figure:
        with rc_context(STYLE):
            return func(*args, **kwargs)

    return wrapper


# -- result access ---------------------------------------------------------------------------
def load_result(result: Result) -> xr.Dataset:
    """A result Dataset, read from NetCDF when given a path."""
    if isinstance(result, xr.Dataset):
        return result
    from .results import load

    return load(result)


RESULT_VARIABLES = ("block_free", "block_name", "block_position", "rocking_angle")
"""Variables every result of rockdem run or simulate holds (the commands check for them)."""


NETCDF_SIGNATURES = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")
"""The first bytes of a NetCDF file: classic, 64-bit offset and CDF-5 formats, and NetCDF-4 (HDF5)."""


def input_file(path: str | Path, what: str, give: str) -> Path:
    """``path`` as a Path once it is an existing regular file; else FileNotFoundError or ValueError
    naming it as ``what`` and saying what to ``give``."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"{what} {p} does not exist; give {give}")
    if not p.is_file():
        raise ValueError(f"{what} {p} is not a regular file; give {give}")
    return p


def read_result_file(path: str | Path, what: str = "result file") -> xr.Dataset:
    """A rockdem result read from ``path`` for a command: FileNotFoundError or ValueError naming the
    file (as ``what``) when it is missing, not a regular file, not a result or holds no frame."""
    p = input_file(path, what, "the result.nc written by rockdem run (OUT/result.nc)")
    with open(p, "rb") as f:
        head = f.read(8)
    if not head.startswith(NETCDF_SIGNATURES):
        kind = " (a checkpoint: continue it with rockdem run CASE --from it)" if head.startswith(b"PK") else ""
        raise ValueError(f"{what} {p} is not a rockdem result: not a NetCDF file{kind}; give the result.nc written by "
                         "rockdem run (OUT/result.nc)")
    try:
        ds = load_result(p)
    except (ValueError, OSError, KeyError) as exc:
        raise ValueError(f"{what} {p} is not a rockdem result (the NetCDF file written by rockdem run): "
                         f"{str(exc)[:200]}") from None
    missing = [v for v in RESULT_VARIABLES if v not in ds]
    if missing or "time" not in ds.coords:
        raise ValueError(f"{what} {p} is not a rockdem result: it has no {', '.join(missing or ['time'])}")
    if ds.sizes["time"] == 0:
        raise ValueError(f"{what} {p} holds no recorded frame; rerun the case")
    return ds


def _label(ds: xr.Dataset, fallback: str) -> str:
    return str(ds.attrs.get("name", fallback))


def _block(ds: xr.Dataset, block: int | str | None) -> int:
    """Block id from a name or id; default: the lowest free block at t = 0."""
    names = [str(n) for n in ds.block_name.values]
    if block is None:
        free = np.flatnonzero(ds.block_free.values)
        if free.size == 0:
            raise ValueError("block: the result has no free block to plot")
        return int(free[np.argmin(ds.block_position.values[0, free, 2])])
    if isinstance(block, str) and not block.lstrip("-").isdigit():
        if block not in names:
            raise ValueError(f"block {block!r} not in the result; give one of {names}")
        return names.index(block)
    b = int(block)
    if not 0 <= b < len(names):
        raise ValueError(f"block id {b} out of range 0..{len(names) - 1}")
    return b


def _monitor(ds: xr.Dataset, monitor: str | None) -> int | None:
    names = [str(n) for n in ds.monitor.values] if "monitor" in ds.coords else []
    if monitor is None:
        return 0 if names else None
    if monitor not in names:
        raise ValueError(f"monitor {monitor!r} not in the result; recorded monitors are {names}")
    return names.index(monitor)


def _reference_rotation(ds: xr.Dataset, b: int) -> np.ndarray:
    """Orientation (3, 3) of block b before any initial tilt: R_ref = exp(rv_0)^T R(q_0)."""
    r0 = quats_to_matrices(ds.block_quaternion.values[0, b])
    rv = ds.block_rotation.values[0, b]
    ang = float(np.linalg.norm(rv))
    tilt = axis_angle_matrix(rv / ang, ang) if ang > 1e-12 else np.eye(3)
    return tilt.T @ r0


def _vertex_range(ds: xr.Dataset, b: int) -> slice:
    s = ds.block_vertex_start.values
    return slice(int(s[b]), int(s[b + 1]))


def block_dimensions(ds: xr.Dataset, block: int | str | None = None) -> tuple[float, float]:
    """Width B along the rocking direction and height H of a block, untilted [m]."""
    b = _block(ds, block)
    v = ds.vertex_local.values[_vertex_range(ds, b)] @ _reference_rotation(ds, b).T
    d = rocking_direction(ds)
    up = np.cross(d, np.asarray(ds.attrs.get("rocking_axis", (0.0, 1.0, 0.0)), dtype=float))
    return float(np.ptp(v @ d)), float(np.ptp(v @ up))


def world_vertices(ds: xr.Dataset, frames: int | Sequence[int] | slice, block: int | None = None) -> np.ndarray:
    """World vertex positions R(q) v_local + x [m] at the given frames.

    Returns:
        (nv, 3) for one frame (all blocks' vertices, global vertex ids) or (F, nv, 3) for several;
        with ``block`` only that block's vertices.
    """
    q = ds.block_quaternion.values[frames]
    x = ds.block_position.values[frames]
    vl = ds.vertex_local.values
    start = ds.block_vertex_start.values
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    if block is not None:
        sel = _vertex_range(ds, block)
        vl, owner = vl[sel], owner[sel]
    r = quats_to_matrices(q)  # (..., nb, 3, 3)
    return np.einsum("...vij,vj->...vi", r[..., owner, :, :], vl) + x[..., owner, :]


def top_displacement(ds: xr.Dataset, monitor: str | None = None) -> tuple[np.ndarray, str]:
    """Horizontal top displacement along the rocking direction [m], relative to the ground, and a
    label saying its source.

    A recorded monitor is used when there is one (``monitor_displacement``: from the reference,
    untilted position, relative to the ground); otherwise the highest vertex of the free blocks,
    measured from its t = 0 position minus the ground's displacement.
    """
    d = rocking_direction(ds)
    base = ground_displacement(ds)
    rel = ", relative to the ground" if np.any(base != 0.0) else ""
    k = _monitor(ds, monitor)
    if k is not None:
        return ds.monitor_displacement.values[:, k] @ d, f"monitor {ds.monitor.values[k]!s}{rel}"
    free = np.flatnonzero(ds.block_free.values)
    if free.size == 0:
        raise ValueError("monitor: the result has no monitor and no free block")
    best, best_z, vid = free[0], -np.inf, 0
    for b in free:
        w = world_vertices(ds, 0, int(b))
        i = int(np.argmax(w[:, 2]))
        if w[i, 2] > best_z:
            best, best_z, vid = int(b), float(w[i, 2]), i
    path = world_vertices(ds, slice(None), best)[:, vid]
    return (path - path[0] - base) @ d, f"highest vertex, from t = 0{rel}"


def ground_displacement(ds: xr.Dataset) -> np.ndarray:
    """Displacement (T, 3) [m] of the ground (the driven="ground" blocks); zeros when the result
    has none (no ground motion, or a result without ``ground_displacement``)."""
    if "ground_displacement" in ds:
        return np.asarray(ds.ground_displacement.values, dtype=float)
    return np.zeros((ds.sizes["time"], 3))


def _block_label(ds: xr.Dataset, b: int) -> str:
    """'block NAME', or just NAME when it already says block (no "block block")."""
    name = str(ds.block_name.values[b])
    return name if "block" in name.lower() else f"block {name}"


# -- plots --------------------------------------------------------------------------------------
@_styled
def plot_history(
    result: Result, *, block: int | str | None = None, monitor: str | None = None, length: float | None = None
) -> Figure:
    """Rocking angle [rad] and normalised top displacement u/B [-] vs time (Figs. 6, 9B, 10B, 13).

    Args:
        result: a result or its NetCDF path.
        block: block whose rocking angle is drawn (name or id); default the lowest free block.
        monitor: monitor for the top displacement; default the first recorded.
        length: normalising length B [m]; default the block's width along the rocking direction.
    """
    ds = load_result(result)
    b = _block(ds, block)
    t = ds.time.values
    u, src = top_displacement(ds, monitor)
    bw = _normalising_length(ds, length, b)
    quake = ground_acceleration(ds)
    fig = InlineFigure(figsize=(_WIDTH, 4.6 if quake is None else 8.2))
    axes = fig.subplots(2 if quake is None else 5, 1, sharex=True)
    ax1, ax2 = axes[0], axes[1]
    ax1.plot(t, ds.rocking_angle.values[:, b], color="C0")
    ax1.set_ylabel("rocking angle θ [rad]")
    ax1.set_title(f"{_label(ds, 'result')}: {_block_label(ds, b)}")
    ax2.plot(t, u / bw, color="C1")
    ax2.set_ylabel("top displacement u/B [-]")
    ax2.text(0.99, 0.03, f"{src}; B = {bw:.3g} m", transform=ax2.transAxes, ha="right", va="bottom", fontsize=7)
    if quake is not None:
        from .spectra import plot_ground_motion_axes

        plot_ground_motion_axes(tuple(axes[2:]), t, quake)
        rec = f" {ds.attrs['earthquake_record']}" if "earthquake_record" in ds.attrs else ""
        axes[2].set_title(f"input motion{rec}, along the rocking direction", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    fig.align_ylabels()
    fig.tight_layout()
    return fig


@_styled
def plot_restitution(result: Result, *, block: int | str | None = None, min_fraction: float = 0.01) -> Figure:
    """Half-cycle peaks |theta_n| and apparent restitution e_a per impact (Eq. 6, Figs. 6D-F, 8C-D).

    The Housner value e_eta = 1 - 1.5 sin^2(eta) and 0.95 e_eta are drawn for reference, with
    eta the instability angle about the pivot the block rocks on (:func:`rockdem.analysis.result_eta`:
    the base contact face, so a reduced parapet base counts; the assembly's for a released
    assembly), else atan(B/H) of :func:`block_dimensions`. Peaks and e_a come from
    :func:`rockdem.analysis.half_cycle_peaks` and :func:`rockdem.analysis.apparent_restitution`.

    Args:
        result: a result or its NetCDF path.
        block: the rocking block (name or id); default the lowest free block.
        min_fraction: peaks less prominent than this fraction of max |theta| are ignored.
    """
    ds = load_result(result)
    b = _block(ds, block)
    eta = result_eta(ds, b)
    if eta is None:
        eta = float(np.arctan2(*block_dimensions(ds, b)))
    e_eta = 1.0 - 1.5 * np.sin(eta) ** 2
    t, theta = ds.time.values, ds.rocking_angle.values[:, b]
    amp = float(np.max(np.abs(theta), initial=0.0))
    pk = half_cycle_peaks(t, theta, min_prominence=min_fraction * amp) if amp > 0 else None
    tp, peaks = (pk.time, np.abs(pk.value)) if pk is not None else (np.zeros(0), np.zeros(0))
    ea, note = np.zeros(0), "no impact recorded"
    if peaks.size >= 2:
        try:
            ea = apparent_restitution(peaks[1:], peaks[0], eta).per_impact
            note = f"mean e_a = {np.mean(ea):.3f} over {ea.size} impacts"
        except ValueError as exc:  # e.g. a first peak beyond eta: Eq. 6 is undefined
            note = f"e_a undefined: {exc}"
    fig = InlineFigure(figsize=(_WIDTH, 3.2))
    ax1, ax2 = fig.subplots(1, 2)
    ax1.plot(t, np.abs(theta) / eta, color="0.6", lw=0.8, label="|θ|/η")
    ax1.plot(tp, peaks / eta, "o", color="C0", ms=4, label="peaks |θ_n|/η")
    ax1.set_xlabel("time [s]")
    ax1.set_ylabel("|θ| / η [-]")
    ax1.set_title(f"{_block_label(ds, b)}, η = {eta:.4f} rad")
    ax1.legend(loc="upper right")
    n = np.arange(1, ea.size + 1)
    ax2.plot(n, ea, "o-", color="C0", ms=4, label="e_a (Eq. 6)")
    ax2.axhline(e_eta, color="k", ls="--", lw=1.0, label=f"e_η = {e_eta:.3f}")
    ax2.axhline(0.95 * e_eta, color="C3", ls=":", lw=1.2, label=f"0.95 e_η = {0.95 * e_eta:.3f}")
    ax2.set_xlabel("impact n [-]")
    ax2.set_ylabel("apparent restitution e_a [-]")
    ax2.set_title(note if len(note) < 60 else note[:57] + "...")
    ax2.margins(y=0.2)
    ax2.legend(loc="best")
    fig.tight_layout()
    return fig


@_styled
def plot_bouncing(result: Result, *, block: int | str | None = None, gap: float = 1e-5) -> Figure:
    """Vertical centroid displacement [mm] with the airborne phases shaded (Fig. 5A).

    A block is airborne while its lowest vertex is more than ``gap`` [m] above its level at t = 0
    (which follows the foundation's vertical motion). Each phase's bouncing magnitude is its
    amplitude divided by its duration (paper §3.1, Fig. 5B) [m/s]; see :func:`rockdem.analysis.bouncing`.
    """
    ds = load_result(result)
    b = _block(ds, block)
    t = ds.time.values
    uz = ds.block_displacement.values[:, b, 2]
    low = lowest_point_height(ds, b)
    base = ground_displacement(ds)
    bo = bouncing(t, low, z_contact=low[0] + base[:, 2], tol=gap)
    fig = InlineFigure(figsize=(_WIDTH, 3.4))
    ax = fig.subplots()
    rel = " (relative to the ground)" if ds.block_displacement.attrs.get("reference") == "ground" else ""
    ax.plot(t, uz * 1e3, color="C0", label=f"centroid u_z{rel}")
    for k, (t0, dur) in enumerate(zip(bo.start, bo.duration)):
        ax.axvspan(t0, t0 + dur, color="C3", alpha=0.25, lw=0, label="airborne" if k == 0 else None)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("vertical centroid displacement [mm]")
    text = (
        f"{bo.start.size} airborne phases, max bouncing {bo.max_magnitude * 1e3:.3g} mm/s"
        if bo.start.size
        else "no airborne phase"
    )
    ax.set_title(f"{_block_label(ds, b)}: {text} (gap {gap * 1e3:.3g} mm)")
    ax.legend(loc="upper right")
    fig.tight_layout()
    return fig


_ENERGY_LINES = (
    ("energy_kinetic", "kinetic"),
    ("energy_potential", "potential (from t = 0)"),
    ("energy_elastic", "elastic (joints)"),
    ("energy_damping_mass", "dissipated: MP damping"),
    ("energy_damping_stiffness", "dissipated: SP damping"),
    ("energy_friction", "dissipated: friction"),
    ("energy_bond", "dissipated: bond breakage"),
    ("energy_local_damping", "dissipated: local damping"),
    ("work_driven", "work of driven blocks"),
    ("work_body", "work of body loads"),
)


@_styled
def plot_energy(result: Result) -> Figure:
    """Energy components [J] and the balance error (relative, %) vs time."""
    ds = load_result(result)
    t = ds.time.values
    fig = InlineFigure(figsize=(_WIDTH, 5.0))
    ax1, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=(2.2, 1.0))
    scale = max((float(np.max(np.abs(ds[n].values))) for n, _ in _ENERGY_LINES if n in ds), default=0.0)
    for k, (name, label) in enumerate(_ENERGY_LINES):
        if name not in ds:
            continue
        y = ds[name].values
        if np.max(np.abs(y), initial=0.0) <= 1e-9 * max(scale, 1e-300):
            continue  # an identically zero component only clutters the legend
        ax1.plot(t, y, color=f"C{k}", label=label)
    ax1.set_ylabel("energy [J]")
    ax1.set_title(f"{_label(ds, 'result')}: energy balance")
    ax1.legend(loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax2.plot(t, 100.0 * ds.energy_balance_error_relative.values, color="k")
    ax2.set_ylabel("balance error [%]")
    ax2.set_xlabel("time [s]")
    fig.align_ylabels()
    fig.tight_layout()
    return fig


def _capacity_force(ds: xr.Dataset, monitor: str | None) -> tuple[np.ndarray, str]:
    """Load factor (T,) [-] of a pushover and its axis label."""
    if "load_factor" in ds:
        return ds.load_factor.values, "load factor [-]"
    if not is_pushover(ds):
        raise ValueError(f"capacity: {_label(ds, 'the result')} is not a pushover (no pushover_* attributes); "
                         "capacity curves apply to pushover results ([loading] type = \"pushover\")")
    from .loading import capacity_curve

    names = [str(n) for n in ds.monitor.values] if "monitor" in ds.coords else []
    lam, _ = capacity_curve(ds, monitor or (names[0] if names else "top"))
    if ds.attrs.get("pushover_rod") is not None:
        return lam, "load factor: rod force / weight [-]"
    return lam, "load factor λ [-]"


@_styled
def plot_capacity(
    results: Result | Sequence[Result], *, labels: Sequence[str] | None = None, monitor: str | None = None
) -> Figure:
    """Capacity curves of pushovers (Fig. 9A): load factor vs top displacement [mm].

    The load factor is the result's ``load_factor`` variable when present, otherwise
    :func:`rockdem.loading.capacity_curve`'s: the pushing rod's force over the weight of the free
    blocks (displacement control), or the applied ramp lambda(t) (load control).

    Raises:
        ValueError: a result is not a pushover.
    """
    items = _as_list(results)
    labels = _labels(items, labels)
    fig = InlineFigure(figsize=(_WIDTH, 4.0))
    ax = fig.subplots()
    ylabel = src = ""
    for ds, lab in zip(items, labels):
        u, src = top_displacement(ds, monitor)
        y, ylabel = _capacity_force(ds, monitor)
        ax.plot(u * 1e3, y, label=lab)
    ax.set_xlabel(f"top displacement [mm] ({src})")
    ax.set_ylabel(ylabel)
    ax.set_title("capacity curve" + ("s" if len(items) > 1 else ""))
    ax.legend(loc="best")
    fig.tight_layout()
    return fig


@_styled
def plot_contacts(result: Result) -> Figure:
    """Sub-contact states vs time: in contact, bonded, failed in tension, failed in shear [-]."""
    ds = load_result(result)
    t = ds.time.values
    total = int(ds.attrs.get("point_count", 0))
    bonded0 = int(ds.contacts_bonded.values[0]) if t.size else 0
    fig = InlineFigure(figsize=(_WIDTH, 3.6))
    ax = fig.subplots()
    series = (
        ("contacts_active", "in contact", "C0", "-"),
        ("contacts_bonded", "bonded", "C2", "--"),
        ("contacts_failed_tension", "failed in tension", "C1", "-"),
        ("contacts_failed_shear", "failed in shear", "C3", "-"),
    )
    for name, label, color, ls in series:
        y = ds[name].values
        end = f" (end {int(y[-1])}" + (f", {100 * y[-1] / bonded0:.0f} % of bonded at t = 0)" if bonded0 else ")")
        ax.step(t, y, where="post", color=color, ls=ls, label=label + (end if t.size and "failed" in name else ""))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("sub-contacts [-]")
    ax.set_title(f"{_label(ds, 'result')}: sub-contact states ({total} interface points, {bonded0} bonded at t = 0)")
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2)
    fig.tight_layout()
    return fig


def read_history_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a measured history: first column time [s], second the value (same quantity as plotted).

    Separators (comma, semicolon, whitespace) and a header row are detected; ``#`` starts a comment.
    """
    import pandas as pd

    p = input_file(path, "measured history", "a CSV or text file of time [s] and value")
    try:
        df = pd.read_csv(p, sep=None, engine="python", comment="#", header=None)
    except (UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError, csv.Error) as exc:
        raise ValueError(f"measured history {p} is not a text table of time [s] and value: {str(exc)[:120]}") from None
    df = df.apply(pd.to_numeric, errors="coerce").dropna(how="any")
    if df.shape[1] < 2 or df.shape[0] < 2:
        raise ValueError(f"measured {p}: need two numeric columns (time [s], value) and two rows at least")
    t, v = df.iloc[:, 0].to_numpy(float), df.iloc[:, 1].to_numpy(float)
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"measured {p}: the time column (first) must increase strictly")
    return t, v


def _as_list(results: Result | Sequence[Result]) -> list[xr.Dataset]:
    if isinstance(results, (xr.Dataset, str, Path)):
        results = [results]
    items = [load_result(r) for r in results]
    if not items:
        raise ValueError("results: give at least one result")
    return items


def _labels(items: Sequence[xr.Dataset], labels: Sequence[str] | None) -> list[str]:
    if labels is None:
        return [_label(ds, f"result {k + 1}") for k, ds in enumerate(items)]
    if len(labels) != len(items):
        raise ValueError(f"labels: give one per result ({len(items)}), got {len(labels)}")
    return [str(x) for x in labels]


def _normalising_length(ds: xr.Dataset, length: float | None, block: int | str | None) -> float:
    """The length B [m] that u / B divides by: ``length``, or the block's width along the rocking
    direction (None)."""
    if length is None:
        return float(block_dimensions(ds, block)[0])
    if not float(length) > 0.0:
        raise ValueError(f"length = {length!r}: the normalising length B must be positive [m] (None: the block's width)")
    return float(length)


def _quantity(ds: xr.Dataset, quantity: str, monitor: str | None, length: float | None) -> np.ndarray:
    if quantity == "rotation":
        return ds.rocking_angle.values[:, _block(ds, None)]
    if quantity == "displacement":
        u, _ = top_displacement(ds, monitor)
        return u / _normalising_length(ds, length, None)
    raise ValueError(f"quantity must be 'displacement' (u/B) or 'rotation' [rad], got {quantity!r}")


@_styled
def plot_comparison(
    results: Result | Sequence[Result],
    *,
    labels: Sequence[str] | None = None,
    measured: str | Path | tuple[np.ndarray, np.ndarray] | None = None,
    measured_label: str = "measured",
    quantity: str = "displacement",
    monitor: str | None = None,
    length: float | None = None,
) -> Figure:
    """Several results (and a measured history) on one axis, with the WME of each in the legend.

    WME = sum|x_i - y_i||x_i| / sum x_i^2 on the reference's time base, cut at the end of the
    reference's motion; the reference is the measured history when given, else the first result.

    Args:
        results: results or NetCDF paths.
        labels: legend labels, one per result.
        measured: CSV path (time [s], value) or a (time, value) pair, in the plotted quantity.
        quantity: "displacement" (top displacement u/B [-]) or "rotation" (rocking angle [rad]).
        monitor: monitor for the displacement; length: normalising length B [m].
    """
    items = _as_list(results)
    labels = _labels(items, labels)
    curves = [(ds.time.values, _quantity(ds, quantity, monitor, length)) for ds in items]
    ref = None
    fig = InlineFigure(figsize=(_WIDTH, 3.6))
    ax = fig.subplots()
    if measured is not None:
        ref = read_history_csv(measured) if isinstance(measured, (str, Path)) else tuple(map(np.asarray, measured))
        ax.plot(ref[0], ref[1], color="k", lw=1.6, label=f"{measured_label} (reference)")
    for k, ((t, y), lab) in enumerate(zip(curves, labels)):
        if ref is None and k == 0:
            ref = (t, y)
            ax.plot(t, y, color="k", lw=1.6, label=f"{lab} (reference)")
            continue
        err = wme(ref[0], ref[1], t, y, overlap_only=True)  # warned about when it covers less than the reference
        ax.plot(t, y, color=f"C{k}", label=f"{lab} (WME = {err:.3f})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("top displacement u/B [-]" if quantity == "displacement" else "rotation θ [rad]")
    ax.legend(loc="upper right")
    fig.tight_layout()
    return fig


PLOTS: dict[str, Callable[..., Figure]] = {
    "history": plot_history,
    "restitution": plot_restitution,
    "bouncing": plot_bouncing,
    "energy": plot_energy,
    "capacity": plot_capacity,
    "contacts": plot_contacts,
    "comparison": plot_comparison,
}
"""Plot kinds of ``rockdem plot --kind``."""


# -- CLI ----------------------------------------------------------------------------------------
def _not_applicable(kind: str, items: Sequence[xr.Dataset], measured: object) -> str:
    """Why a plot kind does not apply to these results ("" when it does)."""
    first = items[0]
    if kind == "capacity" and not all(is_pushover(ds) for ds in items):
        return "not a pushover result"
    if kind == "restitution" and not is_free_rocking(first):
        return "not a free-rocking run; e_a (Eq. 6) measures the decay of rocking released from rest"
    if kind == "bouncing" and is_pushover(first):
        return "a quasi-static pushover has no impacts"
    if kind == "comparison" and len(items) < 2 and measured is None:
        return "one result and no --measured history: nothing to compare"
    return ""


def _file_label(path: Path) -> str:
    """A result's name from its file: the folder for the usual ``<folder>/result.nc``."""
    return path.resolve().parent.name if path.stem == "result" else path.stem


def _plot(args: argparse.Namespace) -> int:
    kinds = list(PLOTS) if args.kind == "all" else [args.kind]
    multi = {"capacity", "comparison"}
    first = Path(args.results[0])
    if len(args.results) > 1 and not set(kinds) & multi:
        raise ValueError(f"--kind {args.kind} draws one result; give one RESULT or use --kind comparison/capacity")
    if args.output:
        from .cli import output_file

        output_file(args.output, "-o")
    loaded = [read_result_file(r) for r in args.results]
    for ds, r in zip(loaded, args.results):
        ds.attrs.setdefault("name", _file_label(Path(r)))
    written, skipped = [], []
    for kind in kinds:
        why = _not_applicable(kind, loaded if kind in multi else loaded[:1], args.measured)
        if why and args.kind == "all":
            skipped.append(f"{kind}: {why}")
            continue
        if why and kind == "capacity":
            raise ValueError(f"--kind capacity: {why}; capacity curves apply to pushover results")
        if why and kind == "comparison":  # (drawn alone, labelled its own reference, before 2026-12-08)
            raise ValueError(f"--kind comparison: {why}; give two or more RESULTs, or --measured FILE (time, value)")
        func = PLOTS[kind]
        kw: dict[str, object] = {}
        if kind in multi:
            kw["labels"] = args.labels or [_file_label(Path(r)) for r in args.results]
            target: object = loaded
        else:
            target = loaded[0]
        if kind in ("history", "restitution", "bouncing") and args.block is not None:
            kw["block"] = args.block
        if kind in ("history", "capacity", "comparison") and args.monitor is not None:
            kw["monitor"] = args.monitor
        if kind in ("history", "comparison") and args.length is not None:
            kw["length"] = args.length
        if kind == "comparison":
            kw["measured"] = args.measured
            kw["quantity"] = args.quantity
        fig = func(target, **kw)
        if args.output and len(kinds) == 1:
            out = Path(args.output)
        else:
            suffix = (Path(args.output).suffix if args.output else "") or f".{args.format}"
            base = Path(args.output).with_suffix("") if args.output else first.with_suffix("")
            out = base.parent / f"{base.name}_{kind}{suffix}"
        written.append(save_figure(fig, out, dpi=args.dpi))
    for p in written:
        print(f"rockdem plot: wrote {p}")
    for note in skipped:
        print(f"rockdem plot: skipped {note}")
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``plot`` sub-command."""
    p = subparsers.add_parser("plot", help="plot a result (PNG or PDF)", description=__doc__.split("\n\n")[0])
    p.add_argument("results", nargs="+", metavar="RESULT.nc", help="result file(s); several for comparison/capacity")
    p.add_argument("--kind", default="history", choices=sorted(PLOTS) + ["all"], help="what to plot (default history)")
    p.add_argument("-o", "--output", help="output .png or .pdf (default RESULT_KIND.png next to the result)")
    p.add_argument("--format", default="png", choices=("png", "pdf"), help="format when -o is not given")
    p.add_argument("--dpi", type=dots_per_inch, default=None, help="resolution [dots per inch] (default 100)")
    p.add_argument("--block", help="block name or id (default: the lowest free block)")
    p.add_argument("--monitor", help="monitor for the top displacement (default: the first recorded)")
    p.add_argument("--length", type=positive_float, help="normalising length B [m] for u/B (default: the block width)")
    p.add_argument("--measured", help="CSV of a measured history (time [s], value) for --kind comparison")
    p.add_argument("--quantity", default="displacement", choices=("displacement", "rotation"))
    p.add_argument("--labels", nargs="+", help="legend labels, one per result")
    p.set_defaults(func=_plot)
