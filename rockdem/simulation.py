"""``simulate()``: the one entry point that owns the time loop, the recording and the progress.

The loop runs in compiled chunks (:func:`rockdem.kernels.step.advance`); Python only sees chunk
boundaries, where it updates the progress bar and enlarges the contact buffers when a detection
asks for it. A run that goes wrong stops at the first bad recorded frame: when its energy balance
breaks or its state is no longer finite (diverged), or when a free block leaves the model's extent
(it fell through its support or flew away); the result keeps the frames before it and says where
(``attrs["diverged"]``, ``diverged_time``, ``diverged_step``, ``diverged_blocks``,
``diverged_reason``). An interrupted run (Ctrl-C) returns the frames computed so far, flagged
``interrupted``. With ``stop=`` (:mod:`rockdem.stopping`) the loop checks between chunks of a fixed
number of steps whether the outcome is decided (collapsed, or at rest after the input) and ends
there (``attrs["stop_reason"]``, ``stop_time``). :func:`run_model` is the loop without the Dataset
(studies summarise its raw frames).
"""

from __future__ import annotations

import math
import time as _time
import warnings
from typing import Any, Mapping, NamedTuple, Sequence

import numpy as np
import xarray as xr

from .kernels.layout import STATUS_DIVERGED, STATUS_DONE, STATUS_GROW, STATUS_LOST, Records, new_records
from .kernels.step import DIVERGENCE_ERROR, advance
from .model import Model
from .results import block_thickness, build_dataset
from .snapshots import ContactSnapshots
from .state import grow_buffers, initial_state
from .stopping import Decision, Stopper, StopRule, stop_rule
from .timestep import DEFAULT_RESOLUTION, DEFAULT_SAFETY, TimestepInfo, stable_timestep

__all__ = ["simulate", "run_model", "prepare_start", "Start", "RunOutput", "Monitor", "DEFAULT_MAX_STEPS", "first_diverged_frame"]

Monitor = tuple[int | str, Sequence[float]]
"""A monitor point: (block id or name, world coordinates in the reference configuration [m])."""

_MAX_RECORD_BYTES = 2 * 1024**3

DEFAULT_MAX_STEPS = 1_000_000_000
"""Largest number of steps a run may need before it is refused (raise it with ``max_steps``)."""


def simulate(
    model: Model,
    duration: float,
    *,
    dt: float | None = None,
    timestep_rule: str = "bound",
    safety: float = DEFAULT_SAFETY,
    resolution: float = DEFAULT_RESOLUTION,
    record_interval: float = 0.002,
    monitors: Mapping[str, Monitor] | None = None,
    progress: bool | None = None,
    contact_interval: float | None = None,
    max_steps: int = DEFAULT_MAX_STEPS,
    stop: str | StopRule | None = "off",
) -> xr.Dataset:
    """Run ``model`` for ``duration`` seconds and return the recorded histories.

    Args:
        model: a finalized model (:meth:`rockdem.model.ModelBuilder.finalize`).
        duration: simulated time [s].
        dt: timestep [s]; default automatic (see :mod:`rockdem.timestep`); refused above the bound.
        timestep_rule: "bound" (default) or "3dec" (0.2 sqrt(m_min/k_max)).
        safety: fraction of the stable bound for the automatic timestep.
        resolution: largest omega_max dt / 2, so that impacts last several steps and keep their
            energy error below 1 % (see :mod:`rockdem.timestep`); 1 turns this limit off.
        record_interval: time between recorded frames [s] (rounded to whole steps).
        monitors: named points whose world displacement is recorded, e.g.
            ``{"top": ("wall", (0.1, 0.0, 2.0))}``: block and world position [m] in the reference
            configuration (before any initial tilt); displacements are measured from there.
        progress: show a progress bar; default: only for runs expected to last over 2 s.
        contact_interval: time between sub-contact snapshots [s] (see :mod:`rockdem.snapshots`);
            default None: none recorded.
        max_steps: a run estimated to need more steps (duration / initial dt) is refused before it
            starts, with the estimate: an absurd stiffness, mass or damping would otherwise hang.
        stop: end the run once its outcome is decided (:mod:`rockdem.stopping`): "off" (default),
            "decided" (collapsed, or at rest after the input), "collapse" or "rest"; the result
            then ends at that frame and says why and when (attrs ``stop_reason``, ``stop_time``,
            ``stop_block``).

    Returns:
        An xarray Dataset (see :func:`rockdem.results.build_dataset` for the variables).

    Raises:
        TypeError: ``model`` is not a finalized Model.
        ValueError: bad options, a timestep longer than the run, or more steps than ``max_steps``.
    """
    out = run_model(model, duration, dt=dt, timestep_rule=timestep_rule, safety=safety, resolution=resolution,
                    record_interval=record_interval, monitors=monitors, progress=progress,
                    contact_interval=contact_interval, max_steps=max_steps, stop=stop)
    ds = build_dataset(model, out.records, monitors=out.monitors, attrs=out.attrs)
    return out.snapshots.attach(ds)


