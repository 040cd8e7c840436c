"""Calibration: parameters that minimise the WME against a reference history (paper §3.1, §4).

The paper matched alpha (MP) and beta (SP) "by lengthy and tedious trial and error" (§4.2); here
SciPy does it. One parameter: ``scipy.optimize.minimize_scalar(method="bounded")`` (optionally in
log space), after a coarse scan that brackets the global minimum (WME curves of rocking are not
convex: the scan picks the best cell and the bounded search refines inside its neighbours). Several
parameters (e.g. joint ``kn``, ``cohesion``, ``tension``, ``friction_angle_deg``): Powell with bounds
on scaled variables.

The report gives the optimum, the WME curve around it (relative changes of -20 .. +20 %) and a
sensitivity figure: the largest WME increase for a +-5 % and +-10 % change of the parameter. The
paper's observation that MP (alpha) results change a lot for small alpha changes while SP (beta)
results are robust shows up there as a much larger sensitivity for ``damping.alpha``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ._warn import warn_user
from .analysis import rest_time, wme
from .plots import save_figure
from .case import parse_assignment
from .studies import RunSpec, Store, check_first_run, execute, resolve_base, with_stop

__all__ = ["Reference", "load_reference", "reference_from_row", "CalibrationResult", "calibrate", "wme_of_row", "register_cli"]

QUANTITIES = ("rotation", "displacement")
SENSITIVITY_STEPS = (-0.20, -0.10, -0.05, -0.02, 0.02, 0.05, 0.10, 0.20)
MAX_RECENTRES = 8
"""Times the WME curve is moved onto a better point it found, at most (one parameter)."""
POWELL_RESTARTS = 3
"""Several parameters: Powell is restarted from its result at most this many times while it improves the WME by 10 %."""


@dataclass(frozen=True)
class Reference:
    """A reference history: time [s] and values (rotation [rad] or displacement [m])."""

    time: np.ndarray
    value: np.ndarray
    quantity: str = "rotation"


def load_reference(path: str | os.PathLike[str], *, quantity: str = "rotation", column: int = 1) -> Reference:
    """Read a reference history.

    ``.nc``: a rockdem result (rotation of the first free block, or the first monitor's x
    displacement). Otherwise a CSV/text file of time and value columns (header lines skipped).
    """
    p = Path(path)
    if p.is_dir():
        raise ValueError(f"reference {p} is a folder; give a CSV or text file of time and value, or a rockdem result .nc")
    if not p.is_file():
        raise FileNotFoundError(f"reference {p} does not exist")
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {QUANTITIES}, got {quantity!r}")
    if isinstance(column, bool) or not isinstance(column, (int, np.integer)) or column < 1:
        raise ValueError(f"reference column must be 1 or more (zero-based; column 0 holds the time), got {column!r}")
    if p.suffix == ".nc":
        from .plots import read_result_file

        ds = read_result_file(p, "reference")
        t = np.asarray(ds.time.values, dtype=float)
        if quantity == "rotation":
            free = np.flatnonzero(ds.block_free.values)
            if free.size == 0:
                raise ValueError(f"reference {p}: the result has no free block whose rotation to match")
            x = np.asarray(ds.rocking_angle.values[:, int(free[0])], dtype=float)
        else:
            if ds.sizes.get("monitor", 0) == 0:
                raise ValueError(f"reference {p}: the result has no monitor; use --quantity rotation or a result "
                                 "with a monitor")
            x = np.asarray(ds.monitor_displacement.values[:, 0, 0], dtype=float)
        return Reference(t, x, quantity)
    need = (f"need rows of time [s] and value (column {column}, zero-based), separated by commas or spaces, or by "
            "semicolons or tabs (then with decimal points or commas)")
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"reference {p}: not a text file; {need}") from None
    lines = [line.split("#", 1)[0].strip() for line in text.splitlines()]
    split = _splitter([line for line in lines if line])
    rows, widths = [], set()
    nonfinite = 0
    for line in lines:
        try:
            values = [float(f) for f in split(line)]
        except ValueError:
            continue  # a header, a note, or a row with an empty field
        if values and all(math.isfinite(v) for v in values):
            widths.add(len(values))
            rows.append(values)
        elif values:
            nonfinite += 1
    if nonfinite:
        warn_user(f"reference {p}: {nonfinite} row(s) with NaN or infinite values left out")
    if rows and min(widths) <= column:
        raise ValueError(f"reference {p}: {need}; found {min(widths)} column(s)")
    if len(rows) < 2:
        raise ValueError(f"reference {p}: {len(rows)} numeric row(s) of finite values; {need}, at least two rows")
    t = np.array([r[0] for r in rows])
    if np.any(np.diff(t) <= 0.0):
        k = int(np.flatnonzero(np.diff(t) <= 0.0)[0])
        raise ValueError(f"reference {p}: its times must increase, but {t[k + 1]:g} s follows {t[k]:g} s (numeric row {k + 2})")
    return Reference(t, np.array([r[column] for r in rows]), quantity)


def _splitter(lines: Sequence[str]) -> Callable[[str], list[str]]:
    """How a reference file's lines split into fields, chosen for the whole file: at semicolons
    where it has them, or at tabs in a file without decimal points, with decimal commas
    ("0,1;0,25", as spreadsheets in many locales write); else at commas ("0.1, 0.25"; an empty
    field leaves its row out); else at spaces ("   0.100   0.250")."""
    text = "\n".join(lines)
    if ";" in text or ("\t" in text and "," in text and "." not in text):
        sep = ";" if ";" in text else "\t"
        return lambda line: [f.strip().replace(",", ".") for f in line.split(sep)] if line else []
    if "," in text:
        return lambda line: [f.strip() for f in line.split(",")] if line else []
    return lambda line: line.split()


def reference_from_row(row: Mapping[str, Any], quantity: str = "rotation") -> Reference:
    """A reference from a study row run with ``history=True``."""
    h = row["history"]
    return Reference(np.asarray(h["time"], float), np.asarray(h[quantity], float), quantity)


FAILED_WME = 1e3
"""The WME a failed run (an error, a divergence) is given in a calibration: worse than any run's."""


