"""Contact geometry against independent computations.

- Narrow phase: two convex polyhedra {x: N_a x <= d_a} and {x: N_b x <= d_b} have overlapping
  interiors iff the linear programme max t s.t. N x + t <= d (both sets) has t* > 0 (scipy
  linprog). The engine's separating axes (face normals and edge x edge) must agree both ways, and
  its penetration depth must match the plain-NumPy separating-axis check of
  :mod:`rockdem.diagnostics`.
- Sub-contact areas: a block pressed uniformly into a larger one carries kn un A, where A is the
  area of the intersection of the two faces (scipy HalfspaceIntersection), for any offset and
  turn: the force goes continuously to zero as the block slides off the edge.
"""

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection

from rockdem.diagnostics import penetration_depth
from rockdem.geometry import box, convex_hull
from rockdem.kernels.detect import EDGE_AXIS_BIAS
from rockdem.kernels.forces import compute_forces
from rockdem.kernels.rotation import axis_angle_matrix
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.state import initial_state


def random_hull(rng, scale):
    pts = rng.normal(size=(12, 3))
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    return convex_hull(pts * scale * rng.uniform(0.5, 1.0, size=3))  # on an ellipsoid: all corners


def lp_depth(pa, pb):
    a = np.vstack([pa.normals, pb.normals])
    d = np.concatenate([pa.offsets, pb.offsets])
    res = linprog(c=[0, 0, 0, -1], A_ub=np.hstack([a, np.ones((len(a), 1))]), b_ub=d, bounds=[(None, None)] * 3 + [(None, 1.0)])
    return -res.fun


def _shape(poly):
    """Vertices, face normals and unit edge directions of a polyhedron (for the NumPy SAT)."""
    v = poly.vertices
    dirs = []
    for face in poly.faces:
        p = v[list(face)]
        e = np.roll(p, -1, axis=0) - p
        dirs.extend(e / np.linalg.norm(e, axis=1, keepdims=True))
    return v, poly.normals, np.array(dirs)


def test_narrow_phase_agrees_with_linear_programming_and_numpy_sat(rng):
    tol = 0.01
    checked_overlap = checked_sep = 0
    for trial in range(200):
        pa = random_hull(rng, 0.5)
        pb = random_hull(rng, 0.4).transformed(
            axis_angle_matrix(rng.normal(size=3), rng.uniform(0, np.pi)), rng.normal(size=3) * 0.3 + [0.75, 0, 0]
        )
        bld = ModelBuilder(gravity=(0, 0, 0), points=(3, 3))
        bld.default_material = JointMaterial(kn=1e9)
        bld.add_block(pa, name="a")
        bld.add_block(pb, name="b")
        model = bld.finalize(contact_tolerance=tol)
        _, sc = initial_state(model, check_overlap=False)
        sep = float(sc.min_separation[0])
        depth = lp_depth(pa, pb)
        exact = penetration_depth(*_shape(pa), *_shape(pb))
        true_sep = -exact
        if not np.isfinite(sep):  # beyond the broad phase: must be well apart
            assert true_sep > tol
            continue
        # The engine prefers a face axis unless an edge axis separates better by a small bias
        # (EDGE_AXIS_BIAS tol, plus half the depth when overlapping): it never overstates the
        # separation and understates it by at most that bias.
        bias = EDGE_AXIS_BIAS * tol + 0.5 * max(-sep, 0.0) + 1e-9
        assert true_sep - bias <= sep <= true_sep + 1e-9, f"trial {trial}: separation {sep} vs SAT {true_sep}"
        if depth > 1e-6:
            checked_overlap += 1
            assert sep < 0.0, f"trial {trial}: interiors overlap by {depth} but narrow phase says separated"
        if sep > 1e-9:
            checked_sep += 1
            assert depth <= 1e-9, f"trial {trial}: narrow phase separation {sep} but LP overlap {depth}"
    assert checked_overlap > 20 and checked_sep > 20


