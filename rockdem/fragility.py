"""Incremental dynamic analysis (IDA) and lognormal fragility curves.

Each record of a set is scaled to a range of peak ground accelerations (PGA [g]); each (record,
PGA) pair is a :class:`rockdem.studies.RunSpec` run through the study executors and store. A run
fails (collapse) when the block overturns or when its peak rotation exceeds ``drift_limit`` x eta
(eta = slenderness angle). Only runs that finished (status "ok") have an outcome: runs that
raised an error (e.g. an unreadable record) or diverged are counted apart and never enter a fit. The fragility P(fail | PGA) = Phi(ln(PGA / theta) / beta) is fitted by
maximum likelihood: on (PGA, failed) outcomes with a binomial likelihood (Baker 2015), or on the
per-record collapse capacities of an IDA (lognormal MLE: theta = exp(mean ln IM), beta = std ln IM
with ddof = 0).
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy.optimize import minimize
from scipy.stats import norm

from .plots import save_figure
from .studies import RunSpec, Store, execute, resolve_base, save_table, study_table

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
    "plot_fragility",
    "register_cli",
]


@dataclass(frozen=True)
class Fragility:
    """Lognormal fragility: median ``theta`` [g] and dispersion ``beta`` [-]."""

    theta: float
    beta: float
    n: int = 0

    def probability(self, im: Any) -> np.ndarray:
        """P(failure | IM)."""
        im = np.asarray(im, dtype=float)
        with np.errstate(divide="ignore"):
            return norm.cdf(np.log(np.maximum(im, 1e-300) / self.theta) / self.beta)


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
    if np.any(x <= 0):
        raise ValueError("fit_fragility_mle: intensities must be > 0")
    if z.sum() == 0 or z.sum() == n.sum():
        raise ValueError("fit_fragility_mle: need both failures and survivals to fit a fragility")
    lx = np.log(x)

    def nll(p: np.ndarray) -> float:
        mu, lb = p
        pr = np.clip(norm.cdf((lx - mu) / np.exp(lb)), 1e-12, 1 - 1e-12)
        return -float(np.sum(z * np.log(pr) + (n - z) * np.log(1 - pr)))

    # start: median where half the analyses fail, dispersion from the spread of intensities
    p0 = np.array([float(np.sum(lx * n) / n.sum()), np.log(max(float(np.std(lx)), 0.1))])
    res = minimize(nll, p0, method="Nelder-Mead", options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000})
    return Fragility(float(np.exp(res.x[0])), float(np.exp(res.x[1])), int(n.sum()))


def fit_fragility_capacities(capacities: Sequence[float]) -> Fragility:
    """Lognormal MLE from per-record collapse capacities (IDA): theta = exp(mean ln c), beta = std ln c."""
    c = np.asarray(capacities, dtype=float)
    c = c[np.isfinite(c)]
    if len(c) < 2 or np.any(c <= 0):
        raise ValueError("fit_fragility_capacities: need at least 2 finite positive capacities")
    lc = np.log(c)
    return Fragility(float(np.exp(lc.mean())), float(lc.std(ddof=0)), len(c))


def ida_specs(base: str | Mapping[str, Any], records: Sequence[str], pga_g: Sequence[float], *,
              fixed: Mapping[str, Any] | None = None, duration: float | None = None) -> list[RunSpec]:
    """One spec per (record, PGA [g])."""
    b = resolve_base(base)
    return [RunSpec.make(b, fixed, duration=duration, record=str(r), pga_g=float(a)) for r in records for a in pga_g]


def completed(table: pd.DataFrame) -> pd.Series:
    """Runs whose outcome is known: status "ok" (not "error", not "diverged")."""
    if "status" not in table:
        return pd.Series(True, index=table.index)
    return table["status"].eq("ok")


def failed(table: pd.DataFrame, drift_limit: float | None = None) -> pd.Series:
    """Failure of each run: overturned, or peak rotation > drift_limit x eta (a nullable boolean:
    <NA> for runs without an outcome, see :func:`completed`)."""
    done = completed(table)
    f = pd.Series(pd.NA, index=table.index, dtype="boolean")
    if done.any():
        sub = table[done]
        g = sub["overturned"].astype(bool)
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


def run_ida(base: str | Mapping[str, Any], records: Sequence[str], pga_g: Sequence[float], out: str | os.PathLike[str], *,
            fixed: Mapping[str, Any] | None = None, duration: float | None = None, drift_limit: float | None = None,
            executor: str = "process", workers: int | None = None, scheduler: Any = None,
            progress: bool = True) -> tuple[pd.DataFrame, Fragility | None]:
    """Run an IDA into folder ``out`` (store, table, plots) and fit the fragility (None if it cannot).

    The table's ``failed`` column is empty for runs without an outcome (errors, divergence); only
    the completed runs enter the fit and the plots.

    Raises:
        ValueError: no run completed (the table is written first; the message gives the first error).
    """
    specs = ida_specs(base, records, pga_g, fixed=fixed, duration=duration)
    store = Store(out)
    execute(specs, store, executor=executor, workers=workers, scheduler=scheduler, progress=progress)
    df = study_table(store, specs=specs)
    df = df.assign(failed=failed(df, drift_limit))
    save_table(df, out)
    done = df[completed(df)]
    if done.empty:
        first = df["error"].dropna().iloc[0] if "error" in df and df["error"].notna().any() else "no error message"
        raise ValueError(f"none of the {len(df)} IDA runs completed ({ida_counts(df).line()}), so there is no "
                         f"fragility; first error: {first}. See {Path(out) / 'table.csv'}")
    try:
        frag = fit_fragility_mle(done["pga_g"], done["failed"].astype(int))
    except ValueError:
        frag = None
    plot_ida(done, Path(out) / "ida.png", drift_limit=drift_limit)
    if frag is not None:
        plot_fragility(frag, done, Path(out) / "fragility.png")
    return df, frag


def _fig() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_ida(table: pd.DataFrame, path: str | os.PathLike[str], *, drift_limit: float | None = None) -> Path:
    """IDA curves: PGA [g] against peak rotation / eta, one line per record; failures marked."""
    plt = _fig()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for rec, g in table.sort_values("pga_g").groupby("record"):
        x = np.minimum(g["max_rotation_over_eta"].astype(float), 1.5)
        ax.plot(x, g["pga_g"], "-o", ms=3, label=Path(str(rec)).stem)
        f = failed(g, drift_limit).fillna(False).astype(bool)
        ax.plot(x[f], g["pga_g"][f], "x", color="k")
    if drift_limit is not None:
        ax.axvline(drift_limit, color="r", lw=0.8, ls="--")
    ax.set_xlabel("peak rotation / eta [-] (capped at 1.5; x = failure)")
    ax.set_ylabel("PGA [g]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    p = save_figure(fig, path)
    plt.close(fig)
    return p


def plot_fragility(frag: Fragility, table: pd.DataFrame | None, path: str | os.PathLike[str]) -> Path:
    """Fitted fragility curve with the observed failure fraction per PGA level."""
    plt = _fig()
    fig, ax = plt.subplots(figsize=(6, 4))
    hi = float(table["pga_g"].max()) * 1.2 if table is not None else 3 * frag.theta
    x = np.linspace(1e-3, hi, 300)
    ax.plot(x, frag.probability(x), label=f"theta = {frag.theta:.3g} g, beta = {frag.beta:.3g}")
    if table is not None and "failed" in table:
        obs = table[completed(table)].assign(failed=lambda t: t["failed"].astype(float)).groupby("pga_g")["failed"].mean()
        ax.plot(obs.index, obs.values, "o", label="observed fraction")
    ax.set_xlabel("PGA [g]")
    ax.set_ylabel("P(failure)")
    ax.set_ylim(-0.02, 1.02)
    ax.legend()
    fig.tight_layout()
    p = save_figure(fig, path)
    plt.close(fig)
    return p


def _fragility_cli(args: argparse.Namespace) -> int:
    import tomllib

    fixed: dict[str, Any] = {}
    for item in args.set or []:
        k, _, v = item.partition("=")
        try:
            fixed[k.strip()] = tomllib.loads(f"v = {v}")["v"]
        except tomllib.TOMLDecodeError:
            fixed[k.strip()] = v
    lo, hi, n = args.pga
    levels = np.linspace(float(lo), float(hi), int(n))
    df, frag = run_ida(args.base, args.records, levels, args.out, fixed=fixed, duration=args.duration,
                       drift_limit=args.drift_limit, executor=args.executor or "process", workers=args.workers,
                       scheduler=args.scheduler, progress=not args.no_progress)
    print(f"{ida_counts(df).line()} -> {Path(args.out) / 'table.csv'}")
    if frag is None:
        print("fragility: not fitted (every completed run failed, or none did; widen the PGA range)")
    else:
        print(f"fragility: median {frag.theta:.4g} g, dispersion {frag.beta:.4g}")
    return 0


def register_cli(subparsers: argparse._SubParsersAction, add_exec_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """Add ``fragility``."""
    p = subparsers.add_parser("fragility", help="IDA over records and PGA levels, with a lognormal fragility fit")
    p.add_argument("records", nargs="+", help="shipped record names (`rockdem records`), files, or file names in $ROCKDEM_DATA")
    p.add_argument("--base", default="free-rocking", help="base case (its block; the loading is replaced)")
    p.add_argument("--pga", nargs=3, default=(0.05, 1.0, 10), metavar=("LOW", "HIGH", "N"), help="PGA levels [g]")
    p.add_argument("--duration", type=float, default=None, help="simulated time [s]")
    p.add_argument("--drift-limit", type=float, default=None, help="failure when peak rotation > this x eta")
    p.add_argument("--set", action="append", metavar="table.key=value", help="fixed override (repeatable)")
    p.add_argument("--out", "-o", default="ida", help="output folder")
    add_exec_args(p)
    p.set_defaults(func=_fragility_cli)
