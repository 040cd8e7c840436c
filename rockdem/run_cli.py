"""``rockdem run``: run a case file or a built-in example, save results, plot, print a summary."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .case import Case, apply_overrides, example_case, example_names, load_case, parse_case
from .results import export_csv, save
from .simulate import simulate

__all__ = ["run_case", "register_cli", "summary_lines"]


def run_case(case: Case, *, duration: float | None = None, progress: bool | None = None) -> xr.Dataset:
    """Run a built case with its own options (``duration`` overrides [run] duration).

    The loading's attributes (``case.attrs``) go into the result's attrs, its input series
    (``case.series``, e.g. ``ground_acceleration``) become variables sampled at the recorded times.
    """
    r = case.run
    ds = simulate(
        case.model,
        duration if duration is not None else r.duration,
        dt=r.dt,
        timestep_rule=r.timestep_rule,
        safety=r.safety,
        record_interval=r.record_interval,
        monitors=case.monitors,
        progress=progress,
    )
    ds.attrs.update(case.attrs)
    t = ds.time.values
    for name, (ts, values) in case.series.items():
        v = np.column_stack([np.interp(t, ts, values[:, i], left=0.0, right=0.0) for i in range(values.shape[1])])
        ds[name] = (("time", "xyz"), v, {"units": "m/s2" if "acceleration" in name else "1"})
    return ds


def summary_lines(ds: xr.Dataset) -> list[str]:
    """Human-readable summary of a result: steps, timestep, runtime, peaks, energy balance."""
    a = ds.attrs
    lines = [
        f"steps            {a['steps']}",
        f"dt               {a['dt']:.4e} s (smallest {a['dt_min']:.4e} s, rule {a['timestep_rule']})",
        f"runtime          {a['runtime_s']:.3f} s for {float(ds.time[-1]):.3f} s simulated",
    ]
    free = np.flatnonzero(ds.block_free.values)
    theta = ds.rocking_angle.values[:, free]
    k = int(np.argmax(np.max(np.abs(theta), axis=0)))
    b = int(free[k])
    lines.append(
        f"peak rotation    {np.degrees(np.max(np.abs(theta[:, k]))):.3f} deg "
        f"(block {ds.block_name.values[b]!s}, about axis {a['rocking_axis']})"
    )
    for j, name in enumerate(ds.monitor.values):
        d = ds.monitor_displacement.values[:, j, :]
        lines.append(f"peak |u| {name!s:8s} {np.max(np.linalg.norm(d, axis=1)) * 1e3:.2f} mm")
    err = float(np.max(np.abs(ds.energy_balance_error_relative.values)))
    lines.append(f"energy balance   max relative error {err:.2e}")
    npts = max(int(a.get("point_count", 1)), 1)
    lines.append(
        f"sub-contacts     {int(ds.contacts_failed_shear[-1])} failed in shear "
        f"({100 * int(ds.contacts_failed_shear[-1]) / npts:.1f} %), "
        f"{int(ds.contacts_failed_tension[-1])} in tension "
        f"({100 * int(ds.contacts_failed_tension[-1]) / npts:.1f} %) of {npts}"
    )
    if int(a.get("tilted_blocks", 0)) > 1:
        # a released assembly (e.g. a discretised wall): analyse a block of its base course
        z0 = ds.block_position.values[0, free, 2]
        b = int(free[int(np.argmin(z0))])
        lines.append(f"analysed block   {ds.block_name.values[b]!s} (base of the released assembly of {a['tilted_blocks']} blocks)")
    lines.extend(_analysis_lines(ds, b))
    if a.get("diverged"):
        lines.append(f"DIVERGED at t = {a['diverged_time']:.4g} s: the result holds the sound frames before it")
    if a.get("interrupted"):
        lines.append("INTERRUPTED: the result holds the frames computed before the interruption")
    return lines


def _analysis_lines(ds: xr.Dataset, block: int) -> list[str]:
    try:
        from .analysis import summarize_result
    except ImportError:  # analysis module not installed in this build
        return []
    try:
        summary: dict[str, Any] = summarize_result(ds, block=block)
    except ValueError as exc:
        return [f"analysis         skipped: {exc}"]
    out = []
    for key, value in summary.items():
        if isinstance(value, float):
            out.append(f"{key:16s} {value:.4g}")
        elif isinstance(value, (bool, int, str)):
            out.append(f"{key:16s} {value}")
    return out


def plot_rocking(ds: xr.Dataset, path: Path) -> Path:
    """Rotation and top displacement versus time, saved as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    free = np.flatnonzero(ds.block_free.values)
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    t = ds.time.values
    for b in free:
        axes[0].plot(t, np.degrees(ds.rocking_angle.values[:, b]), label=str(ds.block_name.values[b]))
    axes[0].set_ylabel("rocking angle [deg]")
    axes[0].grid(True, alpha=0.3)
    if len(free) <= 8:
        axes[0].legend(loc="upper right", fontsize=8)
    if ds.sizes.get("monitor", 0):
        for j, name in enumerate(ds.monitor.values):
            axes[1].plot(t, ds.monitor_displacement.values[:, j, 0] * 1e3, label=f"{name} (x)")
        axes[1].set_ylabel("displacement [mm]")
        axes[1].legend(loc="upper right", fontsize=8)
    else:
        for b in free:
            axes[1].plot(t, ds.block_displacement.values[:, b, 0] * 1e3)
        axes[1].set_ylabel("centroid displacement x [mm]")
    axes[1].set_xlabel("time [s]")
    axes[1].grid(True, alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _run(args: argparse.Namespace) -> int:
    if args.list_examples:
        print("\n".join(example_names()))
        return 0
    if (args.case is None) == (args.example is None):
        raise ValueError("give a case file (rockdem run CASE.toml) or --example NAME, not both")
    data = example_case(args.example) if args.example else load_case(args.case)
    data = apply_overrides(data, args.set or [])
    t0 = time.perf_counter()
    case = parse_case(data)
    out = Path(args.out or case.output["directory"] or Path("results") / case.name)
    ds = run_case(case, duration=args.duration, progress=None if not args.quiet else False)
    wall = time.perf_counter() - t0
    written = [save(ds, out / "result.nc")]
    if case.output["csv"]:
        written.append(export_csv(ds, out / "histories.csv"))
    if case.output["plot"] and not args.no_plot:
        written.append(plot_rocking(ds, out / "rocking.png"))
    print(f"rockdem run: {case.name}")
    for line in summary_lines(ds):
        print("  " + line)
    print(f"  wall time        {wall:.2f} s including set-up (and compilation on a first run)")
    for p in written:
        print(f"  wrote            {p}")
    return 130 if ds.attrs.get("interrupted") else 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``run`` sub-command."""
    p = subparsers.add_parser("run", help="run a case file or a built-in example")
    p.add_argument("case", nargs="?", help="TOML case file")
    p.add_argument("--example", help=f"built-in example ({', '.join(example_names())})")
    p.add_argument("--list-examples", action="store_true", help="list the built-in examples")
    p.add_argument("--out", help="output directory (default results/<case name>)")
    p.add_argument("--set", action="append", metavar="TABLE.KEY=VALUE", help="override a case value")
    p.add_argument("--duration", type=float, help="simulated time [s], overrides [run] duration")
    p.add_argument("--no-plot", action="store_true", help="do not write the PNG plot")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_run)
