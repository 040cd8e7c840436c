"""Specimen builders: stacked blocks, brick walls, parapets, one-sided façades, two-block walls.

Each builder adds blocks (and the joint materials between its groups) to a
:class:`~rockdem.model.ModelBuilder` and returns monitors ``{name: (block name, world point in the
reference configuration [m])}`` for :func:`rockdem.simulation.simulate`. Each has a TOML form
(``[specimen] type = ...``) registered here with :func:`rockdem.case.specimen`.

Conventions: SI units; z is up; the rocking direction is x (out of plane), walls run along y;
every specimen stands on a driven box ``"foundation"`` (group ``"foundation"``, ``driven="ground"``:
it follows the model's ground motion) whose top face is the plane z = 0. The specimens follow the
paper's experiments (Galvez et al. 2022): parapets §4.1, one-sided façades §4.2, discretised walls
§3.2, vertically spanning two-block walls §4.4.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np

from .case import Table, joint_material, specimen
from .geometry import MAX_LENGTH, Polyhedron, box, convex_hull, mass_properties
from .kernels.rotation import axis_angle_matrix
from .materials import JointMaterial, real_number
from .model import GROUND, Motion, ModelBuilder
from .records import STANDARD_GRAVITY
from .simulation import Monitor

__all__ = [
    "collapse_extent",
    "stacked_blocks",
    "brick_wall",
    "parapet",
    "facade",
    "two_block_wall",
    "add_foundation",
    "rounded_prism",
    "push_motion",
    "MAX_BLOCKS",
    "MAX_EDGE_FACETS",
]

Monitors = dict[str, Monitor]

MAX_BLOCKS = 10_000
"""Most blocks a specimen builder adds (the paper's discretised walls have a few hundred)."""

MAX_EDGE_FACETS = 90
"""Most flat facets of a rounded edge (90: one per degree)."""


# -- checks and small geometry helpers ------------------------------------------------------------
def _positive(name: str, value: float, unit: str = "m") -> float:
    """``value`` as a float, refused (naming ``name``) unless positive and finite, and for a length
    (``unit`` "m") at most MAX_LENGTH."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive number [{unit}], got {value!r}")
    if unit == "m" and value > MAX_LENGTH:
        raise ValueError(f"{name} = {value:g} m is beyond any structure (at most {MAX_LENGTH:g} m); lengths are in metres")
    return float(value)


def _non_negative(name: str, value: float, unit: str = "m") -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a non-negative number [{unit}], got {value!r}")
    return float(value)


def _count(name: str, value: int, max_: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    if max_ is not None and value > max_:
        raise ValueError(f"{name} = {value} exceeds the limit of {max_}")
    return int(value)


def _brick(brick: object) -> tuple[float, float]:
    """A ``brick`` argument as (length along y, height) [m], both positive; ValueError otherwise."""
    try:
        by, bz = (float(v) for v in brick)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ValueError(f"brick must be (length along y, height) [m] or None, got {brick!r}") from None
    return _positive("brick[0] (length, y)", by), _positive("brick[1] (height, z)", bz)


def _material(name: str, material: JointMaterial | None) -> JointMaterial | None:
    if material is not None and not isinstance(material, JointMaterial):
        raise ValueError(f"{name} must be a JointMaterial or None (the builder's default_material), got {material!r}")
    return material


def _block_count(what: str, count: int) -> None:
    if count > MAX_BLOCKS:
        raise ValueError(f"{what} gives {count} blocks, above the limit of {MAX_BLOCKS}; use larger or fewer blocks")


def _set_pairs(builder: ModelBuilder, pairs: Sequence[tuple[str, str]], material: JointMaterial | None) -> None:
    """Set ``material`` on every group pair (nothing when None: the builder's default applies)."""
    if material is None:
        return
    for a, b in pairs:
        builder.set_material(a, b, material)


def collapse_extent(width: float, length: float, height: float) -> float:
    """Plan size [m] of a square foundation on which a specimen of plan ``width`` x ``length`` and
    ``height`` [m] (centred on the origin) lands whole when it topples in any direction: its plan
    half-size plus its height, plus half its height again for the parts that slide, tumble or
    bounce on, doubled: max(width, length) + 3 height."""
    return max(width, length) + 3.0 * height


def _foundation_size(given: float | None, width: float, length: float, height: float) -> float:
    """The foundation's plan size [m]: ``given`` (a specimen's ``foundation_extent``), at least its
    footprint ``width`` x ``length`` [m] (a smaller one would leave the specimen overhanging, or on
    a pedestal it sinks into), else :func:`collapse_extent`."""
    if given is None:
        return collapse_extent(width, length, height)
    size = _positive("foundation_extent", given)
    if size < max(width, length):
        raise ValueError(f"foundation_extent = {size:g} m is smaller than the specimen's footprint ({width:g} x {length:g} m): "
                         f"give at least {max(width, length):g} m, and for collapse collapse_extent = "
                         f"{collapse_extent(width, length, height):g} m (the default)")
    return size


def add_foundation(builder: ModelBuilder, extent: float, *, name: str = "foundation") -> int:
    """Add a driven ``"ground"`` box (group ``"foundation"``) whose top face is z = 0.

    Args:
        builder: the model builder.
        extent: plan size of the square box [m] (its depth is a quarter of it); it is centred on
            the origin. For collapse give at least :func:`collapse_extent` of the specimen
            (the specimen builders do), else toppled parts land on its edge or fall off.
        name: block name.

    Returns:
        The block id.
    """
    size = _positive("foundation extent", extent)
    return builder.add_box(
        size, size, 0.25 * size, base_center=(0.0, 0.0, -0.25 * size), driven=GROUND, group="foundation", name=name, points=(2, 2)
    )


def rounded_prism(
    width: float, length: float, height: float, *, radius: float = 0.0, facets: int = 4, chamfer: float = 0.0, y0: float | None = None, z0: float = 0.0, name: str = "block"
) -> Polyhedron:
    """A box (x: width, y: length, z: height [m]) whose two bottom edges along y are rounded or chamfered.

    The cross-section in x-z is the rectangle with its two bottom corners replaced either by
    quarter circles of ``radius`` [m] made of ``facets`` flat facets each (worn edges of a rocking
    façade, paper §4.2), or by 45° chamfers removing ``chamfer`` [m] of the width at each side
    (crushed mortar at a parapet's base, §4.1). The bottom face is then ``width - 2 radius``
    (or ``width - 2 chamfer``) wide. The section is centred on x = 0, spans y in
    [y0, y0 + length] (default centred on y = 0) and z in [z0, z0 + height].
    """
    width = _positive(f"{name}: width", width)
    length = _positive(f"{name}: length", length)
    height = _positive(f"{name}: height", height)
    radius = _non_negative(f"{name}: radius", radius)
    chamfer = _non_negative(f"{name}: chamfer", chamfer)
    z0 = real_number(z0, f"{name}: z0 [m]")
    y0 = None if y0 is None else real_number(y0, f"{name}: y0 [m]")
    if radius > 0 and chamfer > 0:
        raise ValueError(f"{name}: give either radius or chamfer, not both")
    cut = max(radius, chamfer)
    if not cut < 0.5 * width:
        raise ValueError(f"{name}: the edge radius/chamfer ({cut} m) must be below half the width ({0.5 * width} m)")
    if not cut < height:
        raise ValueError(f"{name}: the edge radius/chamfer ({cut} m) must be below the height ({height} m)")
    hw = 0.5 * width
    if cut == 0.0:
        section = [(-hw, 0.0), (hw, 0.0), (hw, height), (-hw, height)]
    elif chamfer > 0:
        section = [(-hw + chamfer, 0.0), (hw - chamfer, 0.0), (hw, chamfer), (hw, height), (-hw, height), (-hw, chamfer)]
    else:
        n = _count(f"{name}: facets", facets, MAX_EDGE_FACETS)
        ang = np.linspace(0.0, 0.5 * math.pi, n + 1)
        right = [(hw - radius + radius * math.sin(a), radius - radius * math.cos(a)) for a in ang]
        left = [(-x, z) for (x, z) in right[::-1]]
        section = left + right + [(hw, height), (-hw, height)]
    y_lo = -0.5 * length if y0 is None else y0
    pts = [(x, y, z + z0) for (x, z) in section for y in (y_lo, y_lo + length)]
    return convex_hull(np.array(pts), name=name)


# -- stacked blocks ---------------------------------------------------------------------------------
def stacked_blocks(
    builder: ModelBuilder,
    *,
    width: float,
    length: float,
    heights: Sequence[float],
    density: float = 1800.0,
    material: JointMaterial | None = None,
    points: tuple[int, int] | None = None,
    foundation: bool = True,
    foundation_extent: float | None = None,
) -> Monitors:
    """Blocks stacked with coinciding corners on a ground-driven foundation (paper §2.2).

    Args:
        builder: the model builder.
        foundation_extent: plan size of the foundation [m]; default :func:`collapse_extent` of the
            specimen, room for it to topple in any direction and land on the foundation.
        width: block width along x, the rocking direction [m].
        length: block length along y [m].
        heights: block heights from the bottom up [m]; blocks are named ``block1`` (bottom) to
            ``blockN`` and belong to group ``"block"``.
        density: [kg/m^3].
        material: joint material of all joints (block-block and block-foundation); None uses
            ``builder.default_material``. Joints touching at the start are bonded when it has
            cohesion or tension. For kn = E / l, l is the block height (paper §3).
        points: interface points per face (across, along); default the builder's.
        foundation: add the foundation box (False when it is added separately).

    Returns:
        Monitors ``top`` (top block, top edge on the +x face) and ``blockI_top`` for every block.
    """
    w = _positive("width", width)
    ln = _positive("length", length)
    if isinstance(heights, (str, bytes)) or not isinstance(heights, (Sequence, np.ndarray)) or len(heights) == 0:
        raise ValueError(f"heights must be a non-empty list of block heights [m], got {heights!r}"[:200])
    _block_count(f"heights ({len(heights)} entries)", len(heights))
    hs = [_positive(f"heights[{k}]", h) for k, h in enumerate(heights)]
    _positive("density", density, "kg/m^3")
    material = _material("material", material)
    if foundation:
        add_foundation(builder, _foundation_size(foundation_extent, w, ln, sum(hs)))
    _set_pairs(builder, [("block", "block"), ("block", "foundation"), ("foundation", "foundation")], material)
    monitors: Monitors = {}
    z = 0.0
    for k, h in enumerate(hs):
        name = f"block{k + 1}"
        builder.add_box(w, ln, h, base_center=(0.0, 0.0, z), density=density, name=name, group="block", points=points)
        z += h
        monitors[f"{name}_top"] = (name, (0.5 * w, 0.0, z))
    monitors["top"] = (f"block{len(hs)}", (0.5 * w, 0.0, z))
    return monitors


# -- brick walls ------------------------------------------------------------------------------------
BONDS = ("running", "stack")
"""Brick bond patterns: ``running`` (alternate courses shifted by half a brick) or ``stack``."""


def brick_wall(
    builder: ModelBuilder,
    *,
    brick: tuple[float, float, float] = (0.11, 0.23, 0.076),
    courses: int,
    bricks_per_course: int,
    bond: str = "running",
    joint: JointMaterial | None = None,
    base: JointMaterial | None = None,
    density: float = 1800.0,
    points: tuple[int, int] = (2, 3),
    base_reduction: float = 0.0,
    foundation: bool = True,
    foundation_extent: float | None = None,
) -> Monitors:
    """A wall discretised brick by brick (paper §3.2, Fig. 10C, 12A), standing on the foundation.

    The wall spans x in [-lx/2, lx/2] (thickness, the rocking direction), y in [-W/2, W/2] with
    W = bricks_per_course * ly, z in [0, courses * lz]. Bricks are the units *plus* mortar: they
    touch exactly, and every joint touching at the start is bonded when its material has cohesion
    or tension (the engine does this). Bricks are named ``brick_<course>_<i>`` (course 0 at the
    bottom, i from -y to +y), group ``"brick"``.

    Running bond: odd courses are shifted by half a brick and start and end with half bricks, so
    both wall ends are flush. Contact detail: the engine takes the interface points of the
    smaller of two facing faces (tie: lower block id, i.e. the lower course) and tests them
    against the other face. With 2 points along a brick (corners only) a brick resting on two
    half-offset bricks would be carried on single lines; with an odd count (3, 5) a point falls on
    the half-brick offset, so every bed joint has supported points on both sides of it. An even
    ``points[1]`` is therefore refused for running bond.

    Args:
        builder: the model builder.
        foundation_extent: plan size of the foundation [m]; default :func:`collapse_extent` of the
            specimen, room for it to topple in any direction and land on the foundation.
        brick: (lx thickness along x, ly length along the wall y, lz height z) [m], mortar included.
        courses: number of courses (>= 1).
        bricks_per_course: full bricks per unshifted course (>= 1).
        bond: ``"running"`` or ``"stack"``.
        joint: material of bed and head joints (groups "brick"-"brick"); None: the builder's default.
            For kn = E / l, l is the brick height (paper §3).
        base: material of the base joint ("brick"-"foundation"); None: same as ``joint``.
        density: [kg/m^3].
        points: interface points per face (across, along); along must be odd for running bond.
        base_reduction: width [m] removed from the bottom course's base by 45° chamfers (half on
            each side) so the base contact is lx - base_reduction wide (crushed mortar, §4.1).
        foundation: add the foundation box.

    Returns:
        Monitors ``top`` (top course, centre of the +x face's top edge), ``top_left`` and
        ``top_right`` (the -y and +y ends of that edge), as in the paper's Fig. 12B.
    """
    try:
        lx, ly, lz = (float(v) for v in brick)
    except (TypeError, ValueError):
        raise ValueError(f"brick must be (lx thickness, ly length, lz height) [m], got {brick!r}") from None
    for nm, v in (("brick[0] (thickness, x)", lx), ("brick[1] (length, y)", ly), ("brick[2] (height, z)", lz)):
        _positive(nm, v)
    nc = _count("courses", courses)
    nb = _count("bricks_per_course", bricks_per_course)
    _block_count(f"courses x bricks_per_course = {nc} x {nb}", nc * (nb + 1))
    if bond not in BONDS:
        raise ValueError(f"bond must be one of {list(BONDS)}, got {bond!r}")
    _positive("density", density, "kg/m^3")
    joint = _material("joint", joint)
    base = _material("base", base)
    if (
        isinstance(points, (str, bytes))
        or not isinstance(points, (Sequence, np.ndarray))
        or len(points) != 2
        or any(isinstance(p, bool) or not isinstance(p, (int, np.integer)) or p < 1 for p in points)
    ):
        raise ValueError(f"points must be (across, along) integers >= 1, got {points!r}")
    if bond == "running" and points[1] % 2 == 0:
        raise ValueError(
            f"points along = {points[1]} is even: with running bond the half-brick offset must land on an "
            "interface point; use an odd count (3 or 5)"
        )
    red = _non_negative("base_reduction", base_reduction)
    if not red < lx:
        raise ValueError(f"base_reduction ({red} m) must be below the brick thickness brick[0] ({lx} m)")
    if not 0.5 * red < lz:
        raise ValueError(f"base_reduction / 2 ({0.5 * red} m) must be below the brick height brick[2] ({lz} m)")
    width = nb * ly
    height = nc * lz
    if foundation:
        add_foundation(builder, _foundation_size(foundation_extent, lx, width, height))
    _set_pairs(builder, [("brick", "brick")], joint)
    _set_pairs(builder, [("brick", "foundation"), ("foundation", "foundation")], base if base is not None else joint)
    pts = (int(points[0]), int(points[1]))
    top_names: list[tuple[str, float, float]] = []
    for c in range(nc):
        edges = [-0.5 * width + i * ly for i in range(nb + 1)]
        if bond == "running" and c % 2 == 1:
            edges = [edges[0]] + [e + 0.5 * ly for e in edges[:-1]] + [edges[-1]]
        z0 = c * lz
        for i in range(len(edges) - 1):
            y0, y1 = edges[i], edges[i + 1]
            name = f"brick_{c}_{i}"
            if c == 0 and red > 0:
                poly = rounded_prism(lx, y1 - y0, lz, chamfer=0.5 * red, y0=y0, z0=z0, name=name)
            else:
                poly = box(lx, y1 - y0, lz, center=(0.0, 0.5 * (y0 + y1), z0 + 0.5 * lz), name=name)
            builder.add_block(poly, density=density, group="brick", name=name, points=pts)
            if c == nc - 1:
                top_names.append((name, y0, y1))
    mid = next(n for (n, y0, y1) in top_names if y0 <= 0.0 < y1 or y1 >= 0.5 * width)
    return {
        "top": (mid, (0.5 * lx, 0.0, height)),
        "top_left": (top_names[0][0], (0.5 * lx, -0.5 * width, height)),
        "top_right": (top_names[-1][0], (0.5 * lx, 0.5 * width, height)),
    }


# -- parapet ----------------------------------------------------------------------------------------
def parapet(
    builder: ModelBuilder,
    *,
    thickness: float = 0.23,
    height: float,
    length: float,
    base_reduction: float = 0.007,
    brick: tuple[float, float] | None = None,
    bond: str = "running",
    density: float = 1800.0,
    material: JointMaterial | None = None,
    base_material: JointMaterial | None = None,
    points: tuple[int, int] | None = None,
    foundation_extent: float | None = None,
) -> Monitors:
    """A free-standing URM parapet (Giaretton et al., paper §4.1) as one block or brick by brick.

    The crushed soft mortar at the base (the paper removes 7 mm of the 230-mm thickness) is
    modelled by **45° chamfers on the two bottom edges along the wall**, each removing
    ``base_reduction / 2`` of the width: the base contact face is ``thickness - base_reduction``
    wide and the block rocks about its edges, the rest of the geometry (and, to within
    base_reduction^2 / 4 per metre, the mass) being unchanged.

    Args:
        builder: the model builder.
        foundation_extent: plan size of the foundation [m]; default :func:`collapse_extent` of the
            specimen, room for it to topple in any direction and land on the foundation.
        thickness: out-of-plane thickness along x [m].
        height: [m].
        length: along y [m].
        base_reduction: width removed at the base [m], 0 <= base_reduction < thickness.
        brick: None for a single block named ``"parapet"``; or (ly length, lz height) [m] of the
            bricks, one brick through the thickness; they are adjusted to fit the length and height
            exactly (whole numbers of bricks and courses), see :func:`brick_wall`.
        bond: ``"running"`` or ``"stack"`` (discretised parapet).
        density: [kg/m^3].
        material: material of every joint (base, bed and head); None: ``builder.default_material``.
            For kn = E / l, l is the height (single block) or brick height (paper §3).
        base_material: the parapet-foundation joint (e.g. the crushed soft mortar bed, without
            bond); None: ``material``.
        points: interface points per face; default the builder's (single block) or (2, 3).

    Returns:
        Monitors: ``top`` (the +x top edge, centre), plus ``top_left``/``top_right`` when discretised.
    """
    t = _positive("thickness", thickness)
    h = _positive("height", height)
    ln = _positive("length", length)
    red = _non_negative("base_reduction", base_reduction)
    if not red < t:
        raise ValueError(f"base_reduction ({red} m) must be below the thickness ({t} m)")
    _positive("density", density, "kg/m^3")
    if bond not in BONDS:
        raise ValueError(f"bond must be one of {list(BONDS)}, got {bond!r}")
    material = _material("material", material)
    base_material = _material("base_material", base_material)
    if brick is not None:
        by, bz = _brick(brick)
        nb = max(1, round(ln / by))
        nc = max(1, round(h / bz))
        _block_count(f"brick = ({by}, {bz}) m on a {ln} x {h} m parapet", nc * (nb + 1))
        return brick_wall(
            builder,
            brick=(t, ln / nb, h / nc),
            courses=nc,
            bricks_per_course=nb,
            bond=bond,
            joint=material,
            base=material if base_material is None else base_material,
            density=density,
            points=points or (2, 3),
            base_reduction=red,
            foundation_extent=foundation_extent,
        )
    add_foundation(builder, _foundation_size(foundation_extent, t, ln, h))
    _set_pairs(builder, [("block", "block"), ("foundation", "foundation")], material)
    _set_pairs(builder, [("block", "foundation")], material if base_material is None else base_material)
    poly = rounded_prism(t, ln, h, chamfer=0.5 * red, name="parapet") if red > 0 else box(t, ln, h, center=(0, 0, 0.5 * h), name="parapet")
    builder.add_block(poly, density=density, group="block", name="parapet", points=points)
    return {"top": ("parapet", (0.5 * t, 0.0, h))}


# -- one-sided façade -------------------------------------------------------------------------------
ROCKING_SPEED_LIMIT = 10.0
"""A façade's initial ``rocking_velocity`` that moves its top faster than this many times the speed
of a fall from its height is refused (1e6 rad/s ran 46 million steps before leaving the model)."""


def facade(
    builder: ModelBuilder,
    *,
    width: float = 0.11,
    height: float = 0.8,
    length: float = 1.5,
    density: float = 1750.0,
    return_thickness: float = 0.11,
    return_length: float = 0.5,
    return_height: float | None = None,
    gap: float = 0.004,
    edge_radius: float = 0.0,
    edge_facets: int = 4,
    slope_deg: float = 0.0,
    material: JointMaterial | None = None,
    return_material: JointMaterial | None = None,
    points: tuple[int, int] | None = None,
    rocking_velocity: float = 0.0,
    foundation_extent: float | None = None,
    brick: tuple[float, float] | None = None,
    bond: str = "running",
) -> Monitors:
    """A façade rocking one-sidedly against return walls (Sorrentino et al., Shawa et al.; paper §4.2).

    The façade (block ``"facade"``, group ``"facade"``) spans x in [-B/2, B/2] (B = width, the
    out-of-plane thickness), y in [-L/2, L/2], z in [0, H]. The building's inside is +x: two
    return walls (driven ``"ground"`` blocks ``return_left``/``return_right``, group
    ``"return"``) run along x behind the façade's ends, y in [L/2 - t_r, L/2] and its mirror,
    starting ``gap`` behind the façade's inner face. The façade rocks freely outward (towards -x)
    but, rocking inward, its inner face strikes the return walls' end faces once the top has
    moved ``gap``: the inward rotation is limited to about gap / H (one-sided rocking).

    Args:
        builder: the model builder.
        foundation_extent: plan size of the foundation [m]; default :func:`collapse_extent` of the
            specimen, room for it to topple in any direction and land on the foundation.
        width: B, out-of-plane thickness (x) [m]. height: H [m]. length: L, along y [m].
        density: [kg/m^3].
        return_thickness: thickness t_r of each return wall (along y) [m], at most L/2.
        return_length: length of the return walls along x [m].
        return_height: [m]; default H.
        gap: clear gap between the façade's inner face and the return walls [m] (>= 0; 4 mm in
            Shawa et al.).
        edge_radius: radius [m] of the rounded bottom edges (8 mm in §4.2), 0 <= r < B/2; the
            bottom face is then B - 2 r wide.
        edge_facets: flat facets per rounded edge.
        slope_deg: foundation slope phi [deg] (dust under the wall, §4.2): the foundation and the
            façade are turned together by phi about the y axis through the base centre, positive
            leaning the façade outward (top towards -x, away from the return walls). An inward lean
            must not close the gap.
        material: façade-foundation joint; None: ``builder.default_material``. For kn = E / l,
            l = H (paper §3).
        return_material: façade-return wall contact; None: same as ``material``.
        points: interface points per face; default the builder's.
        rocking_velocity: initial rocking rate [rad/s] about the bottom edge: positive towards
            the return walls (about the inner edge), negative outward (about the outer edge).
        brick: None for the single block ``"facade"``; or (ly length, lz height) [m] of bricks, one
            through the thickness, to discretise the façade brick by brick (paper Fig. 12A; sizes
            adjusted to whole bricks and courses, names and groups of :func:`brick_wall`, group
            ``"brick"``). ``material`` is then every joint's (bed, head and base; kn = E / course
            height), and the bricks start at rest: ``edge_radius`` and ``rocking_velocity`` apply
            to the single block only.
        bond: ``"running"`` or ``"stack"`` (discretised façade).

    Returns:
        Monitors ``top`` (centre of the outer (-x) top edge), ``top_left`` and ``top_right``.
    """
    b = _positive("width", width)
    h = _positive("height", height)
    ln = _positive("length", length)
    _positive("density", density, "kg/m^3")
    tr = _positive("return_thickness", return_thickness)
    lr = _positive("return_length", return_length)
    hr = h if return_height is None else _positive("return_height", return_height)
    g = _non_negative("gap", gap)
    r = _non_negative("edge_radius", edge_radius)
    if not r < 0.5 * b:
        raise ValueError(f"edge_radius ({r} m) must be below half the width ({0.5 * b} m); reduce it")
    if r > 0:
        _count("edge_facets", edge_facets, MAX_EDGE_FACETS)
    if not tr <= 0.5 * ln:
        raise ValueError(f"return_thickness ({tr} m) must be at most half the façade length ({0.5 * ln} m)")
    if isinstance(slope_deg, bool) or not isinstance(slope_deg, (int, float)) or not abs(slope_deg) < 45:
        raise ValueError(f"slope_deg must be an angle in (-45, 45) degrees, got {slope_deg!r}")
    real_number(rocking_velocity, "rocking_velocity [rad/s]")
    fall = math.sqrt(2.0 * STANDARD_GRAVITY * h)  # the speed of a fall from the façade's height
    if abs(rocking_velocity) * h > ROCKING_SPEED_LIMIT * fall:
        raise ValueError(f"rocking_velocity = {rocking_velocity:g} rad/s moves the façade's top at {abs(rocking_velocity) * h:.3g} "
                         f"m/s, more than {ROCKING_SPEED_LIMIT:g} times the speed of a fall from its height ({fall:.3g} m/s); "
                         "check the value (rad/s, not deg/s)")
    material = _material("material", material)
    return_material = _material("return_material", return_material)
    if brick is not None:
        by, bz = _brick(brick)
        if r > 0 or rocking_velocity != 0.0:
            raise ValueError("edge_radius and rocking_velocity apply to the single-block façade; give 0 with brick")
        if bond not in BONDS:
            raise ValueError(f"bond must be one of {list(BONDS)}, got {bond!r}")
    phi = math.radians(slope_deg)
    # inner top edge after the lean (rotation about y by -phi moves the top towards -x)
    rot = axis_angle_matrix(np.array([0.0, 1.0, 0.0]), -phi)
    inner_top = rot @ np.array([0.5 * b, 0.0, min(h, hr)])
    if inner_top[0] - (0.5 * b + g) > 1e-9 * b:  # touching (gap 0, no slope) is allowed
        raise ValueError(
            f"slope_deg = {slope_deg} leans the façade into the return walls (top moves "
            f"{inner_top[0] - 0.5 * b:.4g} m inward, gap {g} m); use a smaller inward slope or a larger gap"
        )
    fid = add_foundation(builder, _foundation_size(foundation_extent, b + g + lr, ln, h))
    groups = [("facade", "foundation"), ("facade", "facade"), ("foundation", "foundation"), ("return", "return"), ("return", "foundation")]
    _set_pairs(builder, groups, material)
    _set_pairs(builder, [("facade", "return"), ("brick", "return")], return_material if return_material is not None else material)
    top = lambda y: tuple(float(v) for v in rot @ np.array([-0.5 * b, y, h]))  # noqa: E731
    if brick is not None:
        nb, nc = max(1, round(ln / by)), max(1, round(h / bz))
        before = set(builder.block_names())
        walls = brick_wall(builder, brick=(b, ln / nb, h / nc), courses=nc, bricks_per_course=nb, bond=bond, joint=material,
                           base=material, density=density, points=points or (2, 3), foundation=False)
        if phi != 0.0:
            builder.transform_block(fid, rot)
            for nm in builder.block_names():
                if nm not in before:
                    builder.transform_block(nm, rot)
        _add_return_walls(builder, b=b, ln=ln, tr=tr, lr=lr, hr=hr, gap=g, density=density, points=points)
        return {k: (walls[k][0], top(walls[k][1][1])) for k in ("top", "top_left", "top_right")}
    poly = rounded_prism(b, ln, h, radius=r, facets=edge_facets, name="facade")
    # initial rocking about the bottom edge: v_c = omega x (c - pivot)
    omega = np.array([0.0, rocking_velocity, 0.0])
    side = 1.0 if rocking_velocity >= 0 else -1.0
    pivot = np.array([side * (0.5 * b - r), 0.0, 0.0])
    c = mass_properties(poly, density).centroid
    vel = np.cross(omega, c - pivot)
    builder.add_block(
        poly, density=density, group="facade", name="facade", points=points, velocity=rot @ vel, angular_velocity=rot @ omega
    )
    if phi != 0.0:
        builder.transform_block(fid, rot)
        builder.transform_block("facade", rot)
    _add_return_walls(builder, b=b, ln=ln, tr=tr, lr=lr, hr=hr, gap=g, density=density, points=points)
    return {"top": ("facade", top(0.0)), "top_left": ("facade", top(-0.5 * ln)), "top_right": ("facade", top(0.5 * ln))}


def _add_return_walls(builder: ModelBuilder, *, b: float, ln: float, tr: float, lr: float, hr: float, gap: float, density: float,
                      points: tuple[int, int] | None) -> None:
    """The two ground-driven return walls of :func:`facade`, ``gap`` behind the façade's inner face."""
    x0 = 0.5 * b + gap
    for nm, y0 in (("return_left", -0.5 * ln), ("return_right", 0.5 * ln - tr)):
        builder.add_block(
            box(lr, tr, hr, center=(x0 + 0.5 * lr, y0 + 0.5 * tr, 0.5 * hr), name=nm),
            density=density,
            group="return",
            name=nm,
            driven=GROUND,
            points=points,
        )


# -- vertically spanning two-block wall -------------------------------------------------------------
def push_motion(
    displacement: float, push_time: float, *, hold_time: float = 0.1, withdraw_speed: float = 1.0, withdraw_distance: float | None = None
) -> Motion:
    """Velocity history (x) of a pushing rod: push by ``displacement`` [m] over ``push_time`` [s]
    with a half-sine velocity (smooth start and stop), hold ``hold_time`` [s], then withdraw at
    ``withdraw_speed`` [m/s] by ``withdraw_distance`` [m] (default twice the displacement) and stop.
    """
    d0 = _positive("push displacement", displacement)
    tp = _positive("push_time", push_time, "s")
    th = _non_negative("hold_time", hold_time, "s")
    vw = _positive("withdraw_speed", withdraw_speed, "m/s")
    dw = 2.0 * d0 if withdraw_distance is None else _positive("withdraw_distance", withdraw_distance)
    n = 200
    t = list(np.linspace(0.0, tp, n + 1))
    v = [0.5 * math.pi * d0 / tp * math.sin(math.pi * ti / tp) for ti in t]
    t1 = tp + th
    tw = dw / vw
    eps = 1e-9 * max(tp, 1.0)
    if th > 0:
        t.append(t1)
        v.append(0.0)
    t += [t1 + eps, t1 + tw, t1 + tw + eps]
    v += [-vw, -vw, 0.0]
    vel = np.zeros((len(t), 3))
    vel[:, 0] = v
    return Motion(np.array(t), vel)


def two_block_wall(
    builder: ModelBuilder,
    *,
    thickness: float = 0.11,
    height: float = 1.5,
    length: float = 0.95,
    density: float = 1800.0,
    crack_height: float | None = None,
    material: JointMaterial | None = None,
    rod_material: JointMaterial | None = None,
    rod_size: float = 0.02,
    rod_height: float | None = None,
    rod_gap: float = 0.0,
    push_displacement: float = 0.0,
    push_time: float = 1.0,
    hold_time: float = 0.1,
    withdraw_speed: float = 1.0,
    points: tuple[int, int] | None = None,
    foundation_extent: float | None = None,
) -> Monitors:
    """A pre-cracked vertically spanning wall of two blocks (Griffith et al.; paper §4.4, Fig. 17).

    Blocks ``"bottom"`` (z in [0, crack_height]) and ``"top"`` (up to H), group ``"wall"``, span
    x in [-t/2, t/2], y in [-L/2, L/2]. The top is restrained horizontally by two square rods
    (``rod_left`` at -x, ``rod_right`` at +x, group ``"rod"``) touching the wall's faces, driven
    ``"ground"`` so they follow an earthquake, with a frictionless contact so the wall may slide
    up and down between them. With ``push_displacement`` d0 > 0 a third rod ``rod_push`` on the
    -x face at the crack pushes the wall's mid-height to d0 (+x) over ``push_time``, holds it
    ``hold_time`` and withdraws quickly by d0 + t (see :func:`push_motion`): the free rocking test.

    Args:
        builder: the model builder.
        foundation_extent: plan size of the foundation [m]; default :func:`collapse_extent` of the
            specimen, room for it to topple in any direction and land on the foundation.
        thickness: t along x [m]. height: H [m]. length: L along y [m].
        density: [kg/m^3].
        crack_height: height of the crack [m]; default H/2.
        material: wall-foundation and crack joint; None: ``builder.default_material``. The crack
            is pre-cracked: give a material without cohesion or tension, or it starts bonded.
            For kn = E / l, l = H / 2 (two blocks, paper §3).
        rod_material: rod-wall contact; default ``material`` with friction, cohesion and tension 0.
        rod_size: side of the rods' square section [m].
        rod_height: height of the restraining rods' centre [m]; default H - rod_size.
        rod_gap: clear gap between each restraining rod and the wall face [m] (>= 0).
        push_displacement: d0 [m], 0 (no pushing rod) <= d0 < t (beyond t the wall collapses).
        push_time, hold_time: [s]. withdraw_speed: [m/s].
        points: interface points per face; default the builder's.

    Returns:
        Monitors ``mid`` (bottom block, -x face at the crack), ``top`` (top block, -x face top),
        and ``rod_push`` (the pushing rod's +x face at the crack) when there is one.
    """
    t = _positive("thickness", thickness)
    h = _positive("height", height)
    ln = _positive("length", length)
    _positive("density", density, "kg/m^3")
    hc = 0.5 * h if crack_height is None else _positive("crack_height", crack_height)
    if not hc < h:
        raise ValueError(f"crack_height ({hc} m) must be below the height ({h} m)")
    s = _positive("rod_size", rod_size)
    zr = h - s if rod_height is None else _positive("rod_height", rod_height)
    if not (hc + 0.5 * s < zr - 0.5 * s and zr + 0.5 * s <= h + 1e-12):
        raise ValueError(
            f"rod_height ({zr} m) must place the rods ({s} m) on the top block, between the crack "
            f"({hc} m) and the top ({h} m)"
        )
    material = _material("material", material)
    rod_material = _material("rod_material", rod_material)
    d0 = _non_negative("push_displacement", push_displacement)
    if not d0 < t:
        raise ValueError(f"push_displacement ({d0} m) must be below the thickness ({t} m) or the wall overturns")
    if d0 > 0 and not (0.5 * s < hc and hc + 0.5 * s < zr - 0.5 * s):
        raise ValueError(f"rod_size ({s} m) is too large for a pushing rod at the crack ({hc} m)")
    add_foundation(builder, _foundation_size(foundation_extent, t, ln, h))
    _set_pairs(builder, [("wall", "wall"), ("wall", "foundation"), ("foundation", "foundation")], material)
    if rod_material is None:
        base = material if material is not None else builder.default_material
        if base is None:
            raise ValueError("two_block_wall: give material or rod_material (or set builder.default_material)")
        rod_material = dataclasses.replace(base, friction_angle=0.0, cohesion=0.0, tension=0.0, residual_friction_angle=0.0)
    for pair in (("rod", "wall"), ("rod", "rod"), ("rod", "foundation")):
        builder.set_material(*pair, rod_material)
    builder.add_box(t, ln, hc, density=density, group="wall", name="bottom", points=points)
    builder.add_box(t, ln, h - hc, base_center=(0.0, 0.0, hc), density=density, group="wall", name="top", points=points)
    gr = _non_negative("rod_gap", rod_gap)
    for nm, x in (("rod_left", -0.5 * (t + s) - gr), ("rod_right", 0.5 * (t + s) + gr)):
        # one point across: a line contact at the rod's centre height, i.e. a roller (a square
        # rod with corner points would clamp the wall against rotation with lever arm rod_size)
        builder.add_box(s, ln, s, base_center=(x, 0.0, zr - 0.5 * s), group="rod", name=nm, driven=GROUND, points=(1, 2))
    monitors: Monitors = {"mid": ("bottom", (-0.5 * t, 0.0, hc)), "top": ("top", (-0.5 * t, 0.0, h))}
    if d0 > 0:
        motion = push_motion(d0, push_time, hold_time=hold_time, withdraw_speed=withdraw_speed, withdraw_distance=d0 + t)
        builder.add_box(s, ln, s, base_center=(-0.5 * (t + s), 0.0, hc - 0.5 * s), group="rod", name="rod_push", driven=motion, points=(2, 2))
        monitors["rod_push"] = ("rod_push", (-0.5 * t, 0.0, hc))
    return monitors


# -- TOML forms -------------------------------------------------------------------------------------
def _sub_material(t: Table, key: str, *, spacing: float) -> JointMaterial | None:
    """Material from the optional sub-table ``key`` (None when absent)."""
    if key not in t.data:
        t.used.add(key)
        return None
    sub = t.sub(key)
    mat = joint_material(sub, spacing=spacing)
    sub.finish()
    return mat


def _brick_key(t: Table, default: tuple[float, ...] | None, labels: tuple[str, ...]) -> tuple[float, ...]:
    """``brick``, a list of positive lengths [m] named by ``labels`` (checked before the joint
    material, whose kn = E / l may take l from it)."""
    brick = tuple(float(v) for v in t.vector("brick", default, size=len(labels)))
    for i, (v, label) in enumerate(zip(brick, labels)):
        if not v > 0.0:
            raise ValueError(f"[{t.where}] brick[{i}] ({label}) must be a positive length [m], got {v:g}")
    return brick


@specimen("stack")
def _stack_case(t: Table, b: ModelBuilder) -> Monitors:
    """Stacked blocks. Keys: width, length, heights (list) [m], density, points_across,
    points_along, foundation_extent [m] (plan size of the foundation; default sized for collapse) and
    the joint keys (youngs_modulus: kn = E / mean block height)."""
    heights = [float(v) for v in t.numbers("heights", positive=True)]
    _block_count(f"[{t.where}] heights ({len(heights)} entries)", len(heights))
    width = t.number("width", positive=True)
    length = t.number("length", 1.0, positive=True)
    density = t.number("density", 1800.0, positive=True)
    pts = t.points()
    mat = joint_material(t, spacing=sum(heights) / len(heights))
    return stacked_blocks(b, width=width, length=length, heights=heights, density=density, material=mat, points=pts,
                          foundation_extent=t.optional_number("foundation_extent", positive=True))


@specimen("wall")
def _wall_case(t: Table, b: ModelBuilder) -> Monitors:
    """Brick wall. Keys: brick = [lx, ly, lz] [m], courses, bricks_per_course, bond, density,
    points_across, points_along, base_reduction [m], foundation_extent [m] (plan size of the
    foundation; default sized for collapse), [joint] (bed/head joints, kn = E / lz) and optional
    [base] (base joint; default the joint's)."""
    brick = _brick_key(t, (0.11, 0.23, 0.076), ("thickness, x", "length, y", "height, z"))
    kw = dict(
        brick=brick,
        courses=t.integer("courses", min_=1),
        bricks_per_course=t.integer("bricks_per_course", min_=1),
        bond=t.string("bond", "running", choices=BONDS),
        density=t.number("density", 1800.0, positive=True),
        points=t.points(2, 3),
        base_reduction=t.number("base_reduction", 0.0, min_=0.0),
    )
    if "joint" not in t.data:
        raise ValueError(f"[{t.where}] the [joint] sub-table (bed and head joint material) is required")
    joint = _sub_material(t, "joint", spacing=float(brick[2]))
    base = _sub_material(t, "base", spacing=float(brick[2]))
    return brick_wall(b, joint=joint, base=base, foundation_extent=t.optional_number("foundation_extent", positive=True),
                      **kw)  # type: ignore[arg-type]


@specimen("parapet")
def _parapet_case(t: Table, b: ModelBuilder) -> Monitors:
    """Parapet. Keys: thickness, height, length, base_reduction [m], density, brick = [ly, lz]
    (absent: single block "parapet"), bond, points_across, points_along, foundation_extent [m]
    (plan size of the foundation; default sized for collapse), the joint keys
    (kn = E / height, or E / brick height when discretised) and optional [base] (the base joint;
    default the joint keys' material)."""
    thickness = t.number("thickness", 0.23, positive=True)
    height = t.number("height", positive=True)
    length = t.number("length", 1.0, positive=True)
    brick = _brick_key(t, None, ("length, y", "height, z")) if "brick" in t.data else None
    t.used.add("brick")
    bond = t.string("bond", "running", choices=BONDS)
    pts = t.points(2, 3 if brick is not None else 2)
    spacing = height if brick is None else height / max(1, round(height / brick[1]))
    mat = joint_material(t, spacing=spacing)
    return parapet(
        b,
        thickness=thickness,
        height=height,
        length=length,
        base_reduction=t.number("base_reduction", 0.007, min_=0.0),
        brick=brick,  # type: ignore[arg-type]
        bond=bond,
        density=t.number("density", 1800.0, positive=True),
        material=mat,
        base_material=_sub_material(t, "base", spacing=spacing),
        points=pts,
        foundation_extent=t.optional_number("foundation_extent", positive=True),
    )


@specimen("facade")
def _facade_case(t: Table, b: ModelBuilder) -> Monitors:
    """One-sided façade. Keys: width, height, length, return_thickness, return_length,
    return_height, gap, edge_radius [m], edge_facets, slope_deg, rocking_velocity [rad/s],
    density, brick = [ly, lz] (absent: single block "facade"), bond, points_across, points_along,
    foundation_extent [m] (plan size of the foundation; default sized for collapse), the joint keys (kn = E / height, or E / course height when discretised) and optional [return]
    (façade-return wall contact)."""
    height = t.number("height", 0.8, positive=True)
    brick = _brick_key(t, None, ("length, y", "height, z")) if "brick" in t.data else None
    t.used.add("brick")
    spacing = height if brick is None else height / max(1, round(height / brick[1]))
    mat = joint_material(t, spacing=spacing)
    rh = t.optional_number("return_height", positive=True)
    return facade(
        b,
        width=t.number("width", 0.11, positive=True),
        height=height,
        length=t.number("length", 1.5, positive=True),
        density=t.number("density", 1750.0, positive=True),
        return_thickness=t.number("return_thickness", 0.11, positive=True),
        return_length=t.number("return_length", 0.5, positive=True),
        return_height=rh,
        gap=t.number("gap", 0.004, min_=0.0),
        edge_radius=t.number("edge_radius", 0.0, min_=0.0),
        edge_facets=t.integer("edge_facets", 4, min_=1, max_=MAX_EDGE_FACETS),
        slope_deg=t.number("slope_deg", 0.0),
        material=mat,
        return_material=_sub_material(t, "return", spacing=spacing),
        points=t.points(2, 3 if brick is not None else 2),
        rocking_velocity=t.number("rocking_velocity", 0.0),
        brick=brick,  # type: ignore[arg-type]
        bond=t.string("bond", "running", choices=BONDS),
        foundation_extent=t.optional_number("foundation_extent", positive=True),
    )


@specimen("two-block-wall")
def _two_block_case(t: Table, b: ModelBuilder) -> Monitors:
    """Two-block wall. Keys: thickness, height, length, crack_height, rod_size, rod_height, rod_gap,
    push_displacement [m], push_time, hold_time [s], withdraw_speed [m/s], density,
    points_across, points_along, foundation_extent [m] (plan size of the foundation; default sized
    for collapse), the joint keys (kn = E / (H/2)) and optional [rod]."""
    height = t.number("height", 1.5, positive=True)
    mat = joint_material(t, spacing=0.5 * height)
    rod_t = "rod" in t.data
    rod = _sub_material(t, "rod", spacing=0.5 * height) if rod_t else None
    t.used.add("rod")
    return two_block_wall(
        b,
        thickness=t.number("thickness", 0.11, positive=True),
        height=height,
        length=t.number("length", 0.95, positive=True),
        density=t.number("density", 1800.0, positive=True),
        crack_height=t.optional_number("crack_height", positive=True),
        material=mat,
        rod_material=rod,
        rod_size=t.number("rod_size", 0.02, positive=True),
        rod_height=t.optional_number("rod_height", positive=True),
        rod_gap=t.number("rod_gap", 0.0, min_=0.0),
        push_displacement=t.number("push_displacement", 0.0, min_=0.0),
        push_time=t.number("push_time", 1.0, positive=True),
        hold_time=t.number("hold_time", 0.1, min_=0.0),
        withdraw_speed=t.number("withdraw_speed", 1.0, positive=True),
        points=t.points(),
        foundation_extent=t.optional_number("foundation_extent", positive=True),
    )
