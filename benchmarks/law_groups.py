"""The joint law's cost per sub-contact by kind of face pair, on the settled 1000-brick wall (one
thread). Run: ``python benchmarks/law_groups.py`` (prints figures; about a minute and a half with
a warm cache, most of it compiling this script's loops).

The wall of ``bench_engine.py wall`` settles for 0.02 s. Its face pairs are split by how the
target face covers the owner face (``faces.crossing_lines``): *flush* (no target edge line
crosses the owner face: bed and head joints), *cut* (cells clipped by a target edge line: the
head faces of diagonal neighbours, overlapping by the sliver of the settlement difference) and
faces at right angles. Each group's law (``forces._law_pair``) runs 100 times on a copy of the
settled state, best of three rounds (docs/performance.md, "A third machine").

A second table gives the cost per *pair* in cache: the first 300 pairs of a group, each cut to its
first k sub-contacts (k = 0, 1, all), 2,000 passes. These figures held within about 10 % from
run to run on the shared 2-core machine while the whole-wall ones above swung by up to 2 x
(docs/performance.md, "The wall on 2026-11-30"): use them to compare versions of the law.

A third line gives the clipping alone (``faces.cut_cell``, compiled out of line as the law calls
it) per cell that the law clips, in cache, 200 passes, with the face map computed as the law
does: a measure of the clipping that the law's compiled loop does not blur
(docs/performance.md, "twelfth session").

A last line gives a floor for the flush joints: the arithmetic of a bonded, wholly covered,
elastic sub-contact (``_lean_flush``: overlap, point, relative velocity, shear carried and
incremented, limits tested, springs' forces and energy, the pair's resultant; the face map per
pair), without the general law's branches and bookkeeping, on the same pairs and state layout.
It is a measure, not a law: it falls back to nothing when a limit is reached (docs/performance.md,
"fifteenth session").
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

from rockdem.kernels.contact import coulomb_limit, shear_increment  # noqa: E402
from rockdem.kernels.faces import cell_above, crossing_lines, cut_cell, face_map_arrays  # noqa: E402
from rockdem.kernels.forces import _law_pair, _relative_velocity_arrays  # noqa: E402
from rockdem.kernels.layout import PAIR_EDGE, SLOTS  # noqa: E402
from rockdem.simulation import prepare_start, run_model  # noqa: E402

EDGE = -9  # an EDGE pair (no cover)
RIGHT_ANGLES = -2  # crossing_lines' code for faces whose map is singular


@njit(_nrt=False)
def _cover_kinds(m, s, sc, out):  # type: ignore[no-untyped-def]
    for i in range(s.pair_count[0]):
        if s.pair_kind[i] == PAIR_EDGE:
            out[i] = EDGE
            continue
        fo, ft = s.pair_owner_face[i], s.pair_target_face[i]
        fm = face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position, fo, ft)
        out[i] = RIGHT_ANGLES if abs(fm.det) < 1e-9 else crossing_lines(
            m.face_corner_start, m.face_corner_uw, m.face_line_start, m.face_line, fo, ft, fm)


@njit(_nrt=False)  # _nrt=False as the engine's kernels: the inlined law needs it to run at speed
def _laws(m, s, sc, dt, pairs, reps):  # type: ignore[no-untyped-def]
    for _ in range(reps):
        for i in pairs:
            _law_pair(m, s, sc, i, dt, False, False, sc.poly)


@njit(_nrt=False)
def _clipped_cells(m, s, sc, kind, out):  # type: ignore[no-untyped-def]
    """(pair, track index, mask) of every sub-contact whose cell the law clips (faces.cut_cell),
    as forces._law_range picks them (``kind``: the pairs' masks of _cover_kinds; owner side: the
    wall's cut pairs do not blend); their count."""
    n = 0
    for i in range(s.pair_count[0]):
        mask = kind[i]
        if mask == 0 or mask == RIGHT_ANGLES or mask == EDGE:
            continue
        fm = face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position,
                             s.pair_owner_face[i], s.pair_target_face[i])
        for k in range(s.pair_track_start[i], s.pair_track_split[i]):
            p = s.track[k] // SLOTS
            j = s.track[k] - SLOTS * p
            if not s.slot_bonded[p, j] and (s.slot_overlap[p, j] <= 0.0 or s.slot_area[p, j] == 0.0) and cell_above(
                    m.point_cell_start, m.cell_vertex, p, fm.h0, fm.hu, fm.hw):
                continue
            out[n, 0] = i
            out[n, 1] = k
            out[n, 2] = mask
            n += 1
    return n


