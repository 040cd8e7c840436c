"""Small planar and segment geometry for the contact kernels (allocation-free, Numba).

Polygons are (n, 2) counter-clockwise vertex buffers with an explicit count; half-planes are
(lu, lw, lo): lu x + lw y <= lo inside.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, _nrt=False, inline="always")
def clip_halfplane(buf: np.ndarray, i: int, n: int, lu: float, lw: float, lo: float) -> int:
    """Sutherland-Hodgman step: the part of polygon ``buf[i, :n]`` inside lu x + lw y <= lo, written
    to ``buf[1 - i]``; returns its vertex count (0 when nothing is left). Buffers are addressed by
    index (no array views are made: in Numba's compiled code a view costs reference counting)."""
    j = 1 - i
    out = 0
    last = max(n - 1, 0)
    px = buf[i, last, 0]
    py = buf[i, last, 1]
    dp = lu * px + lw * py - lo
    for q in range(n):
        cx = buf[i, q, 0]
        cy = buf[i, q, 1]
        dc = lu * cx + lw * cy - lo
        out = clip_edge(buf, j, out, px, py, dp, cx, cy, dc)
        px = cx
        py = cy
        dp = dc
    return out


@njit(cache=True, _nrt=False, inline="always")
def clip_edge(buf: np.ndarray, j: int, out: int, px: float, py: float, dp: float, cx: float, cy: float, dc: float) -> int:
    """One edge p -> c of :func:`clip_halfplane` (dp, dc: the two ends' signed distances
    lu x + lw y - lo): what it adds to the clipped polygon in ``buf[j]`` from index ``out`` (the
    crossing, then c if c is inside); returns the new count."""
    if dc <= 0.0:
        if dp > 0.0:
            t = dp / (dp - dc)
            buf[j, out, 0] = px + t * (cx - px)
            buf[j, out, 1] = py + t * (cy - py)
            out += 1
        buf[j, out, 0] = cx
        buf[j, out, 1] = cy
        out += 1
    elif dp <= 0.0:
        t = dp / (dp - dc)
        buf[j, out, 0] = px + t * (cx - px)
        buf[j, out, 1] = py + t * (cy - py)
        out += 1
    return out


@njit(cache=True, _nrt=False, inline="always")
def polygon_area(buf: np.ndarray, b: int, n: int) -> float:
    """Area of polygon ``buf[b, :n]`` (positive when counter-clockwise) [m^2]."""
    a = 0.0
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        a += buf[b, i, 0] * buf[b, j, 1] - buf[b, j, 0] * buf[b, i, 1]
    return 0.5 * a


@njit(cache=True, _nrt=False, inline="always")
def nearest_on_polygon(buf: np.ndarray, b: int, n: int, x: float, y: float) -> tuple[float, float]:
    """Point of the boundary of polygon ``buf[b, :n]`` nearest to (x, y)."""
    best = np.inf
    bx, by = x, y
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        ax, ay = buf[b, i, 0], buf[b, i, 1]
        ex, ey = buf[b, j, 0] - ax, buf[b, j, 1] - ay
        ee = ex * ex + ey * ey
        t = ((x - ax) * ex + (y - ay) * ey) / ee if ee > 0.0 else 0.0
        t = min(max(t, 0.0), 1.0)
        qx, qy = ax + t * ex, ay + t * ey
        d = (qx - x) * (qx - x) + (qy - y) * (qy - y)
        if d < best:
            best, bx, by = d, qx, qy
    return bx, by


@njit(cache=True, _nrt=False, inline="always")
def deepest_point(buf: np.ndarray, b: int, n: int, hu: float, hw: float, share: float, tie: float) -> tuple[float, float]:
    """The deepest part of polygon ``buf[b, :n]`` under the height hu u + hw w (+ a constant): the
    mean of its vertices weighted by 1 - (h - h_low) / band, h_low the lowest height and band =
    max(``share`` times the vertices' height range, ``tie`` [m]); vertices higher than h_low + band
    weigh nothing. A continuous function of the heights, unlike the lowest vertex itself, which
    jumps between two nearly equally deep vertices as they cross."""
    low = np.inf
    high = -np.inf
    for i in range(n):
        h = hu * buf[b, i, 0] + hw * buf[b, i, 1]
        low = min(low, h)
        high = max(high, h)
    band = max(share * (high - low), tie)
    su = sw = sum_w = 0.0
    for i in range(n):
        wi = 1.0 - (hu * buf[b, i, 0] + hw * buf[b, i, 1] - low) / band
        if wi > 0.0:
            su += wi * buf[b, i, 0]
            sw += wi * buf[b, i, 1]
            sum_w += wi
    return su / sum_w, sw / sum_w


@njit(cache=True, _nrt=False, inline="always")
def segment_closest(
    p0: float, p1: float, p2: float, d0: float, d1: float, d2: float,
    q0: float, q1: float, q2: float, e0: float, e1: float, e2: float,
) -> tuple[float, float]:
    """Parameters (s, t) in [0, 1] of the closest points p + s d and q + t e of two segments
    (Ericson, Real-Time Collision Detection, 5.1.9)."""
    r0, r1, r2 = p0 - q0, p1 - q1, p2 - q2
    a = d0 * d0 + d1 * d1 + d2 * d2
    e = e0 * e0 + e1 * e1 + e2 * e2
    f = e0 * r0 + e1 * r1 + e2 * r2
    c = d0 * r0 + d1 * r1 + d2 * r2
    b = d0 * e0 + d1 * e1 + d2 * e2
    den = a * e - b * b
    s = min(max((b * f - c * e) / den, 0.0), 1.0) if den > 1e-300 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t = 0.0
        s = min(max(-c / a, 0.0), 1.0)
    elif t > 1.0:
        t = 1.0
        s = min(max((b - c) / a, 0.0), 1.0)
    return s, t

