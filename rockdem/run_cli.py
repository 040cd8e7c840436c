"""``rockdem run``: run a case file or a built-in example, save results, plot, print a summary."""

from __future__ import annotations

import argparse
import contextlib
import copy
import math
import os
import shlex
import signal
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .checkpoint import Checkpoint, load_checkpoint, structure_hash
from .case import SETTLE_LONGEST, Case, apply_overrides, example_case, example_names, load_case, parse_case, with_duration
from ._warn import warn_user
from .cli import EXIT_DIVERGED, hold_signals, output_folder, positive_float, positive_int, stop_on_signals
from .analysis import FALL_FRACTION, TIPPED_ANGLE, fallen_blocks
from .loading import EQUILIBRIUM_TOLERANCE, load_carried, pushover_end
from .results import export_csv, save, write_contact_table
from .rocking_plot import PlotProcess, draw_rocking, rocking_series
from .simulation import LIFT_1MM, REST_SHARE, _deferred_signals, simulate
from .stopping import STOP_MODES

__all__ = ["run_case", "run_options", "register_cli", "summary_lines"]


SETTLE_LOCAL_DAMPING = 0.8
"""Local damping of the settling run of ``[run] settle`` (Cundall's quasi-static value)."""


def settled_start(case: Case) -> tuple[Checkpoint, float]:
    """The start of a case with ``[run] settle``: its model settled under gravity alone (the same
    blocks and joints, no loading, local damping :data:`SETTLE_LOCAL_DAMPING`) until its blocks
    are at rest or for ``case.run.settle`` seconds at most, its clock reset (docs/checkpoints.md,
    "Settle once"), and the settling's length [s]. Gravity loads the joints' springs from zero at
    t = 0: without settling, they ring about their static overlaps between no force and twice the
    weight, for ever undamped and for about 2 / alpha seconds with mass-proportional damping alone.

    Raises:
        ValueError: the loading moves or adds blocks, or the blocks did not come to rest in time.
    """
    data = copy.deepcopy(case.data)
    data["loading"] = {"type": "gravity"}
    data["damping"] = {"local": SETTLE_LOCAL_DAMPING}
    keep = ("dt", "timestep_rule", "safety", "resolution", "contact_tolerance", "contact_interval")
    data["run"] = {**{k: v for k, v in data.get("run", {}).items() if k in keep}, "duration": case.run.settle}
    data.pop("output", None)
    try:
        settle = parse_case(data)
    except ValueError as exc:
        raise ValueError(f"[run] settle: the case without its loading cannot be built ({exc})") from None
    if structure_hash(settle.model) != structure_hash(case.model):
        raise ValueError(f"[run] settle: the {case.data.get('loading', {}).get('type', 'gravity')} loading changes the "
                         "blocks or their starting poses (a free-rocking release tilts them, a rod pushover adds its rod), "
                         "so the case cannot start from its blocks settled without it; leave settle out")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "settled.npz"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # the settling run's own damping and stop notes
            ds = simulate(settle.model, case.run.settle, record_interval=0.01, stop="rest", checkpoint=path, progress=False)
        if ds.attrs.get("stop_reason") != "rest":
            v = float(np.max(np.linalg.norm(ds.block_velocity.values[-1], axis=1)))
            raise ValueError(
                f"[run] settle: the blocks did not come to rest within {case.run.settle:g} s under gravity alone (the fastest "
                f"moves at {v:.3g} m/s at the end): give a longer settle (true: up to {SETTLE_LONGEST:g} s), or the specimen "
                "does not stand under its own weight (it tips or slides; run it without settle to see it)")
        ck = load_checkpoint(path)
        return ck.reset_clock(), float(ck.time)


