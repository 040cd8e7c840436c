"""Prescribed time series (driven-block velocities, body accelerations) read inside the kernels."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, _nrt=False)
def interpolate(times: np.ndarray, values: np.ndarray, start: int, end: int, t: float, out: np.ndarray) -> None:
    """Linear interpolation of rows start:end of a (N, 3) table at time t, holding the end values."""
    if end <= start:
        out[:] = 0.0
        return
    if t <= times[start] or t >= times[end - 1]:
        row = start if t <= times[start] else end - 1
        for i in range(3):
            out[i] = values[row, i]
        return
    lo, hi = start, end - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    w = (t - times[lo]) / (times[hi] - times[lo])
    for i in range(3):
        out[i] = (1.0 - w) * values[lo, i] + w * values[hi, i]