def failure_of_row(row: Mapping[str, Any]) -> str | None:
    """Why a run failed (an error, a divergence), or None."""
    if row.get("status") == "error":
        return str(row.get("error", "error"))
    if row.get("status") != "ok":
        return f"diverged at {row.get('diverged_time_s', '?')} s" if row.get("status") == "diverged" else str(row.get("status"))
    return None


def _check_reference_span(ref: Reference, duration: Any) -> None:
    """Refuse, before any run, a reference that does not move (the WME's cut at rest leaves nothing to
    compare) and a duration that ends before its motion does (the WME would refuse every run:
    before 2026-11-30 the command said so only after the first run, naming options of the Python
    function, not of the command)."""
    t_end = rest_time(ref.time, ref.value)
    if np.count_nonzero(ref.time <= t_end) < 2:
        raise ValueError(f"the reference's {ref.quantity} never moves by more than 1 % of its range from "
                         "its end value, so there is nothing to calibrate against; check the file and its column")
    if isinstance(duration, (int, float)) and not isinstance(duration, bool) and float(duration) < t_end:
        raise ValueError(f"duration = {float(duration):g} s ends before the reference's motion does ({t_end:.4g} s): "
                         f"the runs could not be compared over it; give at least {t_end:.4g} s (--duration), or leave "
                         "the duration out (the reference's length)")