def run_case(
    case: Case,
    *,
    duration: float | None = None,
    progress: bool | None = None,
    initial: Checkpoint | str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: float | None = None,
    threads: int | None = None,
) -> xr.Dataset:
    """Run a built case with its own options (``duration`` overrides [run] duration).

    The loading's attributes (``case.attrs``) go into the result's attrs, its input series
    (``case.series``, e.g. ``ground_acceleration``) become variables sampled at the recorded times.
    ``initial``, ``checkpoint``, ``checkpoint_every`` and ``threads`` are :func:`~rockdem.simulation.simulate`'s.
    """
    settled = None
    if case.run.settle > 0.0 and initial is None:  # (a run continued from its checkpoint was settled when it began)
        initial, settled = settled_start(case)
    options = run_options(case, duration)
    peak = case.attrs.get("earthquake_pga_time_s")
    if peak is not None and options["duration"] < float(peak):
        warn_user(f"the run ends at {options['duration']:g} s ([run] duration or --duration), before the record's peak "
                  f"ground acceleration (at {float(peak):.3g} s of the run): the specimen does not feel the strong "
                  "motion; lengthen the run")
    end = pushover_end(case.attrs)
    if end is not None and options["duration"] < end.time * (1.0 - 1e-9):
        warn_user(f"the run ends at {options['duration']:g} s ([run] duration or --duration), before the pushover reaches "
                  f"{end.what} (at {end.time:.4g} s): the capacity curve stops short of it; lengthen the run")
    ds = simulate(case.model, **options, progress=progress, initial=initial, checkpoint=checkpoint,
                  checkpoint_every=checkpoint_every, threads=threads)
    with _deferred_signals(finishing=True):  # the frames are computed: a stop signal waits for the result
        ds.attrs.update(case.attrs)
        if settled is not None:
            ds.attrs["settled_s"] = settled  # the blocks were settled under gravity alone this long first ([run] settle)
        t = ds.time.values
        for name, (ts, values) in case.series.items():
            v = np.column_stack([np.interp(t, ts, values[:, i], left=0.0, right=0.0) for i in range(values.shape[1])])
            ds[name] = (("time", "xyz"), v, {"units": "m/s2" if "acceleration" in name else "1"})
    return ds


def run_options(case: Case, duration: float | None = None) -> dict[str, Any]:
    """The :func:`rockdem.simulation.simulate` arguments of a case (``duration`` overrides
    [run] duration), checked: the record interval must not exceed the simulated time, and a
    delayed earthquake must start before the run ends."""
    r = case.run
    dur = duration if duration is not None else r.duration
    if r.record_interval > dur:
        raise ValueError(f"[run] record_interval ({r.record_interval:g} s) exceeds the simulated time ({dur:g} s); lower it")
    delay = float(case.attrs.get("earthquake_delay_s", 0.0))
    if delay > 0.0 and delay >= dur:
        raise ValueError(f"[loading] delay = {delay:g} s is not before the run's end ({dur:g} s, [run] duration or "
                         "--duration): the record would never act; shorten the delay or lengthen the run")
    return {"duration": dur, "dt": r.dt, "timestep_rule": r.timestep_rule, "safety": r.safety, "resolution": r.resolution,
            "impact_refinement": r.impact_refinement, "dashpots": r.dashpots, "record_interval": r.record_interval, "monitors": case.monitors, "contact_interval": r.contact_interval,
            "stop": r.stop}


def _row(label: str, value: str, unit: str = "", note: str = "") -> str:
    """One aligned summary row: label, right-aligned value, unit, note."""
    return f"{label:<26} {value:>12}  {unit:<5} {note}".rstrip()


# summarize_result keys -> (label, unit, format)
_ANALYSIS_ROWS: dict[str, tuple[str, str, str]] = {
    "max_rotation_rad": ("peak rotation", "rad", ".4g"),
    "residual_rad": ("residual rotation", "rad", ".4g"),
    "onset_time_s": ("rocking onset", "s", ".4g"),
    "half_cycles": ("half cycles", "", "d"),
    "eta_rad": ("slenderness eta", "rad", ".4g"),
    "exceeded_eta": ("exceeded eta", "", ""),
    "overturned": ("overturned", "", ""),
    "e_a_mean": ("restitution e_a, mean", "", ".4g"),
    "e_a_first": ("restitution e_a, first", "", ".4g"),
    "bounces": ("bounces", "", "d"),
    "bounce_max_m_s": ("largest bounce", "m/s", ".4g"),
}


