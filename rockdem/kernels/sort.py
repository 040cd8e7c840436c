"""Sorting inside the compiled step without allocating (the detection's sweep and pair lookup)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, _nrt=False, inline="always")
def _before(keys: np.ndarray, i: int, j: int) -> bool:
    """(keys[i], i) < (keys[j], j): ties are ordered by index, as a stable sort orders them."""
    return keys[i] < keys[j] or (keys[i] == keys[j] and i < j)


@njit(cache=True, _nrt=False)
def _sift_down(keys: np.ndarray, order: np.ndarray, root: int, end: int) -> None:
    while True:
        child = 2 * root + 1
        if child >= end:
            return
        if child + 1 < end and _before(keys, order[child], order[child + 1]):
            child += 1
        if not _before(keys, order[root], order[child]):
            return
        order[root], order[child] = order[child], order[root]
        root = child


@njit(cache=True, _nrt=False)
def sort_indices(keys: np.ndarray, order: np.ndarray, n: int) -> None:
    """Fill ``order[:n]`` with 0..n-1 in ascending order of ``keys[:n]`` (ties by index: the
    result of a stable argsort), in place (heapsort, O(n log n), no allocation)."""
    for i in range(n):
        order[i] = i
    for start in range(n // 2 - 1, -1, -1):
        _sift_down(keys, order, start, n)
    for end in range(n - 1, 0, -1):
        order[0], order[end] = order[end], order[0]
        _sift_down(keys, order, 0, end)
