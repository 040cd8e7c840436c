"""Collapse scenarios: tumbling blocks, random piles, bond-failure cascades, overturning walls.

Each builder returns a :class:`Scenario` (model, duration, record interval); ``short=True`` gives
the quick version run by the tests, the default the full version run by
``python benchmarks/collapse_scenarios.py`` (``--short``: the quick versions; ``--variants``: the
same families on other records, geometries and seeds, :data:`VARIANTS`). :func:`evaluate` runs one and measures what issue-level
acceptance needs: runtime, divergence, the largest interpenetration between two blocks computed
independently of the engine (:mod:`rockdem.diagnostics`), and the largest energy creation
max(KE + PE - initial - work) as a fraction of the run's energy scale.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
import xarray as xr

from rockdem.case import parse_case
from rockdem.diagnostics import max_interpenetration
from rockdem.geometry import box, convex_hull
from rockdem.kernels.rotation import axis_angle_matrix
from rockdem.loading import apply_earthquake, resolve_record
from rockdem.materials import JointMaterial
from rockdem.model import Damping, Model, ModelBuilder
from rockdem.records import read_record
from rockdem.simulation import simulate
from rockdem.specimens import add_foundation, parapet, stacked_blocks

ELCENTRO = "RSN6_IMPVALL.I_I-ELC180.AT2"


@dataclass
class Scenario:
    """A model to run and how long.

    Attributes:
        name: short identifier.
        model: the finalized model.
        duration: simulated time [s].
        record_interval: [s].
        note: what it exercises.
        checks: extra named checks, each a function of the result returning a float.
    """

    name: str
    model: Model
    duration: float
    record_interval: float
    note: str
    checks: dict[str, Callable[[xr.Dataset], float]] = field(default_factory=dict)


def _mat(kn: float = 6e9, friction: float = 35.0, **kw: float) -> JointMaterial:
    return JointMaterial(kn=kn, friction_angle=friction, **kw)


def _lowest_z(model: Model, ds: xr.Dataset, name: str) -> float:
    """Lowest vertex height of block ``name`` at the last frame [m]."""
    from rockdem.kernels.rotation import quats_to_matrices

    b = model.block_id(name)
    m = model.arrays
    v = m.vertex_local[m.block_vertex_start[b] : m.block_vertex_start[b + 1]]
    r = quats_to_matrices(ds.block_quaternion.values[-1, b])
    return float(np.min((v @ r.T + ds.block_position.values[-1, b])[:, 2]))


def _fell_off(ds: xr.Dataset) -> set[str]:
    """Names of the blocks that fell off the edge of the model's supports."""
    names = str(ds.attrs.get("fell_off_blocks", ""))
    return {n.strip() for n in names.split(",") if n.strip()}


def _lowest_brick(model: Model, ds: xr.Dataset, bricks: list[str]) -> float:
    """Lowest vertex height [m] at the last frame of the bricks still on the supports."""
    fell = _fell_off(ds)
    return min(_lowest_z(model, ds, n) for n in bricks if n not in fell)


