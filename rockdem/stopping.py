"""Stop a run once its outcome is decided: it has collapsed, or it is at rest after the input ended.

Studies (IDA, sweeps, calibration) need the outcome of a run, not its whole history: a slender block
that has toppled spends most of a 20 s record lying on its side, where contacts along the long face
cut the timestep twenty-fold. :func:`rockdem.simulation.simulate` (``stop=``) evaluates a
:class:`StopRule` in Python between the compiled chunks of steps (every :data:`CHECK_STEPS` steps)
on the frames recorded so far, and ends the run at the first recorded frame where the outcome is
decided. The result keeps the frames up to there and says why and when (``attrs["stop_reason"]``,
``stop_time``, ``stop_block``).

Criteria (``docs/studies.md`` lists them per specimen):

* **overturned** (a model with one free block whose supports are the ground or fixed: specimens
  ``block``, ``parapet``): rigid rocking about the base edge on the side it leans to. With
  phi = |theta| - eta the rotation past the instability angle (eta and the semi-diagonal R of that
  pivot, :func:`rockdem.results.block_eta`), gravity's moment m g R sin(phi) about the pivot beats
  the largest the remaining input can oppose, m a R cos(phi), once phi > phi_c = atan(a / g'),
  with a the largest horizontal ground acceleration from now to the end of the input (its held
  end value included) and g' = g minus the largest remaining vertical one. Past phi_c the net
  moment overturns, so a block moving away from upright only falls further; one moving back must
  climb to phi_c against that moment, which needs the energy
  m R [g' (cos phi_c - cos phi) - a (sin phi - sin phi_c)]; when its rocking kinetic energy
  0.5 I_O omega^2 (I_O about the pivot) is below that, the collapse is decided. A block resting
  on a side face (phi = pi/2 - eta) meets this for any a < g' cot(eta) (10 g for a 0.2 x 2 m block).
* **fell** (several free blocks: walls, stacks, façades, released assemblies): a free block's
  centroid has dropped below its starting height, relative to the ground, by more than half the
  block's smallest dimension (a brick thrown off a wall, a toppled slender block: partial
  collapse counts). In every model, also with one free block: a free block left the supports
  (fell off their edge or was thrown clear of them, ``State.fell_off``), at the frame the engine
  noted it.
* **rest** (every model): the input has ended (the ground acceleration is zero, the driven
  velocities constant, from ``t_in`` on) and, over the last :data:`REST_WINDOW` seconds of
  recorded frames after ``t_in``, every free block moved (relative to the ground) by less than
  :data:`REST_DISPLACEMENT` of its smallest dimension and turned by less than
  :data:`REST_ROTATION`, with speeds below :data:`REST_SPEED` sqrt(g d). The residual drift is
  then known to that tolerance. Blocks that left the supports (they fall for ever) are left out,
  as long as one block remains.

Runs without a stop rule (``rockdem run``, the default) are unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .analysis import FALL_FRACTION
from .kernels.rotation import quats_to_matrices, rotation_vector
from .model import Model
from .results import block_thickness, ground_blocks, rocking_pivots

__all__ = [
    "STOP_MODES",
    "StopRule",
    "Decision",
    "Stopper",
    "stop_rule",
    "input_end_time",
    "CHECK_STEPS",
    "REST_WINDOW",
    "REST_DISPLACEMENT",
    "REST_ROTATION",
    "REST_SPEED",
    "FALL_FRACTION",
]

STOP_MODES = ("off", "decided", "collapse", "rest")
"""``off``: run to the end; ``decided``: stop on collapse or at rest after the input; ``collapse``
or ``rest`` alone."""

CHECK_STEPS = 1000
"""Steps per compiled chunk while a stop rule is active. A chunk boundary costs about 20 us of
processor time (the call into the kernel, the engine's own checks and the stop checks); a step of
the 0.2 x 2 m block costs 0.6-0.7 us, so the checks cost ~3 % and a decided run computes at most
0.7 ms too much. Measured on 100 IDA runs of that block (``benchmarks/bench_ida.py --chunks``,
processor time per run): 250 steps 40.1 ms, 1000 steps 34.1 ms, 4000 steps 38.6 ms, 16000 steps
108 ms (the steps after the decision, on a block lying on its side, dominate), with the same
decisions at every interval (they are made per recorded frame)."""

REST_WINDOW = 0.5
"""Time over which a block must stay still to be at rest [s] (at least 5 recorded frames)."""

REST_DISPLACEMENT = 1e-4
"""Largest centroid motion over the rest window, as a fraction of the block's smallest dimension."""

REST_ROTATION = 1e-4
"""Largest rotation over the rest window [rad]."""

REST_SPEED = 1e-3
"""Largest speed at rest (centroid, and angular speed times the block's radius), as a fraction of
sqrt(g d), d the block's smallest dimension (1.4 mm/s for d = 0.2 m)."""

INPUT_ZERO = 1e-9
"""Input samples below this fraction of the table's largest value (accelerations: at least 1 m/s^2)
count as zero (a record's last sample is zero up to rounding)."""


@dataclass(frozen=True)
class StopRule:
    """What ends a run early.

    Attributes:
        collapse: stop once collapse is decided (overturned, or a block fell).
        rest: stop once every free block is at rest after the input ended.
        check_steps: steps per compiled chunk between two checks.
    """

    collapse: bool = True
    rest: bool = True
    check_steps: int = CHECK_STEPS

    @property
    def mode(self) -> str:
        """The :data:`STOP_MODES` name of this rule."""
        return {(True, True): "decided", (True, False): "collapse", (False, True): "rest"}.get((self.collapse, self.rest), "off")


def stop_rule(mode: str | StopRule | None) -> StopRule | None:
    """The rule of a mode name (:data:`STOP_MODES`), None for ``off``."""
    if mode is None or isinstance(mode, StopRule):
        return None if isinstance(mode, StopRule) and mode.mode == "off" else mode
    if mode not in STOP_MODES:
        raise ValueError(f"stop must be one of {list(STOP_MODES)}, got {mode!r}")
    if mode == "off":
        return None
    return StopRule(collapse=mode in ("decided", "collapse"), rest=mode in ("decided", "rest"))


@dataclass(frozen=True)
class Decision:
    """Why and when a run stopped: ``reason`` ("overturned", "fell" or "rest"), ``time`` [s] of
    the recorded frame where it was decided (its index ``frame``), ``block`` (the block's name)."""

    reason: str
    time: float
    block: str
    frame: int


def _up(model: Model) -> np.ndarray:
    g = model.arrays.gravity
    n = float(np.linalg.norm(g))
    return -g / n if n > 0 else np.array([0.0, 0.0, 1.0])


def _input_accelerations(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sample times [s] and the horizontal and vertical magnitudes [m/s^2] of the input
    acceleration: the inertial body acceleration and the ground motion's (its velocity table is
    linear between samples, so its acceleration is constant over each interval)."""
    m = model.arrays
    up = _up(model)
    times, horiz, vert = [np.zeros(1)], [np.zeros(1)], [np.zeros(1)]
    if m.body_time.size:
        a = m.body_acceleration
        av = a @ up
        times.append(m.body_time)
        horiz.append(np.linalg.norm(a - av[:, None] * up, axis=1))
        vert.append(np.abs(av))
    if m.ground_motion >= 0:
        lo, hi = int(m.motion_start[m.ground_motion]), int(m.motion_start[m.ground_motion + 1])
        t, v = m.motion_time[lo:hi], m.motion_velocity[lo:hi]
        if len(t) >= 2:
            a = np.diff(v, axis=0) / np.diff(t)[:, None]
            av = a @ up
            times.append(t[:-1])  # a[k] acts over [t_k, t_k+1]; after the last sample v is held
            horiz.append(np.linalg.norm(a - av[:, None] * up, axis=1))
            vert.append(np.abs(av))
    t = np.concatenate(times)
    order = np.argsort(t, kind="stable")
    return t[order], np.concatenate(horiz)[order], np.concatenate(vert)[order]


def input_end_time(model: Model) -> float:
    """Time from which the input is over [s]: the body acceleration is zero and every driven
    velocity constant (a ground moving on at a constant velocity counts as over: rest is measured
    relative to it; another driven block that keeps moving does not: inf)."""
    m = model.arrays
    end = 0.0
    if m.body_time.size:
        a = np.abs(m.body_acceleration)
        nz = np.flatnonzero(np.any(a > INPUT_ZERO * max(float(a.max()), 1.0), axis=1))
        if nz.size:
            k = int(nz[-1])
            if k == len(m.body_time) - 1:
                return math.inf  # held non-zero (a pushover load)
            end = max(end, float(m.body_time[k + 1]))
    for j in range(len(m.motion_start) - 1):
        lo, hi = int(m.motion_start[j]), int(m.motion_start[j + 1])
        t, v = m.motion_time[lo:hi], m.motion_velocity[lo:hi]
        scale = max(float(np.abs(v).max()) if v.size else 0.0, 1e-300)
        if j != m.ground_motion and np.any(np.abs(v[-1]) > INPUT_ZERO * scale):
            return math.inf  # a driven block (a pushing rod) that keeps moving
        changes = np.flatnonzero(np.any(np.abs(np.diff(v, axis=0)) > INPUT_ZERO * scale, axis=1))
        if changes.size:
            end = max(end, float(t[int(changes[-1]) + 1]))
    return end


class Stopper:
    """Evaluates a :class:`StopRule` on the frames recorded so far (see the module notes).

    Args:
        model: the model being run.
        rule: the rule.
        record_interval: time between recorded frames [s].
    """

    def __init__(self, model: Model, rule: StopRule, record_interval: float) -> None:
        m = model.arrays
        self.model, self.rule = model, rule
        self.free = np.flatnonzero(m.block_free)
        ground = ground_blocks(model)
        self.ground = int(ground[0]) if ground.size else -1
        self.g = float(np.linalg.norm(m.gravity))
        self.up = _up(model)
        self.thickness = block_thickness(model)
        self.radius = np.asarray(m.block_radius, dtype=float)
        self.window = max(REST_WINDOW, 5.0 * record_interval)
        # frames in a rest window, fixed (not counted back from the last frame recorded, whose time
        # lies within half a step of its nominal time): a frame's verdict must not depend on where
        # the chunks end, so that continued runs decide as uninterrupted ones do
        self.window_frames = int(math.floor(self.window / record_interval + 1e-9)) + 1
        self.t_input = input_end_time(model)
        t, h, v = _input_accelerations(model)
        self.acc_time = t
        self.acc_h_after = np.maximum.accumulate(h[::-1])[::-1]  # largest from sample k on
        self.acc_v_after = np.maximum.accumulate(v[::-1])[::-1]
        own_motions = np.any((m.block_motion >= 0) & (m.block_motion != m.ground_motion) & ~m.block_free.astype(bool))
        self.pivot = self._pivot() if len(self.free) == 1 and self.g > 0 and not own_motions else None
        self.checked = 0  # frames examined so far

    def _pivot(self) -> dict[str, Any] | None:
        """Rigid-rocking data of the single free block: eta, R and I_O of each base edge."""
        b = int(self.free[0])
        pivots = rocking_pivots(self.model, b)
        if pivots is None:
            return None
        return {"block": b, "mass": pivots[0].mass, "eta": np.array([p.eta for p in pivots]),
                "radius": np.array([p.radius for p in pivots]), "inertia": np.array([p.inertia for p in pivots]),
                "quat_ref": quats_to_matrices(self.model.quaternion_ref[b]), "axis": self.model.rocking_axis,
                "q_ref": np.asarray(self.model.quaternion_ref[b], dtype=float), "eta_min": min(p.eta for p in pivots)}

    def check(self, rec: Any, frame: int, fell_off: np.ndarray | None = None) -> Decision | None:
        """The first decided frame among those recorded since the last check (frames
        ``checked..frame-1`` of ``rec``, a Records, from frame 1 on), or None. The decision does not depend on how
        the run was cut into chunks: each frame is judged on its own (collapse) or on the window
        of frames before it (rest).

        ``fell_off`` (nb,): the time [s] each block left the supports (``State.fell_off``, -1: it
        did not; the engine notes it at a recorded frame's time). Such a block has fallen (the
        collapse rule decides "fell" at that frame, for a single block too) and is left out of the
        rest check from then on: it falls for ever, and the others may come to rest."""
        lo, self.checked = max(self.checked, 1), frame  # a result keeps at least two frames
        if frame <= lo:
            return None
        off = np.full(len(self.thickness), -1.0) if fell_off is None else np.asarray(fell_off, dtype=float)
        found: list[Decision] = []
        if self.rule.collapse:
            for d in (self._overturned(rec, lo, frame) if self.pivot is not None else self._fell(rec, lo, frame),
                      self._left(rec, lo, frame, off)):
                if d is not None:
                    found.append(d)
        if self.rule.rest and float(rec.time[frame - 1]) - self.window >= self.t_input:
            d = self._rest(rec, lo, frame, off)
            if d is not None:
                found.append(d)
        return min(found, key=lambda d: d.frame) if found else None

    def _left(self, rec: Any, lo: int, hi: int, off: np.ndarray) -> Decision | None:
        """The first frame in lo..hi-1 at which a free block left the supports (``off``: see :meth:`check`)."""
        best: Decision | None = None
        for b in self.free:
            if off[b] < 0.0:
                continue
            k = lo + int(np.searchsorted(rec.time[lo:hi], off[b] - 1e-9 * max(1.0, off[b])))
            if k < hi and (best is None or k < best.frame):
                best = Decision("fell", float(rec.time[k]), self.model.block_names[int(b)], k)
        return best

    def _overturned(self, rec: Any, lo: int, hi: int) -> Decision | None:
        p = self.pivot
        b = p["block"]
        # the rotation since the reference, 2 acos |q . q_ref|, bounds |theta|: most chunks end here
        cos_half = np.abs(rec.quaternion[lo:hi, b] @ p["q_ref"])
        if 2.0 * math.acos(min(1.0, float(cos_half.min()))) <= p["eta_min"]:
            return None
        t = rec.time[lo:hi]
        rel = quats_to_matrices(rec.quaternion[lo:hi, b]) @ p["quat_ref"].T
        theta = rotation_vector(rel) @ p["axis"]
        side = np.where(theta >= 0.0, 0, 1)  # the edge toward +d for theta > 0, else toward -d
        eta, r, i_o = p["eta"][side], p["radius"][side], p["inertia"][side]
        phi = np.abs(theta) - eta
        k = np.clip(np.searchsorted(self.acc_time, t, side="right") - 1, 0, None)
        a_h, a_v = self.acc_h_after[k], self.acc_v_after[k]
        g = self.g - a_v
        with np.errstate(invalid="ignore", divide="ignore"):
            phi_c = np.arctan2(a_h, g)
            omega = rec.omega[lo:hi, b] @ p["axis"]
            # moving back toward upright: it must climb back to phi_c against the net moment
            barrier = p["mass"] * r * (g * (np.cos(phi_c) - np.cos(phi)) - a_h * (np.sin(phi) - np.sin(phi_c)))
            back = (theta * omega < 0.0) & (0.5 * i_o * omega * omega >= barrier)
        decided = (phi > 0.0) & (g > 0.0) & (phi > phi_c) & ~back
        hit = np.flatnonzero(decided)
        if not hit.size:
            return None
        k0 = lo + int(hit[0])
        return Decision("overturned", float(rec.time[k0]), self.model.block_names[b], k0)

    def _fell(self, rec: Any, lo: int, hi: int) -> Decision | None:
        up = self.up
        dz_ground = np.zeros(hi - lo)
        if self.ground >= 0:
            dz_ground = (rec.position[lo:hi, self.ground] - self.model.position0[self.ground]) @ up
        # from the reference pose: a tilted release starts raised (analysis.fallen_blocks)
        drop = (self.model.position_ref[self.free] - rec.position[lo:hi][:, self.free]) @ up + dz_ground[:, None]
        fallen = drop > FALL_FRACTION * self.thickness[self.free]
        frames = np.flatnonzero(fallen.any(axis=1))
        if not frames.size:
            return None
        k0 = lo + int(frames[0])
        return Decision("fell", float(rec.time[k0]), self.model.block_names[int(self.free[np.argmax(fallen[frames[0]])])], k0)

    def _rest(self, rec: Any, lo: int, hi: int, off: np.ndarray) -> Decision | None:
        """First frame k in lo..hi-1 whose window (the frames of the last ``window`` seconds up
        to k, all after the input's end) is at rest: every free block still, except those that
        left the supports by frame k (``off``: see :meth:`check`), and at least one is left."""
        length = self.window_frames
        if hi < length:
            return None
        first = max(lo, length - 1)
        start = first - length + 1
        t = rec.time[start:hi]
        f = self.free
        pos = rec.position[start:hi][:, f]
        vel = rec.velocity[start:hi][:, f]
        if self.ground >= 0:
            pos = pos - rec.position[start:hi][:, self.ground][:, None]
            vel = vel - rec.velocity[start:hi][:, self.ground][:, None]
        d = self.thickness[f]
        v_tol = REST_SPEED * np.sqrt(self.g * d) if self.g > 0 else REST_SPEED * d
        fast = (np.linalg.norm(vel, axis=2) > v_tol) | (np.linalg.norm(rec.omega[start:hi][:, f], axis=2) * self.radius[f] > v_tol)

        def window(x: np.ndarray) -> np.ndarray:  # (frames-length+1, blocks, ..., length)
            return np.lib.stride_tricks.sliding_window_view(x, length, axis=0)

        def spread(x: np.ndarray) -> np.ndarray:  # (frames-length+1, blocks) largest ptp over the window
            w = window(x)
            return (w.max(axis=-1) - w.min(axis=-1)).max(axis=-1)

        tk = t[length - 1 :]
        gone = (off[f] >= 0.0)[None, :] & (off[f][None, :] <= tk[:, None] + 1e-9 * max(1.0, float(tk[-1])))
        still_b = (spread(pos) <= REST_DISPLACEMENT * d) & (spread(rec.quaternion[start:hi][:, f]) <= 0.5 * REST_ROTATION)
        still_b &= ~window(fast).any(axis=-1)
        still = (still_b | gone).all(axis=1) & ~gone.all(axis=1)
        still &= tk - self.window >= self.t_input - 1e-12
        hit = np.flatnonzero(still)
        if not hit.size:
            return None
        k0 = first + int(hit[0])
        return Decision("rest", float(rec.time[k0]), "", k0)
