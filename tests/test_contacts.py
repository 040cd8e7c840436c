"""Narrow phase against brute force: random convex pairs in random poses.

Oracle: two convex polyhedra {x: N_a x <= d_a} and {x: N_b x <= d_b} have overlapping interiors
iff the linear programme max t s.t. N x + t <= d (both sets) has t* > 0 (scipy linprog).
The common-plane test uses face normals only, so it is exact whenever it reports separation, and
may report overlap for edge-edge configurations (the documented limitation):
  - LP overlap  =>  narrow phase reports penetration (largest face separation < 0);
  - narrow phase separation > 0  =>  LP separated.
Every sub-contact reported with a shallow penetration is a point of one block inside the other.
"""

import numpy as np
import pytest
from scipy.optimize import linprog

from rockdem.geometry import convex_hull
from rockdem.kernels.detect import point_in_target
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


def test_narrow_phase_agrees_with_brute_force(rng):
    checked_overlap = checked_sep = checked_points = 0
    for trial in range(200):
        pa = random_hull(rng, 0.5)
        pb = random_hull(rng, 0.4).transformed(
            axis_angle_matrix(rng.normal(size=3), rng.uniform(0, np.pi)), rng.normal(size=3) * 0.3 + [0.75, 0, 0]
        )
        bld = ModelBuilder(gravity=(0, 0, 0), points=(3, 3))
        bld.default_material = JointMaterial(kn=1e9)
        bld.add_block(pa, name="a")
        bld.add_block(pb, name="b")
        model = bld.finalize(contact_tolerance=0.05)
        s, sc = initial_state(model, check_overlap=False)
        sep = float(sc.sums[5])
        depth = lp_depth(pa, pb)
        if depth > 1e-6:
            checked_overlap += 1
            assert sep < 0.0, f"trial {trial}: interiors overlap by {depth} but narrow phase says separated"
        if sep > 1e-9:
            checked_sep += 1
            assert depth <= 1e-9, f"trial {trial}: narrow phase separation {sep} but LP overlap {depth}"
        tmp = np.zeros(4)
        m = model.arrays
        polys = (pa, pb)
        for k in range(int(s.track_count[0])):
            p = int(s.track[k])
            t = int(s.point_partner[p])
            gap = point_in_target(m, s, sc, p, t, int(s.point_target_face[p]), tmp)
            # A shallow penetration (depth below the in-face margin, so the adjacent faces, at most
            # 90 degrees away for these hulls, cannot cut in) must lie inside the target block.
            if -0.02 < gap < -1e-9 and tmp[3] < -0.02:
                owner = int(m.point_block[p])
                world = model.world_points(owner, m.point_local[p])
                assert polys[t].contains(world, tol=1e-9)[0], f"trial {trial}: point {p} penetrates but is outside"
                checked_points += 1
    # The random set must exercise every branch.
    assert checked_overlap > 20 and checked_sep > 20 and checked_points >= 5


def test_each_point_has_at_most_one_partner_in_a_running_bond_row():
    # Two bricks side by side on a third: the middle points of the lower brick's top face touch
    # both upper bricks' faces on their shared edge; each point is claimed once.
    bld = ModelBuilder(points=(2, 3))
    bld.default_material = JointMaterial(kn=1e9, friction_angle=30)
    bld.add_box(0.1, 0.2, 0.05, base_center=(0, 0, 0), driven=True, name="low")
    bld.add_box(0.1, 0.1, 0.05, base_center=(0, -0.05, 0.05), name="left")
    bld.add_box(0.1, 0.1, 0.05, base_center=(0, 0.05, 0.05), name="right")
    model = bld.finalize()
    s, _ = initial_state(model)
    tracked = s.track[: int(s.track_count[0])]
    assert len(np.unique(tracked)) == len(tracked)
    # Both upper bricks are supported: each is the partner or the owner of some tracked points.
    blocks = set(model.arrays.point_block[tracked]) | set(s.point_partner[tracked])
    assert {1, 2} <= blocks


def test_bonded_wall_keeps_its_bonds_under_self_weight():
    # A running-bond wall standing under gravity: joint stresses are far below c and ft, so no
    # bond may break. Points on the shared edge of two upper bricks must not flip partner (and
    # count as failures) from one contact detection to the next; energy balance stays closed.
    from rockdem.simulate import simulate
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
    # tolerance (1 % of a 0.1 m brick), and slip by c / ks = 25 mm. The default covers both, so a strongly
    # bonded discretised block rocks with no failure (with the old 1 mm: 76 of 816 points "failed" in 1 s).
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