@njit(_nrt=False)
def _clip_cells(m, s, sc, cells, reps):  # type: ignore[no-untyped-def]
    total = 0.0
    for _ in range(reps):
        for c in range(cells.shape[0]):
            i, k, mask = cells[c, 0], cells[c, 1], cells[c, 2]
            ft = s.pair_target_face[i]
            fm = face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position,
                                 s.pair_owner_face[i], ft)
            p = s.track[k] // SLOTS
            j = s.track[k] - SLOTS * p
            total += cut_cell(
                m.point_cell_start, m.cell_vertex, m.face_line_start, m.face_line, sc.poly, m.point_node[p, 0],
                m.point_node[p, 1], m.point_area[p], m.touch_tol, p, ft, fm, 0.0, mask, not s.slot_bonded[p, j],
                m.face_area[ft] / (m.face_point_start[ft + 1] - m.face_point_start[ft]),
            )[0]
    return total


@njit(_nrt=False)
def _lean_flush(m, s, sc, dt, pairs, reps):  # type: ignore[no-untyped-def]
    """The floor of the flush joints' law (module notes); returns how many sub-contacts passed
    their limits (all of them on a settled wall)."""
    passed = 0
    for _ in range(reps):
        for i in pairs:
            fo, ft = s.pair_owner_face[i], s.pair_target_face[i]
            o, t = m.face_block[fo], m.face_block[ft]
            g0, g1 = m.block_group[o], m.block_group[t]
            kn, ks, tension = m.mat_kn[g0, g1], m.mat_ks[g0, g1], m.mat_tension[g0, g1]
            cohesion, tan_friction = m.mat_cohesion[g0, g1], m.mat_tan_friction[g0, g1]
            fm = face_map_arrays(m.face_block, m.face_origin, m.face_u, m.face_w, m.face_normal, sc.rotation, s.position, fo, ft)
            n0, n1, n2 = fm.nx, fm.ny, fm.nz
            sf0 = sf1 = sf2 = sm0 = sm1 = sm2 = energy = 0.0
            for k in range(s.pair_track_start[i], s.pair_track_stop[i]):
                p = s.track[k] // SLOTS
                j = s.track[k] - SLOTS * p
                area, yu, yw = m.point_area[p], m.point_node[p, 0], m.point_node[p, 1]
                un = -(fm.h0 + fm.hu * yu + fm.hw * yw) - s.slot_set[p, j]
                x0 = fm.ox + yu * fm.eux + yw * fm.ewx + 0.5 * un * n0
                x1 = fm.oy + yu * fm.euy + yw * fm.ewy + 0.5 * un * n1
                x2 = fm.oz + yu * fm.euz + yw * fm.ewz + 0.5 * un * n2
                v0, v1, v2 = _relative_velocity_arrays(s.position, s.velocity, sc.omega_world, o, t, x0, x1, x2)
                vn = v0 * n0 + v1 * n1 + v2 * n2
                ksa = ks * area
                fn = kn * area * un
                us0, us1, us2, _, _, _ = shear_increment(s.slot_shear[p, j, 0], s.slot_shear[p, j, 1], s.slot_shear[p, j, 2],
                                                         n0, n1, n2, v0 - vn * n0, v1 - vn * n1, v2 - vn * n2, dt)
                fmax = coulomb_limit(cohesion, tan_friction, area, fn)
                passed += s.slot_bonded[p, j] and fn >= -tension * area and ksa * ksa * (us0 * us0 + us1 * us1 + us2 * us2) <= fmax * fmax
                s.slot_overlap[p, j] = un
                s.slot_shear[p, j, 0] = us0
                s.slot_shear[p, j, 1] = us1
                s.slot_shear[p, j, 2] = us2
                s.slot_normal_force[p, j] = fn
                energy += 0.5 * (fn * un + ksa * (us0 * us0 + us1 * us1 + us2 * us2))
                f0, f1, f2 = fn * n0 + ksa * us0, fn * n1 + ksa * us1, fn * n2 + ksa * us2
                r0, r1, r2 = x0 - s.position[o, 0], x1 - s.position[o, 1], x2 - s.position[o, 2]
                sf0, sf1, sf2 = sf0 + f0, sf1 + f1, sf2 + f2  # the resultant and its moment about o's centroid
                sm0, sm1, sm2 = sm0 + (r1 * f2 - r2 * f1), sm1 + (r2 * f0 - r0 * f2), sm2 + (r0 * f1 - r1 * f0)
            sc.side_force[i, 0, 0], sc.side_force[i, 0, 1], sc.side_force[i, 0, 2] = sf0, sf1, sf2
            sc.side_moment[i, 0, 0], sc.side_moment[i, 0, 1], sc.side_moment[i, 0, 2] = sm0, sm1, sm2
            sc.side_elastic[i, 0] = energy
    return passed


