"""Earthquake loading and quasi-static pushover (paper §3.3 and §4).

Earthquakes can be applied in two equivalent frames:

* ``mode="foundation"`` (absolute frame, as 3DEC does): the record's ground velocity v_g(t)
  (trapezoid integral of the acceleration from rest, optionally baseline corrected) becomes the
  velocity history of every block added with ``driven="ground"`` (foundation, return walls, rods).
* ``mode="inertial"`` (relative frame): the foundation stays fixed and every free block carries the
  d'Alembert body force -m a_g(t).

For a rigid foundation both give the same *relative* motion (tested in ``tests/test_loading.py``):
contact forces and stiffness-proportional (SP) dashpots depend on relative displacements and
velocities only. Mass-proportional (MP) damping does not: with absolute velocities (the default,
as in 3DEC) it acts on v = v_rel + v_g in foundation mode but on v_rel in inertial mode, so the
same alpha damps differently. Prefer

* foundation mode to reproduce 3DEC runs with absolute MP damping, to shake several ground-attached
  blocks (return walls, restraining rods) and to apply vertical motion of the supports;
* inertial mode (or foundation mode with ``Damping(alpha_relative=True)``) for MP damping that
  does not resist the rigid-body motion of the ground, and for the smallest drift of the model in
  space (no baseline correction needed: the acceleration is applied as read).

Quasi-static pushover (paper §3.3, Fig. 9A): a lateral body acceleration lambda(t) g d on every free
block, lambda ramped linearly at ``rate`` [1/s] up to ``max_load_factor`` and held, with Cundall's
local damping (0.8) so that the response stays quasi-static. Load control traces the capacity
curve up to its peak only: past the peak the block topples. Displacement control
(:func:`apply_rod_pushover`) drives a frictionless rod against the specimen at a slow constant
velocity and measures the rod's force: it follows the softening branch past the peak as well
(load factor = rod force / weight of the free blocks).

Units: SI (m, s, m/s^2); records are converted once by :mod:`rockdem.records`.
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Mapping, NamedTuple

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from ._warn import warn_user
from .case import Table, loading
from .geometry import box, mass_properties
from .materials import real_number
from .analysis import fallen_blocks
from .model import GROUND, Damping, ModelBuilder, Motion
from .records import STANDARD_GRAVITY, GroundMotion, read_record, record_path
from .simulation import Monitor, simulate

__all__ = [
    "EARTHQUAKE_MODES",
    "EarthquakeInput",
    "PushoverRamp",
    "resolve_record",
    "prepare_record",
    "earthquake_record",
    "apply_earthquake",
    "apply_pushover",
    "RodPushover",
    "apply_rod_pushover",
    "pushover_end",
    "rigid_rod_load_factor",
    "pushover",
    "rocking_axis_of",
    "load_carried",
    "LoadCarried",
    "capacity_curve",
]

EARTHQUAKE_MODES = ("foundation", "inertial")
"""How a record is applied: driven ground blocks (absolute frame) or inertial body forces."""


@dataclass(frozen=True)
class EarthquakeInput:
    """What :func:`apply_earthquake` put on the builder.

    Attributes:
        mode: "foundation" or "inertial".
        time: (n,) simulation times of the samples [s] (the record starts at ``delay``).
        acceleration: (n, 3) ground acceleration [m/s^2] (after scaling and correction).
        velocity: (n, 3) ground velocity [m/s], zero at t = 0 (the model starts from rest).
        motion: the processed record.
    """

    mode: str
    time: NDArray[np.float64]
    acceleration: NDArray[np.float64]
    velocity: NDArray[np.float64]
    motion: GroundMotion

    @property
    def pga(self) -> float:
        """Peak horizontal ground acceleration of the applied input [m/s^2]."""
        return float(np.max(np.linalg.norm(self.acceleration[:, :2], axis=1)))

    @property
    def pga_time(self) -> float:
        """Simulation time [s] of the peak horizontal ground acceleration (the delay included)."""
        return float(self.time[int(np.argmax(np.linalg.norm(self.acceleration[:, :2], axis=1)))])


def resolve_record(name: str | Path) -> Path:
    """Find a record file: a path, a file name in ``$ROCKDEM_DATA`` or a shipped record's short or
    file name, in that order (:func:`rockdem.records.record_path`)."""
    return record_path(name)


AT_REST = 1e-3
"""A record whose velocity ends within this share of its peak velocity of rest is used without
baseline correction (:func:`prepare_record`): a clean synthetic input, or a record already
processed (the shipped PEER NGA ones end within 2e-4 of it)."""


def _at_rest(gm: GroundMotion) -> bool:
    """Whether record ``gm`` (and its vertical component) ends at rest (:data:`AT_REST`)."""
    from .records import _integral  # noqa: PLC0415 - the records' own trapezoid integral

    for acc in [gm.acceleration] + ([] if gm.vertical is None else [gm.vertical]):
        v = _integral(acc, gm.dt)
        if abs(v[-1]) > AT_REST * float(np.max(np.abs(v))):
            return False
    return True


def prepare_record(
    motion: GroundMotion,
    *,
    scale: float = 1.0,
    pga: float | None = None,
    direction: ArrayLike | None = None,
    vertical: bool = False,
    baseline: bool = True,
    tail: float = 0.0,
    window: tuple[float, float] | None = None,
) -> GroundMotion:
    """Process a record for application: window, scale (or scale to ``pga`` [m/s^2]), direction,
    baseline correction (linear velocity trend removed, the ground brought to rest at the end:
    :meth:`rockdem.records.GroundMotion.baseline_corrected`; only for a record that does not end at
    rest, :data:`AT_REST`: a clean pulse was distorted by it, 0.0039 g added throughout and its
    ground displacement tripled) and a free-vibration tail [s].

    The windowed record restarts from rest at the window start. At least one zero-acceleration
    sample is appended so that the held end value of the input tables is "no acceleration".
    """
    gm = motion
    if window is not None:
        t0, t1 = float(window[0]), float(window[1])
        if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
            raise ValueError(f"{gm.name}: window must be (start, end) with end > start [s], got ({t0:g}, {t1:g})")
        keep = (gm.time >= t0 - 1e-9 * gm.dt) & (gm.time <= t1 + 1e-9 * gm.dt)
        if keep.sum() < 2:
            raise ValueError(f"{gm.name}: window ({t0:g}, {t1:g}) holds fewer than two samples "
                             f"(record spans {gm.time[0]:g}..{gm.time[-1]:g} s)")
        if t0 < gm.time[0] - 0.5 * gm.dt or t1 > gm.time[-1] + 0.5 * gm.dt:
            warn_user(f"{gm.name}: window ({t0:g}, {t1:g}) s reaches beyond the record ({gm.time[0]:g}..{gm.time[-1]:g} s): "
                      f"only {float(gm.time[keep][0]):g}..{float(gm.time[keep][-1]):g} s is used")
        vert = None if gm.vertical is None else gm.vertical[keep]
        gm = replace(gm, acceleration=gm.acceleration[keep], vertical=vert, start_time=float(gm.time[keep][0]))
    if not vertical and gm.vertical is not None:
        gm = replace(gm, vertical=None)
    if vertical and gm.vertical is None:
        raise ValueError(f"{gm.name}: vertical=True but the record has no vertical component")
    if direction is not None:
        gm = gm.with_direction(direction)
    if not (math.isfinite(scale) and scale >= 0.0):
        raise ValueError(f"{gm.name}: scale must be a finite factor >= 0, got {scale!r}")
    gm = gm.scaled_to_pga(pga) if pga is not None else gm.scaled(scale)
    if baseline and not _at_rest(gm):
        gm = gm.baseline_corrected(1)
    if not (math.isfinite(tail) and tail >= 0.0):
        raise ValueError(f"{gm.name}: tail must be >= 0 s, got {tail!r}")
    return gm.with_tail(max(tail, gm.dt))


MAX_SUBSTEPS = 1024
"""Most velocity samples per record interval :func:`apply_earthquake` takes."""
TABLE_ROW_BYTES = 96
"""Memory [bytes] that one row of the foundation's velocity table takes at its peak
(:func:`_velocity_table`'s temporaries and the model's copy; measured 1.1 GB of peak resident
memory for a run whose table had 13.6 million rows)."""
MAX_TABLE_BYTES = 2e9
"""Largest input table :func:`apply_earthquake` builds [bytes]."""


def apply_earthquake(
    builder: ModelBuilder,
    motion: GroundMotion,
    *,
    mode: str = "foundation",
    scale: float = 1.0,
    pga: float | None = None,
    direction: ArrayLike | None = None,
    vertical: bool = False,
    baseline: bool = True,
    tail: float = 0.0,
    window: tuple[float, float] | None = None,
    delay: float = 0.0,
    substeps: int = 16,
) -> EarthquakeInput:
    """Apply an earthquake record to a model being built.

    Args:
        builder: the model builder (ground-attached blocks added with ``driven="ground"``).
        motion: the record, in SI (from :func:`rockdem.records.read_record`).
        mode: "foundation": ground velocity history on the ``driven="ground"`` blocks
            (absolute frame); "inertial": body acceleration -a_g(t) on the free blocks, foundation
            fixed (relative frame). See the module docstring for MP damping, which differs.
        scale: factor on the accelerations [-] (ignored when ``pga`` is given).
        pga: scale the record to this horizontal PGA [m/s^2] instead.
        direction: horizontal direction (3,) of the record; default the record's own (+x).
        vertical: apply the record's vertical component too (it must have one).
        baseline: remove the linear trend of the ground velocity and bring the foundation to rest
            at the end (:meth:`rockdem.records.GroundMotion.baseline_corrected`).
        tail: free-vibration time after the record [s].
        window: (start, end) part of the record to use [s of the record]; restarts from rest.
        delay: time at rest before the record starts [s] (lets the model settle under gravity).
        substeps: foundation mode: velocity samples per record interval. The engine interpolates
            the driven velocity linearly, whereas the exact integral of a linearly interpolated
            acceleration is quadratic; sub-sampling it makes the two modes agree to O(1/substeps^2).

    Returns:
        The applied input (times, accelerations, velocities).
    """
    if mode not in EARTHQUAKE_MODES:
        raise ValueError(f"earthquake mode must be one of {list(EARTHQUAKE_MODES)}, got {mode!r}")
    if not (math.isfinite(delay) and delay >= 0.0):
        raise ValueError(f"earthquake delay must be >= 0 s, got {delay!r}")
    if not (math.isfinite(tail) and tail >= 0.0):
        raise ValueError(f"earthquake tail must be >= 0 s, got {tail!r}")
    if (isinstance(substeps, bool) or not isinstance(substeps, (int, float, np.integer, np.floating))
            or not (math.isfinite(substeps) and float(substeps).is_integer() and 1 <= substeps <= MAX_SUBSTEPS)):
        raise ValueError(f"substeps must be an integer from 1 to {MAX_SUBSTEPS}, got {substeps!r} (the foundation's "
                         "velocity differs from the exact integral by O(1/substeps^2): the default 16 suffices)")
    gm = prepare_record(motion, scale=scale, pga=pga, direction=direction, vertical=vertical,
                        baseline=baseline, tail=tail, window=window)
    per = int(substeps) if mode == "foundation" else 1
    if gm.npts * per * TABLE_ROW_BYTES > MAX_TABLE_BYTES:
        raise ValueError(
            f"{gm.name}: the input table would have {gm.npts * per:.3g} rows ({gm.npts} samples of {gm.dt:g} s, the tail "
            f"of {tail:g} s included" + (f", {per} substeps each" if per > 1 else "") + f"), about "
            f"{gm.npts * per * TABLE_ROW_BYTES / 1e9:.1f} GB to build (at most {MAX_TABLE_BYTES / 1e9:g} GB); shorten "
            "the tail (the input's end value is held after it: no tail beyond the run's end is needed) or the window")
    acc = gm.vector_acceleration()
    vel = gm.vector_velocity()  # from rest: v(t_0) = 0
    t = delay + gm.dt * np.arange(gm.npts)
    if delay > 0.0:
        # At rest until the record starts: zero acceleration up to a thousandth of a sample before
        # it (a ramp from 0 at t = 0 up to the first sample would move the ground before the
        # record, by a0 delay^2 / 6, and its velocity would jump back to zero at the delay).
        jump = 1e-3 * gm.dt
        lead = np.array([0.0, delay - jump]) if delay > 2.0 * jump else np.array([0.0])
        t = np.r_[lead, t]
        acc = np.vstack([np.zeros((lead.size, 3)), acc])
        vel = np.vstack([np.zeros((lead.size, 3)), vel])
    if mode == "foundation":
        if builder.ground_motion is not None:
            raise ValueError("the builder already has a ground motion; apply one earthquake per model")
        if not _has_ground_blocks(builder):
            raise ValueError("foundation mode moves the blocks added with driven='ground', and this model "
                             "has none; add the foundation with driven='ground' or use mode='inertial'")
        builder.set_ground_motion(Motion(*_velocity_table(t, acc, vel, substeps)))
    else:
        if builder.body_acceleration is not None:
            raise ValueError("the builder already has a body acceleration (another loading); "
                             "inertial mode needs it for -a_g(t)")
        builder.set_body_acceleration(t, -acc)
    builder.load_along(gm.direction)
    return EarthquakeInput(mode, t, acc, vel, gm)


def _velocity_table(
    t: NDArray[np.float64], acc: NDArray[np.float64], vel: NDArray[np.float64], substeps: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Velocity sampled ``substeps`` times per interval, exact for piecewise-linear acceleration."""
    if int(substeps) != substeps or substeps < 1:
        raise ValueError(f"substeps must be an integer >= 1, got {substeps!r}")
    m = int(substeps)
    if m == 1:
        return t, vel
    h = np.diff(t)[:, None]  # (n-1, 1)
    s = (np.arange(m) / m)[None, :]  # fraction of the interval
    tt = (t[:-1, None] + s * h).reshape(-1)
    # v(t_k + s h) = v_k + h (a_k s + (a_{k+1} - a_k) s^2 / 2)
    da = acc[1:] - acc[:-1]
    vv = vel[:-1, None, :] + h[:, :, None] * (acc[:-1, None, :] * s[:, :, None] + 0.5 * da[:, None, :] * s[:, :, None] ** 2)
    return np.r_[tt, t[-1]], np.vstack([vv.reshape(-1, 3), vel[-1:]])