def summary_lines(ds: xr.Dataset) -> list[str]:
    """Human-readable summary of a result as an aligned table (quantity, value, unit, note): steps,
    timestep, time simulated, peaks, energy balance, failed sub-contacts and the rocking analysis
    of one block (paper Eq. 6 for e_a). Works for results of 0 or 1 frames (a run stopped at t = 0)."""
    a = ds.attrs
    n = int(ds.sizes.get("time", 0))
    lines = [
        _row("steps", f"{int(a.get('steps', 0))}"),
        _row("timestep", f"{a['dt']:.4e}", "s", f"smallest {a.get('dt_min', a['dt']):.4e} s, rule {a.get('timestep_rule', '?')}"),
        _row("time simulated", f"{float(ds.time[-1]) if n else 0.0:.4f}", "s", f"{n} frames, run time {a.get('runtime_s', 0.0):.3f} s"),
    ]
    if a.get("beta_mode") == "auto":
        lines.append(_row("beta (targeted)", f"{float(a['beta']):.5g}", "s",
                          f"mean e_a {float(a['beta_achieved_e_a']):.4f} for target {a['beta_target_restitution']} = "
                          f"{float(a['beta_target_value']):.4f}, {int(a['beta_iterations'])} probe runs, "
                          f"{float(a['beta_search_time_s']):.2g} s"))
    if a.get("beta_mode"):
        for pair in str(a.get("beta_pairs", "")).split("; "):
            if pair and "no free block" not in pair and "no contact possible" not in pair:
                label, value = pair.split(": ", 1)
                lines.append(_row(f"beta {label}", value.split(" s ")[0], "s", value.split(" s ", 1)[-1].strip("()")))
    free = np.flatnonzero(ds.block_free.values)
    carried = load_carried(ds) if n else None  # a load-controlled pushover's base reaction
    b = peak_block = int(free[0]) if len(free) else 0
    if n and len(free):
        theta = np.abs(ds.rocking_angle.values[:, free])
        k = int(np.argmax(np.max(theta, axis=0)))
        b = peak_block = int(free[k])
        peak = float(np.max(theta[:, k]))
        lines.append(_row("peak rotation", f"{peak:.4g}", "rad",
                          f"{np.degrees(peak):.3f} deg, block {str(ds.block_name.values[b])!r}, about {_axis(a)}"))
        if "monitor_displacement" in ds and ds.sizes.get("monitor", 0):
            ref = ds.monitor_displacement.attrs.get("reference", "")
            note = "relative to the ground" if ref == "ground" else f"in the {ref}" if ref else ""
            for j, name in enumerate(ds.monitor.values):
                d = np.linalg.norm(ds.monitor_displacement.values[:, j, :], axis=1)
                lines.append(_row(f"peak |u| at {name!s}", f"{np.max(d) * 1e3:.4g}", "mm", note))
        if "energy_balance_error_relative" in ds:
            errors = ds.energy_balance_error_relative.values
            err = float(np.max(np.abs(errors)))
            joules = float(np.max(np.abs(ds.energy_balance_error.values))) if "energy_balance_error" in ds else 0.0
            lift = LIFT_1MM * float(ds.block_mass.values[ds.block_free.values.astype(bool)].sum()) if "block_mass" in ds else 0.0
            if err > 0.0 and joules / err < REST_SHARE * lift:
                # nothing moved (no gravity, no loading): the scale the error is divided by is noise
                lines.append(_row("energy balance error", f"{joules:.2e}", "J", "largest, absolute: the run's energies stay "
                                  "below 1e-3 of lifting its free blocks by 1 mm, a relative error would be noise"))
            else:
                # the largest is a transient at impact frames (the leapfrog's energy at t_n during an
                # impact), so it depends on where the frames fall
                lines.append(_row("energy balance error", f"{err:.2e}", "",
                                  f"largest, relative (at impacts: depends on the frame times); at the end {float(errors[-1]):.2e}"))
        if carried is not None:
            past = "; past the capacity (below): not a capacity" if carried.exceeded is not None else ""
            lines.append(_row("load factor carried", f"{carried.carried:.4g}", "",
                              f"base reaction / weight, mean of the last {carried.window:.3g} s (applied {carried.applied_mean:.4g} "
                              f"there); peak {carried.peak:.4g} at t = {carried.peak_time:.4g} s, with its ringing{past}"))
        npts = max(int(a.get("point_count", 1)), 1)
        for mode in ("shear", "tension"):
            var = f"contacts_failed_{mode}"
            if var in ds:
                failed = int(ds[var].values[-1])
                lines.append(_row(f"failed in {mode}", f"{failed}", "", f"{100 * failed / npts:.1f} % of {npts} sub-contacts"))
        if len(free) > 1 and all(v in ds for v in ("block_position", "vertex_local", "block_vertex_start")):
            lines.append(_blocks_row("fallen blocks", ds, fallen_blocks(ds), len(free),
                                     f"centroid dropped by over {FALL_FRACTION:g} of its smallest dimension, or tipped "
                                     f"past {math.degrees(TIPPED_ANGLE):.0f} deg"))
        if a.get("fell_off_blocks"):
            names = [s.strip() for s in str(a["fell_off_blocks"]).split(",")]
            times = np.atleast_1d(np.asarray(a.get("fell_off_times", np.full(len(names), np.nan)), dtype=float))
            listed = ", ".join(f"{n} at {t:.3g} s" for n, t in zip(names[:3], times[:3])) + (", ..." if len(names) > 3 else "")
            lines.append(_row("fell off the supports", f"{len(names)}", "",
                              f"of {len(free)}: falling on unhindered ({listed}); a larger foundation keeps them"))
        if len(free) > 1 and "block_eta" in ds:
            with np.errstate(invalid="ignore"):
                tipped = free[np.abs(ds.rocking_angle.values[-1, free]) > ds.block_eta.values[free]]
            lines.append(_blocks_row("blocks past their eta", ds, tipped, len(free), "at the end, each about its own base"))
        if int(a.get("tilted_blocks", 0)) > 1:
            # a released assembly (e.g. a discretised wall): analyse a block of its base course
            z0 = ds.block_position.values[0, free, 2]
            b = int(free[int(np.argmin(z0))])
            lines.append(_row("analysed block", str(ds.block_name.values[b]), "",
                              f"base of the released assembly of {a['tilted_blocks']} blocks"))
        elif len(free) > 1:
            lines.append(_row("analysed block", str(ds.block_name.values[b]), "",
                              "the largest rotation; its eta and overturning are its own, not the assembly's"))
        if n >= 2:
            lines.extend(_analysis_lines(ds, b, skip=("max_rotation_rad",) if b == peak_block else ()))
    else:
        lines.append(_row("recorded frames", f"{n}", "", "nothing to summarise"))
    if a.get("stop_reason"):
        what = {"overturned": f"block {a.get('stop_block')!r} overturned", "fell": f"block {a.get('stop_block')!r} fell",
                "rest": "at rest after the input"}.get(a["stop_reason"], a["stop_reason"])
        lines.append(f"STOPPED at t = {a['stop_time']:.4g} s: {what} (stop = {a.get('stop_rule')!r}); the outcome was decided")
    if carried is not None and carried.exceeded is not None:
        lines.append(f"LOAD EXCEEDED THE CAPACITY from t = {carried.exceeded:.4g} s: the base reaction fell behind the applied "
                     "load and the specimen accelerated (or overturned); the ramp's curve past that time is not a capacity "
                     "(follow the softening branch with [loading] mode = \"displacement\")")
    elif carried is not None and carried.too_fast is not None:
        lines.append(f"NOT QUASI-STATIC from t = {carried.too_fast:.4g} s: the base reaction fell behind the ramp by more than "
                     f"{EQUILIBRIUM_TOLERANCE:.0%} and caught up only after it; the ramp is too fast for the specimen's "
                     "inertia (lower [loading] rate)")
    if a.get("diverged"):
        t_bad, end = float(a["diverged_time"]), float(a.get("duration", np.inf))
        when = f"t = {t_bad:.4g} s" if t_bad <= end else f"the end of the run (its last step reached t = {t_bad:.4g} s)"
        held = ("the frames up to it, the last ones already sinking" if a.get("diverged_reason") == "sank"
                else "the sound frames before it")
        lines.append(f"DIVERGED at {when}: the result holds {held}")
    if a.get("interrupted"):
        lines.append("INTERRUPTED: the result holds the frames computed before the interruption")
    return lines