def edge_on_wall(short: bool = False, *, yaw: float = 45.0, pitch: float = 45.0, wall: float = 0.1, cube_size: float = 0.3,
                 drop: float = 0.02, offset: float = 0.01) -> Scenario:
    """A ``cube_size`` cube turned ``yaw`` deg about z and ``pitch`` deg about y (default 0.3 m, 45
    and 45), dropped from ``drop`` [m] with its lowest vertex ``offset`` [m] off the middle of a free
    ``wall`` thick wall (0.6 m high): it lands on an edge or corner across the wall top, tips and falls."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = _mat()
    add_foundation(b, 3.0)
    b.add_box(wall, 1.0, 0.6, density=2000, name="wall")
    cube = box(cube_size, cube_size, cube_size, name="cube")
    r = axis_angle_matrix(np.array([0, 0, 1.0]), math.radians(yaw)) @ axis_angle_matrix(np.array([0, 1.0, 0]), math.radians(pitch))
    cube = cube.transformed(r, np.zeros(3))
    cube = cube.transformed(np.eye(3), [offset, 0.0, 0.6 + drop - cube.vertices[:, 2].min()])
    b.add_block(cube, density=2000, name="cube")
    return Scenario("edge_on_wall", b.finalize(), 0.35 if short else 1.5, 0.002,
                    "edge landing across a thin wall top (non-conformal, smaller face)")


def ridge_to_ridge(short: bool = False, *, gap: float = 0.0079, speed: float = 0.0) -> Scenario:
    """Two 0.4 m boxes whose ridges cross at right angles, ``gap`` apart, no gravity; the upper one
    moves down at ``speed`` [m/s] (0: they must stay at rest, no force may act across the gap)."""
    b = ModelBuilder(points=(2, 2), gravity=(0.0, 0.0, 0.0))
    b.default_material = _mat(friction=30.0)
    s = 0.4
    half_diag = s / math.sqrt(2.0)
    low = box(s, s, s, name="low").transformed(axis_angle_matrix(np.array([1.0, 0, 0]), math.radians(45)), [0, 0, -half_diag])
    up = box(s, s, s, name="up").transformed(axis_angle_matrix(np.array([0, 1.0, 0]), math.radians(45)), [0, 0, half_diag + gap])
    b.add_block(low, density=2000, name="low", driven=True)
    b.add_block(up, density=2000, name="up", velocity=(0.0, 0.0, -speed))
    dur = 0.05 if speed == 0 else (gap / speed + 0.05 if short else gap / speed + 0.2)
    return Scenario("ridge_to_ridge" if speed == 0 else "ridge_impact", b.finalize(), dur, 0.0005,
                    "crossing edges: no force across a gap; edge-edge impact")


def tumbling_wedge(short: bool = False, *, seed: int = 13, speed: float = 4.5) -> Scenario:
    """A triangular prism (a wedge, 0.08-0.3 m) at a random orientation thrown at the ground at
    ``speed`` [m/s] with a random spin (up to 15 rad/s), 3 x 3 points, MP alpha = 2 and SP beta =
    1e-4 s, kn = 9 GPa/m: it lands on a corner, tumbles and comes to rest. With seed 13 it pivots on
    one vertex of a face standing upright while the next corner of its inclined face comes down,
    which went untracked and created 12 % of the energy scale before 2026-11-30 (a new user's
    random landing; detect.INCIDENT_KEEP)."""
    rng = np.random.default_rng(seed)
    b = ModelBuilder(points=(3, 3))
    b.default_material = _mat(kn=9e9)
    b.add_box(4.0, 4.0, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    size = rng.uniform(0.08, 0.3)
    vel = (rng.uniform(-1, 1), rng.uniform(-1, 1), -speed)
    spin = tuple(rng.uniform(-15, 15, 3))
    length, height = size * rng.uniform(0.6, 1.5), size * rng.uniform(0.6, 1.5)
    wedge = np.array([[0, 0, 0], [size, 0, 0], [0, length, 0], [size, length, 0], [0, 0, height], [0, length, height]])
    wedge = wedge - [size / 3, length / 2, height / 3]
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    rot = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    p = wedge @ rot.T
    p = p - p.mean(axis=0)
    p[:, 2] += 0.01 - p[:, 2].min()
    b.add_block(convex_hull(p, name="wedge"), name="wedge", density=2000.0, velocity=vel, angular_velocity=spin)
    return Scenario("tumbling_wedge", b.finalize(damping=Damping(alpha=2.0, beta=1e-4)), 0.3 if short else 0.6, 2e-4,
                    "a wedge thrown spinning at the ground: corner, edge and face landings, a pivot on a vertex")


PILE_KN = 1.8e9 / 0.2
"""Normal stiffness of the random piles' joints [Pa/m]: the paper's kn = E / l with masonry's
E = 1800 MPa and l = 0.2 m, the boxes' mean size."""