def _has_ground_blocks(builder: ModelBuilder) -> bool:
    return bool(builder.block_names(driven=GROUND))


# -- pushover --------------------------------------------------------------------------------


@dataclass(frozen=True)
class PushoverRamp:
    """A linear load-factor ramp lambda(t) = min(rate t, max_load_factor).

    Attributes:
        rate: d lambda / dt [1/s].
        max_load_factor: the held final value [-].
        direction: (3,) horizontal unit vector of the load.
        gravity: |g| [m/s^2]; the body acceleration is lambda(t) g direction.
    """

    rate: float
    max_load_factor: float
    direction: NDArray[np.float64]
    gravity: float

    @property
    def ramp_time(self) -> float:
        """Time to reach ``max_load_factor`` [s]."""
        return self.max_load_factor / self.rate

    def load_factor(self, time: ArrayLike) -> NDArray[np.float64]:
        """lambda at ``time`` (array) [s]."""
        return np.minimum(self.rate * np.asarray(time, dtype=float), self.max_load_factor)

    def attrs(self) -> dict[str, Any]:
        """The ramp as result attributes (read back by :func:`capacity_curve`)."""
        return {
            "pushover_rate": self.rate,
            "pushover_max_load_factor": self.max_load_factor,
            "pushover_direction": self.direction.tolist(),
            "pushover_gravity": self.gravity,
        }