def _blocks_row(label: str, ds: xr.Dataset, blocks: np.ndarray, of: int, what: str) -> str:
    """A summary row counting ``blocks`` (ids) of ``of`` free blocks, naming the first three."""
    names = ", ".join(str(x) for x in ds.block_name.values[blocks[:3]]) + (", ..." if blocks.size > 3 else "")
    return _row(label, f"{blocks.size}", "", f"of {of}: {what}" + (f" ({names})" if blocks.size else ""))


def _axis(attrs: Any) -> str:
    axis = np.asarray(attrs.get("rocking_axis", (0.0, 1.0, 0.0)), dtype=float).reshape(-1)
    names = {(1.0, 0.0, 0.0): "the x axis", (0.0, 1.0, 0.0): "the y axis", (0.0, 0.0, 1.0): "the z axis"}
    return names.get(tuple(float(v) for v in axis), f"axis {np.array2string(axis, precision=3)}")


def _analysis_lines(ds: xr.Dataset, block: int, skip: tuple[str, ...] = ()) -> list[str]:
    from .analysis import summarize_result

    try:
        summary: dict[str, Any] = summarize_result(ds, block=block)
    except ValueError as exc:
        return [_row("rocking analysis", "skipped", "", str(exc))]
    out = []
    diverged = bool(ds.attrs.get("diverged"))
    stop = ds.attrs.get("stop_reason")
    # A run stopped at collapse whose analysed block did not overturn about its own base (a column
    # toppling as one, its top block falling first): the row must not read as "no collapse".
    collapse = (f"this block about its own base; the run stopped at collapse (block {ds.attrs.get('stop_block')!r} "
                f"{'fell' if stop == 'fell' else 'overturned'})") if stop in ("fell", "overturned") else ""
    for key, value in summary.items():
        label, unit, fmt = _ANALYSIS_ROWS.get(key, (key.replace("_", " "), "", ""))
        if key in skip:
            continue
        if isinstance(value, bool):
            # a run cut as diverged (sunk, lost, energy created) has no outcome: its last frames are unsound
            note = "the run diverged: not an outcome" if diverged and key in ("exceeded_eta", "overturned") else ""
            if collapse and not value and key in ("exceeded_eta", "overturned"):
                note = collapse
            out.append(_row(label, "yes" if value else "no", unit, note))
        elif isinstance(value, (int, float, np.number)):
            out.append(_row(label, format(value, fmt or ".4g") if fmt != "d" else f"{int(value)}", unit))
        elif value is None:
            out.append(_row(label, "-", unit, "not reached"))
        elif isinstance(value, str):
            out.append(_row(label, value, unit))
    return out