def random_pile(short: bool = False, *, count: int = 40, seed: int = 7, kn: float = PILE_KN, name: str = "random_pile",
                sizes: tuple[float, float] = (0.08, 0.3), friction: float = 30.0, spacing: float = 0.45) -> Scenario:
    """``count`` boxes of random sizes (``sizes``: 0.08-0.3 m) and orientations dropped onto the
    ground from a loose column, nine per layer, ``spacing`` [m] apart (it must exceed the largest
    box's diagonal for boxes that are turned); MP + SP damping brings the pile to rest. ``kn`` [Pa/m]: the joints'
    normal stiffness (``random_pile_soft``: 2 GPa/m, 4.5 times softer; an impact's overlap grows as
    v sqrt(m / (kn A)), docs/contacts.md section 5)."""
    n = 12 if short else count
    rng = np.random.default_rng(seed)
    b = ModelBuilder(points=(2, 2))
    b.default_material = _mat(kn=kn, friction=friction)
    add_foundation(b, 4.0)
    per_layer = 9
    for k in range(n):
        dims = rng.uniform(*sizes, size=3)
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        from rockdem.kernels.rotation import quats_to_matrices

        r = quats_to_matrices(q)
        layer, slot = divmod(k, per_layer)
        cx, cy = (slot % 3 - 1) * spacing + rng.uniform(-0.05, 0.05), (slot // 3 - 1) * spacing + rng.uniform(-0.05, 0.05)
        poly = box(*dims, name=f"box{k}").transformed(r, [cx, cy, 0.3 + layer * spacing])
        b.add_block(poly, density=2000, name=f"box{k}")
    return Scenario(name, b.finalize(damping=Damping(alpha=2.0, beta=2e-4)), 2.0 if short else 4.0, 0.005,
                    f"{n} random boxes ({sizes[0]:g}-{sizes[1]:g} m, seed {seed}) dropped on the ground")


def parapet_earthquake(short: bool = False, *, scale: float = 3.0, weak: bool = True, record: str = ELCENTRO,
                       thickness: float = 0.23, height: float = 1.0, length: float = 1.2,
                       brick: tuple[float, float] = (0.2, 1.0 / 12), kn: float = 1.8e9 / 0.0833, friction: float = 31.0,
                       strength: tuple[float, float] = (1e5, 1e6), extent: float = 12.0) -> Scenario:
    """A brick parapet ``thickness`` x ``length`` x ``height`` (default 0.23 x 1.2 x 1.0 m, running
    bond, 0.2 x 0.083 m bricks) under ``record`` (El Centro) x ``scale``, undamped: weak joints
    (c = ft = ``strength[0]``, 0.1 MPa) or strong joints (``strength[1]``, 1 MPa) on an unbonded
    base; a foundation ``extent`` [m] wide."""
    b = ModelBuilder()
    c = strength[0] if weak else strength[1]
    joint = JointMaterial(kn=kn, friction_angle=friction, cohesion=c, tension=c)
    base = joint if weak else JointMaterial(kn=kn, friction_angle=friction)
    parapet(b, thickness=thickness, height=height, length=length, brick=brick, material=joint, base_material=base,
            base_reduction=0.0, foundation_extent=extent)  # the ground around the building: bricks thrown off land on it
    gm = read_record(resolve_record(record))
    dur = 3.0 if short else 8.0
    apply_earthquake(b, gm, scale=scale, window=(0.0, dur), baseline=True)
    model = b.finalize()
    bricks = [n for n in model.block_names if n != "foundation"]
    return Scenario(f"parapet_x{scale:g}_{'weak' if weak else 'strong'}", model, dur, 0.01,
                    "discretised parapet overturning under a strong record",
                    {"lowest brick z [m]": lambda ds: _lowest_brick(model, ds, bricks)})


def cascade_wall(short: bool = False, *, width: float = 0.19, height: float = 2.0, kn: float = 1e10,
                 strength: float = 1e5, friction: float = 16.7) -> Scenario:
    """The weakly bonded ``width`` x ``height`` discretised wall of the Table 1 / Fig. 8 studies
    (default 0.19 x 2 m, c = ft = ``strength`` 0.1 MPa, kn = 1e10 Pa/m), free rocking without
    damping."""
    from rockdem.reproduce.table1 import wall_case

    data = wall_case(width, height, kn, joint={"cohesion": strength, "tension": strength, "friction_angle_deg": friction})
    data["run"]["duration"] = 3.0 if short else 6.0
    case = parse_case(data)
    return Scenario("cascade_wall", case.model, case.run.duration, 0.005, "bond-failure cascade at the impacts")


def drum_column(short: bool = False, *, scale: float = 2.0, record: str = ELCENTRO, count: int = 4, width: float = 0.4,
                drum: float = 0.5, points: tuple[int, int] = (2, 2), modulus: float = 1.8e9, friction: float = 35.0) -> Scenario:
    """``count`` drums ``width`` x ``width`` x ``drum`` (default four 0.4 x 0.4 x 0.5 m, 2 x 2
    points, mu = 0.7, kn = E / drum) under ``record`` (El Centro) x ``scale``."""
    b = ModelBuilder(points=points)
    mat = JointMaterial.from_modulus(modulus, drum, friction_angle=friction)
    b.default_material = mat
    stacked_blocks(b, width=width, length=width, heights=[drum] * count, density=2400, material=mat)
    gm = read_record(resolve_record(record))
    dur = 4.0 if short else 12.0
    apply_earthquake(b, gm, scale=scale, window=(0.0, dur), baseline=True)
    return Scenario(f"drum_column_x{scale:g}", b.finalize(), dur, 0.005, "drums sliding and rocking on each other")


def topple_near_edge(short: bool = False) -> Scenario:
    """A 0.25 x 1.25 m block released past its instability angle topples towards the edge of a
    2.5 m foundation and lands with its top near that edge."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial.from_modulus(1.8e9, 1.25, friction_angle=35.0)
    add_foundation(b, 2.5)
    b.add_box(0.25, 1.0, 1.25, density=1800, name="block", base_center=(0.0, 0.0, 0.0))
    b.tilt("block", 1.15)
    return Scenario("topple_near_edge", b.finalize(), 1.6 if short else 2.5, 0.002, "toppled block landing near an edge")


def offset_pair(short: bool = False, *, offset: float = 0.03, scale: float = 5.0) -> Scenario:
    """Two unbonded bricks (0.23 x 0.2 x 0.083 m, 2 x 3 points) stacked with the upper one offset by
    ``offset`` [m] in x and y, under El Centro x ``scale``, undamped. The upper brick lifts and lands
    tilted: the pair is an edge-edge (EDGE) pair until it comes face to face, which must be seen
    at the step it happens (kernels.detect.edge_pairs_changed), not at the next detection with the
    face sub-contacts 0.13 mm deep (2.4 J of spring energy in one step, balance 2.6 %, taken for
    friction booked in excess before; 0.06 % since)."""
    b = ModelBuilder(points=(2, 3))
    b.default_material = JointMaterial(kn=1.8e9 / 0.0833, friction_angle=31.0)
    add_foundation(b, 12.0)
    for k in range(2):
        b.add_box(0.23, 0.2, 0.0833, base_center=(offset * k, offset * k, 0.0833 * k), density=1800, name=f"brick{k}")
    dur = 3.0 if short else 6.0
    apply_earthquake(b, read_record(resolve_record(ELCENTRO)), scale=scale, window=(0.0, dur), baseline=True)
    return Scenario("offset_pair", b.finalize(), dur, 0.01, "two offset bricks sliding and rocking on each other")


def tip_over_edge(short: bool = False, *, offset: float = 0.005) -> Scenario:
    """A 0.2 x 0.2 x 0.1 m block whose centroid is ``offset`` past the edge of a narrower support:
    the support's edge lies under the middle of the block's bottom face, on the boundary between
    its 2 x 2 interface cells, and the block tips over it and falls (the target's edge pressing
    into the middle of the owner face: kernels/blend.py)."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = _mat(kn=2e9, friction=40.0)
    add_foundation(b, 2.0)
    b.add_box(0.3, 0.2, 0.3, base_center=(-0.15, 0.0, 0.0), driven=True, name="support")  # top face x in [-0.3, 0]
    b.add_box(0.2, 0.2, 0.1, base_center=(offset, 0.0, 0.3), density=2000, name="block")
    return Scenario("tip_over_edge", b.finalize(), 0.5 if short else 1.2, 0.002, "a block tipping over the edge of a narrower support")


def corner_near_edge(short: bool = False, *, inset: float = 0.001) -> Scenario:
    """A 0.12 m cube turned 25 deg about x and 35 deg about y, dropped from 50 mm so that its lowest
    corner lands ``inset`` inside the edge of a 0.4 m support's top face while the cube overhangs
    it: the corner's interface cell is almost all beyond the edge (lumped corner stiffness)."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = _mat(kn=2e9, friction=35.0)
    add_foundation(b, 2.0)
    b.add_box(0.4, 0.4, 0.2, base_center=(0.0, 0.0, 0.0), driven=True, name="support")
    cube = box(0.12, 0.12, 0.12, name="cube")
    cube = cube.transformed(axis_angle_matrix(np.array([1.0, 0, 0]), math.radians(25)) @ axis_angle_matrix(np.array([0, 1.0, 0]), math.radians(35)), np.zeros(3))
    low = cube.vertices[np.argmin(cube.vertices[:, 2])]
    if low[0] > 0:  # turn it so that the cube lies beyond the edge, only its corner over the support
        cube = cube.transformed(axis_angle_matrix(np.array([0, 0, 1.0]), math.pi), np.zeros(3))
        low = cube.vertices[np.argmin(cube.vertices[:, 2])]
    cube = cube.transformed(np.eye(3), [0.2 - inset - low[0], -low[1], 0.2 + 0.05 - low[2]])
    b.add_block(cube, density=2000, name="cube")
    return Scenario("corner_near_edge", b.finalize(), 0.3 if short else 0.8, 0.001, "a corner landing just inside a face's edge")


def facade_topple(short: bool = False) -> Scenario:
    """The paper's one-sided façade (B = 0.11, H = 0.8, L = 1.5 m, 8 mm rounded bottom edges,
    E = 1800 MPa, SP beta = 0.00025 s) pushed outward past its instability angle (away from the
    return walls): it rocks on its rounded edge and slaps down on its 1.2 m^2 face. The incident
    face must change from the small rounded-edge facet to the big face as that lands (a hysteresis
    in angle kept the facet while the face swung 0.12 m into the ground, then launched it at
    1e6 J)."""
    from rockdem.specimens import facade

    b = ModelBuilder(points=(2, 2))
    mat = JointMaterial.from_modulus(1.8e9, 0.8, friction_angle=30.96)
    facade(b, edge_radius=0.008, edge_facets=4, material=mat, rocking_velocity=-1.2)
    return Scenario("facade_topple", b.finalize(damping=Damping(beta=0.00025)), 1.5 if short else 2.5, 0.002,
                    "a rounded-edge façade toppling onto its face")


def thrown_clear(short: bool = False, *, speed: float = 6.0, beta: float = 1e-4) -> Scenario:
    """A 0.3 m cube set sliding at ``speed`` [m/s] across a 0.6 m foundation with SP damping: its
    joints load as it slides, friction pitches it (its rear points lift and land again), and it is
    thrown clear of the foundation, leaving the model's extent through a side as it falls (a brick
    thrown off a wall top). Before 2026-11-28 the run stopped there as lost, and the release of a
    slipping point's shear dashpot pushed the cube along its sliding (15 J gained of 972 J)."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e9 / 0.3, friction_angle=30)
    add_foundation(b, 0.6)
    b.add_box(0.3, 0.3, 0.3, base_center=(0, 0, 0), density=2000, name="cube", velocity=(speed, 0, 0))
    return Scenario("thrown_clear", b.finalize(damping=Damping(beta=beta)), 0.6 if short else 1.0, 0.001,
                    "a cube sliding off a small foundation and thrown clear of it")


