"""The joint law's own compiled code against the copy of it inside ``advance``, on the 1000-brick
wall (docs/performance.md, "The law's own code"). Run: ``python benchmarks/law_copy.py``
(prints figures; about three minutes with a warm cache).

Numba links a copy of every kernel that a kernel calls into the caller's compiled code and
optimizes it again there; a call runs the copy loaded first in the process (they are weak
symbols). :func:`rockdem.simulation._load_law_first` loads ``forces._law_pairs``'s own code
before any caller. Each round runs the wall of ``bench_engine.py wall`` for 0.05 s on one thread
in two fresh processes, one as rockdem runs it and one with that load skipped (so the law runs as
the copy in ``advance`` that Numba's cache loads), alternating; both load every kernel from the
cache and compute the same answer bit for bit.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROUNDS = 3
RUN = """
import sys, time
sys.path.insert(0, {here!r})
import numba
import rockdem.simulation as sim
from bench_engine import wall_model
from rockdem.simulation import simulate
if {skip}:
    sim._load_law_first = lambda model: None
numba.set_num_threads(1)
model = wall_model()
simulate(model, 1e-3, progress=False, threads=1)
ds = simulate(model, 0.05, record_interval=0.01, progress=False, threads=1)
print(ds.attrs["sub_contact_updates"] / ds.attrs["runtime_s"], ds.attrs["runtime_s"], ds.attrs["steps"], repr(float(ds.block_position.values.sum())))
"""


def _run(skip: bool) -> tuple[float, float, int, float]:
    code = RUN.format(here=str(Path(__file__).resolve().parent), skip=skip)
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout.split()
    return float(out[0]), float(out[1]), int(out[2]), float(out[3])


def main() -> None:
    _run(False)  # compile, if the cache is cold
    print("1000-brick wall, 0.05 s on one thread, each run in a fresh process (kernels from Numba's cache)")
    print(f"{'round':>5} {'law own code [updates/s]':>25} {'copy in advance [updates/s]':>28} {'ratio':>6}")
    for r in range(ROUNDS):
        own, copy = _run(False), _run(True)
        if own[2:] != copy[2:]:
            raise SystemExit(f"the two runs differ: {own[2:]} against {copy[2:]} (steps, sum of the recorded positions)")
        print(f"{r + 1:>5} {own[0]:>25.3e} {copy[0]:>28.3e} {own[0] / copy[0]:>6.2f}")


if __name__ == "__main__":
    main()
