"""Incremental dynamic analysis (IDA) and lognormal fragility curves.

Each record of a set is scaled to a range of peak ground accelerations (PGA [g]); each (record,
PGA) pair is a :class:`rockdem.studies.RunSpec` run through the study executors (batch path) and
store, by default stopping each run once its outcome is decided (``run.stop = "decided"``,
:mod:`rockdem.stopping`). A run fails (collapse) when the block overturns, when it stopped because
it collapsed, or when its peak rotation exceeds ``drift_limit`` x eta (eta = slenderness angle).
Only runs that finished (status "ok") have an outcome: runs that raised an error (e.g. an
unreadable record) or diverged are counted apart and never enter a fit.

Every run's input gets its intensity measures (:mod:`rockdem.intensity`: PGV, Arias intensity,
Sa(T) at the block's characteristic period, beside the PGA), and the fragility
P(fail | IM) = Phi(ln(IM / theta) / beta) is fitted against each of them by maximum likelihood: on
(IM, failed) outcomes with a binomial likelihood (Baker 2015), or on the per-record collapse
capacities of an IDA (lognormal MLE: theta = exp(mean ln IM), beta = std ln IM with ddof = 0).
``run_ida`` writes the table, the fits (``fragility.csv``), the IDA curves, the fragility curves,
the input spectra and a ``report.md`` that shows them.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy.optimize import minimize
from scipy.stats import norm

from ._warn import warn_user
from .case import parse_assignment, parse_case
from .intensity import IM_COLUMNS, response_spectrum, rocking_period, spec_intensities
from .loading import earthquake_record
from .plots import save_figure
from .records import STANDARD_GRAVITY
from .stopping import STOP_MODES
from .studies import RunSpec, Store, execute, read_with_care, resolve_base, save_table, study_table, with_stop

__all__ = [
    "Fragility",
    "fit_fragility_mle",
    "fit_fragility_capacities",
    "ida_specs",
    "run_ida",
    "failed",
    "completed",
    "IdaCounts",
    "ida_counts",
    "collapse_capacities",
    "plot_ida",
    "rotation_floor",
    "plot_fragility",
    "plot_fragility_all",
    "plot_spectra",
    "write_report",
    "fit_all",
    "add_intensities",
    "COLLAPSE_REASONS",
    "register_cli",
]


@dataclass(frozen=True)
class Fragility:
    """Lognormal fragility: median ``theta`` (in the unit of its intensity measure, [g] for PGA)
    and dispersion ``beta`` [-]."""

    theta: float
    beta: float
    n: int = 0
    separated: bool = False
    """The outcomes were completely separated by the intensity (:func:`separated`): beta is not identifiable."""

    def probability(self, im: Any) -> np.ndarray:
        """P(failure | IM)."""
        im = np.asarray(im, dtype=float)
        with np.errstate(divide="ignore"):
            return norm.cdf(np.log(np.maximum(im, 1e-300) / self.theta) / self.beta)


MAX_DISPERSION = 5.0
"""Largest lognormal dispersion beta [-] a fit may return (fragilities of structures have 0.2 to 1):
outcomes whose failures do not rise with the intensity drive the likelihood's best beta to
infinity (a failure at 0.25 g and a survival at 0.31 g fitted a median of 0.0047 g and a
dispersion of 4.9e18 before 2026-11-30), and :func:`fit_fragility_mle` refuses them."""


def fit_fragility_mle(im: Sequence[float], failed_: Sequence[bool] | Sequence[int], trials: Sequence[int] | None = None) -> Fragility:
    """Maximum-likelihood lognormal fragility from outcomes (Baker 2015, binomial likelihood).

    Args:
        im: intensity of each outcome (or of each group) [> 0].
        failed_: 0/1 outcome per analysis, or failure counts per group when ``trials`` is given.
        trials: analyses per group (default: one per entry).
    """
    x = np.asarray(im, dtype=float)
    z = np.asarray(failed_, dtype=float)
    n = np.ones_like(x) if trials is None else np.asarray(trials, dtype=float)
    if x.shape != z.shape or x.shape != n.shape or x.ndim != 1 or len(x) < 2:
        raise ValueError("fit_fragility_mle: give equal-length 1-D arrays with at least 2 entries")
    if not np.all(np.isfinite(x)) or np.any(x <= 0):
        raise ValueError("fit_fragility_mle: intensities must be finite and > 0")
    if not np.all(np.isfinite(n)) or np.any(n < 1) or np.any(n != np.round(n)):
        raise ValueError("fit_fragility_mle: trials must be whole numbers >= 1")
    if not np.all(np.isfinite(z)) or np.any(z != np.round(z)) or np.any(z < 0) or np.any(z > n):
        raise ValueError("fit_fragility_mle: outcomes must be 0 or 1 per analysis (failure counts from 0 to the "
                         "trials per group)")
    if z.sum() == 0 or z.sum() == n.sum():
        raise ValueError("fit_fragility_mle: need both failures and survivals to fit a fragility")
    lx = np.log(x)

    def nll(p: np.ndarray) -> float:
        mu, lb = p
        with np.errstate(over="ignore", invalid="ignore"):
            pr = np.clip(norm.cdf((lx - mu) / np.exp(lb)), 1e-12, 1 - 1e-12)
        return -float(np.sum(z * np.log(pr) + (n - z) * np.log(1 - pr)))

    # start: median where half the analyses fail, dispersion from the spread of intensities
    p0 = np.array([float(np.sum(lx * n) / n.sum()), np.log(max(float(np.std(lx)), 0.1))])
    res = minimize(nll, p0, method="Nelder-Mead", options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000})
    with np.errstate(over="ignore"):
        theta, beta = float(np.exp(res.x[0])), float(np.exp(res.x[1]))
    if not beta <= MAX_DISPERSION:
        levels, where = np.unique(x, return_inverse=True)
        rate = [f"{lv:.4g}: {np.sum(z[where == k]):g}/{np.sum(n[where == k]):g}" for k, lv in enumerate(levels)]
        raise ValueError(f"fit_fragility_mle: the failures do not rise with the intensity (failed/analyses by intensity "
                         f"{', '.join(rate[:6])}{' ...' if len(rate) > 6 else ''}): the best lognormal would have a "
                         f"dispersion of {beta:.3g}, beyond {MAX_DISPERSION:g}; no fragility. Add records or levels")
    sep = bool(x[z < n].max() <= x[z > 0].min())  # every level with a failure at or above every one with a survival
    return Fragility(theta, beta, int(n.sum()), separated=sep)


def fit_fragility_capacities(capacities: Sequence[float]) -> Fragility:
    """Lognormal MLE from per-record collapse capacities (IDA): theta = exp(mean ln c), beta = std ln c."""
    c = np.asarray(capacities, dtype=float)
    c = c[np.isfinite(c)]
    if len(c) < 2 or np.any(c <= 0):
        raise ValueError("fit_fragility_capacities: need at least 2 finite positive capacities")
    lc = np.log(c)
    return Fragility(float(np.exp(lc.mean())), float(lc.std(ddof=0)), len(c))


def ida_specs(base: str | Mapping[str, Any], records: Sequence[str], pga_g: Sequence[float], *,
              fixed: Mapping[str, Any] | None = None, duration: float | None = None, stop: str = "decided") -> list[RunSpec]:
    """One spec per (record, PGA [g]); ``stop`` is the runs' ``run.stop`` (:mod:`rockdem.stopping`)
    unless ``fixed`` sets it."""
    b = resolve_base(base)
    fixed = with_stop(fixed, stop)
    return [RunSpec.make(b, fixed, duration=duration, record=str(r), pga_g=float(a)) for r in records for a in pga_g]


def completed(table: pd.DataFrame) -> pd.Series:
    """Runs whose outcome is known: status "ok" (not "error", not "diverged")."""
    if "status" not in table:
        return pd.Series(True, index=table.index)
    return table["status"].eq("ok")


COLLAPSE_REASONS = ("overturned", "fell")
"""``stop_reason`` values of runs stopped because they collapsed."""


def failed(table: pd.DataFrame, drift_limit: float | None = None) -> pd.Series:
    """Failure of each run: overturned, stopped because it collapsed (``stop_reason``), a block
    fallen at its end (``fallen_blocks`` > 0: partial collapse counts, as the "fell" stop does;
    tables from before 2026-11-28 have no such column), or peak rotation > drift_limit x eta (a
    nullable boolean: <NA> for runs without an outcome, see :func:`completed`)."""
    if drift_limit is not None and (isinstance(drift_limit, bool) or not isinstance(drift_limit, (int, float, np.number))
                                    or not (math.isfinite(drift_limit) and drift_limit > 0)):
        raise ValueError(f"drift_limit must be a positive multiple of eta (e.g. 0.5), got {drift_limit!r}")
    done = completed(table)
    f = pd.Series(pd.NA, index=table.index, dtype="boolean")
    if done.any():
        sub = table[done]
        g = sub["overturned"].astype(bool)
        if "stop_reason" in sub:
            g = g | sub["stop_reason"].isin(COLLAPSE_REASONS)
        if "fallen_blocks" in sub:
            g = g | (pd.to_numeric(sub["fallen_blocks"], errors="coerce").fillna(0) > 0)
        if drift_limit is not None:
            g = g | (sub["max_rotation_over_eta"].astype(float) > drift_limit)
        f[done] = g.to_numpy()
    return f


@dataclass(frozen=True)
class IdaCounts:
    """Runs of an IDA by outcome: ``failures`` and ``survivals`` of the completed runs, ``errors``
    (status "error") and ``diverged`` (status "diverged") are outside the fit."""

    runs: int
    failures: int
    survivals: int
    errors: int
    diverged: int

    def line(self) -> str:
        """One-line summary for the command line."""
        out = f"{self.runs} runs: {self.failures} failures, {self.survivals} survivals"
        apart = [f"{n} {what}" for n, what in ((self.errors, "errored"), (self.diverged, "diverged")) if n]
        if apart:
            out += f"; {', '.join(apart)} (no outcome: not in the fit)"
        return out


def ida_counts(table: pd.DataFrame) -> IdaCounts:
    """Count the runs of a table with a ``failed`` column by outcome."""
    status = table["status"] if "status" in table else pd.Series("ok", index=table.index)
    f = table["failed"].astype("boolean")
    return IdaCounts(len(table), int(f.sum()), int((~f).sum()),  # <NA> (no outcome) counts in neither
                     int(status.eq("error").sum()), int(status.eq("diverged").sum()))


def collapse_capacities(table: pd.DataFrame, drift_limit: float | None = None) -> pd.Series:
    """Per record: the lowest PGA [g] that fails (NaN if none does), over the completed runs."""
    t = table.assign(failed=failed(table, drift_limit))
    t = t[completed(t)]
    return t[t.failed.astype(bool)].groupby("record")["pga_g"].min().reindex(sorted(t["record"].unique()))


def add_intensities(table: pd.DataFrame, specs: Sequence[RunSpec], period: float | None) -> pd.DataFrame:
    """The table with the IM columns of each run's input (:data:`rockdem.intensity.IM_COLUMNS`
    besides ``pga_g``, and ``sa_period_s``); ``period`` None: no Sa column."""
    if period is None:
        return table
    ims = spec_intensities(specs, period)
    col = {name: table["id"].map(lambda i, n=name: getattr(ims.get(i), n, np.nan) if ims.get(i) else np.nan)
           for name in ("pgv_m_s", "arias_m_s", "sa_g")}
    return table.assign(**col, sa_period_s=period)


def fit_all(table: pd.DataFrame) -> pd.DataFrame:
    """Binomial MLE fragility against every IM column present (:data:`rockdem.intensity.IM_COLUMNS`)
    over the completed runs: columns ``im``, ``label``, ``theta``, ``beta``, ``n`` (NaN where the
    runs do not have both failures and survivals) and ``separated`` (:func:`separated`: beta is
    then not identifiable)."""
    done = table[completed(table)]
    rows = []
    for im, label in IM_COLUMNS.items():
        if im not in done or done[im].isna().all():
            continue
        sub = done[done[im].notna() & (done[im] > 0)]
        sep = separated(sub[im].astype(float), sub["failed"].astype(bool))
        try:
            f = fit_fragility_mle(sub[im].astype(float), sub["failed"].astype(int))
            rows.append({"im": im, "label": label, "theta": f.theta, "beta": f.beta, "n": f.n, "separated": sep})
        except ValueError:
            rows.append({"im": im, "label": label, "theta": np.nan, "beta": np.nan, "n": len(sub), "separated": sep})
    return pd.DataFrame(rows, columns=["im", "label", "theta", "beta", "n", "separated"])


def separated(im: Sequence[float], failed_: Sequence[bool]) -> bool:
    """Whether the outcomes are separated by the intensity: every failure at or above every
    survival (records sharing their levels tie at the boundary: quasi-complete separation). The
    likelihood then grows as the dispersion goes to 0, so the fitted beta only says how far apart
    the levels were, not the record-to-record dispersion: more records, or levels between the last
    survival and the first failure, are needed."""
    x = np.asarray(im, dtype=float)
    z = np.asarray(failed_, dtype=bool)
    return bool(z.any() and (~z).any() and x[~z].max() <= x[z].min())  # ties at one level too (quasi-complete)


def characteristic_period(specs: Sequence[RunSpec]) -> float | None:
    """The rocking period T = 2 pi / p of the first spec's first free block (None without one)."""
    from .batch import case_of

    try:
        return rocking_period(case_of(specs[0].case_dict()).model)
    except (ValueError, FileNotFoundError, IndexError):
        return None


