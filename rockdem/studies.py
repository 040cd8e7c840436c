"""Studies at scale: sweeps of small picklable run specs, a crash-safe store, executors.

The paper points to damping values fitted by "lengthy and tedious trial and error" (Galvez et al. 2022,
§4.2); here the runs of such a search, a sensitivity study or an IDA are specs run at scale.

A study is a base case (a case dict, e.g. ``example_case("free-rocking")``) plus variations
(grid, list or seeded random samples of ``"table.key"`` overrides). Each variation becomes a
:class:`RunSpec`, a frozen, picklable value with a stable :attr:`RunSpec.id` (sha1 of its canonical
JSON). :func:`run_spec` is a pure function spec -> summary row (a flat dict), optionally with a
decimated history. :func:`execute` runs the specs that are not yet in a :class:`Store` serially, in a
local process pool (default, all cores) or on a Dask cluster, appending each finished row to the
store at once (flushed and fsynced): an interrupted study loses no finished run and a rerun skips
finished specs. :func:`study_table` builds the pandas table (CSV, and Parquet when available).
Pool workers exit when the process that started them dies (a killed sweep leaves no orphan), and an
interrupted sweep (Ctrl-C, SIGTERM, SIGHUP) stops its workers at once; its finished rows are kept.

Command line: ``rockdem sweep STUDY.toml``, ``rockdem calibrate``, ``rockdem fragility`` (the
latter two from :mod:`rockdem.calibration` and :mod:`rockdem.fragility`, registered here).
"""

from __future__ import annotations

import argparse
import copy
import functools
import hashlib
import itertools
import json
import math
import os
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ._warn import warn_user
from .cli import integer_at_least, output_folder, positive_float, positive_int, stop_on_signals
from .case import MAX_MAGNITUDE, apply_overrides, check_plausible, example_case, example_names, load_case, parse_case, read_toml

__all__ = [
    "RunSpec",
    "run_spec",
    "Store",
    "execute",
    "study_table",
    "save_table",
    "expand_grid",
    "expand_list",
    "expand_random",
    "make_specs",
    "with_stop",
    "Study",
    "load_study",
    "read_with_care",
    "run_study",
    "resolve_base",
    "TIMING_COLUMNS",
    "register_cli",
]

TIMING_COLUMNS = ("runtime_s", "kernel_s", "wall_s", "cpu_s", "beta_search_time_s")
"""Row entries that measure time and therefore differ between otherwise identical runs."""

EXECUTORS = ("process", "serial", "dask")
MAX_RUNS = 100_000
"""Most runs of one study (grid, list and random variations multiplied)."""
FINISHED = ("ok", "diverged")
"""Row statuses of finished runs (a diverged run is deterministic: rerunning it gives the same row)."""


# --------------------------------------------------------------------------------------------------
# specs
# --------------------------------------------------------------------------------------------------
def _canonical(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str)