def _intersection_area(pa: np.ndarray, pb: np.ndarray) -> float:
    """Area of the intersection of two convex polygons (counter-clockwise (n, 2) corners) [m^2]."""
    halfspaces = []
    for poly in (pa, pb):
        e = np.roll(poly, -1, axis=0) - poly
        outward = np.column_stack([e[:, 1], -e[:, 0]])
        outward /= np.linalg.norm(outward, axis=1, keepdims=True)
        halfspaces.append(np.column_stack([outward, -np.einsum("ij,ij->i", outward, poly)]))
    hs = np.vstack(halfspaces)
    # Chebyshev centre: an interior point, or none when the polygons do not overlap.
    res = linprog(c=[0, 0, -1], A_ub=np.column_stack([hs[:, :2], np.ones(len(hs))]), b_ub=-hs[:, 2], bounds=[(None, None)] * 2 + [(None, 1.0)])
    if -res.fun <= 1e-9:
        return 0.0
    pts = HalfspaceIntersection(hs, res.x[:2]).intersections
    return float(ConvexHull(pts).volume)


@pytest.mark.parametrize("turn_deg", [0.0, 27.0])
def test_supported_area_is_the_face_intersection_and_varies_continuously(turn_deg):
    kn = 1e9
    un = 2e-4
    lower = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    c, s_ = np.cos(np.radians(turn_deg)), np.sin(np.radians(turn_deg))
    rot = np.array([[c, -s_, 0], [s_, c, 0], [0, 0, 1]])
    areas, forces = [], []
    for dx in np.linspace(0.0, 0.62, 32):
        bld = ModelBuilder(gravity=(0, 0, 0), points=(3, 4))
        bld.default_material = JointMaterial(kn=kn, friction_angle=30)
        bld.add_box(0.6, 0.6, 0.2, base_center=(0, 0, -0.2), driven=True, name="lower")
        upper = box(0.4, 0.3, 0.2).transformed(rot, (dx, 0.05, 0.1 - un))
        bld.add_block(upper, name="upper")
        model = bld.finalize(damping=Damping())
        s, sc = initial_state(model, check_overlap=False)
        compute_forces(model.arrays, s, sc, 0.0, 1e-6)
        corners = np.array([[-0.2, -0.15, 0], [0.2, -0.15, 0], [0.2, 0.15, 0], [-0.2, 0.15, 0]]) @ rot.T
        base = corners[:, :2] + [dx, 0.05]
        areas.append(_intersection_area(base, lower))
        forces.append(float(sc.force[1, 2]))
        assert abs(sc.force[1, 0]) < 1e-6 * kn * un * 0.12 and abs(sc.force[1, 1]) < 1e-6 * kn * un * 0.12
    areas = np.array(areas)
    forces = np.array(forces)
    assert areas[0] == pytest.approx(0.12, rel=1e-9) and areas[-1] == 0.0
    np.testing.assert_allclose(forces, kn * un * areas, rtol=1e-6, atol=1e-6 * kn * un * 0.12)


def test_both_upper_bricks_of_a_running_bond_row_are_supported():
    # Two bricks side by side on a third: the middle points of the lower brick's top face touch
    # both upper bricks' faces on their shared edge; each brick carries its own weight.
    bld = ModelBuilder(points=(2, 3))
    bld.default_material = JointMaterial(kn=1e9, friction_angle=30)
    bld.add_box(0.1, 0.2, 0.05, base_center=(0, 0, 0), driven=True, name="low")
    bld.add_box(0.1, 0.1, 0.05, base_center=(0, -0.05, 0.05), name="left")
    bld.add_box(0.1, 0.1, 0.05, base_center=(0, 0.05, 0.05), name="right")
    model = bld.finalize()
    s, sc = initial_state(model)
    nslot = s.slot_partner.shape[1]
    blocks = set()
    for k in range(int(s.track_count[0])):
        p, j = divmod(int(s.track[k]), nslot)
        blocks |= {int(model.arrays.point_block[p]), int(s.slot_partner[p, j])}
    assert {1, 2} <= blocks