def _check_cases(specs: Sequence[RunSpec], per_record: int) -> None:
    """Refuse an IDA none of whose runs can start, before any run: the first run of each record is
    built (not run) until one is a valid case. A bad base case or ``fixed`` value thus errors at
    once, while a record that cannot be read errors only its own runs (reported apart)."""
    first: Exception | None = None
    for spec in specs[::per_record]:
        try:
            parse_case(spec.case_dict())
            return
        except (ValueError, FileNotFoundError) as exc:
            first = first or exc
    if first is not None:
        n = len(specs) // per_record
        raise ValueError(f"no run of the IDA can start ({'its record gives no' if n == 1 else f'none of its {n} records gives a'} valid "
                         f"case with the base case and settings; nothing was run): {first}")


STRONG_MOTION_SHARE = 0.95
"""A run that ends before this share of its record's Arias intensity has arrived is cut short."""


def _cut_short(specs: Sequence[RunSpec]) -> list[str]:
    """Notes on the records whose runs end (``run.duration``) before their strong motion has
    arrived (:data:`STRONG_MOTION_SHARE` of the Arias intensity) or before their PGA: the
    table's intensity measures are the whole record's, which the block did not feel."""
    notes = []
    for spec in specs:
        data = spec.case_dict()
        load, end = data.get("loading", {}), data.get("run", {}).get("duration")
        if load.get("type") != "earthquake" or end is None:
            continue
        try:
            gm = earthquake_record(load, scale=1.0)
        except (ValueError, FileNotFoundError, OSError):
            continue  # its runs error, reported apart
        a2 = np.cumsum(np.asarray(gm.acceleration, dtype=float) ** 2)
        t = float(load.get("delay", 0.0)) + gm.dt * np.arange(a2.size)  # the run applies it from its delay (a window too)
        t_strong = float(t[np.searchsorted(a2, STRONG_MOTION_SHARE * a2[-1])])
        t_peak = float(t[int(np.argmax(np.abs(gm.acceleration)))])
        missed = [what for what, at in ((f"{STRONG_MOTION_SHARE:.0%} of its Arias intensity has arrived ({t_strong:.3g} s)", t_strong),
                                        (f"its PGA ({t_peak:.3g} s)", t_peak)) if float(end) < at]
        if missed:
            notes.append(f"record {load.get('record')!r}: the runs end at t = {float(end):g} s (run.duration), before "
                         f"{' and '.join(missed)}; the table's intensity measures are the whole record's, not what the "
                         "block felt: lengthen the runs (--duration) or leave the duration to the record")
    return notes