def main() -> None:
    numba.set_num_threads(1)
    model = wall_model()
    start = prepare_start(model)
    run_model(model, 0.02, record_interval=0.01, progress=False, start=start, threads=1)
    m, s = model.arrays, start.state
    n = int(s.pair_count[0])
    kind = np.zeros(n, dtype=np.int64)
    _cover_kinds(m, s, start.scratch, kind)
    per_pair = s.pair_track_stop[:n] - s.pair_track_start[:n]
    dt = float(s.dt[0])
    groups = {
        "flush": np.flatnonzero(kind == 0),
        "cut": np.flatnonzero((kind != 0) & (kind != RIGHT_ANGLES) & (kind != EDGE)),
        "right angles": np.flatnonzero(kind == RIGHT_ANGLES),
        "all face pairs": np.flatnonzero(kind != EDGE),
    }
    copy = start.copy()
    _laws(m, copy.state, copy.scratch, dt, groups["all face pairs"], 1)  # compile
    print(f"1000-brick wall settled 0.02 s: {n} pairs")
    print(f"{'face pairs':>15} {'pairs':>6} {'sub-contacts':>12} {'ms per pass':>11} {'ns per sub-contact':>18}")
    for name, pairs in groups.items():
        if pairs.size == 0:
            continue
        best = np.inf
        for _ in range(3):
            copy = start.copy()
            t0 = time.perf_counter()
            _laws(m, copy.state, copy.scratch, dt, pairs, 100)
            best = min(best, (time.perf_counter() - t0) / 100)
        count = int(per_pair[pairs].sum())
        print(f"{name:>15} {pairs.size:>6} {count:>12} {1e3 * best:>11.3f} {1e9 * best / count:>18.0f}")
    print("in cache, ns per pair (300 pairs) with its first k sub-contacts: k = 0, 1, all (mean count)")
    for name in ("flush", "cut"):
        pairs = groups[name][:300]
        if pairs.size == 0:
            continue
        line = []
        for keep in (0, 1, 1 << 30):
            copy = start.copy()
            st = copy.state
            st.pair_track_stop[:] = np.minimum(st.pair_track_start + keep, s.pair_track_stop)
            st.pair_track_split[:] = np.minimum(st.pair_track_split, st.pair_track_stop)
            t0 = time.perf_counter()
            _laws(m, st, copy.scratch, dt, pairs, 2000)
            mean = float((st.pair_track_stop - st.pair_track_start)[pairs].mean())
            line.append(f"{1e9 * (time.perf_counter() - t0) / 2000 / pairs.size:.0f} ({mean:.2f})")
        print(f"{name:>15}: " + ", ".join(line))
    cells = np.zeros((int(s.track_count[0]), 3), dtype=np.int64)
    cells = cells[:_clipped_cells(m, s, start.scratch, kind, cells)]
    _clip_cells(m, s, start.scratch, cells, 1)  # compile
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        _clip_cells(m, s, start.scratch, cells, 200)
        best = min(best, (time.perf_counter() - t0) / 200)
    print(f"clipping alone (faces.cut_cell, face map included), in cache: {len(cells)} cells, "
          f"{1e9 * best / max(len(cells), 1):.0f} ns per cell")
    flush = groups["flush"]
    bonded = flush[[bool(start.scratch.pair_bonded[i]) for i in flush]]
    count = int(per_pair[bonded].sum())
    if count:
        _lean_flush(m, start.copy().state, start.scratch, dt, bonded, 1)  # compile
        general = lean = np.inf
        for _ in range(3):  # alternating
            copy = start.copy()
            t0 = time.perf_counter()
            _laws(m, copy.state, copy.scratch, dt, bonded, 100)
            general = min(general, (time.perf_counter() - t0) / 100)
            copy = start.copy()
            t0 = time.perf_counter()
            passed = _lean_flush(m, copy.state, copy.scratch, dt, bonded, 100)
            lean = min(lean, (time.perf_counter() - t0) / 100)
        print(f"bonded flush joints, {bonded.size} pairs, {count} sub-contacts: the law {1e9 * general / count:.1f}, "
              f"its arithmetic alone {1e9 * lean / count:.1f} ns per sub-contact (face map included; "
              f"{passed / 100 / count:.0%} within their limits)")


if __name__ == "__main__":
    main()