def test_bonded_wall_keeps_its_bonds_under_self_weight():
    # A running-bond wall standing under gravity: joint stresses are far below c and ft, so no
    # bond may break; the energy balance stays closed.
    from rockdem.simulation import simulate
    from rockdem.specimens import brick_wall

    bld = ModelBuilder()
    joint = JointMaterial(kn=1e10, friction_angle=35, cohesion=1e6, tension=1e6)
    brick_wall(bld, courses=6, bricks_per_course=3, joint=joint, base=JointMaterial(kn=1e10, friction_angle=31))
    model = bld.finalize(damping=Damping(alpha=1.0))
    ds = simulate(model, 0.3, record_interval=0.01)
    bonded0 = int(ds.contacts_bonded[0])
    assert bonded0 > 0
    assert np.all(ds.contacts_bonded.values == bonded0)
    assert int(ds.contacts_failed_tension[-1]) == 0 and int(ds.contacts_failed_shear[-1]) == 0
    assert np.max(np.abs(ds.energy_balance_error_relative.values)) < 0.01


def test_strong_bonds_of_soft_joints_are_not_lost_to_the_contact_tolerance():
    # Paper §3.2.1: bonded joints "sufficiently strong for no bond to fail" with kn = 1000 MPa/m
    # open elastically by up to ft / kn = 10 mm before failing, ten times the default geometric
    # tolerance (1 % of a 0.1 m brick), and slip by c / ks = 25 mm. The default covers both, so a
    # strongly bonded discretised block rocks with no failure.
    from rockdem.case import parse_case
    from rockdem.run_cli import run_case

    joint = {"kn": 1e9, "friction_angle_deg": 31.0, "cohesion": 1e7, "tension": 1e7}
    case = parse_case({
        "run": {"duration": 1.0, "record_interval": 0.01},
        "specimen": {"type": "wall", "brick": [0.19, 0.25, 0.1], "courses": 5, "bricks_per_course": 4,
                     "points_along": 3, "joint": joint, "base": {"kn": 1e9, "friction_angle_deg": 31.0}},
        "loading": {"type": "free-rocking", "tilt_fraction": 0.9},
    })
    ks = 0.4 * 1e9  # poisson 0.25
    assert case.model.arrays.contact_tol == pytest.approx(1.5 * 1e7 / ks, rel=1e-9)  # slip at c governs
    ds = run_case(case, progress=False)
    assert int(ds.contacts_failed_tension.values[-1]) == 0 and int(ds.contacts_failed_shear.values[-1]) == 0
    assert np.max(np.abs(ds.rocking_angle.values[:, 1])) > 0.2  # it did rock (0.9 eta = 0.33 rad)


def test_the_allocation_free_sort_orders_as_a_stable_argsort():
    # The detection sorts in place (no heap allocation in the compiled step): randomized check
    # against NumPy's stable argsort, with ties, integer keys and strided views.
    from rockdem.kernels.sort import sort_indices

    rng = np.random.default_rng(11)
    for trial in range(200):
        n = int(rng.integers(0, 60))
        keys = rng.integers(0, 8, size=(n, 2)).astype(float)[:, 0] if trial % 3 == 0 else rng.normal(size=n)
        if trial % 3 == 1:
            keys = rng.integers(-5, 5, size=n)
        if trial % 3 == 2:
            keys = np.repeat(rng.normal(size=(n, 1)), 3, axis=1)[:, 1]  # a strided view
        order = np.full(n + 3, -7, dtype=np.int64)
        sort_indices(keys, order, n)
        assert np.array_equal(order[:n], np.argsort(keys, kind="stable"))
        assert np.all(order[n:] == -7)