def apply_pushover(
    builder: ModelBuilder, *, rate: float, max_load_factor: float, direction: ArrayLike = (1.0, 0.0, 0.0)
) -> PushoverRamp:
    """Put the pushover body acceleration lambda(t) |g| d on every free block of ``builder``.

    Args:
        rate: load-factor rate [1/s]; slow enough for a quasi-static response (ramp time much
            longer than the elastic rocking period, e.g. > 50 periods).
        max_load_factor: final lambda [-] (held after the ramp); for a rigid block the capacity is B/H.
        direction: horizontal load direction (3,), normalised here.
    """
    if not real_number(rate, "pushover rate [1/s]") > 0.0:
        raise ValueError(f"pushover rate must be a positive load-factor rate [1/s], got {rate!r}")
    if not real_number(max_load_factor, "pushover max_load_factor") > 0.0:
        raise ValueError(f"pushover max_load_factor must be positive, got {max_load_factor!r}")
    d = _horizontal_unit(direction, builder.gravity, "pushover direction")
    if builder.body_acceleration is not None:
        raise ValueError("the builder already has a body acceleration (another loading)")
    g = float(np.linalg.norm(builder.gravity))
    if g == 0.0:  # a load factor is a fraction of the weight
        raise ValueError("a load-controlled pushover applies lambda g: the model has no gravity; give it gravity")
    ramp = PushoverRamp(float(rate), float(max_load_factor), d, g)
    t_end = ramp.ramp_time
    builder.set_body_acceleration([0.0, t_end], [np.zeros(3), max_load_factor * g * d])
    builder.load_along(d)
    return ramp


@dataclass(frozen=True)
class RodPushover:
    """A displacement-controlled pushover: a driven rod moving at ``velocity`` along ``direction``.

    Attributes:
        rod: name of the driven rod block.
        velocity: rod speed [m/s]. displacement: total imposed displacement [m].
        height: height of the rod's line of contact [m].
        direction: (3,) horizontal unit vector. weight: weight of the free blocks [N].
    """

    rod: str
    velocity: float
    displacement: float
    height: float
    direction: NDArray[np.float64]
    weight: float

    @property
    def push_time(self) -> float:
        """Time to impose the full displacement [s]."""
        return self.displacement / self.velocity

    def attrs(self) -> dict[str, Any]:
        """The rod pushover as result attributes (read back by :func:`capacity_curve`)."""
        return {
            "pushover_rod": self.rod,
            "pushover_rod_velocity": self.velocity,
            "pushover_displacement": self.displacement,
            "pushover_rod_height": self.height,
            "pushover_direction": self.direction.tolist(),
            "pushover_weight": self.weight,
        }


