"""Where a warm ``rockdem run --example free-rocking`` spends its time, phase by phase, in one
process: each library's import, then the parts of the run (the kernels' load and the simulation,
the Dataset, ``result.nc``, ``histories.csv``, the plot). Run: ``python benchmarks/warm_phases.py``
with a warm Numba cache (run the example once first); prints seconds per phase. The imports are
timed in the order the run needs them, so each line holds only what the lines above did not load
(docs/performance.md, "The warm start").
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

_last = [time.perf_counter()]


def lap(name: str) -> None:
    now = time.perf_counter()
    print(f"{name:34s} {now - _last[0]:.3f} s")
    _last[0] = now


def main() -> None:
    start = _last[0]
    import numpy  # noqa: F401
    lap("NumPy")
    import numba  # noqa: F401
    lap("Numba")
    import xarray  # noqa: F401
    lap("xarray (with pandas)")
    import rockdem.run_cli as rc
    lap("rockdem's modules")
    import matplotlib.figure  # noqa: F401
    lap("Matplotlib's figure")
    from rockdem import results, simulation
    from rockdem.case import example_case, parse_case

    case = parse_case(example_case("free-rocking"))
    lap("the case")
    build = results.build_dataset

    def timed_build(*args, **kwargs):  # type: ignore[no-untyped-def]
        lap("kernels loaded, 10 s simulated")
        ds = build(*args, **kwargs)
        lap("the Dataset")
        return ds

    simulation.build_dataset = timed_build
    ds = rc.run_case(case, progress=False)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        results.save(ds, out / "result.nc")
        lap("result.nc")
        rc.export_csv(ds, out / "histories.csv")
        lap("histories.csv")
        rc.plot_rocking(ds, out / "rocking.png")
        lap("the plot")
    print(f"{'in all (after the interpreter start)':34s} {time.perf_counter() - start:.3f} s")


if __name__ == "__main__":
    main()