SCENARIOS: dict[str, Callable[..., Scenario]] = {
    "edge_on_wall": edge_on_wall,
    "ridge_to_ridge": ridge_to_ridge,
    "ridge_impact": lambda short=False: ridge_to_ridge(short, gap=0.002, speed=0.2),
    "random_pile": random_pile,
    "random_pile_soft": lambda short=False: random_pile(short, kn=2e9, name="random_pile_soft"),
    "parapet_x3_weak": lambda short=False: parapet_earthquake(short, scale=3.0, weak=True),
    "parapet_x5_strong": lambda short=False: parapet_earthquake(short, scale=5.0, weak=False),
    "cascade_wall": cascade_wall,
    "drum_column_x2": drum_column,
    "topple_near_edge": topple_near_edge,
    "offset_pair": offset_pair,
    "tip_over_edge": tip_over_edge,
    "corner_near_edge": corner_near_edge,
    "facade_topple": facade_topple,
    "thrown_clear": thrown_clear,
}



def _big_parapet(record: str, scale: float, weak: bool) -> Scenario:
    """A 0.35 x 1.8 x 1.5 m parapet of 0.25 x 0.075 m bricks (mu = 0.65, c = ft = 0.05 MPa weak,
    0.8 MPa strong) on a 14 m foundation under ``record`` x ``scale``."""
    return parapet_earthquake(scale=scale, weak=weak, record=record, thickness=0.35, height=1.5, length=1.8,
                              brick=(0.25, 0.075), kn=1.8e9 / 0.075, friction=33.0, strength=(5e4, 8e5), extent=14.0)