def test_face_clearance_is_the_least_height_of_the_other_blocks_vertices(rng):
    """blend.face_clearance (the clarity of kernels.blend) against plain NumPy: the least height
    n . (R v + x - c) - offset of the other block's world vertices above a face's plane, that
    vertex and the face's world normal, for random shapes, turns and places far from the origin."""
    from rockdem.kernels.blend import face_clearance

    for trial in range(300):
        counts = rng.integers(4, 14, size=2)
        local = rng.normal(size=(int(counts.sum()), 3)) * rng.uniform(0.01, 2.0)
        start = np.array([0, counts[0], counts.sum()])
        rot = np.stack([axis_angle_matrix(rng.normal(size=3), rng.uniform(0, np.pi)) for _ in range(2)])
        pos = rng.normal(size=(2, 3)) * 10.0 ** rng.uniform(-2, 3)
        normal = rng.normal(size=(1, 3))
        normal /= np.linalg.norm(normal)
        offset = rng.normal(size=1)
        sep, x0, x1, x2, n0, n1, n2 = face_clearance(normal, offset, np.array([0]), start, local, rot, pos, 0, 1)
        n = rot[0] @ normal[0]
        world = local[start[1]:] @ rot[1].T + pos[1]
        heights = (world - pos[0]) @ n - offset[0]
        scale = 1e-13 * (1.0 + np.abs(pos).max() + np.abs(local).max())
        assert abs(sep - heights.min()) <= scale, f"trial {trial}"
        assert np.allclose([n0, n1, n2], n, atol=1e-15)
        # the vertex returned is (one of) the lowest
        assert abs(((np.array([x0, x1, x2]) - pos[0]) @ n - offset[0]) - heights.min()) <= scale


def _clip_area(poly, lu, lw, lo):
    """Area of the part of convex polygon ``poly`` (n, 2) with lu x + lw y <= lo (plain NumPy:
    the vertices inside and the edges' crossings, ordered by angle about their mean)."""
    d = poly @ np.array([lu, lw]) - lo
    pts = [poly[k] for k in range(len(poly)) if d[k] <= 0.0]
    for k in range(len(poly)):
        q = (k + 1) % len(poly)
        if (d[k] < 0.0 < d[q]) or (d[q] < 0.0 < d[k]):
            pts.append(poly[k] + d[k] / (d[k] - d[q]) * (poly[q] - poly[k]))
    if len(pts) < 3:
        return 0.0
    pts = np.array(pts)
    c = pts.mean(axis=0)
    pts = pts[np.argsort(np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0]))]
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def test_a_quad_cell_cut_by_one_line_is_clipped_as_the_generic_polygon_is(rng):
    """faces.cut_cell's path for a four-vertex cell crossed by one target edge line (the usual cut
    cell: a face sliding off its partner's edge, a wall's diagonal neighbours) gives what the
    generic covered + partly_covered give, bit for bit, for random cells (rectangles and random
    convex quads), face maps (turned, mirrored, sheared, tilted) and lines (through a vertex too),
    lumped or not; and its effective area is the clipped cell's area of plain NumPy."""
    from rockdem.kernels.faces import (
        COVER_FULL, COVER_NONE, COVER_PART, FaceMap, _cut_quad, covered, partly_covered,
    )

    buf = np.zeros((2, 32, 2))
    cell_start = np.array([0, 4])
    line_start = np.array([0, 4])
    partial = 0
    for trial in range(3000):
        centre = rng.uniform(-0.1, 0.1, 2)
        half = rng.uniform(1e-3, 0.05, 2)
        quad = centre + half * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
        if trial % 3 == 0:  # a random convex quad (counter-clockwise)
            quad = quad + rng.normal(0.0, 0.2 * half.min(), quad.shape)
            e = np.roll(quad, -1, axis=0) - quad
            if (e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0] <= 0.0).any():
                continue
        turn = rng.uniform(0.0, 2.0 * np.pi)
        mirror = rng.choice([-1.0, 1.0])
        m00, m01, m10, m11 = np.cos(turn), -np.sin(turn) * mirror, np.sin(turn), np.cos(turn) * mirror
        if trial % 5 == 0:  # a slanted target: the map is not a rotation
            m01 *= rng.uniform(0.3, 1.0)
        t0, t1 = rng.uniform(-0.05, 0.05, 2)
        h0 = rng.normal(0.0, 1e-4) if trial % 2 else 0.0
        hu, hw = rng.normal(0.0, 1e-3, 2) if trial % 4 else (0.0, 0.0)
        fm = FaceMap(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0,
                     m00, m01, m10, m11, t0, t1, h0, hu, hw, m00 * m11 - m01 * m10)
        side = rng.uniform(0.01, 0.2)
        lines = np.array([[1.0, 0.0, side], [0.0, 1.0, side], [-1.0, 0.0, side], [0.0, -1.0, side]])
        li = int(rng.integers(4))
        mapped = quad @ np.array([[m00, m10], [m01, m11]]) + [t0, t1]
        if trial % 10 == 0:  # the line through a cell vertex
            lines[li, 2] = lines[li, :2] @ mapped[rng.integers(4)]
        node = quad.mean(axis=0) if trial % 5 else quad[rng.integers(4)]
        area = 0.5 * abs(np.dot(quad[:, 0], np.roll(quad[:, 1], -1)) - np.dot(np.roll(quad[:, 0], -1), quad[:, 1]))
        lumped = bool(trial % 3)
        cap = rng.uniform(1e-4, 1e-2)
        mask = 1 << li
        fast = _cut_quad(cell_start, quad, lines, li, buf, node[0], node[1], area, 1e-5, 0, fm, 0.0, lumped, cap)
        state = covered(cell_start, quad, line_start, lines, 0, 0, fm, 0.0, mask)
        if state == COVER_FULL:
            generic = (area, node[0], node[1], 0.0, 0.0, node[0], node[1], node[0], node[1])
        elif state == COVER_NONE:
            generic = (0.0, node[0], node[1], 0.0, 0.0, node[0], node[1], node[0], node[1])
        else:
            partial += 1
            generic = partly_covered(cell_start, quad, line_start, lines, buf, node[0], node[1], area, 1e-5, 0, 0, fm,
                                     0.0, lumped, cap, mask)
        assert np.array_equal(np.array(fast).view(np.int64), np.array(generic).view(np.int64)), f"trial {trial}"
        if state == COVER_PART and not lumped:
            assert fast[0] == pytest.approx(_clip_area(mapped, *lines[li]) / abs(fm.det), rel=1e-9), f"trial {trial}"
    assert partial > 300