def plot_rocking(ds: xr.Dataset, path: Path) -> Path:
    """Rotation and top displacement versus time (and the input motion of an earthquake run),
    saved as PNG."""
    return draw_rocking(rocking_series(ds), path)


def continue_command(args: argparse.Namespace, checkpoint: str | os.PathLike[str]) -> str:
    """The command line that continues an interrupted ``rockdem run`` from ``checkpoint``: the same
    case, overrides, duration, output folder and stop rule (shell-quoted)."""
    words = ["rockdem", "run", *(["--example", args.example] if args.example else [str(args.case)])]
    words += ["--from", str(checkpoint)]
    for item in args.set or []:
        words += ["--set", item]
    for flag, value in (("--duration", args.duration), ("--out", args.out), ("--stop", args.stop),
                        ("--checkpoint-every", args.checkpoint_every), ("--threads", args.threads)):
        if value is not None:
            words += [flag, str(value)]
    for flag, on in (("--quiet", args.quiet), ("--no-plot", args.no_plot)):
        if on:
            words.append(flag)
    return shlex.join(words)


def _run(args: argparse.Namespace) -> int:
    if args.list_examples:
        print("\n".join(example_names()))
        return 0
    if args.case is None and args.example is None:
        raise ValueError("give a case file (rockdem run CASE.toml) or --example NAME (rockdem run --list-examples)")
    if args.case is not None and args.example is not None:
        raise ValueError("give a case file (rockdem run CASE.toml) or --example NAME, not both")
    if args.from_ and args.settled:
        raise ValueError("give --from CHECKPOINT (continue a run) or --settled CHECKPOINT (a new run from its state), not both")
    data = example_case(args.example) if args.example else load_case(args.case)
    data = apply_overrides(data, args.set or [])
    if args.stop is not None:
        data = apply_overrides(data, [f'run.stop="{args.stop}"'])
    if args.duration is not None:  # (before 2026-12-01 a case without one was refused whatever --duration said)
        data = with_duration(data, args.duration)
    t0 = time.perf_counter()
    case = parse_case(data)
    initial = None
    if args.from_ or args.settled:
        initial = load_checkpoint(args.from_ or args.settled)
        initial = initial.reset_clock() if args.settled else initial
        initial.check_model(case.model)
    out = Path(args.out or case.output["directory"] or Path("results") / case.name)
    files = ("result.nc", "histories.csv", "rocking.png", "checkpoint.npz", "contacts.csv", "contacts.parquet")
    output_folder(out, "--out" if args.out else "[output] directory" if case.output["directory"] else "output folder", files)
    earlier = _stamps(out, files)  # an earlier run's outputs (named below where this run does not rewrite them)
    save_ck = case.output["checkpoint"] and not args.no_checkpoint
    every = args.checkpoint_every if args.checkpoint_every is not None else case.output["checkpoint_every"]
    if every is not None and not save_ck:
        raise ValueError("--checkpoint-every needs checkpoints: drop --no-checkpoint ([output] checkpoint = false)")
    received: list[int] = []
    plot = case.output["plot"] and not args.no_plot
    if not plot:
        PlotProcess.discard_early()  # started by the command line before the case said no plot
    # the plot is drawn by a second process, which imports Matplotlib while this one runs
    with PlotProcess.take() if plot else contextlib.nullcontext() as plotter:
        with stop_on_signals(received):  # SIGTERM and SIGHUP stop the run as Ctrl-C does
            ds = run_case(case, duration=args.duration, progress=None if not args.quiet else False, initial=initial,
                          checkpoint=out / "checkpoint.npz" if save_ck else None, checkpoint_every=every,
                          threads=args.threads)
        wall = time.perf_counter() - t0
        written: list[Path] = []
        try:
            with hold_signals(received, "saving the results computed so far"):
                series = rocking_series(ds) if plot else None
                if plotter is not None:
                    plotter.submit(series, out / "rocking.png")
                written.append(save(ds, out / "result.nc"))
                if case.output["csv"]:
                    written.append(export_csv(ds, out / "histories.csv"))
                if "contact_time" in ds.coords and case.output["contacts"] != "none":
                    written.append(write_contact_table(ds, out / "contacts", case.output["contacts"]))
                if plotter is not None:
                    written.append(plotter.draw(series, out / "rocking.png"))
                if "checkpoint" in ds.attrs:
                    written.append(Path(ds.attrs["checkpoint"]))
        except KeyboardInterrupt:  # a second stop signal abandoned the save: say what the folder holds
            now = _stamps(out, files)
            new = [f for f in now if earlier.get(f) != now[f]]
            left = [f for f in now if earlier.get(f) == now[f]]
            print(f"rockdem run: the save was abandoned; written: {', '.join(new) or 'nothing'}"
                  + (f"; {out} also holds {', '.join(left)} of an earlier run" if left else ""), file=sys.stderr)
            raise
    print(f"rockdem run: {case.name}")
    for line in summary_lines(ds):
        print("  " + line)
    print("  " + _row("wall time", f"{wall:.2f}", "s", "including set-up (and compilation on a first run)"))
    for p in written:
        print("  " + _row("wrote", "", "", str(p)))
    now = _stamps(out, files)
    left = [f for f in now if earlier.get(f) == now[f]]
    if left:  # (before 2026-12-01 they stayed beside the new result without a word)
        print(f"rockdem run: warning: {out} also holds {', '.join(left)} of an earlier run, not written by this one "
              "(remove them, or give another --out)", file=sys.stderr)
    if ds.attrs.get("interrupted"):  # stopped before the end: the frames computed so far are saved
        if "checkpoint" in ds.attrs:
            print(f"  continue with: {continue_command(args, ds.attrs['checkpoint'])}")
        return 128 + (received[0] if received else signal.SIGINT)
    if received:  # the signal came once every frame was computed: the result is complete and saved
        print(f"rockdem run: {signal.Signals(received[0]).name} came after the run had ended; the result is complete",
              file=sys.stderr)
    return EXIT_DIVERGED if ds.attrs.get("diverged") else 0