class Start(NamedTuple):
    """What a run starts from: the timestep (:func:`rockdem.timestep.stable_timestep`) and the
    initial state and scratch arrays (:func:`rockdem.state.initial_state`). They depend on the
    model's geometry, materials, damping and initial pose, not on its prescribed inputs (ground
    motion, body acceleration), so the runs of a study that only change the record reuse them."""

    timestep: TimestepInfo
    state: Any
    scratch: Any

    def copy(self) -> Start:
        """An independent copy (every array of the state and scratch tuples copied, field by field)."""
        def dup(nt: Any) -> Any:
            return type(nt)(*(a.copy() if isinstance(a, np.ndarray) else a for a in nt))

        return Start(self.timestep, dup(self.state), dup(self.scratch))


def prepare_start(model: Model, *, timestep_rule: str = "bound", safety: float = DEFAULT_SAFETY,
                  resolution: float = DEFAULT_RESOLUTION, dt: float | None = None) -> Start:
    """The :class:`Start` of a run of ``model`` with these timestep options."""
    info = stable_timestep(model, rule=timestep_rule, safety=safety, resolution=resolution, dt=dt)
    return Start(info, *initial_state(model))


class RunOutput(NamedTuple):
    """What :func:`run_model` returns: the recorded frames (Records trimmed to the frames computed),
    the result's attributes, the checked monitors (name -> (block id, reference point [m])) and the
    contact snapshots."""

    records: Records
    attrs: dict[str, Any]
    monitors: dict[str, tuple[int, np.ndarray]]
    snapshots: ContactSnapshots