def wme_of_row(row: Mapping[str, Any], ref: Reference) -> float:
    """WME of a run row (with history) against the reference; FAILED_WME for failed runs."""
    if failure_of_row(row) is not None or "history" not in row:
        return FAILED_WME
    h = row["history"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return wme(ref.time, ref.value, np.asarray(h["time"]), np.asarray(h[ref.quantity]))


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate`.

    Attributes:
        parameters: calibrated keys.
        optimum: best values, by key.
        wme: WME at the optimum.
        evaluations: every evaluated point (parameter columns, ``wme``), in evaluation order.
        curve: WME around the optimum (one parameter): ``relative_change``, value, ``wme``.
        sensitivity: largest WME increase for +-2/5/10/20 % changes (one parameter), e.g. ``{"5%": 0.12}``.
        notes: caveats (a better point outside the bounds, a curve not centred on its minimum, runs
            that failed).
        failed: how many evaluated runs failed (their WME is FAILED_WME; ``evaluations.error``).
        flat: the WME did not depend on the parameters over the bounds (:data:`FLAT_WME`): the
            optimum is an arbitrary point, nothing was calibrated (a note says so).

    The optimum is the best point evaluated within the bounds (scan, search and curve alike): the
    WME curve is re-centred on any better point it finds, so its 0 % row is the optimum.
    """

    parameters: list[str]
    optimum: dict[str, float]
    wme: float
    evaluations: pd.DataFrame
    curve: pd.DataFrame | None = None
    sensitivity: dict[str, float] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    failed: int = 0
    flat: bool = False

    def report(self) -> str:
        """Plain-text report."""
        lines = [f"optimum   {', '.join(f'{k} = {v:.6g}' for k, v in self.optimum.items())}", f"WME       {self.wme:.4g}",
                 f"evaluations {len(self.evaluations)}"]
        if self.curve is not None:
            lines.append("WME around the optimum:")
            for _, r in self.curve.iterrows():
                lines.append(f"  {r['relative_change']:+6.0%}  {self.parameters[0]} = {r[self.parameters[0]]:.6g}  WME = {r['wme']:.4g}")
        if self.sensitivity:
            lines.append("sensitivity (largest WME increase over the optimum for a +- change of the parameter):")
            lines.extend(f"  +-{k:>4s}  dWME = {v:.4f}" for k, v in self.sensitivity.items())
        lines.extend(f"note: {n}" for n in self.notes)
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        return {"parameters": self.parameters, "optimum": self.optimum, "wme": self.wme, "sensitivity": self.sensitivity,
                "notes": self.notes, "failed": self.failed, "flat": self.flat}


def calibrate(
    base: str | Mapping[str, Any],
    parameters: str | Sequence[str],
    bounds: Sequence[float] | Sequence[Sequence[float]],
    reference: Reference | str | os.PathLike[str],
    *,
    fixed: Mapping[str, Any] | None = None,
    duration: float | None = None,
    log: bool = True,
    scan_points: int = 9,
    xatol: float = 1e-3,
    maxiter: int = 40,
    curve: bool = True,
    executor: str = "process",
    workers: int | None = None,
    scheduler: Any = None,
    store: Any = None,
    stop: str = "rest",
) -> CalibrationResult:
    """Find the parameter value(s) minimising WME(reference, simulation).

    Args:
        base: base case (example name, path or dict).
        parameters: ``"damping.beta"``, ``"damping.alpha"``, or several keys (joint parameters,
            e.g. ``["specimen.kn", "specimen.tension"]``).
        bounds: ``(low, high)`` for one parameter, one pair per parameter for several.
        reference: the reference history (quantity ``rotation`` or ``displacement``).
        fixed: other overrides applied to every run.
        duration: simulated time [s] (default: the reference's last time).
        log: search in log(parameter) (needs positive bounds); relative accuracy is what matters.
        scan_points: coarse scan (in parallel) before the bounded search (one parameter), >= 3.
        xatol: tolerance of the bounded search, in the search variable (log units when ``log``).
        maxiter: iteration limit of the optimiser.
        curve: evaluate the WME curve and sensitivity around the optimum (one parameter).
        executor, workers, scheduler: how the scan and curve runs execute (see
            :func:`rockdem.studies.execute`); optimiser steps run one by one in this process.
        store: optional store, so that a repeated calibration reuses finished runs.
        stop: the runs' ``run.stop`` (:mod:`rockdem.stopping`) unless ``fixed`` sets it: "rest"
            (default) ends a run once it is at rest after its input and continues its history at
            rest to the duration, so that it compares with the reference; "off" runs to the end.
            (Not "decided": a run stopped as collapsed has no history to compare after the stop.)
    """
    from scipy.optimize import minimize, minimize_scalar

    if isinstance(reference, (str, os.PathLike)):
        reference = load_reference(reference)
    if not isinstance(reference, Reference):
        raise ValueError(f"reference must be a Reference (load_reference) or a file path, got {type(reference).__name__}")
    keys = [parameters] if isinstance(parameters, str) else list(parameters)
    try:
        bnds = [tuple(map(float, bounds))] if isinstance(parameters, str) else [tuple(map(float, b)) for b in bounds]
    except (TypeError, ValueError):
        bnds = []
    if len(bnds) != len(keys) or any(len(b) != 2 or not b[1] > b[0] for b in bnds):
        raise ValueError(f"bounds: give one (low, high) pair with low < high per parameter ({len(keys)} parameter(s): "
                         f"{keys}), got {bounds!r}")
    if log and any(b[0] <= 0 for b in bnds):
        raise ValueError("log search needs positive bounds (use log=False for a parameter that may be 0)")
    base_d = resolve_base(base)
    if stop not in ("rest", "off"):
        raise ValueError(f"calibrate: stop must be 'rest' or 'off', got {stop!r} (a run stopped as collapsed has no history to compare)")
    both = sorted(set(keys) & set(fixed or {}))
    if both:
        raise ValueError(f"calibrate: {both} both calibrated and fixed (--set): the fixed value would be ignored; "
                         "leave the parameter out of the fixed overrides")
    fixed = with_stop(fixed, stop)
    # the duration: given, else a fixed run.duration, else the reference's last time
    dur = float(duration) if duration is not None else None if "run.duration" in fixed else float(reference.time[-1])
    _check_reference_span(reference, dur if dur is not None else fixed.get("run.duration"))
    evals: list[dict[str, Any]] = []
    cache: dict[str, float] = {}

    def to_x(v: Sequence[float]) -> np.ndarray:
        return np.log(v) if log else np.asarray(v, float)

    def to_v(x: Sequence[float]) -> list[float]:
        return [float(z) for z in (np.exp(x) if log else x)]

    def spec(values: Sequence[float]) -> RunSpec:
        return RunSpec.make(base_d, {**(fixed or {}), **dict(zip(keys, values))}, duration=dur, history=True)

    check_first_run([spec([b[0] for b in bnds])], "the calibration")

    def record(s: RunSpec, row: Mapping[str, Any], values: Sequence[float]) -> float:
        if s.id not in cache:
            cache[s.id] = wme_of_row(row, reference)
            evals.append({**dict(zip(keys, values)), "wme": cache[s.id], "error": failure_of_row(row)})
        return cache[s.id]

    def batch(values_list: list[list[float]]) -> list[float]:
        specs = [spec(v) for v in values_list]
        todo = [s for s in specs if s.id not in cache]
        if todo:
            rows = {r["id"]: r for r in execute(todo, store, executor=executor if len(todo) > 1 else "serial",
                                                 workers=workers, scheduler=scheduler, progress=False)}
            for s, v in zip(specs, values_list):
                if s.id in rows:
                    record(s, rows[s.id], v)
            if all(e["error"] is not None for e in evals):  # nothing to compare: no optimum to report
                raise ValueError(f"calibration: every run so far failed ({len(evals)}), e.g. at "
                                 f"{', '.join(f'{k} = {evals[0][k]:.6g}' for k in keys)}: {evals[0]['error']}")
        return [cache[s.id] for s in specs]

    def objective(x: Sequence[float]) -> float:
        v = to_v(np.atleast_1d(x))
        v = [min(max(vi, b[0]), b[1]) for vi, b in zip(v, bnds)]
        return batch([v])[0]  # one run, serial, through the store (a rerun reuses it)

    lo, hi = to_x([b[0] for b in bnds]), to_x([b[1] for b in bnds])
    if len(keys) == 1:
        grid = np.linspace(lo[0], hi[0], max(3, scan_points))
        w = batch([to_v([g]) for g in grid])
        k = int(np.argmin(w))
        a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
        res = minimize_scalar(lambda x: objective([x]), bounds=(a, b), method="bounded",
                              options={"xatol": xatol, "maxiter": maxiter})
        cands = [(w[k], [grid[k]]), (float(res.fun), [float(res.x)])]
    else:
        # Powell, restarted from its result with fresh directions while that still improves: the
        # WME valley of correlated parameters (tilt and alpha) is narrow, diagonal and V-shaped,
        # where one pass stops short of the bottom.
        x0 = 0.5 * (lo + hi)
        cands = []
        for _ in range(POWELL_RESTARTS + 1):
            res = minimize(objective, x0, method="Powell", bounds=list(zip(lo, hi)),
                           options={"xtol": xatol, "maxiter": maxiter})
            cands.append((float(res.fun), list(res.x)))
            if len(cands) > 1 and not cands[-1][0] < 0.9 * cands[-2][0]:
                break
            x0 = np.asarray(res.x)
    best_w, best_x = min(cands, key=lambda c: c[0])
    best_v = to_v(best_x)

    def inside(e: Mapping[str, Any]) -> bool:
        return all(b[0] <= float(e[k]) <= b[1] for k, b in zip(keys, bnds))

    def best_evaluated() -> tuple[float, list[float]]:
        # rocking WME surfaces are rough: the optimiser's last point is not always the best one seen
        top = min((e for e in evals if inside(e)), key=lambda e: e["wme"])
        if top["wme"] < best_w:
            return float(top["wme"]), [float(top[k]) for k in keys]
        return best_w, best_v

    best_w, best_v = best_evaluated()
    result = CalibrationResult(keys, dict(zip(keys, best_v)), float(best_w), pd.DataFrame(evals))
    if len(keys) == 1 and curve:
        steps = [0.0, *SENSITIVITY_STEPS]
        for _ in range(MAX_RECENTRES + 1):
            vals = [[best_v[0] * (1.0 + s)] for s in steps]
            w = batch(vals)
            previous = best_v
            best_w, best_v = best_evaluated()
            if best_v == previous:
                break  # the curve is centred on the best point evaluated
        cur = pd.DataFrame({"relative_change": steps, keys[0]: [v[0] for v in vals], "wme": w}).sort_values("relative_change")
        result.curve = cur.reset_index(drop=True)
        result.optimum, result.wme = dict(zip(keys, best_v)), float(best_w)
        w0 = w[0]
        for mag in sorted({abs(s) for s in SENSITIVITY_STEPS}):
            near = [wi for s, wi in zip(steps, w) if abs(abs(s) - mag) < 1e-12]
            result.sensitivity[f"{mag:.0%}"] = float(max(near) - w0)
        result.evaluations = pd.DataFrame(evals)
    failed = [e for e in evals if e["error"] is not None]
    if failed:
        result.failed = len(failed)
        result.notes.append(f"{len(failed)} of {len(evals)} runs failed (WME {FAILED_WME:g} taken there; the error column of "
                            f"the evaluations), e.g. at {', '.join(f'{k} = {failed[0][k]:.6g}' for k in keys)}: {failed[0]['error']}")
    ok = [e["wme"] for e in evals if e["error"] is None]
    margin = FLAT_WME * max(ok, default=0.0)  # differences below it are no improvement
    if len(ok) >= 3 and max(ok) - min(ok) <= margin:
        note = (f"the WME does not depend on {', '.join(keys)} over the bounds: all {len(ok)} runs gave {min(ok):.4g}, "
                "to 1e-6, so the optimum reported is an arbitrary point; the runs' history does not see the parameter "
                "there (a reference too short for it, or another quantity): nothing was calibrated")
        result.notes.append(note)
        result.flat = True
        warn_user(f"calibration: {note}")
        return result  # (the notes below would compare equal values)
    outside = [e for e in evals if not inside(e) and e["wme"] < result.wme - margin]
    if outside:
        e = min(outside, key=lambda e: e["wme"])
        result.notes.append(f"a point outside the bounds did better: {', '.join(f'{k} = {e[k]:.6g}' for k in keys)} "
                            f"(WME {e['wme']:.4g}); widen the bounds")
    if result.curve is not None and float(result.curve["wme"].min()) < result.wme - margin:
        result.notes.append("the curve around the optimum is not centred on its minimum "
                            f"(after {MAX_RECENTRES} re-centrings); the WME surface is rough here")
    return result


def plot_calibration(result: CalibrationResult, reference: Reference, path: str | os.PathLike[str]) -> Path:
    """WME curve (evaluations and the curve around the optimum) next to nothing else: one figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    key = result.parameters[0]
    fig, ax = plt.subplots(figsize=(6, 4))
    ev = result.evaluations.sort_values(key)
    ax.plot(ev[key], ev["wme"], "o", ms=3, color="0.5", label="evaluations")
    if result.curve is not None:
        ax.plot(result.curve[key], result.curve["wme"], "-o", ms=4, label="around the optimum")
    ax.axvline(result.optimum[key], color="k", lw=0.8, ls="--")
    ax.set_xscale("log")
    ax.set_xlabel(key)
    ax.set_ylabel("WME [-]")
    ax.set_title(f"{key} = {result.optimum[key]:.4g}, WME = {result.wme:.3f}")
    ax.legend()
    fig.tight_layout()
    p = save_figure(fig, path)
    plt.close(fig)
    return p


FLAT_WME = 1e-6
"""Relative spread of the evaluated WME below which the surface is flat: the parameter does not
act on the runs' history (before 2026-12-01 a calibration against a reference of two samples 0.2 s
apart, WME 4.322 at every point to 3e-7, reported the lower bound as its optimum and its surface
as rough)."""


def _calibrate_cli(args: argparse.Namespace) -> int:
    from .cli import hold_signals, output_folder, stop_on_signals

    ref = load_reference(args.reference, quantity=args.quantity)
    fixed = dict(parse_assignment(item) for item in args.set or [])
    if not args.linear and min(args.bounds) <= 0:
        raise ValueError(f"--bounds {args.bounds[0]:g} {args.bounds[1]:g}: the search is in log(parameter) and needs "
                         "positive bounds; add --linear for a parameter that may be 0")
    out = output_folder(args.out, "--out", create=False) if args.out else None
    store = Store(out) if out is not None else None  # finished runs kept: a rerun resumes
    received: list[int] = []
    try:
        with stop_on_signals(received):  # SIGTERM and SIGHUP stop it as Ctrl-C does
            res = calibrate(args.base, args.parameter, args.bounds, ref, fixed=fixed, duration=args.duration,
                            log=not args.linear, scan_points=args.scan, executor=args.executor or "process",
                            workers=args.workers, scheduler=args.scheduler, stop=args.stop, store=store)
        if out is not None:  # the files first: a closed standard output must not lose them
            # A stop signal here is held until every file is written (a second one abandons them):
            # before 2026-12-01 a Ctrl-C while they were written left evaluations.csv and curve.csv
            # without report.txt.
            with hold_signals(received, "writing the calibration's files"):
                out.mkdir(parents=True, exist_ok=True)
                res.evaluations.to_csv(out / "evaluations.csv", index=False)
                if res.curve is not None:
                    res.curve.to_csv(out / "curve.csv", index=False)
                    plot_calibration(res, ref, out / "wme.png")
                (out / "calibration.json").write_text(json.dumps(res.to_json(), indent=2))
                (out / "report.txt").write_text(res.report() + "\n")
    except KeyboardInterrupt:
        print(f"rockdem calibrate: stopped; {store.kept() if store is not None else 'give --out to keep finished runs'}",
              file=sys.stderr)
        raise
    print(res.report())
    if received:  # held while the files were written (or come as the calibration ended): they are complete
        print(f"rockdem calibrate: {signal.Signals(received[-1]).name} came as the calibration ended; its files are "
              "complete", file=sys.stderr)
        return 128 + received[-1]
    return 1 if res.failed or res.flat else 0  # as a sweep with failed runs


def register_cli(subparsers: argparse._SubParsersAction, add_exec_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """Add ``calibrate``."""
    p = subparsers.add_parser("calibrate", help="find a parameter minimising WME against a reference history",
                              epilog="Exit status: 0 done; 1 some runs failed (counted in the report's notes; WME 1000 "
                              "taken there), or the WME does not depend on the parameter (nothing calibrated); 2 bad "
                              "input, or every run failed (nothing to compare); 128+N stopped by signal N (130 Ctrl-C): "
                              "the finished runs kept in --out, a rerun resumes; a signal while the files are written "
                              "is held until they are complete (a second one abandons them).")
    p.add_argument("reference", help="reference: CSV (time, value) or a rockdem result .nc")
    p.add_argument("--base", default="free-rocking", help="base case: example name or TOML path")
    p.add_argument("--parameter", default="damping.beta", help="table.key to calibrate (damping.alpha, specimen.kn, ...)")
    p.add_argument("--bounds", nargs=2, type=float, required=True, metavar=("LOW", "HIGH"))
    p.add_argument("--quantity", choices=QUANTITIES, default="rotation")
    p.add_argument("--set", action="append", metavar="table.key=value", help="fixed override (repeatable)")
    p.add_argument("--duration", type=float, default=None, help="simulated time [s] (default: the reference's)")
    p.add_argument("--linear", action="store_true", help="search in the parameter itself, not its log")
    p.add_argument("--scan", type=int, default=9, help="coarse scan points before the bounded search")
    p.add_argument("--stop", choices=("rest", "off"), default="rest",
                   help="end each run once it is at rest after its input (default; its history is continued at rest) or run it to the end")
    p.add_argument("--out", "-o", default=None, help="folder for report.txt, curve.csv, wme.png and runs.jsonl (a rerun resumes)")
    add_exec_args(p)
    p.set_defaults(func=_calibrate_cli)