STURNO, PACOIMA, BAGNOLI, NAHANNI = ("RSN292_ITALY_A-STU270.AT2", "RSN77_SFERN_PUL164.AT2", "RSN285_ITALY_A-BAG270.AT2",
                                     "Nahanni_1985_NS1-280.csv")
VARIANTS: dict[str, Callable[[], Scenario]] = {
    # The same families on other records, geometries, materials and seeds (issue 11: "the same
    # families will be run on unseen geometries and records"); full length only, about 35 min.
    "edge_on_wall_30": lambda: edge_on_wall(yaw=30.0, pitch=40.0, wall=0.12, drop=0.05, offset=-0.02),
    "edge_on_wall_corner": lambda: edge_on_wall(yaw=60.0, pitch=35.0, wall=0.08, cube_size=0.25, drop=0.1),
    "random_pile_45": lambda: random_pile(count=45, seed=11, friction=25.0),
    "random_pile_50_wide": lambda: random_pile(count=50, seed=12, sizes=(0.05, 0.4), spacing=0.7),
    **{name: (lambda rec=rec, scale=scale, weak=weak: _big_parapet(rec, scale, weak))
       for name, rec, scale, weak in (("parapet_sturno_x3_weak", STURNO, 3.0, True), ("parapet_pacoima_x2_strong", PACOIMA, 2.0, False),
                                       ("parapet_bagnoli_x5_weak", BAGNOLI, 5.0, True))},
    "cascade_wall_squat": lambda: cascade_wall(width=0.25, height=1.5, kn=8e9, strength=5e4, friction=20.0),
    "cascade_wall_slender": lambda: cascade_wall(width=0.15, height=2.5, kn=8e9, strength=2e4, friction=20.0),
    "drum_column_sturno_x3": lambda: drum_column(scale=3.0, record=STURNO, count=3, width=0.3, drum=0.6, points=(3, 3),
                                                 modulus=2.4e9, friction=38.0),
    "drum_column_nahanni_x2": lambda: drum_column(scale=2.0, record=NAHANNI, count=5, width=0.35, drum=0.45, points=(3, 3),
                                                  modulus=2.4e9, friction=38.0),
    "tumbling_wedge_13": lambda: tumbling_wedge(seed=13),
    "tumbling_wedge_7": lambda: tumbling_wedge(seed=7),
}
"""Unseen variants of the scenarios, full length only, run under their key
(``python benchmarks/collapse_scenarios.py --variants``)."""