def run_model(
    model: Model,
    duration: float,
    *,
    dt: float | None = None,
    timestep_rule: str = "bound",
    safety: float = DEFAULT_SAFETY,
    resolution: float = DEFAULT_RESOLUTION,
    record_interval: float = 0.002,
    monitors: Mapping[str, Monitor] | None = None,
    progress: bool | None = None,
    contact_interval: float | None = None,
    max_steps: int = DEFAULT_MAX_STEPS,
    stop: str | StopRule | None = "off",
    start: Start | None = None,
) -> RunOutput:
    """:func:`simulate` without building the Dataset: the raw recorded frames and attributes
    (studies summarise these directly; same arguments). ``attrs["kernel_s"]`` is the time spent
    inside the compiled kernel [s], ``runtime_s`` the whole loop's. ``start``: the timestep and
    initial state of :func:`prepare_start` for this model and these options (a copy, see
    :meth:`Start.copy`; the run mutates it), computed here when None."""
    if not isinstance(model, Model):
        hint = " (call builder.finalize() first)" if type(model).__name__ == "ModelBuilder" else ""
        raise TypeError(f"simulate: model must be a rockdem Model{hint}, got {type(model).__name__}")
    duration = _positive_number("duration", duration, "s")
    record_interval = _positive_number("record_interval", record_interval, "s")
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) or max_steps < 1:
        raise ValueError(f"max_steps must be a positive integer, got {max_steps!r}")
    mon = _check_monitors(model, monitors or {})
    rule = stop_rule(stop)
    snaps = ContactSnapshots(model, contact_interval)
    if start is None:
        start = prepare_start(model, timestep_rule=timestep_rule, safety=safety, resolution=resolution, dt=dt)
    info = start.timestep
    _check_step_count(info, duration, max_steps)
    frames = int(math.floor(duration / record_interval + 1e-9)) + 1
    need = frames * model.block_count * 13 * 8
    if need > _MAX_RECORD_BYTES:
        raise ValueError(
            f"recording {frames} frames of {model.block_count} blocks needs {need / 1e9:.1f} GB; "
            f"raise record_interval (now {record_interval} s)"
        )
    wall0 = _time.perf_counter()
    state, scratch = start.state, start.scratch
    state.dt[0] = state.dt_prev[0] = state.dt_min[0] = info.dt
    state.safety[0] = safety
    state.resolution[0] = resolution if info.rule == "bound" else 1.0
    m = model.arrays
    scratch.energy_scale[0] = 9.81e-3 * float(m.block_mass[m.block_free].sum())  # lifting the free blocks by 1 mm
    snaps.take(state)
    rec = new_records(frames, model.block_count, int(np.count_nonzero(~m.block_free.astype(bool))))
    frame = 0
    status = STATUS_DONE
    sunk: tuple[str, str] | None = None
    thickness = block_thickness(model)
    chunk = 2000 * info.dt  # simulated seconds per compiled call, adapted to ~0.25 s of wall time
    stopper = Stopper(model, rule, record_interval) if rule is not None else None
    decision: Decision | None = None
    kernel = 0.0
    bar = None
    interrupted = False
    try:
        t_end = duration + 0.5 * info.dt  # one step past the end records the frame at t = duration
        while state.time[0] < t_end and frame < frames:
            if stopper is not None:  # a fixed number of steps between checks (see CHECK_STEPS)
                chunk = stopper.rule.check_steps * float(state.dt[0])
            t_stop = snaps.clip(min(t_end, float(state.time[0]) + chunk))
            t0 = _time.perf_counter()
            frame, status = advance(m, state, scratch, t_stop, record_interval, rec, frame)
            elapsed = _time.perf_counter() - t0
            kernel += elapsed
            if status == STATUS_GROW:
                state, scratch = grow_buffers(state, scratch)
                continue
            if status != STATUS_DONE:
                break
            sunk = _sunk(model, state, thickness)
            if sunk is not None:
                break
            snaps.take(state)
            if stopper is not None:
                decision = stopper.check(rec, frame)
                if decision is not None:
                    frame = decision.frame + 1  # the result ends at the decided frame
                    break
            else:
                chunk = min(chunk * 4.0, max(float(state.dt[0]), chunk * 0.25 / max(elapsed, 1e-6)))
            if bar is None and (progress or (progress is None and _time.perf_counter() - wall0 > 2.0)):
                bar = _progress_bar(duration)
            if bar is not None:
                bar.update(min(float(state.time[0]), duration) - bar.n)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if bar is not None:
            bar.close()
    runtime = _time.perf_counter() - wall0
    attrs: dict[str, Any] = {
        "dt": info.dt,
        "dt_min": float(state.dt_min[0]),
        "dt_critical": info.critical,
        "omega_max": info.omega_max,
        "sp_factor": info.sp_factor,
        "resolution": info.resolution,
        "timestep_rule": info.rule,
        "steps": int(state.step[0]),
        "runtime_s": runtime,
        "kernel_s": kernel,
        "duration": duration,
        "record_interval": record_interval,
        "interrupted": int(interrupted),
        "stop_rule": rule.mode if rule is not None else "off",
    }
    if decision is not None:
        attrs.update({"stop_reason": decision.reason, "stop_time": decision.time, "stop_block": decision.block})
    if status in (STATUS_DIVERGED, STATUS_LOST):
        attrs.update(_failure(model, rec, frame - 1, status, int(scratch.lost_block[0]), int(state.step[0])))
        warnings.warn(attrs["diverged_message"], RuntimeWarning, stacklevel=2)
        frame -= 1  # keep the sound frames before the bad one
    elif sunk is not None:
        t_now = float(state.time[0])
        block, what = sunk
        msg = f"the run stopped at t = {t_now:.4g} s (step {int(state.step[0])}): {what}; the result holds the frames computed"
        attrs.update({"diverged": 1, "diverged_time": t_now, "diverged_step": int(state.step[0]),
                      "diverged_blocks": block, "diverged_reason": "sank", "diverged_message": msg})
        warnings.warn(msg, RuntimeWarning, stacklevel=2)
    fell = np.flatnonzero(state.fell_off >= 0.0)
    if fell.size:
        listed = ", ".join(f"{model.block_names[b]} ({state.fell_off[b]:.3g} s)" for b in fell)
        attrs["fell_off_blocks"] = ", ".join(model.block_names[b] for b in fell)
        attrs["fell_off_times"] = state.fell_off[fell].astype(float)
        warnings.warn(
            f"block(s) fell off the edge of the model's supports and fall on unhindered: {listed}; "
            "a larger foundation (the specimen builders' foundation_extent) keeps them",
            RuntimeWarning, stacklevel=2,
        )
    rec = Records(*(a[:frame] for a in rec))
    return RunOutput(rec, attrs, mon, snaps)