def _stamps(out: Path, files: tuple[str, ...]) -> dict[str, tuple[int, int]]:
    """(modification time [ns], size [bytes]) of each of ``files`` found in ``out``, by name: a file
    whose stamp a run left unchanged is an earlier run's."""
    stamps = {}
    for f in files:
        try:
            st = (out / f).stat()
        except OSError:
            continue
        stamps[f] = (st.st_mtime_ns, st.st_size)
    return stamps


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``run`` sub-command."""
    p = subparsers.add_parser(
        "run",
        help="run a case file or a built-in example",
        description="Run a TOML case file (or a built-in example), save result.nc, histories.csv, "
        "rocking.png and checkpoint.npz (contacts.csv with [run] contact_interval), and print a summary.",
        epilog="Exit status: 0 done; 2 bad input (nothing run); 3 the run diverged (the result holds the "
        "frames before it); 128+N stopped by signal N (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP): the frames "
        "computed so far are saved. A signal once every frame is computed is held: the complete result is "
        "saved, with the run's own exit status. An interrupt while saving is held (the save goes on); a "
        "second one abandons the save.",
    )
    p.add_argument("case", nargs="?", help="TOML case file")
    p.add_argument("--example", help=f"built-in example ({', '.join(example_names())})")
    p.add_argument("--list-examples", action="store_true", help="list the built-in examples")
    p.add_argument("--out", "-o", help="output directory (default results/<case name>)")
    p.add_argument("--set", action="append", metavar="TABLE.KEY=VALUE",
                   help="override a case value (repeatable); TABLE.KEY= with no value removes the key")
    p.add_argument("--duration", type=positive_float, help="simulated time [s], overrides [run] duration")
    p.add_argument("--stop", choices=STOP_MODES, default=None,
                   help="end the run once its outcome is decided: collapsed, or at rest after the input "
                   "(default: [run] stop, off; docs/studies.md)")
    p.add_argument("--no-plot", action="store_true", help="do not write the PNG plot")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--from", dest="from_", metavar="CHECKPOINT",
                   help="continue the run saved in CHECKPOINT (OUT/checkpoint.npz) up to the case's duration "
                        "(or --duration): the same case and options; the result holds all frames from t = 0")
    p.add_argument("--settled", metavar="CHECKPOINT",
                   help="start this case at t = 0 from the state saved in CHECKPOINT (e.g. a model settled under "
                        "gravity): the same blocks and joints, any loading and damping")
    p.add_argument("--checkpoint-every", type=positive_float, metavar="SECONDS",
                   help="also write OUT/checkpoint.npz every SECONDS of wall time (always written at the end and "
                        "when stopped)")
    p.add_argument("--no-checkpoint", action="store_true", help="do not write OUT/checkpoint.npz")
    p.add_argument("--threads", type=positive_int, metavar="N",
                   help="threads for the joint law (default: all for models of 200 blocks or more, else 1; "
                        "the same answer on any number)")
    p.set_defaults(func=_run)