def _numbers_as_floats(obj: Any) -> Any:
    """``obj`` (JSON-like) with every int a float (bools kept)."""
    if isinstance(obj, dict):
        return {k: _numbers_as_floats(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_numbers_as_floats(v) for v in obj]
    if isinstance(obj, int) and not isinstance(obj, bool):
        return float(obj)
    return obj


def _warn_respelled(specs: Sequence[RunSpec]) -> None:
    """Warn where two runs' settings differ only in how a number is written (a grid's ``[1, 1.0]``):
    their ids differ (:attr:`RunSpec.id` hashes the JSON as written, and stored ids must not
    change), and an integer setting may refuse the float, so both run."""
    first: dict[str, RunSpec] = {}
    twins: list[tuple[RunSpec, RunSpec]] = []
    for spec in specs:
        twin = first.setdefault(_canonical(_numbers_as_floats(spec.to_json())), spec)
        if twin is not spec:
            twins.append((twin, spec))
    if twins:
        a, b = twins[0]
        warn_user(f"{len(twins)} run(s) repeat another run's settings with a number written differently, and run as "
                  f"separate runs (the first: {_describe(b)} beside {_describe(a)}); write each value of a grid, a list "
                  "or an IDA once")


def _plain(value: Any) -> Any:
    """NumPy scalars -> Python scalars (so that specs hash and serialise the same way)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


@dataclass(frozen=True)
class RunSpec:
    """One run of a study: a pure, picklable description.

    Attributes:
        base: the base case dict (as read from TOML).
        overrides: ``(("table.key", value), ...)``, sorted by key (use :meth:`make`).
        duration: simulated time [s]; None keeps ``[run] duration`` of the case.
        record: ground-motion record (a name in the shared records folder, or a file path); when
            given, the case's ``[loading]`` becomes an ``earthquake`` loading of that record (the
            base's earthquake keys kept if it has one, else ``mode = "inertial"``).
        pga_g: target peak ground acceleration of the record [g] (None: record unscaled).
        history: keep a decimated history (time, rotation, monitor displacement) in the row.
        history_interval: decimation of the history [s] (None: the case's record interval).
        history_xyz: the history also keeps every monitor's three displacement components
            (``monitor_xyz``, (T, monitors, 3) [m]; vertical rattling, torsion, out-of-plane drift).
    """

    base: Mapping[str, Any]
    overrides: tuple[tuple[str, Any], ...] = ()
    duration: float | None = None
    record: str | None = None
    pga_g: float | None = None
    history: bool = False
    history_interval: float | None = None
    history_xyz: bool = False

    @classmethod
    def make(cls, base: Mapping[str, Any], overrides: Mapping[str, Any] | None = None, **kwargs: Any) -> "RunSpec":
        """Build a spec from an overrides mapping ``{"damping.beta": 0.002, ...}``."""
        if not isinstance(base, Mapping):
            raise ValueError(f"base must be a case dict (e.g. example_case('free-rocking')), got {base!r}"[:200])
        if overrides is not None and not isinstance(overrides, Mapping):
            raise ValueError(f"overrides must be a mapping of 'table.key' to values, got {overrides!r}"[:200])
        items = tuple(sorted((str(k), _plain(v)) for k, v in (overrides or {}).items()))
        given = {k for k, _ in items}
        for arg, keys in (("duration", ("run.duration",)), ("record", ("loading.record",)),
                          ("pga_g", ("loading.pga_g", "loading.scale"))):
            clash = sorted(given.intersection(keys)) if kwargs.get(arg) is not None else []
            if clash:
                raise ValueError(f"{clash[0]} is set by an override and by the study's own {arg} "
                                 f"({kwargs[arg]!r}); the spec would silently take one of them: give it in one place")
        for key in ("duration", "pga_g", "history_interval"):
            if kwargs.get(key) is not None:
                kwargs[key] = _positive(kwargs[key], key)
        if kwargs.get("pga_g") is not None:
            check_plausible(kwargs["pga_g"], "pga_g", "pga_g")
        return cls(base=base, overrides=items, **kwargs)

    def to_json(self) -> dict[str, Any]:
        """Canonical JSON-able form (what the id hashes; with a record, its file's sha1 too, so that
        an edited record file is a new run)."""
        out = {
            "base": self.base,
            "overrides": [[k, v] for k, v in self.overrides],
            "duration": self.duration,
            "record": self.record,
            "pga_g": self.pga_g,
            "history": self.history,
            "history_interval": self.history_interval,
        }
        if self.history_xyz:  # only when set: specs without it keep the ids they had before it existed
            out["history_xyz"] = True
        if self.record is not None:
            out["record_sha1"] = _file_sha1(self.record)
        files = {k: v for k, v in _record_files(self.case_dict()).items() if not (k == "record" and self.record is not None)}
        if files:  # the base case's or an override's own record files (not shipped ones): edited, a new run
            out["files_sha1"] = files
        return out

    @property
    def id(self) -> str:
        """Stable identifier: first 16 hex digits of sha1(canonical JSON)."""
        return hashlib.sha1(_canonical(self.to_json()).encode()).hexdigest()[:16]

    @property
    def inputs(self) -> dict[str, Any]:
        """The varied inputs, as table columns."""
        out: dict[str, Any] = dict(self.overrides)
        if self.duration is not None:
            out["duration"] = self.duration
        if self.record is not None:
            out["record"] = self.record
            out["pga_g"] = self.pga_g
        return out

    def case_dict(self) -> dict[str, Any]:
        """The full case dict of this run."""
        data = copy.deepcopy(dict(self.base))
        if self.record is not None:
            # the base case's earthquake settings (mode, direction, tail, ...) are kept; any other
            # loading becomes the record as inertial body forces on the free blocks
            load = data.get("loading", {})
            load = dict(load) if load.get("type") == "earthquake" else {"type": "earthquake", "mode": "inertial"}
            load["record"] = self.record
            if self.pga_g is not None:
                load.pop("scale", None)
                load["pga_g"] = self.pga_g
            data["loading"] = load
        data = apply_overrides(data, [f"{k}={_toml_value(v)}" for k, v in self.overrides])
        if self.duration is not None:
            data.setdefault("run", {})["duration"] = self.duration
        return data


def _file_sha1(record: str) -> str:
    """sha1 of a record's file (a shipped name or a path), "missing" when there is none."""
    from .loading import resolve_record

    try:
        path = resolve_record(record)
        stat = path.stat()
    except (FileNotFoundError, ValueError, OSError):
        return "missing"
    return _path_sha1(str(path), stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=256)
def _path_sha1(path: str, mtime_ns: int, size: int) -> str:
    """sha1 of the file at ``path``, cached while its modification time and size stay the same."""
    try:
        return hashlib.sha1(Path(path).read_bytes()).hexdigest()
    except OSError:
        return "missing"


def _record_files(data: Mapping[str, Any]) -> dict[str, str]:
    """sha1 of the record files a case's earthquake loading reads (``record``, ``vertical``), by
    key; shipped records (fixed by their SHA-256) are left out, so their runs keep their ids.
    Before 2026-11-30 a sweep whose base case read a record file reused its old results after
    the file was edited."""
    from .records import SHIPPED_RECORDS

    load = data.get("loading")
    if not isinstance(load, Mapping) or load.get("type") != "earthquake":
        return {}
    shipped = {r.name for r in SHIPPED_RECORDS}
    return {key: _file_sha1(v) for key in ("record", "vertical") if isinstance(v := load.get(key), str) and v not in shipped}


def _positive(value: Any, what: str) -> float:
    """A positive finite number, or ValueError naming ``what``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)) or not (math.isfinite(value) and value > 0):
        raise ValueError(f"{what} must be a positive number, got {value!r}")
    if value > MAX_MAGNITUDE:
        raise ValueError(f"{what} = {value!r} is beyond any plausible value; check the units")
    return float(value)


def _workers(value: Any, what: str = "workers") -> int | None:
    """None (all cores) or an integer >= 1."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{what} must be an integer >= 1 (processes; omit it for all cores), got {value!r}")
    return int(value)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise ValueError(f"override value {v!r} is not a TOML scalar or list")


def run_spec(spec: RunSpec) -> dict[str, Any]:
    """Run one spec as a single run and return its summary row (pure: same spec -> same row,
    timings aside). The executors use the batch path (:mod:`rockdem.batch`), which gives the same
    row without the Dataset; this is the reference it is tested against.

    Row keys: ``id``, the inputs (override keys, duration, record, pga_g), ``status`` ("ok", or
    "diverged" with ``diverged_time_s`` when the engine's divergence check cut the run short: the
    summary then covers the sound part), with ``run.stop`` on (:mod:`rockdem.stopping`):
    ``stop_reason`` ("overturned", "fell", "rest", or None for a run that went to its end),
    ``stop_time_s`` and ``stop_block``; ``max_rotation_rad``, ``max_rotation_over_eta``,
    ``overturned``, ``fallen_blocks`` (free blocks fallen at the end: :func:`rockdem.analysis.fallen`),
    ``residual_rad``, ``residual_disp_m`` / ``max_disp_m`` (first monitor,
    horizontal), ``e_a_mean``, ``bounce_max_m_s``, ``failed_shear_fraction``,
    ``failed_tension_fraction``, ``energy_created_J`` (the largest rise of the mechanical energy beyond
    the work done: energy the engine created), ``energy_error_J`` (energy-balance error at the end) and
    ``energy_scale_J`` (the run's energy scale; :func:`rockdem.results.energy_check`), ``steps``, ``dt`` (the starting timestep), ``dt_min`` (the
    smallest, after any lowering at contact detections), ``runtime_s`` (engine loop), ``kernel_s``
    (inside the compiled kernel), ``wall_s`` (whole run), ``cpu_s`` (its processor time), and
    ``history`` when asked for; with ``damping.beta = "auto"`` or ``"critical"`` also ``beta_s``,
    ``beta_pairs`` and for "auto" ``beta_target_value``, ``beta_achieved_e_a``, ``beta_iterations``,
    ``beta_search_time_s`` (the search's time, run once per specimen and damping on the batch path).
    """
    from .batch import frames_from_dataset, summary_row
    from .run_cli import run_case

    t0, c0 = time.perf_counter(), time.process_time()
    data = spec.case_dict()
    case = parse_case(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = run_case(case, progress=False, threads=1)  # one thread per run, as on the batch path
    row = summary_row(spec, data, frames_from_dataset(ds))
    row["wall_s"] = time.perf_counter() - t0
    row["cpu_s"] = time.process_time() - c0
    return row


def _safe_run(spec: RunSpec) -> dict[str, Any]:
    """:func:`run_spec`, with an error row instead of an exception (a study goes on)."""
    try:
        return run_spec(spec)
    except Exception as exc:  # noqa: BLE001 - a failed run is recorded, not fatal
        return {"id": spec.id, **spec.inputs, "status": "error", "error": f"{type(exc).__name__}: {exc}"}


# --------------------------------------------------------------------------------------------------
# store
# --------------------------------------------------------------------------------------------------
class Store:
    """Append-only JSON-lines store of finished rows, one line per run, fsynced at once.

    Reading tolerates a truncated or corrupt last line (an interrupted write). When an id appears
    several times (an error retried), the last finished ("ok" or "diverged") row wins.
    """

    def __init__(self, path: str | os.PathLike[str]) -> None:
        p = Path(path)
        if p.suffix != ".jsonl":
            p = p / "runs.jsonl"
        self.path = p  # its folder is made at the first row: a study refused before any run writes nothing

    def kept(self) -> str:
        """What an interrupted study kept, for its stop message."""
        return f"the finished runs are kept in {self.path} (rerun to resume)" if self.path.exists() else "no run had finished (nothing kept)"

    def rows(self) -> list[dict[str, Any]]:
        """All stored rows, one per id (in first-finished order)."""
        if not self.path.exists():
            return []
        by_id: dict[str, dict[str, Any]] = {}
        with self.path.open("rb") as fh:
            for raw in fh:
                try:
                    row = json.loads(raw)
                except ValueError:
                    continue  # a truncated line from an interrupted write
                if not isinstance(row, dict) or "id" not in row:
                    continue
                old = by_id.get(row["id"])
                if old is None or old.get("status") not in FINISHED:
                    by_id[row["id"]] = row
        return list(by_id.values())

    def done_ids(self) -> set[str]:
        """Ids of the runs finished successfully."""
        return {r["id"] for r in self.rows() if r.get("status") in FINISHED}

    def append(self, row: Mapping[str, Any]) -> None:
        """Append one row and make it durable (flush + fsync)."""
        self.extend([row])

    def extend(self, rows: Sequence[Mapping[str, Any]]) -> None:
        """Append rows (one line each, in one write) and make them durable (flush + fsync)."""
        if not rows:
            return
        line = "".join(json.dumps(row, separators=(",", ":"), default=_json_default) + "\n" for row in rows)
        # a previous interrupted write may have left a partial line: start on a fresh line
        if self.path.exists() and self.path.stat().st_size > 0:
            with self.path.open("rb") as fh:
                fh.seek(-1, os.SEEK_END)
                if fh.read(1) != b"\n":
                    line = "\n" + line
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("a", encoding="utf-8") as fh:
            fh.write(line)
            fh.flush()
            os.fsync(fh.fileno())


def _json_default(v: Any) -> Any:
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    return str(v)


# --------------------------------------------------------------------------------------------------
# executors
# --------------------------------------------------------------------------------------------------
def exit_with_parent() -> None:
    """Pool-worker initializer: a daemon thread ends this process as soon as the process that
    started it dies (its sentinel pipe closes), so that killing a sweep, even with SIGKILL, leaves
    no orphaned worker running."""
    import multiprocessing as mp
    import threading

    parent = mp.parent_process()
    if parent is None:
        return

    def watch() -> None:
        parent.join()  # returns when the parent process is gone
        os._exit(1)

    threading.Thread(target=watch, name="rockdem-exit-with-parent", daemon=True).start()


def _stop_workers(pool: Any) -> None:
    """Terminate a process pool's workers now (an interrupted study does not wait for them)."""
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    if callable(terminate):
        terminate()
        return
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        proc.terminate()


def _iter_process(tasks: Sequence[list[RunSpec]], workers: int | None, fn: Callable[[list[RunSpec]], list[dict]]) -> Iterator[list[dict]]:
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    n = workers or os.cpu_count() or 1
    pool = ProcessPoolExecutor(max_workers=min(n, len(tasks)), mp_context=mp.get_context("spawn"), initializer=exit_with_parent)
    finished = False
    try:
        futures = [pool.submit(fn, t) for t in tasks]
        for fut in as_completed(futures):
            yield fut.result()
        finished = True
    finally:
        if not finished:  # interrupted (Ctrl-C, SIGTERM) or failed: stop the running workers now
            _stop_workers(pool)
        pool.shutdown(wait=finished, cancel_futures=True)


def _iter_dask(todo: Sequence[RunSpec], scheduler: Any, fn: Callable[[list[RunSpec]], list[dict]], batch: bool) -> Iterator[list[dict]]:
    try:
        from distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - optional extra
        raise ValueError("the dask executor needs the optional extra: pip install 'rockdem[dask]'") from exc
    own = not isinstance(scheduler, Client)
    client = Client(scheduler) if own else scheduler
    try:
        tasks = _tasks(todo, max(1, sum(client.nthreads().values())), batch)
        keys = [f"rockdem-runs-{hashlib.sha1(''.join(s.id for s in t).encode()).hexdigest()[:16]}" for t in tasks]
        futures = client.map(fn, list(tasks), key=keys, pure=False)
        try:
            for fut in as_completed(futures):
                yield fut.result()
        finally:
            client.cancel(futures)
    finally:
        if own:
            client.close()


MAX_TASK_RUNS = 16
"""Most runs per task of the process pool or Dask (the batch path): a task's rows reach the store
when the whole task is done, so a killed sweep recomputes at most this many runs per worker (half
a second of work for the IDA block of ``benchmarks/bench_ida.py``); a task costs ~1 ms to send."""

TASKS_PER_WORKER = 4
"""Tasks per worker at least, when there are enough runs (balances runs of unequal length)."""


def _single_tasks(specs: list[RunSpec]) -> list[dict]:
    """A task of the single-run path: :func:`run_spec` per spec, error rows for failures."""
    return [_safe_run(s) for s in specs]


def _tasks(todo: Sequence[RunSpec], workers: int, batch: bool) -> list[list[RunSpec]]:
    """Split the runs into tasks: by specimen (so that a worker reuses its model), at most
    :data:`MAX_TASK_RUNS` runs and at least :data:`TASKS_PER_WORKER` tasks per worker."""
    if not batch:
        return [[s] for s in todo]
    from .case import template_key

    keys: dict[str, str] = {}
    for s in todo:
        try:
            keys[s.id] = template_key(s.case_dict())
        except Exception:  # noqa: BLE001 - a bad spec fails in its task, with its error row
            keys[s.id] = ""
    ordered = sorted(todo, key=lambda s: keys[s.id])  # stable: the given order within a specimen
    size = max(1, min(MAX_TASK_RUNS, math.ceil(len(ordered) / (workers * TASKS_PER_WORKER))))
    tasks: list[list[RunSpec]] = []
    for s in ordered:
        if not tasks or len(tasks[-1]) >= size or keys[tasks[-1][-1].id] != keys[s.id]:
            tasks.append([])
        tasks[-1].append(s)
    return tasks


def execute(
    specs: Iterable[RunSpec],
    store: Store | str | os.PathLike[str] | None = None,
    *,
    executor: str = "process",
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = True,
    batch: bool = True,
) -> list[dict[str, Any]]:
    """Run the specs not yet finished in ``store``; each finished row is stored at once.

    Args:
        specs: run specs (duplicates, by id, run once).
        store: a :class:`Store` or its folder / ``.jsonl`` path; None keeps rows in memory only.
        executor: "process" (local process pool, default), "serial" or "dask".
        workers: process count for "process" (default: all cores).
        scheduler: Dask scheduler address (or a ``distributed.Client``); implies "dask".
        progress: show a progress bar with ETA (tqdm).
        batch: run through the batch path (:mod:`rockdem.batch`: one model per specimen and
            process, no Dataset, many runs per task); False runs :func:`run_spec` per spec. Both
            give identical rows (timings aside).

    Returns:
        The rows of all specs (stored ones included), in the order of ``specs``. Serial runs reach
        the store one by one; pool and Dask runs task by task (a task is at most
        :data:`MAX_TASK_RUNS` runs of one specimen).
    """
    if scheduler is not None:
        executor = "dask"
    if executor not in EXECUTORS:
        raise ValueError(f"executor must be one of {EXECUTORS}, got {executor!r}")
    if executor == "dask" and scheduler is None:
        raise ValueError("the dask executor needs a scheduler address (--scheduler tcp://HOST:PORT)")
    workers = _workers(workers)
    unique: dict[str, RunSpec] = {}
    for s in specs:
        unique.setdefault(s.id, s)
    if len(unique) < len(specs):
        seen: set[str] = set()
        for twice in specs:  # the first run that repeats an earlier one
            if twice.id in seen:
                break
            seen.add(twice.id)
        warn_user(f"{len(specs) - len(unique)} of the {len(specs)} runs repeat another run's settings and are run once "
                  f"(the first: {_describe(twice)}); a repeated value in a grid, a list or the levels and records of "
                  "an IDA adds no run")
    _warn_respelled(list(unique.values()))
    st = Store(store) if store is not None and not isinstance(store, Store) else store
    stored = {r["id"]: r for r in st.rows()} if st is not None else {}
    done = {i for i, r in stored.items() if r.get("status") in FINISHED}
    todo = [s for i, s in unique.items() if i not in done]
    results: dict[str, dict[str, Any]] = {i: stored[i] for i in unique if i in done}
    from tqdm.auto import tqdm

    from .batch import run_batch

    bar = tqdm(total=len(unique), initial=len(unique) - len(todo), disable=not progress, unit="run", desc="study")
    try:
        if not todo:
            return [results[i] for i in unique]
        fn = run_batch if batch else _single_tasks
        if executor == "serial":
            it: Iterator[list[dict]] = (fn([s]) for s in todo)
        elif executor == "process":
            it = _iter_process(_tasks(todo, workers or os.cpu_count() or 1, batch), workers, fn)
        else:
            it = _iter_dask(todo, scheduler, fn, batch)
        try:
            for rows in it:
                if st is not None:
                    st.extend(rows)  # a task's rows arrive together: one write, one fsync
                for row in rows:
                    results[row["id"]] = row
                bar.update(len(rows))
        finally:
            close = getattr(it, "close", None)
            if close is not None:
                close()  # an interrupted study stops its workers here, not at garbage collection
    finally:
        bar.close()
    return [results[i] for i in unique if i in results]


# --------------------------------------------------------------------------------------------------
# table
# --------------------------------------------------------------------------------------------------
def study_table(rows: Store | str | os.PathLike[str] | Iterable[Mapping[str, Any]], *, specs: Sequence[RunSpec] | None = None) -> pd.DataFrame:
    """The study table: one row per run, scalar columns only (histories dropped), sorted by id.

    Args:
        rows: a store (or its path) or rows.
        specs: keep only (and order by) these specs.
    """
    if isinstance(rows, (str, os.PathLike)):
        rows = Store(rows)
    data = rows.rows() if isinstance(rows, Store) else list(rows)
    data = [{k: v for k, v in r.items() if k != "history"} for r in data]
    df = pd.DataFrame(data)
    if df.empty:
        return df
    if specs is not None:
        order = {s.id: k for k, s in enumerate(specs)}
        df = df[df["id"].isin(order)].copy()
        df["_order"] = df["id"].map(order)
        return df.sort_values("_order").drop(columns="_order").reset_index(drop=True)
    return df.sort_values("id").reset_index(drop=True)


def save_table(df: pd.DataFrame, folder: str | os.PathLike[str], name: str = "table") -> list[Path]:
    """Write ``name.csv`` (and ``name.parquet`` when pyarrow or fastparquet is installed)."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{name}.csv"]
    df.to_csv(paths[0], index=False)
    try:
        df.to_parquet(out / f"{name}.parquet", index=False)
        paths.append(out / f"{name}.parquet")
    except (ImportError, ValueError):
        pass
    return paths


def histories(rows: Store | Iterable[Mapping[str, Any]]) -> dict[str, dict[str, np.ndarray]]:
    """Decimated histories by run id: {"time", "rotation", "displacement"} arrays (and
    "monitor_xyz", (T, monitors, 3), for specs with ``history_xyz``)."""
    data = rows.rows() if isinstance(rows, Store) else list(rows)
    return {r["id"]: {k: np.asarray(v, dtype=float) for k, v in r["history"].items()} for r in data if r.get("history")}


# --------------------------------------------------------------------------------------------------
# variations
# --------------------------------------------------------------------------------------------------
def expand_grid(params: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    """Full factorial: ``{"a": [1, 2], "b": [3]}`` -> ``[{"a": 1, "b": 3}, {"a": 2, "b": 3}]``."""
    if not isinstance(params, Mapping):
        raise ValueError(f"grid must be a table of \"table.key\" = [values], got {params!r}"[:200])
    keys = list(params)
    for k in keys:
        if not isinstance(params[k], (list, tuple)) or len(params[k]) == 0:
            raise ValueError(f"grid parameter {k!r}: give a non-empty list of values, got {params[k]!r}"[:200])
    _run_count(math.prod(len(params[k]) for k in keys), "grid")
    return [dict(zip(keys, combo)) for combo in itertools.product(*(params[k] for k in keys))]


def _run_count(n: int, what: str) -> None:
    if n > MAX_RUNS:
        raise ValueError(f"{what}: {n} runs exceed the limit of {MAX_RUNS} per study; split the study")


def expand_list(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Explicit variations, one mapping per run."""
    if isinstance(rows, (str, bytes, Mapping)) or not isinstance(rows, Sequence):
        raise ValueError(f"list: give a list of tables of \"table.key\" = value, got {rows!r}"[:200])
    if len(rows) == 0:
        raise ValueError("list: no rows; give at least one table of \"table.key\" = value (one per run)")
    _run_count(len(rows), "list")
    out = []
    for r in rows:
        if not isinstance(r, Mapping):
            raise ValueError(f"list variation {r!r}: give a table of table.key = value"[:200])
        out.append(dict(r))
    return out


def expand_random(ranges: Mapping[str, Any], n: int, seed: int) -> list[dict[str, Any]]:
    """``n`` seeded uniform samples; a range is ``[low, high]`` or ``{low, high, log = true}``
    (log-uniform) or a list of more than two choices (``{choices = [...]}``)."""
    if not isinstance(ranges, Mapping):
        raise ValueError(f"random must be a table of \"table.key\" = [low, high] (and n, seed), got {ranges!r}"[:200])
    for what, v, low in (("n", n, 1), ("seed", seed, 0)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low:
            raise ValueError(f"random: {what} must be an integer >= {low}, got {v!r}")
    _run_count(int(n), "random: n")
    rng = np.random.default_rng(seed)
    out: list[dict[str, Any]] = [{} for _ in range(n)]
    for key in sorted(ranges):
        r = ranges[key]
        if isinstance(r, Mapping) and "choices" in r:
            choices = r["choices"]
            if not isinstance(choices, (list, tuple)) or not choices:
                raise ValueError(f"random parameter {key!r}: choices must be a non-empty list, got {choices!r}")
            idx = rng.integers(0, len(choices), size=n)
            vals = [choices[i] for i in idx]
        else:
            extra = sorted(set(r) - {"low", "high", "log"}) if isinstance(r, Mapping) else []
            if extra:
                raise ValueError(f"random parameter {key!r}: unknown key(s) {extra}; a range takes low, high and log "
                                 "(or choices alone)")
            try:
                lo, hi, log = (r["low"], r["high"], r.get("log", False)) if isinstance(r, Mapping) else (*r, False)
                if isinstance(r, (str, bytes)) or isinstance(lo, bool) or isinstance(hi, bool):
                    raise TypeError
                lo, hi = float(lo), float(hi)
            except (TypeError, ValueError, KeyError):
                raise ValueError(
                    f"random parameter {key!r}: give [low, high], {{low, high, log = true}} or {{choices = [...]}}, got {r!r}"[:200]
                ) from None
            if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo) or (log and lo <= 0) or not isinstance(log, bool):
                raise ValueError(f"random parameter {key!r}: need finite low < high (and low > 0 for log = true), got {r!r}")
            u = rng.random(n)
            vals = list(np.exp(np.log(lo) + u * (np.log(hi) - np.log(lo))) if log else lo + u * (hi - lo))
        for row, v in zip(out, vals):
            row[key] = _plain(v)
    return out


def make_specs(
    base: Mapping[str, Any],
    variations: Iterable[Mapping[str, Any]],
    *,
    fixed: Mapping[str, Any] | None = None,
    duration: float | None = None,
    history: bool = False,
    history_interval: float | None = None,
    stop: str = "decided",
) -> list[RunSpec]:
    """One spec per variation (``fixed`` overrides are applied to every run). ``stop``: the runs'
    ``run.stop`` (:mod:`rockdem.stopping`; "decided" ends a run once it collapsed or is at rest
    after its input), unless ``fixed`` or the variation sets it; "off" adds nothing."""
    fixed = with_stop(fixed, stop)
    return [
        RunSpec.make(base, {**fixed, **v}, duration=duration, history=history, history_interval=history_interval)
        for v in variations
    ]


def with_stop(fixed: Mapping[str, Any] | None, stop: str) -> dict[str, Any]:
    """``fixed`` overrides with ``run.stop = stop`` added unless already set (nothing for "off",
    so that runs without stopping keep the ids they had before stopping existed)."""
    from .stopping import stop_rule

    out = dict(fixed or {})
    stop_rule(stop)  # checks the name
    if stop != "off":
        out.setdefault("run.stop", stop)
    return out


def resolve_base(base: str | Mapping[str, Any], relative_to: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """A base case dict from a built-in example name, a TOML path or a dict."""
    if isinstance(base, Mapping):
        return dict(base)
    if not isinstance(base, (str, os.PathLike)):
        raise ValueError(f"base must be a built-in example name, a case file path or a case dict, got {base!r}")
    if base in example_names():
        return example_case(base)
    p = Path(base)
    if not p.is_absolute() and relative_to is not None:
        p = Path(relative_to) / p
    return load_case(p)


@dataclass
class Study:
    """A study read from TOML: its specs and execution options."""

    name: str
    specs: list[RunSpec]
    executor: str = "process"
    workers: int | None = None
    scheduler: str | None = None
    options: dict[str, Any] = field(default_factory=dict)


def parse_study(data: Mapping[str, Any], *, relative_to: str | os.PathLike[str] | None = None, name: str = "study") -> Study:
    """Build a :class:`Study` from a dict of the study file format (see docs/studies.md)."""
    if not isinstance(data, Mapping) or not isinstance(data.get("study"), Mapping):
        raise ValueError("a study file needs a [study] table (base, duration, grid/list/random)")
    outside = sorted(set(data) - {"study"})
    if outside:
        raise ValueError(f"the study file has {outside} outside [study]: every key of a study lies in [study] or its "
                         "sub-tables ([study.grid], [study.list], [study.random], [study.set]); e.g. [grid] is [study.grid]")
    s = dict(data["study"])
    allowed = {"base", "duration", "executor", "workers", "scheduler", "set", "grid", "list", "random", "history",
               "history_interval", "name", "stop"}
    unknown = sorted(set(s) - allowed)
    if unknown:
        raise ValueError(f"[study] unknown key(s) {unknown}; accepted keys are {sorted(allowed)}")
    if "base" not in s:
        raise ValueError('[study] needs base = "free-rocking" (a built-in example) or a case file path')
    if not isinstance(s["base"], (str, Mapping)):
        raise ValueError(f'[study] base must be a built-in example name or a case file path (a string), got {s["base"]!r}')
    for key, kind in (("name", str), ("scheduler", str), ("history", bool), ("stop", str)):
        if key in s and not isinstance(s[key], kind):
            raise ValueError(f"[study] {key} must be a {'string' if kind is str else 'true or false'}, got {s[key]!r}")
    for key in ("duration", "history_interval"):
        if key in s:
            _positive(s[key], f"[study] {key} [s]")
    workers = _workers(s.get("workers"), "[study] workers")
    base = resolve_base(s["base"], relative_to)
    fixed = s.get("set", {})
    if not isinstance(fixed, Mapping):
        raise ValueError(f'[study] set must be a table of "table.key" = value, got {fixed!r}')
    parts: list[list[dict[str, Any]]] = []
    try:
        if "grid" in s:
            parts.append(expand_grid(s["grid"]))
        if "list" in s:
            lst = s["list"]
            if isinstance(lst, Mapping) and set(lst) - {"rows"}:
                raise ValueError(f"list: unknown key(s) {sorted(set(lst) - {'rows'})}; [study.list] holds rows = [...] "
                                 "(or give list = [...] directly)")
            parts.append(expand_list(lst["rows"] if isinstance(lst, Mapping) and "rows" in lst else lst))
        if "random" in s:
            r = s["random"]
            if not isinstance(r, Mapping):
                raise ValueError(f"random must be a table of \"table.key\" = [low, high] (and n, seed), got {r!r}")
            r = dict(r)
            n, seed = r.pop("n", 10), r.pop("seed", 0)
            parts.append(expand_random(r, n, seed))
    except ValueError as exc:
        raise ValueError(f"[study] {exc}") from None
    _run_count(math.prod(len(p) for p in parts), "[study] grid x list x random")
    seen: dict[str, str] = {key: "[study] set" for key in fixed}
    for key in ("duration", "stop"):
        if key in s and f"run.{key}" in seen:
            raise ValueError(f"[study] 'run.{key}' is given both in [study] set and as [study] {key}; give it in one place")
        if key in s:
            seen[f"run.{key}"] = f"[study] {key}"
    for where, part in zip([n for n in ("grid", "list", "random") if n in s], parts):
        for key in sorted({k for row in part for k in row}):
            if key in seen:
                raise ValueError(f"[study] {key!r} is given both in {seen[key]} and in [study.{where}]; "
                                 "give each key in one place (the runs would silently take one of them)")
            seen[key] = f"[study.{where}]"
    variations = [{}]
    for part in parts:
        variations = [{**a, **b} for a in variations for b in part]
    executor = s.get("executor", "process")
    if executor not in EXECUTORS:
        raise ValueError(f"[study] executor must be one of {EXECUTORS}, got {executor!r}")
    if executor == "dask" and not s.get("scheduler"):
        raise ValueError('[study] executor = "dask" needs scheduler = "tcp://HOST:PORT" (or --scheduler)')
    from .stopping import STOP_MODES

    if s.get("stop", "decided") not in STOP_MODES:
        raise ValueError(f"[study] stop must be one of {list(STOP_MODES)}, got {s['stop']!r}")
    specs = make_specs(
        base, variations, fixed=fixed, duration=s.get("duration"), history=s.get("history", False),
        history_interval=s.get("history_interval"), stop=s.get("stop", "decided"),
    )
    return Study(str(s.get("name", name)), specs, executor, workers, s.get("scheduler"), s)


def load_study(path: str | os.PathLike[str]) -> Study:
    """Read a study TOML file."""
    data = read_toml(path, "study file")
    p = Path(path)
    return parse_study(data, relative_to=p.parent, name=p.stem)


def run_study(study: Study, out: str | os.PathLike[str], *, executor: str | None = None, workers: int | None = None,
              scheduler: str | None = None, progress: bool = True) -> pd.DataFrame:
    """Run (or resume) a study into folder ``out``: ``runs.jsonl`` and ``table.csv`` (+ parquet)."""
    store = Store(out)
    execute(study.specs, store, executor=executor or study.executor, workers=workers or study.workers,
            scheduler=scheduler or study.scheduler, progress=progress)
    df = study_table(store, specs=study.specs)
    save_table(df, Path(out))
    for note in read_with_care(df):
        warn_user(note)
    return df


def read_with_care(df: pd.DataFrame) -> list[str]:
    """Notes on the rows of a study table whose figures to read with care (the runs' own warnings
    are silenced inside a study): runs whose ``energy_created_J`` (the largest rise of their
    mechanical energy beyond the work done) exceeds :data:`rockdem.simulation.ENERGY_DRIFT_SHARE`
    of their energy scale (the share at which a single run warns of its balance error), and
    free-rocking runs whose mean apparent restitution ``e_a_mean`` exceeds 1 (the rocking grew
    between impacts, which no restitution model gives: Eq. 6 then reads no loss). One note per
    kind, naming the worst run; an empty list when none. (A row carries no free mass, so runs
    whose energies are noise, without gravity or load, are not told apart as a single run does.)"""
    from .simulation import ENERGY_DRIFT_SHARE

    notes = []
    if {"energy_created_J", "energy_scale_J"} <= set(df.columns):
        created, scale = (pd.to_numeric(df[c], errors="coerce") for c in ("energy_created_J", "energy_scale_J"))
        share = created / scale.where(scale > 0.0)
        bad = share[share > ENERGY_DRIFT_SHARE]
        if len(bad):
            k = bad.idxmax()
            notes.append(f"{len(bad)} of {len(df)} runs created energy beyond {ENERGY_DRIFT_SHARE:.0%} of their energy scale "
                         f"(the most: run {df.at[k, 'id']}, {created[k]:.3g} J, {bad[k]:.1%}; column "
                         "energy_created_J): fast impacts on small faces, blocks passing through one another; read those "
                         "rows with care (docs/contacts.md section 5)")
    if "e_a_mean" in df.columns:
        ea = pd.to_numeric(df["e_a_mean"], errors="coerce")
        above = ea[ea > 1.0]
        if len(above):
            k = above.idxmax()
            notes.append(f"{len(above)} of {len(df)} runs read a mean apparent restitution e_a_mean above 1 (the largest: "
                         f"run {df.at[k, 'id']}, {above[k]:.4f}): their rocking grew between impacts, so Eq. 6 reads no "
                         "loss there. Without damping the joints' elastic vibration, started by the release and the "
                         "impacts, feeds the rocking back (see energy_created_J for energy the engine created); "
                         "damp the joints (rockdem advise) before comparing e_a")
    return notes


# --------------------------------------------------------------------------------------------------
# CLI
# --------------------------------------------------------------------------------------------------
def _add_exec_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--executor", choices=EXECUTORS, default=None, help="default: the study's, else process")
    p.add_argument("--workers", type=positive_int, default=None, help="processes of the local pool (default: all cores)")
    p.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


CHECKED_RUNS = 64
"""Most runs whose cases :func:`check_first_run` builds before a study starts."""


def check_first_run(specs: Sequence[RunSpec], what: str = "the study") -> None:
    """Build the cases (no simulation) of the first run and of each run that brings a value no
    run before it had (up to CHECKED_RUNS of them), so that a bad base case, override or grid value
    is refused before any run starts, instead of ending as error rows (before 2026-11-29 only the
    first run was built: a grid [0.002, -0.002] failed at its second run)."""
    seen: set[tuple[str, str]] = set()
    checked = 0
    for k, spec in enumerate(specs):
        values = {(key, repr(v)) for key, v in spec.overrides} | {("record", repr(spec.record)), ("pga_g", repr(spec.pga_g))}
        if k > 0 and values <= seen:
            continue
        seen |= values
        try:
            parse_case(spec.case_dict())
        except (ValueError, FileNotFoundError) as exc:
            which = "first run" if k == 0 else f"run {k + 1} ({_describe(spec)})"
            raise ValueError(f"{what}'s {which} is not a valid case: {exc}") from None
        checked += 1
        if checked >= CHECKED_RUNS:
            return


def _describe(spec: RunSpec) -> str:
    """A run's settings in a line: its overrides, record and PGA."""
    parts = [f"{k} = {v!r}" for k, v in spec.overrides if k != "run.stop"]
    parts += [f"record {spec.record!r}"] if spec.record is not None else []
    parts += [f"pga_g = {spec.pga_g:g}"] if spec.pga_g is not None else []
    return ", ".join(parts) or "the base case"


def _sweep(args: argparse.Namespace) -> int:
    study = load_study(args.study)
    out = Path(args.out) if args.out else Path(args.study).with_suffix("")
    check_first_run(study.specs)
    output_folder(out, "--out", create=False)
    kept = len({spec.id for spec in study.specs} & Store(out).done_ids())  # finished by an earlier call: not run again
    t0 = time.perf_counter()
    try:
        with stop_on_signals():  # SIGTERM and SIGHUP stop the sweep and its workers as Ctrl-C does
            df = run_study(study, out, executor=args.executor, workers=args.workers, scheduler=args.scheduler,
                           progress=not args.no_progress)
    except KeyboardInterrupt:
        print(f"rockdem sweep: stopped; {Store(out).kept()}", file=sys.stderr)
        raise
    n_err = int((df["status"] == "error").sum()) if "status" in df else 0
    n_div = int((df["status"] == "diverged").sum()) if "status" in df else 0
    again = f", {kept} of them kept from an earlier call" if kept else ""  # (a resumed study ran only the rest)
    print(f"{len(df)} runs ({n_err} failed, {n_div} diverged{again}) in {time.perf_counter() - t0:.1f} s -> {out / 'table.csv'}")
    if n_err:
        failed = df[df["status"] == "error"]
        for _, row in failed.head(FAILED_SHOWN).iterrows():
            print(f"rockdem sweep: run {row['id']} failed: {row['error']}", file=sys.stderr)
        if n_err > FAILED_SHOWN:
            print(f"rockdem sweep: {n_err - FAILED_SHOWN} more failed runs: see the error column of {out / 'table.csv'}",
                  file=sys.stderr)
    return 0 if n_err == 0 else 1


FAILED_SHOWN = 5
"""Failed runs whose error a sweep prints at its end (all are in table.csv)."""


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add ``sweep``, ``calibrate`` and ``fragility``."""
    p = subparsers.add_parser("sweep", help="run (or resume) a parameter study from a study TOML file",
                              description="Run a study file; finished runs are kept in OUT/runs.jsonl and skipped on rerun.",
                              epilog="Exit status: 0 done; 1 some runs failed (see table.csv); 2 bad input (nothing run); "
                              "128+N stopped by signal N (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP): the pool workers are "
                              "stopped, the finished runs kept; rerun to resume. Workers also exit if the sweep is killed.")
    p.add_argument("study", help="study TOML file ([study] base, duration, grid/list/random)")
    p.add_argument("--out", "-o", default=None, help="output folder (default: the study file name)")
    _add_exec_args(p)
    p.set_defaults(func=_sweep)
    for mod in ("calibration", "fragility"):
        try:
            module = __import__(f"rockdem.{mod}", fromlist=["register_cli"])
        except ModuleNotFoundError as exc:
            if exc.name != f"rockdem.{mod}":
                raise
            continue
        module.register_cli(subparsers, _add_exec_args)
    for name in ("calibrate", "fragility"):
        if name in subparsers.choices:
            _check_flags(subparsers.choices[name])


_FLAG_TYPES: dict[str, Callable[[str], Any]] = {
    "workers": positive_int,
    "duration": positive_float,
    "scan": integer_at_least(3),  # the coarse scan of calibrate needs 3 points to bracket a minimum
    "drift_limit": positive_float,
}
"""Checks of the numeric flags shared by the study commands (calibrate, fragility)."""


def _check_flags(parser: argparse.ArgumentParser) -> None:
    """Give the numeric flags of a study command their checked types (bad values exit 2 naming the flag)."""
    for action in parser._actions:
        if action.dest in _FLAG_TYPES:
            action.type = _FLAG_TYPES[action.dest]