SINK_FRACTION = 0.25
"""A run stops when a sub-contact's overlap exceeds this fraction of the thinner of its two blocks:
the joints are then far too soft for their load (elastic overlaps are normally below 1 %)."""


def _sunk(model: Model, state: Any, thickness: np.ndarray) -> tuple[str, str] | None:
    """(name of the sinking block, description) of the deepest sub-contact overlap if it exceeds
    SINK_FRACTION of the thinner block, else None."""
    m = model.arrays
    partner = state.slot_partner
    live = (partner >= 0) & (state.slot_area > 0.0)
    if not live.any():
        return None
    pts, slot = np.nonzero(live)
    owner, other = m.point_block[pts], partner[pts, slot]
    depth = state.slot_overlap[pts, slot]
    limit = SINK_FRACTION * np.minimum(thickness[owner], thickness[other])
    k = int(np.argmax(depth / limit))
    if not depth[k] > limit[k]:
        return None
    a, b = model.block_names[owner[k]], model.block_names[other[k]]
    return a, (
        f"block {a!r} sank {depth[k]:.3g} m into {b!r}, more than {SINK_FRACTION:.0%} of the thinner block: the joint "
        f"stiffness kn = {m.mat_kn[m.block_group[owner[k]], m.block_group[other[k]]]:.3g} Pa/m is far too low for the load "
        "(kn = E / l with E in Pa, not MPa)"
    )


def _positive_number(name: str, value: Any, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name} must be a number [{unit}], got {type(value).__name__} {value!r}")
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive time [{unit}], got {value!r}")
    return float(value)


def _check_step_count(info: TimestepInfo, duration: float, max_steps: int) -> None:
    """Refuse runs whose timestep exceeds the run or whose step count exceeds ``max_steps``."""
    where = (
        f"(omega_max = {info.omega_max:.4g} rad/s, SP reduction {info.sp_factor:.3g}); check the units "
        "(stiffness kn in Pa/m or E in Pa, density in kg/m^3, beta in s)"
    )
    if not (math.isfinite(info.dt) and info.dt > 0):
        raise ValueError(f"the stable timestep of this model is {info.dt!r} s: the run would need infinitely many steps {where}")
    if info.dt > duration:
        raise ValueError(
            f"the timestep {info.dt:.3g} s is longer than the run ({duration:.3g} s): the contacts are implausibly "
            f"soft or the blocks implausibly heavy {where}"
        )
    steps = duration / info.dt
    if steps > max_steps:
        raise ValueError(
            f"the run needs about {steps:.3g} steps of {info.dt:.3g} s (limit max_steps = {max_steps:.3g}): "
            f"the contacts are implausibly stiff or the damping implausibly high {where}; raise max_steps "
            "if this is intended"
        )