@dataclass
class Outcome:
    """Measured figures of one scenario run."""

    name: str
    runtime_s: float
    steps: int
    simulated_s: float
    diverged: bool
    overlap_m: float
    overlap_relative: float
    overlap_blocks: tuple[str, str]
    energy_created: float
    energy_scale: float
    balance_error: float
    final_kinetic: float
    extra: dict[str, float]

    def line(self) -> str:
        return (
            f"{self.name:20s} {self.runtime_s:8.2f} s {self.steps:9d} steps  {self.simulated_s:6.2f}/{'DIV' if self.diverged else 'ok '} "
            f" overlap {self.overlap_m * 1e3:7.3f} mm ({100 * self.overlap_relative:5.2f} %)"
            f"  E created {100 * self.energy_created / max(self.energy_scale, 1e-300):6.3f} %  balance {100 * self.balance_error:6.3f} %"
            f"  KE_end {self.final_kinetic:.3g} J"
        )


def energy_creation(ds: xr.Dataset) -> tuple[float, float]:
    """(max over time of KE + PE - initial - work [J], the energy scale [J]).

    The scale is the largest of (kinetic + elastic + |potential| + dissipated + |work|) over the
    run, as for ``energy_balance_error_relative``."""
    e = ds.energy_kinetic.values + ds.energy_potential.values
    work = ds.work_driven.values + ds.work_body.values
    created = float(np.max(e - e[0] - (work - work[0])))
    parts = [np.abs(ds[n].values) for n in ds.data_vars if str(n).startswith(("energy_", "work_")) and "balance" not in str(n)]
    return created, float(np.max(np.sum(parts, axis=0)))