ROD_RAMP_SHARE = 0.2
"""The rod's half-cosine speed ramps at the start and the end of its push each last this share of
the push time displacement / velocity (:func:`apply_rod_pushover`)."""
QUASI_STATIC_WARN = 0.05
"""A rod pushover faster than this times sqrt(g H) (H the specimen's height) is warned about as not
quasi-static (:func:`apply_rod_pushover`)."""

QUASI_STATIC_LIMIT = 0.5
"""A rod pushover faster than this times sqrt(g H) is refused: the rod strikes the specimen (at 10
m/s a 1 m block's rod sank 1 cm into it in 17 steps, and the run stopped blaming the joint
stiffness)."""


def apply_rod_pushover(
    builder: ModelBuilder,
    *,
    displacement: float,
    velocity: float,
    height: float | None = None,
    direction: ArrayLike = (1.0, 0.0, 0.0),
    rod_size: float = 0.02,
    material: Any = None,
    name: str = "rod_pushover",
) -> RodPushover:
    """Add a driven rod that pushes the free blocks of ``builder`` along ``direction``.

    The rod (square section ``rod_size``, as long as the specimen across the push) touches the
    specimen's face on the ``-direction`` side with its line of contact at ``height``, moves at
    ``velocity`` until it has imposed ``displacement``, then stops. Its contact is frictionless
    (a roller) so that the face can slide up as the specimen rocks. With ``height`` at the free
    blocks' centre of mass (the default) the rod force over the weight equals the load factor of
    a uniform lateral body load: the rigid-block capacity is B/H for a block (paper Fig. 9A).

    Args:
        displacement: imposed rod displacement [m]. velocity: rod speed [m/s]; slow for a
            quasi-static response (use Cundall local damping 0.8).
        height: height of the contact line above z = 0 [m]; default the centre of mass height.
        direction: horizontal push direction (3,). rod_size: [m].
        material: rod-specimen joint; default ``builder.default_material`` without friction or bond,
            with a critically damping dashpot beta = 2 / omega, omega = sqrt(kn rod_size span / m).
        name: rod block name.
    """
    if not real_number(displacement, "pushover displacement [m]") > 0:
        raise ValueError(f"pushover displacement must be a positive distance [m], got {displacement!r}")
    if not real_number(velocity, "pushover velocity [m/s]") > 0:
        raise ValueError(f"pushover velocity must be a positive speed [m/s] (slow: quasi-static), got {velocity!r}")
    if not real_number(rod_size, "pushover rod_size [m]") > 0:
        raise ValueError(f"pushover rod_size must be a positive length [m], got {rod_size!r}")
    d = _horizontal_unit(direction, builder.gravity, "pushover direction")
    gn = float(np.linalg.norm(builder.gravity))
    up = -builder.gravity / gn if gn > 0 else np.array([0.0, 0.0, 1.0])
    across = np.cross(up, d)
    free = builder.block_names(driven=False)
    if not free:
        raise ValueError("pushover: the model has no free block to push")
    verts = np.vstack([builder.block(n).vertices for n in free])
    props = [mass_properties(builder.block(n), builder.density(n)) for n in free]
    mass = sum(p.mass for p in props)
    centre = sum(p.mass * p.centroid for p in props) / mass
    zmin, zmax = float((verts @ up).min()), float((verts @ up).max())
    h = float(centre @ up) if height is None else float(height)
    if not (math.isfinite(h) and zmin + 0.5 * rod_size <= h <= zmax - 0.5 * rod_size):
        raise ValueError(
            f"pushover rod height {h!r} m must lie on the specimen, between {zmin + 0.5 * rod_size:.4g} "
            f"and {zmax - 0.5 * rod_size:.4g} m (rod_size {rod_size} m)"
        )
    impact = math.sqrt((gn or STANDARD_GRAVITY) * (zmax - zmin))  # the speed of a fall from the specimen's height
    if velocity > QUASI_STATIC_LIMIT * impact:
        raise ValueError(f"pushover velocity = {velocity:g} m/s: the rod would strike the specimen (above "
                         f"{QUASI_STATIC_LIMIT:g} sqrt(g H) = {QUASI_STATIC_LIMIT * impact:.3g} m/s for its height H = "
                         f"{zmax - zmin:.3g} m), not push it; a pushover is slow (default displacement / 10 s)")
    if velocity > QUASI_STATIC_WARN * impact:
        warn_user(f"pushover velocity = {velocity:g} m/s is above {QUASI_STATIC_WARN:g} sqrt(g H) = "
                  f"{QUASI_STATIC_WARN * impact:.3g} m/s for the specimen's height H = {zmax - zmin:.3g} m: the rod force "
                  "then holds the specimen's inertia too, not only its capacity; push slower for a quasi-static curve")
    front = float((verts @ d).min())
    lo, hi = float((verts @ across).min()), float((verts @ across).max())
    span = hi - lo
    rot = np.column_stack([d, across, up])
    centre_rod = (front - 0.5 * rod_size) * d + 0.5 * (lo + hi) * across + h * up
    poly = box(rod_size, span, rod_size, name=name).transformed(rot, centre_rod)
    if material is None:
        base = builder.default_material
        if base is None:
            raise ValueError("pushover rod: give material or set builder.default_material")
        # critically damped rod contact (beta = 2 / omega of the specimen on the rod spring): the
        # dashpot removes the chatter of the stiff rod contact; it does not bias the force, the
        # rod and the face moving together in a quasi-static push
        omega = math.sqrt(base.kn * rod_size * span / mass)
        material = replace(base, friction_angle=0.0, cohesion=0.0, tension=0.0, residual_friction_angle=0.0, beta=2.0 / omega)
    # The rod's joint with every group: the free blocks' (the push), and the driven ones' too, which
    # it never touches but the model needs a material for every pair (given a material and no
    # default, finalize() refused the rod-foundation pair before 2026-11-30).
    for g in {builder.group(n) for n in builder.block_names()} | {"pushover_rod"}:
        builder.set_material("pushover_rod", g, material)
    # smooth start and stop (half-cosine speed ramps over 20 % of the push time each, no impact
    # on the face); the ramps lose and gain the same distance, so displacement = velocity * push_time
    push_time = float(displacement) / float(velocity)
    tt = np.linspace(0.0, ROD_RAMP_SHARE * push_time, 41)
    up_ = 0.5 * (1.0 - np.cos(np.pi * tt / tt[-1]))
    times = np.r_[tt, push_time + tt]
    speed = np.r_[up_, 1.0 - up_]
    motion = Motion(times, np.outer(speed * velocity, d))
    # one point across the rod: a line contact at the rod's centre height (a roller)
    builder.add_block(poly, group="pushover_rod", name=name, driven=motion, points=(1, 3))
    builder.load_along(d)
    if gn == 0.0:
        warn_user("pushover rod in a model without gravity: its load factor is the rod force over the specimen's "
                  f"mass times the standard {STANDARD_GRAVITY} m/s^2 (it has no weight)")
    return RodPushover(name, float(velocity), float(displacement), h, d, mass * (gn or STANDARD_GRAVITY))