def _failure(model: Model, rec: Records, bad: int, status: int, block: int, step: int) -> dict[str, Any]:
    """Attributes describing where a run went wrong (the bad frame ``bad``)."""
    t_bad = float(rec.time[bad])
    if block >= 0:
        blocks = [model.block_names[block]]
    else:  # the blocks moving fastest at the bad frame
        ke = 0.5 * model.arrays.block_mass * np.sum(np.nan_to_num(rec.velocity[bad], nan=np.inf) ** 2, axis=1)
        ke[~model.arrays.block_free] = -1.0
        blocks = [model.block_names[b] for b in np.argsort(-ke)[: min(3, int(model.arrays.block_free.sum()))]]
    if status == STATUS_LOST:
        reason = "left the model's extent (fell through its support or flew away: check the joint stiffness and the foundation size)"
    else:
        reason = (
            f"created energy (kinetic + potential + elastic above the initial energy plus the work done) beyond "
            f"{DIVERGENCE_ERROR:.0%} of the energy scale, or a non-finite state "
            "(check the timestep safety, the joint stiffness and strengths)"
        )
    msg = f"the run stopped at t = {t_bad:.4g} s (step {step}): block(s) {', '.join(blocks)} {reason}; the result holds the frames before it"
    return {
        "diverged": 1,
        "diverged_time": t_bad,
        "diverged_step": step,
        "diverged_blocks": ", ".join(blocks),
        "diverged_reason": "lost" if status == STATUS_LOST else "energy",
        "diverged_message": msg,
    }


def _progress_bar(duration: float) -> Any:
    from tqdm.auto import tqdm

    return tqdm(
        total=duration,
        unit="s",
        desc="rockdem",
        bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.3f}/{total:.3f} s simulated [{elapsed}<{remaining}]",
    )


def first_diverged_frame(ds: xr.Dataset) -> int | None:
    """Index of the first frame of a result with a non-finite state or created energy: kinetic +
    potential + elastic energy above the initial value plus the work done by more than
    :data:`DIVERGENCE_ERROR` of the energy scale reached so far (kinetic + elastic + |potential| +
    dissipated + |work|, at least the work of lifting the free blocks by 1 mm); None if the run
    stayed sound. The engine applies the same test while it runs and stops there."""
    mech = ds.energy_kinetic.values + ds.energy_potential.values + ds.energy_elastic.values
    work = ds.work_driven.values + ds.work_body.values
    err = (mech - mech[0]) - (work - work[0])
    parts = [np.abs(ds[n].values) for n in ds.data_vars if n.startswith(("energy_", "work_")) and "balance" not in n]
    floor = 9.81e-3 * float(ds.block_mass.values[ds.block_free.values.astype(bool)].sum())  # 1 mm of lift
    running = np.maximum(np.maximum.accumulate(np.sum(parts, axis=0)), floor)
    finite = np.isfinite(ds.block_position.values).all(axis=(1, 2)) & np.isfinite(err)
    bad = ~finite | (err > DIVERGENCE_ERROR * running)
    idx = np.flatnonzero(bad)
    return int(idx[0]) if len(idx) else None


def _check_monitors(model: Model, monitors: Mapping[str, Monitor]) -> dict[str, tuple[int, np.ndarray]]:
    out = {}
    for name, spec in monitors.items():
        try:
            blk, point = spec
            p = np.asarray(point, dtype=float).reshape(3)
        except (TypeError, ValueError):
            raise ValueError(
                f"monitor {name!r}: give (block, (x, y, z)) with the world position at t = 0 [m], got {spec!r}"
            ) from None
        b = model.block_id(blk) if isinstance(blk, str) else int(blk)
        if not 0 <= b < model.block_count:
            raise ValueError(f"monitor {name!r}: block id {b} out of range")
        out[str(name)] = (b, p)
    return out