def test_a_flat_cells_deepest_point_moves_continuously_as_its_ends_cross():
    """A partly covered cell pressed flat into its target (a crack closed along a wall's length)
    twists about its short axis: its ends' depths cross. Its deepest covered point (the force
    point's goal, faces.partly_covered) must slide along the cell as they do, not jump from end to
    end: a jump at a fixed pose is a cover change that goes into the cell's set while the force
    point moves, and the step's work then falls short of what the spring holds at each turn of
    the twist. With the vertices within 1e-7 m of the deepest sharing the point (before
    2026-12-07) it jumped 0.25 m, from an end to the middle, within a 2e-7 m change of the ends'
    depths; a two-block wall's crack (Poisson 0.45, undamped, with the symmetric sets of
    forces.cover_change) lost 1.28 % of its energy scale at such turns, 0.40 % with the band's
    floor. Now the band is at least the touching tolerance: the point moves in proportion to the
    depths."""
    from rockdem.kernels.faces import FaceMap, partly_covered

    touch = 2e-4
    length, width = 0.5, 0.05
    quad = np.array([[0.0, 0.0], [length, 0.0], [length, width], [0.0, width]])
    cell_start = np.array([0, 4])
    lines = np.array([[0.0, 1.0, 0.03]])  # the target covers w <= 0.03 (60 % of the cell)
    line_start = np.array([0, 1])
    area = length * width
    buf = np.zeros((2, 32, 2))
    points = []
    slopes = np.linspace(-1.2, 1.2, 2401) * touch / length  # the ends' depths differ by up to 1.2 tau
    for slope in slopes:
        fm = FaceMap(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0,
                     1.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1e-3, slope, 0.0, 1.0)
        out = partly_covered(cell_start, quad, line_start, lines, buf, 0.25, 0.025, area, touch, 0, 0, fm, 0.0, False, 1.0, 1)
        assert out[0] == pytest.approx(0.6 * area)
        points.append(out[7])  # the deepest covered point's u
    points = np.array(points)
    assert points[0] == pytest.approx(length) and points[-1] == pytest.approx(0.0)  # the deeper end
    assert points[len(points) // 2] == pytest.approx(0.5 * length)  # level: the middle
    step_depth = (slopes[1] - slopes[0]) * length
    # At most 4 times the cell's length per touching tolerance of the ends' depths.
    assert np.abs(np.diff(points)).max() <= 4.0 * length * step_depth / touch
