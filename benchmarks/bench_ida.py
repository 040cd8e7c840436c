"""IDA at scale (issue 13). Run: ``python benchmarks/bench_ida.py`` (prints figures; 3-6 min);
``--full`` runs the whole 10 000-run grid on the pool and measures it end to end.

The target study: the built-in free-rocking block (0.2 x 2 m, 1800 kg/m^3, E = 1800 MPa, SP
damping with DeJong's beta = 0.00693 s, 2 x 2 interface points) under El Centro RSN6 and the
Peknold processing (both shipped), scaled to 5000 PGA levels from 0.05 to 1 g each, 20 s per run
(inertial mode, the case's record interval 2 ms): 2 x 5000 = 10 000 runs, by default stopping each
run once its outcome is decided.

The figures come from a sample of that grid: every k-th PGA level of both records (``--runs``,
default 400), evenly spread over 0.05-1 g, so the sample's mean cost per run estimates the full
grid's. The projection for 10 000 runs on 2 cores is

    pool start-up + 10 000 x (mean processor time per run) / 2,

processor time (``cpu_s`` of the rows) rather than wall time, so that other jobs sharing the
machine do not inflate it; the measured wall time of the pool is printed beside it.

Prints:
(a) the batch path in this process: per run, wall and processor time, the time inside the
    compiled kernel and outside it (model derivation + checks + summary), and why runs stopped;
(b) a local process pool of ``--workers`` (2): wall time, runs per second and per second per core,
    and the projection above;
(c) the same sample on a Dask LocalCluster (2 workers, 1 thread each): its rows are identical to
    the pool's (timings aside);
(d) the single-run path of before (parse, run to the end, Dataset, summary) on a few runs;
(e) ``--chunks``: the check interval (steps per compiled chunk, rockdem.stopping.CHECK_STEPS):
    loop overhead against wasted steps, and the same decisions at every interval.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings

import numpy as np
import pandas as pd

from rockdem.batch import case_of, frames_from_run, run_batch, summary_row
from rockdem.fragility import ida_specs
from rockdem.run_cli import run_options
from rockdem.simulation import run_model
from rockdem.stopping import CHECK_STEPS, StopRule
from rockdem.studies import TIMING_COLUMNS, Store, execute, run_spec, study_table

RECORDS = ("elcentro-rsn6", "elcentro-peknold")
LEVELS = 5000
TOTAL = len(RECORDS) * LEVELS


def sample_specs(runs: int, stop: str = "decided") -> list:
    """Every k-th of the 5000 PGA levels, for both records (about ``runs`` runs)."""
    levels = np.linspace(0.05, 1.0, LEVELS)
    k = max(1, TOTAL // runs)
    return ida_specs("free-rocking", RECORDS, levels[k // 2 :: k], duration=20.0, stop=stop)


def load() -> str:
    return " / ".join(f"{x:.1f}" for x in os.getloadavg())


class KernelClock:
    """Wraps the compiled ``advance`` called by rockdem.simulation to add up its processor time
    (this thread's), which other jobs on the machine do not inflate as they do wall time."""

    def __init__(self) -> None:
        import rockdem.simulation as sim

        self.sim, self.advance, self.cpu = sim, sim.advance, 0.0

    def __enter__(self) -> "KernelClock":
        def timed(*args):
            c0 = time.thread_time()
            try:
                return self.advance(*args)
            finally:
                self.cpu += time.thread_time() - c0

        self.sim.advance = timed
        return self

    def __exit__(self, *exc) -> None:
        self.sim.advance = self.advance


def part_a(specs: list) -> None:
    print(f"(a) batch path, serial, {len(specs)} runs (load average {load()})")
    run_batch(specs[:2])  # warm: Numba's cached kernels loaded, templates built
    t0 = time.perf_counter()
    with KernelClock() as clock:
        rows = pd.DataFrame(run_batch(specs))
    wall = time.perf_counter() - t0
    ok = rows[rows["status"] == "ok"]
    kernel, runtime, w, cpu = (ok[c].astype(float) for c in ("kernel_s", "runtime_s", "wall_s", "cpu_s"))
    k_cpu = clock.cpu / len(rows)
    print(f"    {wall:.1f} s, {wall / len(rows) * 1e3:.1f} ms per run; per run: wall {w.mean() * 1e3:.1f} ms, "
          f"processor {cpu.mean() * 1e3:.1f} ms = kernel {k_cpu * 1e3:.1f} ms + outside the kernel "
          f"{(cpu.mean() - k_cpu) * 1e3:.2f} ms (processor times: robust to other jobs)")
    print("    wall-clock split (inflated by other jobs on the machine):")
    print(f"    kernel {kernel.mean() * 1e3:.1f} ms (median {kernel.median() * 1e3:.1f}); outside it "
          f"{(w - kernel).mean() * 1e3:.2f} ms = {(runtime - kernel).mean() * 1e3:.2f} ms in the loop (chunk calls, "
          f"stop checks) + {(w - runtime).mean() * 1e3:.2f} ms around it (model from the template, start, summary row)")
    print(f"    steps per run {ok['steps'].mean():.0f}; stop reasons: "
          + ", ".join(f"{n} {r}" for r, n in ok["stop_reason"].fillna("ran to the end").value_counts().items()))
    for reason, g in ok.groupby(ok["stop_reason"].fillna("ran to the end")):
        print(f"      {reason:>15}: kernel {g['kernel_s'].mean() * 1e3:.1f} ms, stopped at {g['stop_time_s'].mean():.2f} s"
              if reason != "ran to the end" else f"      {reason:>15}: kernel {g['kernel_s'].mean() * 1e3:.1f} ms")


def part_b(specs: list, workers: int, folder: str) -> pd.DataFrame:
    print(f"(b) local process pool, {workers} workers, {len(specs)} runs (load average {load()})")
    t0 = time.perf_counter()
    execute(sample_specs(2 * workers)[: 2 * workers], os.path.join(folder, "warm"), workers=workers, progress=False)
    startup = time.perf_counter() - t0
    t0 = time.perf_counter()
    execute(specs, os.path.join(folder, "pool"), workers=workers, progress=False)
    wall = time.perf_counter() - t0
    df = study_table(Store(os.path.join(folder, "pool")), specs=specs)
    cpu = df["cpu_s"].astype(float)
    print(f"    start-up of a pool (spawn, imports, cached kernels, {2 * workers} short runs): {startup:.1f} s")
    print(f"    {wall:.1f} s wall incl. its start-up: {len(df) / wall:.1f} runs/s, {len(df) / wall / workers:.1f} runs/s/core; "
          f"after start-up {len(df) / max(wall - startup, 1e-9) / workers:.1f} runs/s/core")
    print(f"    processor time per run {cpu.mean() * 1e3:.1f} ms: {1 / cpu.mean():.1f} runs/s/core on a free core")
    proj = startup + TOTAL * cpu.mean() / workers
    from_wall = startup + TOTAL * max(wall - startup, 0.0) / len(df)
    print(f"    projected {TOTAL} runs on {workers} cores: {startup:.1f} + {TOTAL} x {cpu.mean() * 1e3:.1f} ms / {workers} "
          f"= {proj:.0f} s ({proj / 60:.1f} min); from this pool's wall time after start-up: {from_wall / 60:.1f} min")
    return df


def part_c(specs: list, pool: pd.DataFrame, folder: str) -> None:
    try:
        import distributed
    except ImportError:
        print("(c) Dask: not installed (pip install 'rockdem[dask]')")
        return
    print(f"(c) Dask LocalCluster, 2 workers x 1 thread, {len(specs)} runs")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None) as cluster:
            t0 = time.perf_counter()
            execute(specs, os.path.join(folder, "dask"), scheduler=cluster.scheduler_address, progress=False)
            wall = time.perf_counter() - t0
    dask = study_table(Store(os.path.join(folder, "dask")), specs=specs)

    def strip(df: pd.DataFrame) -> pd.DataFrame:
        return df.drop(columns=[c for c in TIMING_COLUMNS if c in df]).sort_values("id").reset_index(drop=True)

    same = strip(pool).equals(strip(dask))
    print(f"    {wall:.1f} s; rows identical to the pool's (timings aside): {same}")


