"""Numba's compile time of a parallel region that is handed named tuples of arrays.

``python benchmarks/parfor_tuple_compile.py 20 50 100`` (one tuple of N arrays per figure) or
``python benchmarks/parfor_tuple_compile.py 62,47,91`` (three tuples: the sizes of ModelArrays, State
and Scratch, which the joint law's parallel pass hands to its chunks). The body of the ``prange``
calls a trivial compiled function, so the time printed is the cost of the tuples entering the
parallel region (Numba unpacks them into gufunc arguments). Each figure runs in a fresh process.
See docs/performance.md ("Another machine").
"""

from __future__ import annotations

import subprocess
import sys
import time

CHILD = '''
import sys, time
from collections import namedtuple
import numpy as np
import numba
from numba import njit

sizes = [int(x) for x in sys.argv[1].split(",")]
tuples = [namedtuple(f"T{k}", [f"a{i}" for i in range(n)])(*[np.zeros(100) for _ in range(n)])
          for k, n in enumerate(sizes)]
names = ", ".join(f"t{k}" for k in range(len(sizes)))
last = f"t{len(sizes) - 1}"
src = f"""
@njit(_nrt=False)
def work({names}, first, last):
    for i in range(first, last):
        t0.a0[i] += {last}[len({last}) - 1][i] + 1.0

@njit(_nrt=False)
def serial({names}, n):
    work({names}, 0, n)

@njit(_nrt=False, parallel=True)
def par({names}, n):
    for k in numba.prange(8):
        work({names}, min(n, k * 13), min(n, (k + 1) * 13))
"""
exec(src)
t0 = time.perf_counter(); serial(*tuples, 100); t1 = time.perf_counter()
print(f"{t1 - t0:.1f}", flush=True)
par(*tuples, 100)
print(f"{time.perf_counter() - t1:.1f}", flush=True)
'''


def main(args: list[str]) -> None:
    for spec in args or ["20", "50", "100"]:
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", CHILD, spec], capture_output=True, text=True)
        lines = out.stdout.split()
        if out.returncode or len(lines) < 2:
            print(f"tuples of {spec} arrays: failed after {time.perf_counter() - t0:.0f} s: {out.stderr.strip().splitlines()[-1:]}")
            continue
        print(f"tuples of {spec} arrays: serial compile {lines[0]} s, parallel region {lines[1]} s")


if __name__ == "__main__":
    main(sys.argv[1:])
