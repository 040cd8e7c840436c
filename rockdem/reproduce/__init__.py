"""The paper's studies reproduced: ``rockdem reproduce NAME`` (Galvez et al. 2022).

Each study is a function ``study(ctx) -> Report`` registered with :func:`reproduction`. It runs its
simulations through :meth:`Context.execute` (a :mod:`rockdem.studies` sweep with a resumable store
per study, so an interrupted or repeated reproduction reuses finished runs), and returns a
:class:`Report`: a table with the paper's published values beside ours, a figure, and a short honest
comment on the differences. :func:`write_report` writes ``NAME.md``, ``NAME.csv`` and the figure
into the output folder (``docs/reproduction/`` for the full versions, committed with their
runtime on the machine that ran them). ``--reduced`` runs a small, fast version of the same code
path (what CI runs); its output goes elsewhere so that it never overwrites the full results.

Published values used for comparison are in :mod:`rockdem.reproduce.paper`.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import os
import platform
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from ..studies import RunSpec, Store, execute

__all__ = ["energy_share", "record_duration", "Context", "Report", "Reproduction", "REPRODUCTIONS", "reproduction", "run_reproduction", "write_report", "register_cli"]

STUDY_MODULES = ("fig4", "table1", "fig8", "table2", "fig5_7", "fig16", "damping", "rattling", "parapet", "facade", "two_block_wall")
"""Modules of :mod:`rockdem.reproduce` that register studies (imported on first use)."""

DEFAULT_OUT = Path("docs") / "reproduction"
DEFAULT_REDUCED_OUT = Path("results") / "reproduction-reduced"
DEFAULT_CACHE = Path("results") / "reproduction-cache"


@dataclass
class Context:
    """Where and how a reproduction runs.

    Attributes:
        out: folder for the report, table and figures.
        cache: folder of the run stores (one ``NAME.jsonl`` per study); reruns skip finished runs.
        reduced: the small CI version (fewer cases, shorter runs).
        executor: "process" (default, all cores), "serial" or "dask".
        workers: process count. scheduler: Dask scheduler address.
        progress: progress bars.
    """

    out: Path
    cache: Path
    reduced: bool = False
    executor: str = "process"
    workers: int | None = None
    scheduler: Any = None
    progress: bool = True
    computed: int = 0
    reused: int = 0

    def execute(self, name: str, specs: Sequence[RunSpec]) -> list[dict[str, Any]]:
        """Run ``specs`` (skipping those finished in the store ``cache/name.jsonl``); rows in order.
        A run cut short by the engine's divergence check comes back with status "diverged".

        Raises:
            RuntimeError: naming the first failed run (a reproduction needs every run).
        """
        self.cache.mkdir(parents=True, exist_ok=True)
        store = Store(self.cache / f"{name}.jsonl")
        done = store.done_ids()
        ids = {s.id for s in specs}
        self.reused += len(ids & done)
        self.computed += len(ids - done)
        rows = execute(specs, store, executor=self.executor, workers=self.workers,
                       scheduler=self.scheduler, progress=self.progress)
        bad = [r for r in rows if r.get("status") not in ("ok", "diverged")]
        if bad:
            raise RuntimeError(f"{name}: {len(bad)} run(s) failed, e.g. {bad[0].get('error')} (inputs {_inputs(bad[0])})")
        return rows


def record_duration(name: str) -> float:
    """Duration [s] of the ground-motion record ``name`` (a shipped record or a path)."""
    from ..records import read_record, record_path, shipped_record

    shipped = shipped_record(name)
    return float(read_record(record_path(name), units=shipped.units if shipped is not None else None).duration)


def energy_share(row: Mapping[str, Any]) -> float:
    """Energy the engine created in a run over the run's energy scale (the study row's energy check,
    :func:`rockdem.results.energy_check`); NaN for a row stored before rows carried it."""
    created, scale = row.get("energy_created_J"), row.get("energy_scale_J")
    if created is None or scale is None:
        return float("nan")
    return float(created) / max(float(scale), 1e-300)


def _inputs(row: Mapping[str, Any]) -> dict[str, Any]:
    skip = {"id", "status", "error", "history"}
    return {k: v for k, v in row.items() if k not in skip}


@dataclass
class Report:
    """What a reproduction produced.

    Attributes:
        name: study name (file stem). title: heading.
        table: results, with the paper's values in columns named ``paper ...`` beside ours.
        figures: figure files written into the output folder (names relative to it).
        comment: short honest discussion of the differences (Markdown).
        runtime_s: wall time of the reproduction [s] (set by :func:`run_reproduction`).
        load: 1-minute load average of the machine at the start and at the end of the run (set by
            :func:`run_reproduction`; a shared machine's load lengthens the runtime).
        notes: extra Markdown sections (e.g. a second table), appended after the comment.
    """

    name: str
    title: str
    table: pd.DataFrame
    figures: list[str] = field(default_factory=list)
    comment: str = ""
    runtime_s: float = 0.0
    load: tuple[float, float] | None = None
    notes: str = ""


@dataclass(frozen=True)
class Reproduction:
    """A registered study: ``name``, one-line ``title`` and ``run(ctx) -> Report``."""

    name: str
    title: str
    run: Callable[[Context], Report]


REPRODUCTIONS: dict[str, Reproduction] = {}
"""Registered studies by name."""


def reproduction(name: str, title: str) -> Callable[[Callable[[Context], Report]], Callable[[Context], Report]]:
    """Register ``func(ctx) -> Report`` as the study ``name``."""

    def deco(func: Callable[[Context], Report]) -> Callable[[Context], Report]:
        REPRODUCTIONS[name] = Reproduction(name, title, func)
        return func

    return deco


def _load_studies() -> None:
    for mod in STUDY_MODULES:
        try:
            importlib.import_module(f"{__name__}.{mod}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{mod}":
                raise


def _machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} logical cores, Python {platform.python_version()}"


def _markdown_table(df: pd.DataFrame) -> str:
    def fmt(v: Any) -> str:
        if isinstance(v, float):
            return "" if v != v else f"{v:.4g}"
        return str(v)

    cols = [str(c) for c in df.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, r in df.iterrows():
        lines.append("| " + " | ".join(fmt(v) for v in r.tolist()) + " |")
    return "\n".join(lines)


def write_report(report: Report, ctx: Context) -> list[Path]:
    """Write ``NAME.md`` (figure, table with the paper's values, comment, runtime, machine) and
    ``NAME.csv`` into ``ctx.out``; returns the written paths (figures are written by the study)."""
    ctx.out.mkdir(parents=True, exist_ok=True)
    csv = ctx.out / f"{report.name}.csv"
    report.table.to_csv(csv, index=False)
    from .. import __version__

    version = "reduced (CI) version" if ctx.reduced else "full version"
    lines = [
        f"# {report.title}",
        "",
        f"Written by `rockdem reproduce {report.name}{' --reduced' if ctx.reduced else ''}` ({version}), rockdem {__version__}, "
        f"on {_dt.date.today().isoformat()}: **{report.runtime_s:.0f} s** wall time on {_machine()}"
        f" (executor {ctx.executor}{'' if ctx.workers is None else f', {ctx.workers} workers'}); "
        f"{ctx.computed} runs computed, {ctx.reused} reused from the study stores."
        + (f" Machine load (1-minute load average): {report.load[0]:.1f} at the start, {report.load[1]:.1f} at the end."
           if report.load is not None else ""),
        "",
    ]
    lines += [f"![{f}]({f})" for f in report.figures]
    lines += ["", "## Results (ours beside the paper's)", "", _markdown_table(report.table), "",
              f"Table as CSV: [{csv.name}]({csv.name}).", "", "## Comment", "", report.comment.strip(), ""]
    if report.notes:
        lines += [report.notes.strip(), ""]
    md = ctx.out / f"{report.name}.md"
    md.write_text("\n".join(lines))
    return [md, csv]


def write_index(ctx: Context) -> Path:
    """``README.md`` of the output folder: one line per study report found there."""
    _load_studies()
    lines = ["# The paper's studies reproduced", "",
             "Each report below was written by `rockdem reproduce NAME`; it shows the paper's published values "
             "beside ours, a figure and a comment on the differences, with the runtime on the machine that ran it.", ""]
    for name, rep in REPRODUCTIONS.items():
        md = ctx.out / f"{name}.md"
        if md.exists():
            lines.append(f"- [{rep.title}]({md.name})")
    p = ctx.out / "README.md"
    p.write_text("\n".join(lines) + "\n")
    return p


def _load() -> float | None:
    """1-minute load average, or None where the system does not give it."""
    try:
        return float(os.getloadavg()[0])
    except (AttributeError, OSError):
        return None


def run_reproduction(name: str, ctx: Context) -> Report:
    """Run the study ``name`` and write its report; returns the report (with ``runtime_s``)."""
    _load_studies()
    if name not in REPRODUCTIONS:
        raise ValueError(f"unknown study {name!r}; studies are {sorted(REPRODUCTIONS)} (or 'all')")
    t0 = time.perf_counter()
    load0 = _load()
    ctx.computed = ctx.reused = 0
    report = REPRODUCTIONS[name].run(ctx)
    report.runtime_s = time.perf_counter() - t0
    load1 = _load()
    report.load = (load0, load1) if load0 is not None and load1 is not None else None
    write_report(report, ctx)
    return report


def names() -> list[str]:
    """Registered study names, in registration order."""
    _load_studies()
    return list(REPRODUCTIONS)


def _run_cli(args: argparse.Namespace) -> int:
    if args.list or not args.names:
        for n in names():
            print(f"{n:8s} {REPRODUCTIONS[n].title}")
        return 0
    todo: Iterable[str] = names() if args.names == ["all"] else args.names
    out = Path(args.out) if args.out else (DEFAULT_REDUCED_OUT if args.reduced else DEFAULT_OUT)
    ctx = Context(out=out, cache=Path(args.cache), reduced=args.reduced, executor=args.executor or "process",
                  workers=args.workers, scheduler=args.scheduler, progress=not args.quiet)
    from ..cli import stop_on_signals

    try:
        with stop_on_signals():  # SIGTERM and SIGHUP as Ctrl-C (it ended the command without a word)
            for n in todo:
                rep = run_reproduction(n, ctx)
                print(f"rockdem reproduce {n}: {rep.runtime_s:.1f} s -> {ctx.out / (n + '.md')}")
    except KeyboardInterrupt:
        print(f"rockdem reproduce: stopped; the finished runs are kept in {ctx.cache} and a rerun of the same "
              "command resumes", file=sys.stderr)
        raise
    write_index(ctx)
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``reproduce`` sub-command."""
    p = subparsers.add_parser("reproduce", help="reproduce a study of the paper (figure + table in docs/reproduction/)")
    p.add_argument("names", nargs="*", help="study names, or 'all'; none: list them")
    p.add_argument("--list", action="store_true", help="list the studies")
    p.add_argument("--reduced", action="store_true", help="small, fast version (CI); written to results/reproduction-reduced/")
    p.add_argument("--out", help=f"output folder (default {DEFAULT_OUT}, or {DEFAULT_REDUCED_OUT} with --reduced)")
    p.add_argument("--cache", default=str(DEFAULT_CACHE), help=f"run stores, reused by reruns (default {DEFAULT_CACHE})")
    p.add_argument("--executor", choices=("process", "serial", "dask"), help="how runs execute (default process)")
    p.add_argument("--workers", type=int, help="processes (default: all cores)")
    p.add_argument("--scheduler", help="Dask scheduler address (implies --executor dask)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=_run_cli)