class PushoverEnd(NamedTuple):
    """When a pushover's load is complete: ``time`` [s] and ``what`` it then reaches (words)."""

    time: float
    what: str


def pushover_end(attrs: Mapping[str, Any]) -> PushoverEnd | None:
    """The end of the pushover described by a result's (or a case's) ``attrs``: for load control
    the ramp's end, max_load_factor / rate; for a rod its full displacement, reached at 1.2
    displacement / velocity (:func:`apply_rod_pushover`'s speed ramps over 0.2 of the push time at
    each end); None for other loadings."""
    if "pushover_rate" in attrs:
        return PushoverEnd(float(attrs["pushover_max_load_factor"]) / float(attrs["pushover_rate"]), "its max_load_factor")
    if "pushover_rod_velocity" in attrs:
        push_time = float(attrs["pushover_displacement"]) / float(attrs["pushover_rod_velocity"])
        return PushoverEnd((1.0 + ROD_RAMP_SHARE) * push_time, "its full displacement")
    return None


def rigid_rod_load_factor(b: float, h: float, z_rod: float, theta: ArrayLike) -> NDArray[np.float64]:
    """Horizontal rod force / weight that holds a rigid b x h block at rotation ``theta`` [rad]
    about its toe (moment balance of the weight and of a frictionless rod force normal to the
    tilted pushed face, line of contact at height ``z_rod`` [m]). At theta = 0 it is b / (2 z_rod);
    it reaches 0 at theta = atan(b / h). The reference curve of :func:`apply_rod_pushover`."""
    th = np.asarray(theta, dtype=float)
    c, s = np.cos(th), np.sin(th)
    r_g = -0.5 * b * c + 0.5 * h * s  # lever arm (x) of the weight about the toe
    up_face = (z_rod - b * s) / c  # distance of the contact point up the pushed face
    r_x = -b * c + up_face * s
    fn = -r_g / (z_rod * c + r_x * s)  # normal force per weight: the torques about the toe cancel
    return fn * c


def pushover(
    builder: ModelBuilder,
    *,
    rate: float,
    max_load_factor: float,
    direction: ArrayLike = (1.0, 0.0, 0.0),
    local_damping: float = 0.8,
    damping: Damping | None = None,
    monitors: Mapping[str, Monitor] | None = None,
    duration: float | None = None,
    record_interval: float | None = None,
    **simulate_kwargs: Any,
) -> xr.Dataset:
    """Run a load-controlled quasi-static pushover (paper §3.3, Fig. 9A).

    Applies :func:`apply_pushover`, finalizes with Cundall local damping ``local_damping`` (added to
    ``damping`` if given), runs until the ramp ends (or ``duration`` [s]) and stores the ramp in the
    result's attributes for :func:`capacity_curve`.

    Returns:
        The result Dataset (attrs ``pushover_*``).
    """
    ramp = apply_pushover(builder, rate=rate, max_load_factor=max_load_factor, direction=direction)
    base = Damping() if damping is None else damping
    # rotation about up x d, positive along the load, as the case files' pushover (a push along +y
    # measured its rocking about y, ~0, before 2026-11-29)
    model = builder.finalize(damping=replace(base, local=local_damping),
                             rocking_axis=rocking_axis_of(direction, builder.gravity))
    duration = ramp.ramp_time if duration is None else duration
    if record_interval is None:
        record_interval = duration / 500.0
    ds = simulate(model, duration, monitors=monitors, record_interval=record_interval, **simulate_kwargs)
    ds.attrs.update(ramp.attrs())
    return ds