def _check_records(records: Sequence[str]) -> None:
    """Refuse, before any run, a record that names no file, and two names of one file (a short
    name, its file name, a path: before 2026-11-30 each ran and counted as a record of its own in
    the fit, and a misspelt name failed only after the other records had run)."""
    from .loading import resolve_record

    seen: dict[Path, str] = {}
    for r in records:
        try:
            path = resolve_record(r).resolve()
        except (FileNotFoundError, ValueError) as exc:
            raise ValueError(f"record {r!r}: {exc}") from None
        if path in seen:
            raise ValueError(f"records {seen[path]!r} and {r!r} are the same file ({path.name}); give each record once")
        seen[path] = str(r)


def run_ida(base: str | Mapping[str, Any], records: Sequence[str], pga_g: Sequence[float], out: str | os.PathLike[str], *,
            fixed: Mapping[str, Any] | None = None, duration: float | None = None, drift_limit: float | None = None,
            im: str = "pga_g", period: float | None = None, stop: str = "decided", executor: str = "process",
            workers: int | None = None, scheduler: Any = None, progress: bool = True,
            batch: bool = True) -> tuple[pd.DataFrame, Fragility | None]:
    """Run an IDA into folder ``out`` and fit the fragility against ``im`` (None if it cannot).

    Writes ``table.csv`` (one row per run, with the IM columns), ``fragility.csv`` (the fit against
    every IM), ``ida.png``, ``fragility.png``, ``spectra.png`` and ``report.md``. The table's
    ``failed`` column is empty for runs without an outcome (errors, divergence); only the
    completed runs enter the fits.

    Args:
        im: the intensity measure of the returned fit and of the IDA plot's axis
            (:data:`rockdem.intensity.IM_COLUMNS`).
        period: spectral period of Sa [s]; default the block's rocking period 2 pi / p.
        stop: ``run.stop`` of the runs (:mod:`rockdem.stopping`): "decided" (default) stops a run
            once it has collapsed (or is at rest after the record); "off" runs every record to its end.
        batch: the batch path (identical rows, faster); False runs each spec as a single run.

    Raises:
        ValueError: an unknown ``im``; no record or PGA level; no run can start (the first run of
            every record is not a valid case: a bad base case or ``fixed`` value; nothing is run
            or written); or no run completed (the table is written first; the message gives the
            first error).
    """
    if im not in IM_COLUMNS:
        raise ValueError(f"im must be one of {list(IM_COLUMNS)}, got {im!r}")
    if period is not None and not (np.isfinite(period) and period > 0):
        raise ValueError(f"period must be a positive time [s], got {period!r}")
    if isinstance(records, str) or len(records) == 0 or len(pga_g) == 0:
        raise ValueError(f"give a list of at least one record and one PGA level [g], got records={records!r}, pga_g={pga_g!r}")
    failed(pd.DataFrame({"overturned": []}), drift_limit)  # drift_limit checked before any run
    _check_records(records)
    specs = ida_specs(base, records, pga_g, fixed=fixed, duration=duration, stop=stop)
    _check_cases(specs, len(pga_g))
    notes = _cut_short(specs[::len(pga_g)])
    for note in notes:
        warn_user(note)
    store = Store(out)
    execute(specs, store, executor=executor, workers=workers, scheduler=scheduler, progress=progress, batch=batch)
    df = study_table(store, specs=specs)
    df = df.assign(failed=failed(df, drift_limit))
    t_p = period if period is not None else characteristic_period(specs)
    df = add_intensities(df, specs, t_p)
    save_table(df, out)
    for note in read_with_care(df):
        warn_user(note)
    done = df[completed(df)]
    if done.empty:
        first = df["error"].dropna().iloc[0] if "error" in df and df["error"].notna().any() else "no error message"
        raise ValueError(f"none of the {len(df)} IDA runs completed ({ida_counts(df).line()}), so there is no "
                         f"fragility; first error: {first}. See {Path(out) / 'table.csv'}")
    if im not in df or df[im].isna().all():
        raise ValueError(f"no {IM_COLUMNS[im]} for these runs (the Sa period is unknown: give period=)")
    fits = fit_all(df)
    fits.to_csv(Path(out) / "fragility.csv", index=False)
    chosen = fits[fits["im"] == im].iloc[0]
    frag = None if not np.isfinite(chosen["theta"]) else Fragility(float(chosen["theta"]), float(chosen["beta"]), int(chosen["n"]),
                                                                    bool(chosen["separated"]))
    plot_ida(df, Path(out) / "ida.png", drift_limit=drift_limit, im=im)
    plot_fragility_all(df, fits, Path(out) / "fragility.png")
    plot_spectra(specs, Path(out) / "spectra.png", period=t_p)
    write_report(df, fits, Path(out), drift_limit=drift_limit, period=t_p, notes=notes)
    return df, frag