def part_d(specs: list) -> None:
    print("(d) single-run path of before (parse, run to the end, Dataset, summary), serial")
    before = sample_specs(len(specs), stop="off")
    pick = before[:: max(1, len(before) // 6)][:6]
    t0 = time.perf_counter()
    rows = [run_spec(s) for s in pick]
    wall = time.perf_counter() - t0
    print(f"    {len(pick)} runs: {wall / len(pick):.2f} s per run (kernel {np.mean([r['kernel_s'] for r in rows]):.2f} s); "
          f"projected {TOTAL} runs on 2 cores: {TOTAL * wall / len(pick) / 2 / 3600:.1f} h")


def part_e(specs: list) -> None:
    print(f"(e) check interval: steps per compiled chunk (default {CHECK_STEPS}), serial, {len(specs)} runs")
    base = None
    print(f"    {'steps':>7} {'kernel [ms]':>11} {'loop outside it [ms]':>20} {'run [ms]':>8} {'steps per run':>13} {'same decisions':>14}"
          "   (processor times per run)")
    for n in (250, 1000, 2000, 4000, 8000, 16000, 64000):
        rows, steps = [], []
        c0 = time.process_time()
        with KernelClock() as clock:
            loop = 0.0
            for s in specs:
                data = s.case_dict()
                case = case_of(data)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    l0, k0 = time.process_time(), clock.cpu
                    out = run_model(case.model, **{**run_options(case), "stop": StopRule(check_steps=n)}, progress=False)
                    loop += time.process_time() - l0 - (clock.cpu - k0)
                row = summary_row(s, data, frames_from_run(case, out))
                steps.append(out.attrs["steps"])
                rows.append((row["stop_reason"], row["stop_time_s"], row["max_rotation_rad"]))
        total = (time.process_time() - c0) / len(specs)
        base = base or rows
        print(f"    {n:>7} {clock.cpu / len(specs) * 1e3:>11.1f} {loop / len(specs) * 1e3:>20.2f} {total * 1e3:>8.1f} "
              f"{np.mean(steps):>13.0f} {str(rows == base):>14}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=400, help="sample size (evenly spread over the 10 000-run grid)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--chunks", action="store_true", help="also (e): the check interval sweep")
    p.add_argument("--no-dask", action="store_true")
    p.add_argument("--full", action="store_true", help="only (b), on all 10 000 runs: the target measured end to end")
    args = p.parse_args()
    if args.full:
        print(f"IDA benchmark, the whole grid: {TOTAL} runs on a pool of {args.workers} workers; {os.cpu_count()} cores here")
        with tempfile.TemporaryDirectory() as folder:
            part_b(sample_specs(TOTAL), args.workers, folder)
        return
    specs = sample_specs(args.runs)
    print(f"IDA benchmark: sample of {len(specs)} of the {TOTAL} runs (2 records x {LEVELS} PGA levels 0.05-1 g, 20 s, "
          f"the free-rocking block, SP beta 0.00693 s, 2 x 2 points, stop = decided); {os.cpu_count()} cores here")
    part_a(specs)
    with tempfile.TemporaryDirectory() as folder:
        pool = part_b(specs, args.workers, folder)
        if not args.no_dask:
            part_c(specs, pool, folder)
    part_d(specs)
    if args.chunks:
        part_e(specs[:: max(1, len(specs) // 100)])


if __name__ == "__main__":
    main()