def capacity_curve(
    ds: xr.Dataset,
    monitor: str = "top",
    direction: ArrayLike | None = None,
    *,
    source: str = "auto",
    rate: float | None = None,
    max_load_factor: float | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Capacity curve of a pushover result: load factor lambda vs monitor displacement.

    Args:
        ds: a result of :func:`pushover`, of a run with :func:`apply_rod_pushover`, or of a case
            with ``[loading] type = "pushover"``.
        monitor: monitor point name (default "top").
        direction: displacement component (3,); default the load direction (else +x).
        source: "ramp": lambda(t) of the applied ramp (from the attrs or ``rate`` and
            ``max_load_factor``); "rod": lambda = F.d / W from the pushing rod's force F
            (displacement control); "reaction": lambda = -R.d / W from the base reaction R (quasi-
            static equilibrium; includes inertia after the peak); W is the weight of the free
            blocks. "auto": the rod when there is one, else the ramp when known, else the reaction.

    Returns:
        (load_factor (T,) [-], displacement (T,) [m]).
    """
    if source not in ("auto", "ramp", "rod", "reaction"):
        raise ValueError(f"source must be 'auto', 'ramp', 'rod' or 'reaction', got {source!r}")
    a = ds.attrs
    rate = a.get("pushover_rate") if rate is None else rate
    lam_max = a.get("pushover_max_load_factor") if max_load_factor is None else max_load_factor
    if direction is None:
        direction = a.get("pushover_direction", (1.0, 0.0, 0.0))
    d = np.asarray(direction, dtype=float).reshape(3)
    if not (np.all(np.isfinite(d)) and np.linalg.norm(d) > 0.0):
        raise ValueError(f"capacity_curve: direction must be a non-zero finite 3-vector, got {_vector_text(direction)}")
    d = d / np.linalg.norm(d)
    names = [str(n) for n in ds.monitor.values]
    if monitor not in names:
        raise KeyError(f"no monitor {monitor!r} in the result; monitors are {names}")
    disp = ds.monitor_displacement.values[:, names.index(monitor), :] @ d
    g = float(a.get("pushover_gravity", np.linalg.norm(a.get("gravity", (0.0, 0.0, -STANDARD_GRAVITY)))))
    weight = float(a.get("pushover_weight", ds.block_mass.values[ds.block_free.values.astype(bool)].sum() * g))
    rod = a.get("pushover_rod")
    if source == "rod" or (source == "auto" and rod is not None):
        if rod is None or "driven_reaction" not in ds:
            raise ValueError("the result has no pushover rod (apply_rod_pushover / [loading] mode = 'displacement')")
        k = [str(n) for n in ds.driven_block.values].index(str(rod))
        lam = (ds.driven_reaction.values[:, k, :] @ d) / weight
    elif source == "ramp" or (source == "auto" and rate is not None):
        if rate is None or lam_max is None:
            raise ValueError("the ramp is unknown: pass rate and max_load_factor, or use source='reaction'")
        lam = np.minimum(float(rate) * ds.time.values, float(lam_max))
    else:
        lam = -(ds.base_reaction.values @ d) / weight
    return lam, disp


EQUILIBRIUM_TOLERANCE = 0.05
"""A load-controlled pushover is out of static equilibrium where the base reaction, averaged over
:data:`EQUILIBRIUM_WINDOW` of the run, falls short of the applied load by more than this share of
the largest applied load (the rest accelerates the specimen)."""

EQUILIBRIUM_WINDOW = 0.1
"""Share of the run (at least 3 frames) over which the base reaction is averaged for that test:
impacts of the base's points make it ring by +-10 %, the shortfall that moves the specimen lasts."""


class LoadCarried(NamedTuple):
    """What a load-controlled pushover's specimen carried (:func:`load_carried`). Load factors
    lambda are forces over the weight of the free blocks [-]; times in s.

    Attributes:
        peak: largest lambda of the base reaction (-R.d / W), with its ringing.
        peak_time: its time.
        applied: the applied lambda at the last frame.
        carried: the base reaction's lambda averaged over the last ``window`` seconds.
        applied_mean: the applied lambda averaged over the same frames.
        window: that averaging time (:data:`EQUILIBRIUM_WINDOW` of the run).
        lag: the first time the reaction, averaged over ``window`` around it, falls short of the
            applied load by more than :data:`EQUILIBRIUM_TOLERANCE` of the largest applied load
            (the rest accelerates the specimen), or None.
        exceeded: when the load exceeded what the specimen carries (the shortfall lasts to the
            end while the monitor moves on to its largest displacement, or a block overturned,
            rotated past its eta, or fell): the time from which the reaction stays short of the
            load by more than :data:`EQUILIBRIUM_TOLERANCE` of the load itself, up to the end or
            to the largest shortfall; else None.
        too_fast: ``lag`` otherwise (the shortfall is gone by the end, or the specimen swings
            back, and nothing overturned): the ramp was too fast for a quasi-static response;
            else None.
    """

    peak: float
    peak_time: float
    applied: float
    carried: float
    applied_mean: float
    window: float
    lag: float | None
    exceeded: float | None
    too_fast: float | None


def load_carried(ds: xr.Dataset) -> LoadCarried | None:
    """The base reaction of a load-controlled pushover against its applied ramp (None for another
    result). A ramp past the specimen's capacity reads as carried on the ramp's own curve while
    the specimen accelerates out of equilibrium (or has overturned); a ramp too fast for the
    specimen's inertia leaves the reaction behind too, until the ramp stops."""
    a = ds.attrs
    if a.get("pushover_rate") is None or a.get("pushover_rod") is not None or "base_reaction" not in ds or ds.sizes.get("time", 0) < 2:
        return None
    if not ds.sizes.get("monitor", 0):
        return None
    monitor = str(ds.monitor.values[0])
    applied, disp = capacity_curve(ds, monitor, source="ramp")
    reaction, _ = capacity_curve(ds, monitor, source="reaction")
    t = ds.time.values
    w = max(3, int(round(EQUILIBRIUM_WINDOW * t.size)))
    sums = np.cumsum(np.r_[0.0, applied - reaction])
    k = np.arange(t.size)
    lo, hi = np.maximum(k - w // 2, 0), np.minimum(k + w // 2 + 1, t.size)
    shortfall = (sums[hi] - sums[lo]) / (hi - lo)  # (T,) mean over the window around each frame
    short = shortfall > EQUILIBRIUM_TOLERANCE * float(np.max(applied))  # a share of the largest load, not of a ramp near 0
    lag = float(t[np.argmax(short)]) if short.any() else None
    free = np.flatnonzero(np.asarray(ds.block_free.values, dtype=bool))
    eta = ds.block_eta.values[free] if "block_eta" in ds else np.full(free.size, np.nan)
    with np.errstate(invalid="ignore"):
        overturned = bool(np.any(np.abs(ds.rocking_angle.values[:, free]) > eta)) if "rocking_angle" in ds else False
    collapsed = overturned or (all(v in ds for v in ("block_position", "vertex_local", "block_vertex_start")) and fallen_blocks(ds).size > 0)
    tail = slice(t.size - w, t.size)
    # Running away: short of the load at the end and moving to a new largest displacement (a
    # ringing specimen after a fast ramp is short at times too, but swings back).
    running = bool(short[-1]) and t.size > w and disp[-1] > float(np.max(disp[: t.size - w]))
    exceeded = None
    if lag is not None and (running or collapsed):
        # Since when: the last time before the shortfall that ends the run (or the collapse) that
        # the reaction still carried the load within the tolerance of the load itself.
        end = t.size - 1 if running else int(np.argmax(shortfall))
        held = np.flatnonzero(shortfall[:end + 1] <= EQUILIBRIUM_TOLERANCE * applied[:end + 1])
        exceeded = float(t[held[-1] + 1]) if held.size and held[-1] + 1 < t.size else lag
    too_fast = lag if lag is not None and exceeded is None else None
    j = int(np.argmax(reaction))
    return LoadCarried(float(reaction[j]), float(t[j]), float(applied[-1]), float(np.mean(reaction[tail])),
                       float(np.mean(applied[tail])), float(t[-1] - t[-w]), lag, exceeded, too_fast)


def rocking_axis_of(direction: ArrayLike, gravity: ArrayLike, what: str = "direction") -> tuple[float, float, float]:
    """The axis a load along ``direction`` rocks blocks about: up x d, d the horizontal unit
    direction (so that the rocking direction, rocking_axis x up, is d and a positive
    ``rocking_angle`` tips blocks along the load); (0, 1, 0) for +x under gravity along -z."""
    g = np.asarray(gravity, dtype=float).reshape(3)
    d = _horizontal_unit(direction, g, what)
    up = -g / np.linalg.norm(g) if np.linalg.norm(g) > 0 else np.array([0.0, 0.0, 1.0])
    axis = np.cross(up, d)
    return (float(axis[0]) + 0.0, float(axis[1]) + 0.0, float(axis[2]) + 0.0)  # + 0.0: no -0.0


def _vector_text(v: object) -> str:
    """A vector as a user wrote it ([0.0, 0.0, 1.0]), not as NumPy shows it (array([0., 0., 1.]))."""
    try:
        return str(np.asarray(v, dtype=float).tolist())
    except (TypeError, ValueError):
        return repr(v)


def _horizontal_unit(direction: ArrayLike, gravity: NDArray[np.float64], what: str) -> NDArray[np.float64]:
    d = np.asarray(direction, dtype=float).reshape(3)
    gn = float(np.linalg.norm(gravity))
    if gn > 0:
        up = -gravity / gn
        d = d - up * (up @ d)
    n = float(np.linalg.norm(d))
    if not (math.isfinite(n) and n > 0):
        raise ValueError(f"{what} must be a finite vector with a horizontal component, got {_vector_text(direction)}")
    return d / n


# -- TOML loading types ------------------------------------------------------------------------


RECORD_DT_RANGE = (1e-4, 0.1)
"""[s] the sampling steps of recorded ground motions, widely (0.001 to 0.05 s in the archives); a record
outside is warned about (a dt of 1e-9 s ended in an error about the foundation's path, before 2026-12-08)."""


def _read_table_record(t: Table, key: str, units: str | None, dt: float | None, columns: tuple[int | None, int | None]) -> GroundMotion:
    """The record file of key ``key`` of a loading table, read with the table's units, dt and columns;
    a file that cannot be read is refused with the table's keys that tell how to read it."""
    name = t.string(key)
    try:
        return _read_cached(str(record_path(name)), units, dt, columns)
    except ValueError as exc:
        raise ValueError(f"[{t.where}] {key} = {name!r}: {exc} (in the case file: [{t.where}] units = \"g\", \"m/s2\" or "
                         "\"cm/s2\"; dt = the time step [s]; time_column, acc_column = zero-based columns)") from None


def _read_cached(path: str, units: str | None, dt: float | None, columns: tuple[int | None, int | None] = (None, None)) -> GroundMotion:
    """:func:`read_record`, remembered per process by file, size and modification time (a record
    read for every run of a study is parsed once; an edited file is read again). GroundMotion is
    immutable, so the runs share it safely. ``columns``: (time_column, acc_column) or Nones."""
    st = os.stat(path)
    return _read_record_at(path, st.st_size, st.st_mtime_ns, units, dt, columns)


@functools.lru_cache(maxsize=64)
def _read_record_at(path: str, size: int, mtime_ns: int, units: str | None, dt: float | None,
                    columns: tuple[int | None, int | None]) -> GroundMotion:
    return read_record(path, units=units, dt=dt, time_column=columns[0], acc_column=columns[1])


def _earthquake_settings(t: Table) -> dict[str, Any]:
    """The keys of an ``earthquake`` loading table, read and checked: the record (``motion``) and
    the :func:`apply_earthquake` options."""
    units = t.raw("units")
    if units is not None and not isinstance(units, str):
        raise ValueError(f"[{t.where}] units must be a string such as \"g\", got {units!r}")
    dt = t.optional_number("dt", positive=True)
    columns = tuple(t.integer(key) if key in t.data else None for key in ("time_column", "acc_column"))
    gm = _read_table_record(t, "record", units, dt, columns)
    if not RECORD_DT_RANGE[0] <= gm.dt <= RECORD_DT_RANGE[1]:
        warn_user(f"[{t.where}] record {t.string('record')!r}: dt = {gm.dt:g} s lies far outside the {RECORD_DT_RANGE[0]:g} to "
                  f"{RECORD_DT_RANGE[1]:g} s of recorded ground motions (its {gm.acceleration.size} samples span "
                  f"{(gm.acceleration.size - 1) * gm.dt:.3g} s); check its dt ([{t.where}] dt, or the file's header or time column)")
    vert = t.raw("vertical", False)
    vcol = t.integer("vertical_column") if "vertical_column" in t.data else None
    if vcol is not None and not isinstance(vert, str):
        raise ValueError(f"[{t.where}] vertical_column is the column of the vertical record: give vertical = \"FILE\" too")
    if isinstance(vert, str):
        same = record_path(vert).resolve() == record_path(t.string("record")).resolve()
        if same and vcol is None:
            raise ValueError(f"[{t.where}] vertical is the record's own file: give vertical_column, the zero-based column of "
                             "the vertical acceleration (the horizontal's is acc_column)")
        if same and vcol == (1 if columns[1] is None else columns[1]):
            raise ValueError(f"[{t.where}] vertical_column = {vcol} is the horizontal record's column (acc_column); give "
                             "the column of the vertical acceleration")
        # The vertical file's columns: vertical_column, and time_column with it (a layout like the
        # record's); without vertical_column, read as its format says (a two-column file: 0 and 1).
        try:
            gv = read_record(vert, units=units, dt=dt, time_column=columns[0] if vcol is not None else None, acc_column=vcol)
        except ValueError as exc:
            raise ValueError(f"[{t.where}] vertical record {vert!r}: {exc} (its acceleration column is vertical_column, "
                             "its time column time_column)") from exc
        n = min(gv.npts, gm.npts)
        if abs(gv.dt - gm.dt) > 1e-9 * gm.dt:
            raise ValueError(f"[{t.where}] vertical record dt {gv.dt} s differs from the record's {gm.dt} s")
        gm = replace(gm, acceleration=gm.acceleration[:n], vertical=gv.acceleration[:n])
    elif vert is not False:
        raise ValueError(f"[{t.where}] vertical must be false or a record file of the vertical component, got {vert!r}")
    if not np.any(gm.acceleration) and (gm.vertical is None or not np.any(gm.vertical)):
        raise ValueError(f"[{t.where}] record {t.raw('record')!r}: its acceleration is zero at every sample, so nothing would "
                         "move; check the file (and acc_column for a file of several columns)")
    scale = t.number("scale", 1.0, min_=0.0)
    if scale == 0.0:
        raise ValueError(f"[{t.where}] scale = 0 applies no ground motion, so nothing would move; give a positive factor "
                         "or pga_g")
    pga_g = t.optional_number("pga_g", positive=True)
    if pga_g is not None and "scale" in t.data:
        raise ValueError(f"[{t.where}] give scale or pga_g, not both (on the command line --set {t.where}.scale= "
                         "removes the case's scale)")
    window = t.raw("window")
    if window is not None:
        window = tuple(t.vector("window", size=2))
    return {
        "motion": gm,
        "mode": t.string("mode", "foundation", choices=EARTHQUAKE_MODES),
        "scale": scale,
        "pga": None if pga_g is None else pga_g * STANDARD_GRAVITY,
        "direction": t.vector("direction", (1.0, 0.0, 0.0)),
        "vertical": isinstance(vert, str),
        "baseline": t.boolean("baseline", True),
        "tail": t.number("tail", 0.0, min_=0.0),
        "window": window,
        "delay": t.number("delay", 0.0, min_=0.0),
    }


def earthquake_record(table: Mapping[str, Any], *, scale: float | None = None) -> GroundMotion:
    """The record an ``earthquake`` loading table applies, processed as :func:`apply_earthquake`
    processes it (window, scale or PGA, direction, baseline correction, tail); ``scale`` replaces
    the table's scale and pga_g (``scale=1``: the record at its own amplitude)."""
    t = Table(table, "loading")
    t.string("type", "earthquake")
    opts = _earthquake_settings(t)
    if scale is not None:
        opts["scale"], opts["pga"] = float(scale), None
    return prepare_record(opts["motion"], scale=opts["scale"], pga=opts["pga"], direction=opts["direction"],
                          vertical=opts["vertical"], baseline=opts["baseline"], tail=opts["tail"], window=opts["window"])


@loading("earthquake")
def _earthquake(t: Table, b: ModelBuilder, monitors: dict[str, Monitor], ctx: dict[str, Any]) -> None:
    """An earthquake record on the foundation (or as inertial forces), starting from rest.

    Keys: record (a shipped record's short name, e.g. "elcentro-rsn6" (``rockdem records`` lists
    them), or a file: a path relative to the working folder, or a file name in ``$ROCKDEM_DATA``),
    units ("g", "m/s2", "cm/s2"; optional for AT2 and shipped records), dt [s] (single-column files), scale (default 1) or pga_g
    (scale to this PGA [g]), direction (default [1, 0, 0]), vertical (false, or a record file of
    the vertical acceleration in the same units and dt), mode ("foundation" or "inertial"),
    baseline (true), tail [s] (0), window ([start, end] of the record [s]), delay [s] (0, before
    the run's end: :func:`rockdem.run_cli.run_options`), time_column and acc_column (zero-based
    columns of a time/acceleration file with more than two columns; defaults 0 and 1),
    vertical_column (the vertical record's acceleration column, needed for a file of more than
    two columns: the record's own file, or another).
    """
    settings = _earthquake_settings(t)
    info = apply_earthquake(b, **settings)
    ctx["rocking_axis"] = rocking_axis_of(settings["direction"], b.gravity, f"[{t.where}] direction")
    ctx["attrs"].update(
        earthquake_delay_s=settings["delay"],  # checked against the run's end (run_cli.run_options)
        earthquake_record=info.motion.name,
        earthquake_mode=info.mode,
        earthquake_pga_m_s2=info.pga,
        earthquake_pga_time_s=info.pga_time,  # a run ending before it is warned about (run_cli.run_case)
        earthquake_duration_s=float(info.time[-1]),
    )
    ctx["series"]["ground_acceleration"] = (info.time, info.acceleration)


@loading("pushover")
def _pushover(t: Table, b: ModelBuilder, monitors: dict[str, Monitor], ctx: dict[str, Any]) -> None:
    """Quasi-static pushover, load or displacement controlled (set ``[damping] local = 0.8``).

    Keys: mode ("load", default, or "displacement"), direction (default [1, 0, 0]).
    Load control: lateral body acceleration lambda(t) g d, lambda = min(rate t, max_load_factor);
    keys rate [1/s] (default 0.1), max_load_factor (required).
    Displacement control: a frictionless rod pushes the specimen (see :func:`apply_rod_pushover`);
    keys displacement [m] (required), velocity [m/s] (default displacement / 10 s), rod_height [m]
    (default the centre of mass height), rod_size [m] (0.02). Monitor ``rod`` follows the rod.
    """
    mode = t.string("mode", "load", choices=("load", "displacement"))
    direction = t.vector("direction", (1.0, 0.0, 0.0))
    ctx["rocking_axis"] = rocking_axis_of(direction, b.gravity, f"[{t.where}] direction")
    if mode == "load":
        ramp = apply_pushover(
            b,
            rate=t.number("rate", 0.1, positive=True),
            max_load_factor=t.number("max_load_factor", positive=True),
            direction=direction,
        )
        ctx["attrs"].update(ramp.attrs())
        return
    disp = t.number("displacement", positive=True)
    rod = apply_rod_pushover(
        b,
        displacement=disp,
        velocity=t.number("velocity", disp / 10.0, positive=True),
        height=t.optional_number("rod_height", positive=True),
        direction=direction,
        rod_size=t.number("rod_size", 0.02, positive=True),
    )
    monitors["rod"] = (rod.rod, tuple(b.block(rod.rod).vertices.mean(axis=0)))
    ctx["attrs"].update(rod.attrs())