def _fig() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


MARKERS = "osD^v<>ph*"
LINESTYLES = ("-", "--", "-.", ":")


def _style(k: int) -> dict[str, Any]:
    """Line style of the k-th record: colour, marker and dash pattern all differ between neighbours."""
    return {"color": f"C{k % 10}", "marker": MARKERS[k % len(MARKERS)], "ls": LINESTYLES[(k // 10) % len(LINESTYLES)]}


ROTATION_FLOOR = 1e-6
"""Smallest peak rotation / eta the IDA plot's log axis reaches down to (a block at rest, 0, is
drawn there). The axis starts at the smallest survival's value, or at 1e-3 when all are larger."""


def rotation_floor(values: pd.Series) -> float:
    """Where the IDA plot's log axis of peak rotation / eta starts, for the survivals' ``values``:
    the smallest positive one, at most 1e-3 and at least :data:`ROTATION_FLOOR` (so that levels
    below 1e-3 stay apart; values below it, a block at rest, are drawn at it)."""
    v = pd.to_numeric(values, errors="coerce").astype(float)
    v = v[v > 0.0]
    return max(min(1e-3, float(v.min()) if len(v) else 1e-3), ROTATION_FLOOR)


def plot_ida(table: pd.DataFrame, path: str | os.PathLike[str], *, drift_limit: float | None = None,
             im: str = "pga_g") -> Path:
    """IDA curves: ``im`` against peak rotation / eta (log axis), one curve per record through its
    survivals; a strip beside it shows every run's outcome per record at its intensity: survival,
    collapse (the lowest one marked as the record's capacity), error, divergence. ``table`` is the
    whole IDA table (with ``failed`` and ``status``)."""
    plt = _fig()
    status = table["status"] if "status" in table else pd.Series("ok", index=table.index)
    fail = table["failed"].astype("boolean") if "failed" in table else failed(table, drift_limit)
    recs = sorted(table["record"].astype(str).unique())
    fig, (ax, strip) = plt.subplots(1, 2, figsize=(9, 5.2), sharey=True, gridspec_kw={"width_ratios": [3.2, 1]}, layout="constrained")
    y_all = table[im].astype(float)
    shown: set[str] = set()
    x_max = 1.0
    floor = rotation_floor(table.loc[status.eq("ok") & fail.eq(False), "max_rotation_over_eta"])
    for k, rec in enumerate(recs):
        g = table[(table["record"].astype(str) == rec)]
        sty = _style(k)
        ok = g[status[g.index].eq("ok") & fail[g.index].eq(False)].sort_values(im)
        x = np.clip(ok["max_rotation_over_eta"].astype(float), floor, None)
        x_max = max(x_max, float(x.max()) if len(x) else 1.0)
        ax.plot(x, ok[im], lw=1.2, ms=3.5, alpha=0.85, markevery=max(1, len(ok) // 40), label=Path(rec).stem, **sty)
        # the strip: one column per record
        for what, sel, mk, col in (
            ("survival", status[g.index].eq("ok") & fail[g.index].eq(False), "o", sty["color"]),
            ("collapse", status[g.index].eq("ok") & fail[g.index].eq(True), "x", "k"),
            ("error", status[g.index].eq("error"), "^", "r"),
            ("diverged", status[g.index].eq("diverged"), "D", "m"),
        ):
            yy = g.loc[sel, im].astype(float)
            strip.plot(np.full(len(yy), k), yy, ls="none", marker=mk, ms=4 if mk != "o" else 3, color=col,
                       mfc="none" if what == "survival" else col, label=what if what not in shown and len(yy) else None)
            if len(yy):
                shown.add(what)
        cap = g.loc[status[g.index].eq("ok") & fail[g.index].eq(True), im].astype(float)
        if len(cap):
            strip.plot([k - 0.35, k + 0.35], [cap.min()] * 2, color="k", lw=2)
            ax.axhline(cap.min(), color=sty["color"], lw=0.6, ls=":", alpha=0.8)
    if drift_limit is not None:
        ax.axvline(drift_limit, color="r", lw=0.8, ls="--", label=f"drift limit {drift_limit:g} eta")
    ax.axvline(1.0, color="0.5", lw=0.6)
    ax.set_xscale("log")
    ax.set_xlim(floor * 0.8, 1.5 * x_max)
    ax.set_xlabel("peak rotation / eta [-] (survivals; dotted: each record's collapse capacity)")
    ax.set_ylabel(_im_label(table, im))
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="upper left", ncol=1 if len(recs) < 8 else 2)
    strip.set_xticks(range(len(recs)))
    strip.set_xticklabels([Path(r).stem for r in recs], rotation=60, ha="right", fontsize=7)
    strip.set_xlim(-0.6, len(recs) - 0.4)
    strip.set_title("outcome of every run\n(bar: lowest collapse)", fontsize=8)
    strip.legend(fontsize=7, loc="upper left", framealpha=0.9)
    strip.grid(True, axis="y", alpha=0.25)
    if y_all.notna().any():
        ax.set_ylim(0.0, float(y_all.max()) * 1.05)
    fig.suptitle(ida_counts(table.assign(failed=fail)).line(), fontsize=9)
    p = save_figure(fig, path)
    plt.close(fig)
    return p


def _im_label(table: pd.DataFrame | None, im: str) -> str:
    """Axis label of an IM column (Sa with its period)."""
    if im == "sa_g" and table is not None and "sa_period_s" in table and table["sa_period_s"].notna().any():
        return f"Sa(T = {float(table['sa_period_s'].dropna().iloc[0]):.3g} s) [g], 5 % damping"
    return IM_COLUMNS.get(im, im)


def _observed(table: pd.DataFrame, im: str, bins: int = 12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Failure fraction of the completed runs in bins of ``im`` of about equal counts: (bin
    median, fraction, runs)."""
    done = table[completed(table) & table[im].notna()]
    x = done[im].astype(float).to_numpy()
    f = done["failed"].astype(float).to_numpy()
    levels = np.unique(x)
    if len(levels) <= bins:
        edges_idx = [x == v for v in levels]
    else:
        edges = np.quantile(x, np.linspace(0, 1, bins + 1))
        idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, bins - 1)
        edges_idx = [idx == k for k in range(bins)]
    out = [(float(np.median(x[m])), float(f[m].mean()), int(m.sum())) for m in edges_idx if m.any()]
    return tuple(np.array(v) for v in zip(*out)) if out else (np.zeros(0), np.zeros(0), np.zeros(0))


def plot_fragility(frag: Fragility, table: pd.DataFrame | None, path: str | os.PathLike[str], *, im: str = "pga_g") -> Path:
    """Fitted fragility curve against ``im`` with the observed failure fraction of the completed runs."""
    plt = _fig()
    fig, ax = plt.subplots(figsize=(6, 4))
    _fragility_axes(ax, frag, table, im)
    fig.tight_layout()
    p = save_figure(fig, path)
    plt.close(fig)
    return p


def _fragility_axes(ax: Any, frag: Fragility | None, table: pd.DataFrame | None, im: str) -> None:
    hi = float(table[im].max()) * 1.2 if table is not None and im in table and table[im].notna().any() else 3 * (frag.theta if frag else 1.0)
    if table is not None and "failed" in table and im in table:
        x, f, n = _observed(table, im)
        ax.scatter(x, f, s=12 + 40 * n / max(n.max(), 1), color="C1", zorder=3, label="observed fraction (binned)")
    if frag is not None:
        xs = np.linspace(hi * 1e-3, hi, 300)
        ax.plot(xs, frag.probability(xs), color="C0", label=f"theta = {frag.theta:.3g}, beta = {frag.beta:.3g}"
                + (" (separated: beta not identifiable)" if frag.separated else ""))
    else:
        ax.text(0.5, 0.5, "not fitted\n(no failures or no survivals)", transform=ax.transAxes, ha="center", fontsize=8)
    ax.set_xlabel(_im_label(table, im))
    ax.set_ylabel("P(failure)")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlim(0.0, hi)
    ax.grid(True, alpha=0.25)
    ax.legend(fontsize=7, loc="lower right")


def plot_fragility_all(table: pd.DataFrame, fits: pd.DataFrame, path: str | os.PathLike[str]) -> Path:
    """Fragility curves against every fitted IM (one panel each), observed fractions beside."""
    plt = _fig()
    n = max(len(fits), 1)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 3.6 * rows), squeeze=False)
    for ax, (_, r) in zip(axes.flat, fits.iterrows()):
        frag = Fragility(float(r["theta"]), float(r["beta"]), int(r["n"]), bool(r.get("separated", False))) if np.isfinite(r["theta"]) else None
        _fragility_axes(ax, frag, table, str(r["im"]))
    for ax in list(axes.flat)[len(fits):]:
        ax.set_visible(False)
    fig.tight_layout()
    p = save_figure(fig, path)
    plt.close(fig)
    return p


def plot_spectra(specs: Sequence[RunSpec], path: str | os.PathLike[str], *, period: float | None = None) -> Path | None:
    """5 %-damped pseudo-acceleration spectra of the IDA's records as applied (processed), each
    scaled to PGA = 1 g, with the spectral period of Sa marked; None when no record can be read."""
    plt = _fig()
    periods = np.geomspace(0.02, 10.0, 160)
    seen: dict[str, Any] = {}
    for s in specs:
        load = s.case_dict().get("loading", {})
        if load.get("type") != "earthquake" or str(load.get("record")) in seen:
            continue
        try:
            gm = earthquake_record({k: v for k, v in load.items() if k != "scale"} | {"pga_g": 1.0})
        except (ValueError, FileNotFoundError, OSError):
            continue
        seen[str(load["record"])] = gm
    if not seen:
        return None
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for k, (rec, gm) in enumerate(sorted(seen.items())):
        sa = response_spectrum(gm.acceleration, gm.dt, periods) / STANDARD_GRAVITY
        sty = _style(k)
        ax.plot(periods, sa, color=sty["color"], ls=sty["ls"], lw=1.3, label=f"{Path(rec).stem} (dt {gm.dt:g} s)")
    if period is not None:
        ax.axvline(period, color="k", lw=0.8, ls="--", label=f"T = 2 pi / p = {period:.3g} s")
    ax.set_xscale("log")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel("Sa(T) [g], 5 % damping, record scaled to PGA = 1 g")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7)
    fig.tight_layout()
    p = save_figure(fig, path)
    plt.close(fig)
    return p


SEPARATED_NOTE = ("Separated: every run that failed had an intensity at or above every run that survived, so the "
                  "likelihood grows as the dispersion goes to 0 and the fitted beta says only how far apart the "
                  "levels were. Add records, or levels between the last survival and the first failure.")


def write_report(table: pd.DataFrame, fits: pd.DataFrame, out: Path, *, drift_limit: float | None = None,
                 period: float | None = None, notes: Sequence[str] = ()) -> Path:
    """``report.md``: the counts, the fits against every IM, the period, ``notes`` and the figures."""
    c = ida_counts(table)
    lines = ["# IDA and fragility", "", f"{c.line()}.", ""]
    if "stop_reason" in table:
        reasons = table["stop_reason"].fillna("ran to the end").value_counts()
        lines += ["Runs stopped once decided: " + ", ".join(f"{n} {r}" for r, n in reasons.items()) + ".", ""]
    lines += [f"Failure: overturned or collapsed{f', or peak rotation > {drift_limit:g} eta' if drift_limit else ''}.",
              f"Sa at T = {period:.4g} s (the block's rocking period 2 pi / p unless given), 5 % damping." if period else "",
              *(["", "Cut short:", *[f"- {n}" for n in notes]] if notes else []),
              "", "| intensity measure | median theta | dispersion beta | runs |", "| --- | --- | --- | --- |"]
    for _, r in fits.iterrows():
        th = f"{r['theta']:.4g}" if np.isfinite(r["theta"]) else "not fitted"
        be = f"{r['beta']:.3g}" if np.isfinite(r["beta"]) else "-"
        if np.isfinite(r["beta"]) and bool(r.get("separated", False)):
            be += " (separated: not identifiable)"
        lines.append(f"| {r['label']} | {th} | {be} | {int(r['n'])} |")
    if fits.get("separated", pd.Series(dtype=bool)).astype(bool).any():
        lines += ["", SEPARATED_NOTE]
    lines += ["", "![IDA curves](ida.png)", "", "![fragility curves](fragility.png)", "", "![input spectra](spectra.png)", ""]
    p = out / "report.md"
    p.write_text("\n".join(lines))
    return p


def _fragility_cli(args: argparse.Namespace) -> int:
    fixed = dict(parse_assignment(item) for item in args.set or [])
    lo, hi, n = args.pga
    try:
        lo, hi = float(lo), float(hi)
        n = int(n)
    except ValueError:
        raise ValueError(f"--pga LOW HIGH N: LOW and HIGH are PGA levels [g] and N a whole count, got {' '.join(args.pga)}") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi) or n < 1 or (n == 1 and lo != hi):
        raise ValueError(f"--pga LOW HIGH N: give 0 < LOW <= HIGH [g] and N >= 1 levels (N = 1 with LOW = HIGH), "
                         f"got {' '.join(args.pga)}")
    levels = np.linspace(lo, hi, n)
    from .cli import output_folder, stop_on_signals

    output_folder(args.out, "--out", create=False)

    try:
        with stop_on_signals():  # SIGTERM and SIGHUP stop it and its workers as Ctrl-C does
            df, frag = run_ida(args.base, args.records, levels, args.out, fixed=fixed, duration=args.duration,
                               drift_limit=args.drift_limit, im=args.im, period=args.period, stop=args.stop,
                               executor=args.executor or "process", workers=args.workers,
                               scheduler=args.scheduler, progress=not args.no_progress)
    except KeyboardInterrupt:
        print(f"rockdem fragility: stopped; {Store(args.out).kept()}", file=sys.stderr)
        raise
    print(f"{ida_counts(df).line()} -> {Path(args.out) / 'table.csv'}, report.md")
    if "error" in df:  # why runs errored (each distinct reason once; the table's "error" column has every row's)
        reasons = df["error"].dropna().astype(str).value_counts()
        for reason, n in reasons.head(3).items():
            print(f"  {n} run(s) errored: {reason}", file=sys.stderr)
        if len(reasons) > 3:
            print(f"  ... {len(reasons) - 3} more reasons in the table's error column", file=sys.stderr)
    if frag is None:
        print(f"fragility against {IM_COLUMNS[args.im]}: not fitted (every completed run failed, or none did, or the "
              "failures do not rise with the intensity; widen the PGA range, or add records or levels)")
    else:
        print(f"fragility against {IM_COLUMNS[args.im]}: median {frag.theta:.4g}, dispersion {frag.beta:.4g}"
              + (" (separated outcomes: the dispersion is not identifiable, report.md)" if frag.separated else ""))
    return 0 if ida_counts(df).errors == 0 else 1


def register_cli(subparsers: argparse._SubParsersAction, add_exec_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """Add ``fragility``."""
    p = subparsers.add_parser("fragility", help="IDA over records and PGA levels, with a lognormal fragility fit")
    p.add_argument("records", nargs="+", help="shipped record names (`rockdem records`), files, or file names in $ROCKDEM_DATA")
    p.add_argument("--base", default="free-rocking", help="base case (its block; the loading is replaced)")
    p.add_argument("--pga", nargs=3, default=(0.05, 1.0, 10), metavar=("LOW", "HIGH", "N"), help="PGA levels [g]")
    p.add_argument("--duration", type=float, default=None, help="simulated time [s]")
    p.add_argument("--drift-limit", type=float, default=None, help="failure when peak rotation > this x eta")
    p.add_argument("--im", choices=tuple(IM_COLUMNS), default="pga_g", help="intensity measure of the printed fit and the IDA plot (all are fitted: fragility.csv)")
    p.add_argument("--period", type=float, default=None, help="period of Sa [s] (default: the block's rocking period 2 pi / p)")
    p.add_argument("--stop", choices=STOP_MODES, default="decided", help="end each run once its outcome is decided (default) or run it to the end (off)")
    p.add_argument("--set", action="append", metavar="table.key=value", help="fixed override (repeatable)")
    p.add_argument("--out", "-o", default="ida", help="output folder")
    add_exec_args(p)
    p.set_defaults(func=_fragility_cli)