def evaluate(sc: Scenario, *, overlap_every: int = 1, dashpots: str | None = None) -> tuple[Outcome, xr.Dataset]:
    """Run a scenario and measure it (``dashpots``: the SP scheme, default the engine's)."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ds = simulate(sc.model, sc.duration, record_interval=sc.record_interval, dashpots=dashpots, progress=False)
    runtime = time.perf_counter() - t0
    pen = max_interpenetration(ds, frames=slice(None, None, overlap_every))
    created, scale = energy_creation(ds)
    err = float(np.max(np.abs(ds.energy_balance_error_relative.values))) if ds.sizes["time"] else float("nan")
    extra = {k: f(ds) for k, f in sc.checks.items()}
    damp = ds.energy_damping_stiffness.values
    # Dashpots that did positive work over a frame. A release's negative share (the last step applied
    # a dashpot past its contact's opening, kernels.contact.dashpot_release_share) takes back a
    # little of what the contact's dashpot dissipated; more than that is a fault (a cube thrown at
    # 6 m/s gained 15 J this way before 2026-11-28).
    if damp.size > 1 and np.diff(damp).min() < 0.0:
        extra["SP damping fell by (share of scale)"] = float(-np.diff(damp).min() / max(scale, 1e-300))
    fell = _fell_off(ds)
    if fell:
        extra["fell off the supports"] = float(len(fell))
    out = Outcome(
        sc.name, runtime, int(ds.attrs["steps"]), float(ds.time.values[-1]) if ds.sizes["time"] else 0.0,
        bool(ds.attrs.get("diverged", 0)), pen.depth, pen.relative, pen.blocks, created, scale, err,
        float(ds.energy_kinetic.values[-1]) if ds.sizes["time"] else float("nan"), extra,
    )
    return out, ds


def run_all(names: list[str] | None = None, *, short: bool = False, dashpots: str | None = None,
            variants: bool = False) -> list[Outcome]:
    """Run the named scenarios (default all; ``variants``: those of :data:`VARIANTS`) and print one
    line each."""
    table = VARIANTS if variants else SCENARIOS
    outs = []
    for name in names or list(table):
        try:
            sc = replace(table[name](), name=name) if variants else table[name](short=short)
            out, _ = evaluate(sc, overlap_every=1 if short else 2, dashpots=dashpots)
        except Exception as exc:  # a scenario that cannot run is reported, not fatal
            print(f"{name:20s} FAILED: {type(exc).__name__}: {exc}", flush=True)
            continue
        print(out.line() + "".join(f"  {k} {v:.4g}" for k, v in out.extra.items()), flush=True)
        outs.append(out)
    return outs


def _print_header() -> None:
    print(f"{'scenario':20s} {'runtime':>10s} {'steps':>15s}  simulated  max overlap (of thinner block)  energy created / scale")


if __name__ == "__main__":  # pragma: no cover
    import sys

    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    _print_header()
    run_all(args or None, short="--short" in sys.argv, dashpots="explicit" if "--explicit" in sys.argv else None,
            variants="--variants" in sys.argv)
