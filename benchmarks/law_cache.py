"""The joint law's cost per sub-contact against the share of the wall it runs over (one thread).
Run: ``python benchmarks/law_cache.py`` (prints figures; about two minutes with a warm cache).

The 1000-brick wall of ``bench_engine.py wall`` settles for 0.03 s; then the joint-law pass
(``forces._law_pairs``, the step's main cost) runs repeatedly over the first 5, 10, 25, 50 and
100 % of its face pairs, and over as many pairs from its middle, each on a fresh copy of the
settled state. The arithmetic per sub-contact is the same for every share, so a cost that grows
with the share is the memory the pass touches outgrowing the caches (docs/performance.md, "The
wall against the code of issue 11's filing").
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numba
import numpy as np
from numba import njit

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_engine import wall_model  # noqa: E402

from rockdem.kernels.forces import _law_pairs  # noqa: E402
from rockdem.simulation import prepare_start, run_model  # noqa: E402


@njit(cache=True)
def _passes(m, s, sc, dt, reps, first, last):  # type: ignore[no-untyped-def]
    for _ in range(reps):
        _law_pairs(m, s, sc, first, last, dt, False, False, sc.poly)


def _copy(arrays):  # type: ignore[no-untyped-def]
    return type(arrays)(*(a.copy() if isinstance(a, np.ndarray) else a for a in arrays))


def main() -> None:
    numba.set_num_threads(1)
    model = wall_model()
    start = prepare_start(model)
    run_model(model, 0.03, record_interval=0.01, progress=False, start=start, threads=1)
    m, s0, sc0 = model.arrays, start.state, start.scratch
    dt = float(s0.dt[0])
    pairs = int(s0.pair_count[0])
    per_pair = s0.pair_track_stop[:pairs] - s0.pair_track_start[:pairs]
    _passes(m, _copy(s0), _copy(sc0), dt, 1, 0, pairs)  # compile
    print(f"1000-brick wall settled 0.03 s: {pairs} face pairs, {int(per_pair.sum())} tracked sub-contacts")
    print(f"{'share':>6} {'pairs':>12} {'sub-contacts':>12} {'ns per sub-contact (best of 3)':>30}")
    for share in (0.05, 0.1, 0.25, 0.5, 1.0):
        for first in (0, pairs // 2) if share <= 0.5 else (0,):
            last = min(pairs, first + max(1, int(share * pairs)))
            n = int(per_pair[first:last].sum())
            reps = max(20, int(3e6 // max(n, 1)))
            best = np.inf
            for _ in range(3):
                s, sc = _copy(s0), _copy(sc0)
                t0 = time.perf_counter()
                _passes(m, s, sc, dt, reps, first, last)
                best = min(best, (time.perf_counter() - t0) / reps)
            print(f"{share:>6.0%} {f'{first}..{last}':>12} {n:>12} {1e9 * best / n:>30.0f}")


if __name__ == "__main__":
    main()
