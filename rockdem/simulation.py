"""``simulate()``: the one entry point that owns the time loop, the recording and the progress.

The loop runs in compiled chunks (:func:`rockdem.kernels.step.advance`); Python only sees chunk
boundaries, where it updates the progress bar and enlarges the contact buffers when a detection
asks for it. A run that goes wrong stops at the first bad recorded frame: when its energy balance
breaks or its state is no longer finite (diverged), or when a free block leaves the model's extent
(it fell through its support or flew away); the result keeps the frames before it and says where
(``attrs["diverged"]``, ``diverged_time``, ``diverged_step``, ``diverged_blocks``,
``diverged_reason``). An interrupted run (Ctrl-C, or SIGTERM / SIGHUP under ``rockdem``) returns the
frames computed so far, flagged ``interrupted``; ``stop_signal`` names the signal (also when it arrived
only as the finished result was put together). A run can be saved to a checkpoint and continued exactly (:mod:`rockdem.checkpoint`).
With ``stop=`` (:mod:`rockdem.stopping`) the loop checks between chunks of a fixed number of steps
whether the outcome is decided (collapsed, or at rest after the input) and ends there
(``attrs["stop_reason"]``, ``stop_time``). :func:`run_model` is the loop without the Dataset
(studies summarise its raw frames).

A run stopped by its stop rule and checkpointed: the result ends at the decided frame, but the
checkpoint holds the state where the loop ended (the end of the chunk in which the decision was
made, at most ``check_steps`` steps later) and every frame computed up to there. Continued with the
same rule, it is decided again from the saved frames and the result is the stopped run's, steps
included, without stepping further (but for the rest of a chunk cut short, below); continued with ``stop="off"`` (or another rule), it runs on
past the decision. A checkpoint written where the end of a run cut a chunk short keeps the time the
chunk was to end at (``Checkpoint.check_target``): the continuation ends its first chunk there, so
its stop checks fall where an uninterrupted run's do and a continued run with ``stop=`` is bit for
bit an uninterrupted one with the same rule (the steps past the decision included).
"""

from __future__ import annotations

import contextlib
import math
import operator
import os
import signal
import sys
import threading
import time as _time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Mapping, NamedTuple, Sequence

import numba
import numpy as np
import xarray as xr

from ._warn import warn_user
from .checkpoint import Checkpoint, field_hashes, load_checkpoint, model_hash, structure_hash
from .kernels.layout import STATUS_DIVERGED, STATUS_DONE, STATUS_GROW, STATUS_LOST, Records, Scratch, State, new_records
from .kernels.step import DIVERGENCE_ERROR, advance, advance_parallel
from .model import Model
from .results import block_thickness, build_dataset, energy_balance
from .snapshots import ContactSnapshots
from .state import grow_buffers, initial_state
from .stopping import Decision, Stopper, StopRule, stop_rule
from .timestep import (
    DEFAULT_RESOLUTION,
    DEFAULT_SAFETY,
    IMPACT_REFINEMENT,
    MAX_DAMPING_RATIO,
    TimestepInfo,
    dashpot_code,
    impact_windows,
    resolve_dashpots,
    stable_timestep,
)

__all__ = ["simulate", "run_model", "prepare_start", "Start", "RunOutput", "Monitor", "DEFAULT_MAX_STEPS", "PARALLEL_MIN_BLOCKS", "first_diverged_frame"]

Monitor = tuple[int | str, Sequence[float]]
"""A monitor point: (block id or name, world coordinates in the reference configuration [m])."""

_MAX_RECORD_BYTES = 2 * 1024**3

DEFAULT_MAX_STEPS = 1_000_000_000
"""Largest number of steps a run may need before it is refused (raise it with ``max_steps``)."""

LIFT_1MM = 9.81e-3
"""Work of lifting 1 kg by 1 mm [J/kg]: times the free mass, the least energy scale of a run (the
divergence check's floor; below :data:`REST_SHARE` of it a run's energies are noise)."""


def simulate(
    model: Model,
    duration: float,
    *,
    dt: float | None = None,
    timestep_rule: str | None = None,
    safety: float | None = None,
    resolution: float | None = None,
    impact_refinement: float | None = None,
    dashpots: str | None = None,
    record_interval: float | None = None,
    monitors: Mapping[str, Monitor] | None = None,
    progress: bool | None = None,
    contact_interval: float | None = None,
    max_steps: int = DEFAULT_MAX_STEPS,
    stop: str | StopRule | None = "off",
    initial: Checkpoint | str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: float | None = None,
    threads: int | None = None,
) -> xr.Dataset:
    """Run ``model`` until time ``duration`` and return the recorded histories.

    Args:
        model: a finalized model (:meth:`rockdem.model.ModelBuilder.finalize`).
        duration: simulated time at the end of the run [s] (continuing a checkpoint: the end time,
            not the time added).
        dt: timestep [s]; default automatic (see :mod:`rockdem.timestep`); refused above the bound.
        timestep_rule: "bound" (default) or "3dec" (0.2 sqrt(m_min/k_max)).
        safety: fraction of the stable bound for the automatic timestep (default 0.9).
        resolution: largest omega_max dt / 2 (default 0.3), so that impacts last several steps and
            keep their energy error below 1 % (see :mod:`rockdem.timestep`); 1 turns this limit off.
        impact_refinement: the step is divided by this around impacts (default 6,
            :data:`rockdem.timestep.IMPACT_REFINEMENT`; rule "bound" with implicit dashpots), so that
            rocking under an earthquake follows the converged history (:func:`rockdem.timestep.impact_windows`);
            1 turns the impact windows off.
        dashpots: how SP dashpots are integrated: "implicit" (trapezoidal, stable at the undamped
            step whatever beta, :mod:`rockdem.kernels.implicit`), "explicit" (on the last half step's
            velocities with Belytschko's step reduction, as 3DEC does) or "auto" (default, None:
            implicit, explicit with local damping); see ``docs/dashpots.md``.
        record_interval: time between recorded frames [s] (default 0.002). Frame k is at exactly
            k record_interval: poses and velocities on the leapfrog path at that time (the step
            need not divide the interval); energies, contact counts and reactions are those of the
            step nearest to it (within half a step).
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
            ``stop_block``). A continued run may use another rule than the checkpoint's run (see
            the module notes for a checkpoint of a stopped run).
        initial: a :class:`~rockdem.checkpoint.Checkpoint` (or its file) to continue: the result
            holds the checkpoint's frames followed by the new ones, bit for bit those of an
            uninterrupted run. The timestep and the record and contact intervals are the
            checkpoint's (giving other values is an error). A checkpoint whose clock was reset
            (:meth:`~rockdem.checkpoint.Checkpoint.reset_clock`) instead starts a new run at t = 0
            from its state, on a model with the same blocks and any loading.
        checkpoint: file written at the end of the run, when it is interrupted (Ctrl-C, or SIGTERM
            under ``rockdem run``), and every ``checkpoint_every`` seconds of wall time; none is
            written for a run that diverged.
        checkpoint_every: wall time between checkpoints during the run [s]; default only at the end.
        threads: threads for the joint law of the face pairs (Numba's, at most as many as it was
            started with, ``NUMBA_NUM_THREADS``); the answer is the same bit for bit on any number.
            Default None: all of them for models of at least :data:`PARALLEL_MIN_BLOCKS` blocks,
            one (serial) below. The parallel code is compiled on its first use (under a minute, once).
            Runs made at once from several Python threads should give 1: Numba's default
            ``workqueue`` threading layer does not take parallel work from two threads at a time
            (the study runners, :mod:`rockdem.batch`, run one thread per run).

    Returns:
        An xarray Dataset (see :func:`rockdem.results.build_dataset` for the variables).

    Raises:
        TypeError: ``model`` is not a finalized Model.
        ValueError: bad options, a timestep longer than the run, more steps than ``max_steps``, or
            a checkpoint of another model.
    """
    out = run_model(model, duration, dt=dt, timestep_rule=timestep_rule, safety=safety, resolution=resolution,
                    impact_refinement=impact_refinement, dashpots=dashpots, record_interval=record_interval, monitors=monitors, progress=progress,
                    contact_interval=contact_interval, max_steps=max_steps, stop=stop, initial=initial,
                    checkpoint=checkpoint, checkpoint_every=checkpoint_every, threads=threads)
    late: list[int] = []
    with _deferred_signals(finishing=True, late=late):
        ds = out.snapshots.attach(build_dataset(model, out.records, monitors=out.monitors, attrs=out.attrs))
    if late and not ds.attrs.get("stop_signal"):
        ds.attrs["stop_signal"] = late[0]
    return ds


class Start(NamedTuple):
    """What a run starts from: the timestep (:func:`rockdem.timestep.stable_timestep`) and the
    initial state and scratch arrays (:func:`rockdem.state.initial_state`). They depend on the
    model's geometry, materials, damping and initial pose, not on its prescribed inputs (ground
    motion, body acceleration), so the runs of a study that only change the record reuse them."""

    timestep: TimestepInfo
    state: State
    scratch: Scratch

    def copy(self) -> Start:
        """An independent copy (every array of the state and scratch tuples copied, field by field)."""
        def dup(nt: Any) -> Any:
            return type(nt)(*(a.copy() if isinstance(a, np.ndarray) else a for a in nt))

        return Start(self.timestep, dup(self.state), dup(self.scratch))


def prepare_start(model: Model, *, timestep_rule: str = "bound", safety: float = DEFAULT_SAFETY,
                  resolution: float = DEFAULT_RESOLUTION, dt: float | None = None, dashpots: str | None = None) -> Start:
    """The :class:`Start` of a run of ``model`` with these timestep options."""
    state, scratch = initial_state(model)
    info = stable_timestep(model, rule=timestep_rule, safety=safety, resolution=resolution, dt=dt, dashpots=dashpots,
                           initial=(state, scratch))
    return Start(info, state, scratch)


class RunOutput(NamedTuple):
    """What :func:`run_model` returns: the recorded frames (Records trimmed to the result's
    frames), the result's attributes, the checked monitors (name -> (block id, reference point
    [m])) and the contact snapshots."""

    records: Records
    attrs: dict[str, Any]
    monitors: dict[str, tuple[int, np.ndarray]]
    snapshots: ContactSnapshots


def run_model(
    model: Model,
    duration: float,
    *,
    dt: float | None = None,
    timestep_rule: str | None = None,
    safety: float | None = None,
    resolution: float | None = None,
    impact_refinement: float | None = None,
    dashpots: str | None = None,
    record_interval: float | None = None,
    monitors: Mapping[str, Monitor] | None = None,
    progress: bool | None = None,
    contact_interval: float | None = None,
    max_steps: int = DEFAULT_MAX_STEPS,
    stop: str | StopRule | None = "off",
    start: Start | None = None,
    initial: Checkpoint | str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: float | None = None,
    threads: int | None = None,
) -> RunOutput:
    """:func:`simulate` without building the Dataset: the raw recorded frames and attributes
    (studies summarise these directly; same arguments). ``attrs["kernel_s"]`` is the time spent
    inside the compiled kernel in this call [s], ``runtime_s`` the whole loop's (with the
    checkpoint's, continuing one). ``start``: the timestep and initial state of
    :func:`prepare_start` for this model and these options (a copy, see :meth:`Start.copy`; the
    run mutates it), computed here when None; not with ``initial``."""
    if not isinstance(model, Model):
        hint = " (call builder.finalize() first)" if type(model).__name__ == "ModelBuilder" else ""
        raise TypeError(f"simulate: model must be a rockdem Model{hint}, got {type(model).__name__}")
    duration = _positive_number("duration", duration, "s")
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) or max_steps < 1:
        raise ValueError(f"max_steps must be a positive integer, got {max_steps!r}")
    if checkpoint_every is not None:
        checkpoint_every = _positive_number("checkpoint_every", checkpoint_every, "s of wall time")
        if checkpoint is None:
            raise ValueError("checkpoint_every needs a checkpoint file: give checkpoint=PATH")
    if checkpoint is not None:
        _check_checkpoint_path(checkpoint)
    mon = _check_monitors(model, monitors or {})
    rule = stop_rule(stop)
    n_threads = _threads(threads, model.block_count)
    step_chunk = advance_parallel if n_threads > 1 else advance
    if start is not None and initial is not None:
        raise ValueError("give start (a prepared fresh start) or initial (a checkpoint), not both")
    ck = None if initial is None else load_checkpoint(initial)
    with _deferred_signals(note="rockdem: stopping once the compiled kernels are loaded (a first run compiles them)"):
        _load_kernels(n_threads)
    wall0 = _time.perf_counter()
    # A stop signal while the start's kernels load (or compile, minutes on a first run) is held until
    # they are ready: raised inside Numba's compiler it left a half-built kernel and a traceback.
    with _deferred_signals(note="rockdem: stopping once the compiled kernels are loaded (a first run compiles them)"):
        if ck is None or ck.fresh:
            run = _fresh_run(model, duration, ck, dt, timestep_rule, safety, resolution, dashpots, record_interval,
                             contact_interval, max_steps, start, impact_refinement)
        else:
            run = _continued_run(model, duration, ck, dt, timestep_rule, safety, resolution, dashpots,
                                 record_interval, contact_interval, max_steps, impact_refinement)
    saver = _Saver(model, run, checkpoint, checkpoint_every)
    info, state, scratch, rec, snaps = run.info, run.state, run.scratch, run.records, run.snaps
    frame, frames = run.frame, rec.time.shape[0]
    m = model.arrays
    status = STATUS_DONE
    sunk: tuple[str, str] | None = None
    thickness = block_thickness(model)
    # Simulated seconds per compiled call, adapted to ~0.25 s of wall time, at most CALL_SHARE
    # of the run. A block sinking into soft joints is found between calls (_sunk), at fixed times
    # (every SINK_CHECK_STEPS starting steps, and at the end): calls end there too, so that the
    # same inputs stop at the same step on any machine and for any duration asked for.
    longest = max(CALL_SHARE * (duration - float(state.time[0])), info.dt)
    chunk = min(200 * info.dt, longest)
    sink_every = min(SINK_CHECK_STEPS * info.dt, SINK_CHECK_TIME)
    next_sink = (math.floor(float(state.time[0]) / sink_every) + 1.0) * sink_every
    stopper = Stopper(model, rule, run.record_interval) if rule is not None else None
    decision: Decision | None = None
    # With a stop rule, chunks of check_steps steps: ``target`` is the time the current chunk ends at
    # (a contact snapshot or the end of the run may cut it short); see the module notes.
    target = run.check_target if stopper is not None else None
    if stopper is not None and frame > 0 and target is None:
        decision = stopper.check(rec, frame, state.fell_off)  # a continued run: the saved frames may decide it already
    kernel = 0.0
    bar = None
    interrupted = False
    stop_signal = 0  # the stop signal that cut the loop short, or that arrived as the result was put together
    try:
        t_end = duration + 0.5 * info.dt  # one step past the end records the frame at t = duration
        while decision is None and state.time[0] < t_end and frame < frames:
            # A stop signal during a chunk is raised once the chunk's bookkeeping is done, so that the
            # state, the frame counter and the snapshots saved in a checkpoint belong together.
            with _deferred_signals():
                if stopper is not None:
                    if target is None:
                        target = float(state.time[0]) + stopper.rule.check_steps * float(state.dt[0])
                    t_stop = snaps.clip(min(t_end, target))
                else:
                    t_stop = snaps.clip(min(t_end, float(state.time[0]) + chunk, next_sink))
                t0 = _time.perf_counter()
                frame, status = _on_threads(n_threads, step_chunk, m, state, scratch, t_stop, run.record_interval, rec, frame)
                elapsed = _time.perf_counter() - t0
                kernel += elapsed
                if status == STATUS_GROW:
                    state, scratch = grow_buffers(state, scratch)
                    continue
                if status != STATUS_DONE:
                    break
                if stopper is not None or t_stop >= next_sink or t_stop >= t_end:  # (the call ran to t_stop)
                    sunk = _sunk(model, state, thickness)
                    # the next grid time past t_stop (which the kernel may stop 1e-12 s short of)
                    next_sink = max(next_sink, (math.floor(t_stop / sink_every + 1e-9) + 1.0) * sink_every)
                if sunk is not None:
                    break
                snaps.take(state)
                if stopper is not None:
                    # a new chunk starts here, unless the end of this run cut it short (kept for a continuation)
                    target = target if t_stop == t_end < target else None
                    decision = stopper.check(rec, frame, state.fell_off)
            if stopper is None:
                chunk = min(chunk * 4.0, max(float(state.dt[0]), chunk * 0.25 / max(elapsed, 1e-6)), longest)
            saver.maybe(state, scratch, rec, frame, snaps, _time.perf_counter() - wall0, target)
            if bar is None and (progress or (progress is None and _time.perf_counter() - wall0 > 2.0)):
                bar = _progress_bar(duration, run.start_time)
            if bar is not None:
                bar.update(min(float(state.time[0]), duration) - bar.n)
    except KeyboardInterrupt as exc:
        interrupted = True
        stop_signal = int(getattr(exc, "signum", signal.SIGINT))
    finally:
        if bar is not None:
            bar.close()
    # Past the loop the frames are computed (all of them, or those before a stop): a stop signal from
    # here on is held until the result is put together, and the result is returned (_deferred_signals).
    late: list[int] = []
    with _deferred_signals(finishing=True, late=late):
        if stopper is not None and decision is None and status == STATUS_DONE and sunk is None:
            decision = stopper.check(rec, frame, state.fell_off)  # frames not examined yet (a continuation with nothing to compute)
        runtime = _time.perf_counter() - wall0 + run.runtime_before
        attrs: dict[str, Any] = {
            "dt": info.dt,
            "dt_min": float(state.dt_min[0]),
            "dt_critical": info.critical,
            "omega_max": info.omega_max,
            "sp_factor": info.sp_factor,
            "resolution": info.resolution,
            "impact_refinement": float(state.refinement[0]) if state.impact_window[0] > 0.0 else 1.0,
            "impact_window_s": float(state.impact_window[0]),
            "impact_window_share": float(state.refined_time[0] / state.time[0]) if state.time[0] > 0.0 else 0.0,
            "timestep_rule": info.rule,
            "dashpots": info.dashpots,
            "damping_ratio": info.damping_ratio,
            "dashpot_sweeps": int(state.dashpot_sweeps[0]),
            "dashpot_unconverged_steps": int(state.dashpot_unconverged[0]),
            "steps": int(state.step[0]),
            "sub_contact_updates": int(state.slot_updates[0]),
            "threads": n_threads,
            "runtime_s": runtime,
            "kernel_s": kernel,
            "duration": duration,
            "record_interval": run.record_interval,
            "interrupted": int(interrupted),
            "stop_rule": rule.mode if rule is not None else "off",
        }
        if run.continued_from is not None:
            attrs["continued_from_time"] = run.continued_from
        if decision is not None:
            attrs.update({"stop_reason": decision.reason, "stop_time": decision.time, "stop_block": decision.block})
        if status in (STATUS_DIVERGED, STATUS_LOST):
            attrs.update(_failure(model, rec, frame - 1, status, int(scratch.lost_block[0]), int(state.step[0])))
            warn_user(attrs["diverged_message"], RuntimeWarning)
            frame -= 1  # keep the sound frames before the bad one
        elif sunk is not None:
            t_now = float(state.time[0])
            block, what = sunk
            when = f"t = {t_now:.4g} s" if t_now <= duration else f"its end (its last step reached t = {t_now:.4g} s)"
            msg = f"the run stopped at {when} (step {int(state.step[0])}): {what}; the result holds the frames computed"
            attrs.update({"diverged": 1, "diverged_time": t_now, "diverged_step": int(state.step[0]),
                          "diverged_blocks": block, "diverged_reason": "sank", "diverged_message": msg})
            warn_user(msg, RuntimeWarning)
        elif checkpoint is not None:  # every frame computed, also past a stop decision (see the module notes)
            attrs["checkpoint"] = str(saver.save(state, scratch, rec, frame, snaps, runtime, target))
        if attrs.get("diverged") and checkpoint is not None:
            attrs["checkpoint_note"] = "no checkpoint written: the run diverged"
        fell = np.flatnonzero(state.fell_off >= 0.0)
        if fell.size:
            listed = ", ".join(f"{model.block_names[b]} ({state.fell_off[b]:.3g} s)" for b in fell)
            attrs["fell_off_blocks"] = ", ".join(model.block_names[b] for b in fell)
            attrs["fell_off_times"] = state.fell_off[fell].astype(float)
            warn_user(
                f"block(s) fell off the edge of the model's supports (or were thrown clear of them) and fall on unhindered: {listed}; "
                "a larger foundation (the specimen builders' foundation_extent) keeps them",
                RuntimeWarning)
        end = decision.frame + 1 if decision is not None else frame  # the result ends at the decided frame
        _warn_energy_drift(rec.time[:end], rec.energy[:end], LIFT_1MM * float(m.block_mass[m.block_free].sum()))
        out = RunOutput(Records(*(a[:end] for a in rec)), attrs, mon, snaps)
    if stop_signal or late:
        attrs["stop_signal"] = stop_signal or late[0]
    return out


@dataclass
class _Run:
    """What the time loop starts from: a fresh state, or a checkpoint's."""

    info: TimestepInfo
    state: State
    scratch: Scratch
    records: Records  # preallocated for every frame of the run, the first ``frame`` filled
    frame: int
    record_interval: float
    snaps: ContactSnapshots
    start_time: float = 0.0
    runtime_before: float = 0.0
    continued_from: float | None = None
    check_target: float | None = None  # the end of a stop-rule chunk the run that saved it did not reach


def _frame_count(duration: float, record_interval: float) -> int:
    """Frames a run to ``duration`` [s] records, one every ``record_interval`` [s] from t = 0."""
    return int(math.floor(duration / record_interval + 1e-9)) + 1


def _frames(model: Model, duration: float, record_interval: float) -> Records:
    """Zeroed records for every frame of a run to ``duration`` [s], refused above 2 GB."""
    frames = _frame_count(duration, record_interval)
    need = frames * model.block_count * 13 * 8
    if need > _MAX_RECORD_BYTES:
        raise ValueError(
            f"recording {frames} frames of {model.block_count} blocks needs {need / 1e9:.1f} GB; "
            f"raise record_interval (now {record_interval} s)"
        )
    driven = int(np.count_nonzero(~model.arrays.block_free.astype(bool)))
    return new_records(frames, model.block_count, driven)


def _fresh_run(model: Model, duration: float, ck: Checkpoint | None, dt: float | None, rule: str | None,
               safety: float | None, resolution: float | None, dashpots: str | None, record_interval: float | None,
               contact_interval: float | None, max_steps: int, start: Start | None = None,
               impact_refinement: float | None = None) -> _Run:
    """A run from t = 0: the model's initial state (``start``'s when given: its timestep and
    arrays, used in place), or a checkpoint's state with its clock reset."""
    interval = _positive_number("record_interval", 0.002 if record_interval is None else record_interval, "s")
    safety = DEFAULT_SAFETY if safety is None else safety
    resolution = DEFAULT_RESOLUTION if resolution is None else resolution
    impact_refinement = IMPACT_REFINEMENT if impact_refinement is None else impact_refinement
    snaps = ContactSnapshots(model, contact_interval)
    if start is None and ck is None:
        start = prepare_start(model, timestep_rule=rule or "bound", safety=safety, resolution=resolution, dt=dt,
                              dashpots=dashpots)
    if start is not None:
        info = start.timestep
        if dashpots is not None and resolve_dashpots(model, dashpots) != info.dashpots:
            raise ValueError(f"dashpots = {dashpots!r} differs from the prepared start's ({info.dashpots!r})")
    else:
        info = stable_timestep(model, rule=rule or "bound", safety=safety, resolution=resolution, dt=dt,
                               dashpots=dashpots)
    _check_step_count(info, duration, max_steps)
    if interval * FRAMES_PER_STEP < info.dt:
        raise ValueError(f"record_interval = {interval:g} s puts {info.dt / interval:.3g} frames in each time step "
                         f"({info.dt:.4g} s), all interpolated between the same two steps (more than {FRAMES_PER_STEP}); "
                         f"give record_interval >= {info.dt / FRAMES_PER_STEP:.3g} s, or the step itself")
    if snaps.interval is not None and snaps.interval < 0.5 * info.dt:
        # Snapshots are taken at steps, one per step at most (an interval just under the step takes
        # one at every step); far below it the clock stopped, at 1e-12 s, the snapshots piling up
        # in memory (before 2026-12-08).
        raise ValueError(f"contact_interval = {snaps.interval:g} s is less than half the time step ({info.dt:.4g} s): contact "
                         f"snapshots are taken at steps, one per step at most; give contact_interval >= {info.dt:.3g} s")
    _check_motions(model, info.dt, duration)
    rec = _frames(model, duration, interval)
    if start is not None:
        state, scratch = start.state, start.scratch
    else:
        ck.check_model(model)
        state, scratch = ck.engine_arrays(model)
        scratch.lost_block[:] = -1
        _warn_not_at_rest(model, state)
    state.dt[0] = state.dt_prev[0] = state.dt_min[0] = state.dt_coarse[0] = info.dt
    state.refinement[0], state.impact_window[0], state.impact_speed[0] = impact_windows(model, info, impact_refinement)
    state.refine_until[0] = state.refine_limit[0] = state.refined_time[0] = 0.0
    state.safety[0] = safety
    state.resolution[0] = resolution if info.rule == "bound" else 1.0
    state.dashpots[0] = dashpot_code(info.dashpots)
    m = model.arrays
    scratch.energy_scale[0] = LIFT_1MM * float(m.block_mass[m.block_free].sum())  # lifting the free blocks by 1 mm
    snaps.take(state)
    return _Run(info, state, scratch, rec, 0, interval, snaps)


FRAMES_PER_STEP = 100
"""Most frames a run may record within one time step: each lies on the leapfrog path between the
same two steps, so a record_interval far below the step only multiplies the output (1e-7 s wrote 5
million frames, 1.9 GB, from 709 steps) and is refused."""

MOTION_MISSED = 0.05
"""Largest share of a driven block's prescribed path [m] that the first time step may miss
(:func:`_check_motions`)."""

MOTION_CHECK_STEPS = 10**6
"""Motions longer than this many first steps are not checked (their samples are far apart
against the step: a recorded ground motion under a stiff model)."""


def _check_motions(model: Model, dt: float, duration: float) -> None:
    """Refuse a prescribed motion that changes faster than the step ``dt`` [s] resolves: a driven
    block moves by its velocity at the middle of each step (kernels.step), so a push over a
    fraction of a step is missed (a pushover rod at 1e4 m/s stayed where it was and the run
    reported success). Compares that sum with the motion's exact integral up to ``duration``."""
    m = model.arrays
    for k in range(m.motion_start.shape[0] - 1):
        t = m.motion_time[m.motion_start[k]:m.motion_start[k + 1]]
        v = m.motion_velocity[m.motion_start[k]:m.motion_start[k + 1]]
        end = min(float(t[-1]), duration)
        steps = math.ceil(end / dt)
        if end <= 0.0 or steps > MOTION_CHECK_STEPS:
            continue
        inside = (t > 0.0) & (t < end)
        tk = np.r_[0.0, t[inside], end]
        vk = np.vstack([[np.interp(0.0, t, v[:, i]) for i in range(3)], v[inside], [np.interp(end, t, v[:, i]) for i in range(3)]])
        h = np.diff(tk)[:, None]
        speed = np.linalg.norm(vk, axis=1)[:, None]
        path = float(np.sum(0.5 * h * (speed[1:] + speed[:-1])))  # trapezoid rules: v is linear between samples
        if path == 0.0:
            continue
        exact = np.sum(0.5 * h * (vk[1:] + vk[:-1]), axis=0)
        mid = (np.arange(steps) + 0.5) * dt
        width = np.minimum(dt, end - np.arange(steps) * dt)  # the last step ends at ``end``
        stepped = np.array([np.sum(np.interp(mid, t, v[:, i]) * width) for i in range(3)])
        missed = float(np.linalg.norm(stepped - exact))
        if missed > MOTION_MISSED * path:
            names = [n for n, mo in zip(model.block_names, m.block_motion) if mo == k]
            raise ValueError(
                f"driven block(s) {names}: the time step ({dt:.3g} s) misses {missed / path:.0%} of their prescribed "
                f"motion ({path:.3g} m of path over {end:.3g} s), which changes faster than a step; make the "
                "motion slower (a pushover's velocity) or give a smaller time step (dt)")


REST_SHARE = 1e-3
"""Energies below this share of :data:`LIFT_1MM` times the free mass are rest, or noise: a saved
state with more kinetic energy that starts a new run (--settled) is warned about, and a run whose
energies all stay below it has its balance error summarised in J."""


def _warn_not_at_rest(model: Model, state: State) -> None:
    """Warn when a saved state that starts a new run at t = 0 is still moving."""
    m = model.arrays
    free = m.block_free.astype(bool)
    ke = 0.5 * float(np.sum(m.block_mass[free] * np.sum(state.velocity[free] ** 2, axis=1))
                     + np.sum(m.block_inertia[free] * state.omega[free] ** 2))
    lift = LIFT_1MM * float(m.block_mass[free].sum())
    if ke > REST_SHARE * lift:
        warn_user(f"the saved state that starts this run at t = 0 is not at rest: kinetic energy {ke:.3g} J "
                  f"({ke / lift:.3g} x lifting its free blocks by 1 mm); the run starts with those velocities. "
                  "Settle longer (or continue that run with --from)")


def _continued_run(model: Model, duration: float, ck: Checkpoint, dt: float | None, rule: str | None,
                   safety: float | None, resolution: float | None, dashpots: str | None,
                   record_interval: float | None, contact_interval: float | None, max_steps: int,
                   impact_refinement: float | None = None) -> _Run:
    """The run saved in ``ck``, continued to ``duration``: its state, frames and snapshots."""
    ck.check_model(model)
    # A rule and a resolution that the saved run did not use are not compared: beside a given dt
    # the rule had no part, and the resolution has none outside the bound rule (the command line
    # passes the case's defaults of both; its printed "continue with" failed on them before 2026-12-08).
    user = ck.timestep.rule == "user"
    given = {"dt": (dt, ck.timestep.dt if user else None),
             "timestep_rule": (None if user else rule, None if user else ck.timestep.rule),
             "safety": (safety, float(ck.state.safety[0])),
             "resolution": (resolution if ck.timestep.rule == "bound" else None,
                            float(ck.state.resolution[0]) if ck.timestep.rule == "bound" else None),
             "impact_refinement": (impact_refinement, float(ck.state.refinement[0])),
             "dashpots": (None if dashpots is None else resolve_dashpots(model, dashpots), ck.timestep.dashpots),
             "record_interval": (record_interval, ck.record_interval),
             "contact_interval": (contact_interval, ck.contact_interval)}
    for name, (value, saved) in given.items():
        if value is not None and value != saved:
            was = "automatic" if saved is None else repr(saved)
            raise ValueError(f"{name} = {value!r} differs from the checkpoint's ({was}): a continued run keeps "
                             f"the options it was started with; leave {name} unset")
    if _frame_count(duration, ck.record_interval) <= ck.frame:
        last = float(ck.records.time[ck.frame - 1]) if ck.frame else 0.0
        raise ValueError(f"nothing is left to compute: the checkpoint's run already recorded its frames up to t = {last:.6g} s "
                         f"(every {ck.record_interval:g} s), and a run to {duration:.6g} s records no later one; to run on, give "
                         f"an end time of at least {last + ck.record_interval:.6g} s (--duration or [run] duration)")
    _check_step_count(ck.timestep, duration - ck.time, max_steps)
    state, scratch = ck.engine_arrays(model)
    rec = _frames(model, duration, ck.record_interval)
    if ck.frame > rec.time.shape[0]:
        raise ValueError(f"the checkpoint holds {ck.frame} frames, more than a run to {duration:g} s records")
    for dst, src in zip(rec, ck.records):
        dst[: ck.frame] = src[: ck.frame]
    snaps = ContactSnapshots(model, ck.contact_interval)
    snaps.restore(ck.snapshots, ck.snapshot_count)
    return _Run(ck.timestep, state, scratch, rec, ck.frame, ck.record_interval, snaps, ck.time, ck.runtime_s, ck.time,
                ck.check_target)


def _check_checkpoint_path(path: str | os.PathLike[str]) -> None:
    """Refuse, before the run, a checkpoint path that cannot be written: a folder, a path under a
    file, or a folder without write permission (the file and its missing folders are made when it
    is saved; a refusal there came as an OSError after the whole run, its result lost)."""
    try:
        p = Path(path)
    except TypeError:
        raise ValueError(f"checkpoint must be a file path, got {path!r}") from None
    if p.is_dir():
        raise ValueError(f"checkpoint = {str(p)!r} is a folder; give a file path in it, e.g. {str(p / 'checkpoint.npz')!r}")
    folder = p.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise ValueError(f"checkpoint = {str(p)!r} lies under {str(folder)!r}, which is a file, not a folder; give another path")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"checkpoint = {str(p)!r}: no permission to write in {str(folder)!r}; give another path")


class _Saver:
    """Writes the run's checkpoint file (at the end, on interruption, every ``every`` s of wall time)."""

    def __init__(self, model: Model, run: _Run, path: str | os.PathLike[str] | None, every: float | None) -> None:
        self.model, self.run, self.path, self.every = model, run, path, every
        self.last = _time.perf_counter()
        self.hashes = (model_hash(model), structure_hash(model)) if path is not None else ("", "")
        self.fields = field_hashes(model) if path is not None else None

    def save(self, state: State, scratch: Scratch, rec: Records, frame: int, snaps: ContactSnapshots,
             runtime: float, check_target: float | None) -> Path:
        """Write the checkpoint now (state after the last completed chunk, frames ``[:frame]``, the
        unreached end of a stop-rule chunk)."""
        assert self.path is not None
        ck = Checkpoint(
            state=state, scratch=scratch, records=Records(*(a[:frame] for a in rec)), frame=frame,
            record_interval=self.run.record_interval, contact_interval=snaps.interval, snapshot_count=snaps.count,
            snapshots=snaps.columns() if snaps.interval else {}, timestep=self.run.info,
            model_hash=self.hashes[0], structure_hash=self.hashes[1], runtime_s=runtime,
            block_names=self.model.block_names, check_target=check_target, field_hashes=self.fields,
        )
        with _deferred_signals():
            p = ck.save(self.path)
        self.last = _time.perf_counter()
        return p

    def maybe(self, state: State, scratch: Scratch, rec: Records, frame: int, snaps: ContactSnapshots,
              wall: float, check_target: float | None) -> None:
        """Save if ``every`` seconds of wall time passed since the last save."""
        if self.every is not None and _time.perf_counter() - self.last >= self.every:
            self.save(state, scratch, rec, frame, snaps, wall + self.run.runtime_before, check_target)


@contextlib.contextmanager
def _deferred_signals(finishing: bool = False, late: list[int] | None = None, note: str | None = None) -> Iterator[None]:
    """Hold SIGINT, SIGTERM and SIGHUP (those with a Python handler) until the block ends, then
    deliver them to their handlers: a Ctrl-C raises its KeyboardInterrupt after the block, never
    halfway through it. With ``finishing`` (the result of a run being put together once its loop
    has ended: every frame computed, or those before a stop), the KeyboardInterrupt the handler
    raises is caught, so that the result is returned; the handler has seen the signal (``rockdem
    run`` then notes it and exits once the result is saved), and its number is appended to ``late``
    (a study then stores no row of the run and stops). ``note`` is printed on stderr when the first
    signal is held. Outside the main thread (where no signal arrives) this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[tuple[int, Any]] = []
    old: dict[int, Any] = {}
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        handler = signal.getsignal(sig) if sig is not None else None
        if callable(handler):
            old[sig] = handler
            signal.signal(sig, lambda signum, frame: _hold(held, signum, frame, note))
    try:
        yield
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
        for signum, frame in held[:1]:
            try:
                old[signum](signum, frame)
            except KeyboardInterrupt:
                if not finishing:
                    raise
                if late is not None:
                    late.append(int(signum))


def _hold(held: list[tuple[int, Any]], signum: int, frame: Any, note: str | None) -> None:
    """A stop signal held by :func:`_deferred_signals` (``note`` on stderr at the first)."""
    if note and not held:
        print(note, file=sys.stderr, flush=True)
    held.append((signum, frame))


ENERGY_DRIFT_SHARE = 0.05
"""A run whose energy balance error reaches this share of its energy scale is warned about
(:func:`_warn_energy_drift`)."""


def _warn_energy_drift(time: np.ndarray, energy: np.ndarray, lift: float) -> None:
    """Warn when the energy balance error of the recorded frames (``time`` (T,) [s], ``energy``
    (T, len(ENERGY_NAMES)) [J], as Records holds them) reaches :data:`ENERGY_DRIFT_SHARE` of the
    run's energy scale (as the result's ``energy_balance_error_relative``), unless that scale is
    below :data:`REST_SHARE` of ``lift`` [J] (lifting the free blocks by 1 mm): then the energies
    are noise (a model without gravity or load was warned about 1e-23 J "created", +93 % of its
    scale, before 2026-12-01, while the run's summary called the same figure noise). The divergence check
    compares the mechanical energy with the initial one plus the work only, so energy created
    after friction or damping had taken some passed it: random convex blocks passing through one
    another ended at balance errors of 20 to 86 % with no word before 2026-11-30."""
    if len(time) < 2:
        return
    err, scale = energy_balance(energy)
    k = int(np.argmax(np.abs(err)))
    if scale > REST_SHARE * lift and abs(err[k]) > ENERGY_DRIFT_SHARE * scale:
        what = "created" if err[k] > 0.0 else "lost, unbooked,"
        warn_user(f"the energy balance is off by {err[k] / scale:+.1%} of the run's energy scale ({scale:.3g} J) at "
                  f"t = {time[k]:.4g} s: the contacts {what} {abs(err[k]):.3g} J (a fast impact on a small face, blocks "
                  "passing through one another); read the result with care, and see energy_balance_error_relative "
                  "(docs/contacts.md)", RuntimeWarning)


SINK_FRACTION = 0.25
"""A run stops when a sub-contact's overlap exceeds this fraction of the thinner of its two blocks:
the joints are then far too soft for their load (elastic overlaps are normally below 1 %)."""


CALL_SHARE = 0.05
"""A compiled call of the loop covers at most this share of the run's time."""

SINK_CHECK_TIME = 0.05
"""[s] The sinking check's interval at most (:data:`SINK_CHECK_STEPS`)."""

SINK_CHECK_STEPS = 5000
"""The sinking check (:func:`_sunk`) runs every this many starting steps of simulated time (at most
every :data:`SINK_CHECK_TIME`), at fixed times, at the end of the run, and with a stop rule after
each of its chunks. Before 2026-11-30
it ran after each compiled call, whose length followed the machine's speed: a block that sank 52 %
into its support stopped a run on a slow machine and not on a fast one, and asking for 1 s instead
of 0.1 s moved the stop from 0.020 to 0.028 s."""


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
        f"(kn = E / l with E in Pa, not MPa), or the blocks far too heavy for it (block {a!r}: {m.block_mass[owner[k]]:.3g} kg; "
        "a density is in kg/m^3, not N/m^3)"
    )


PARALLEL_MIN_BLOCKS = 200
"""Models with at least this many blocks run the joint law on all of Numba's threads by default
(``threads`` of :func:`simulate`); smaller ones run serially (a step of a few blocks is shorter
than waking the threads: the paper's Table 2 block, 2 s of free rocking, took 0.039 s on two
threads against 0.008 s on one, 2026-12-01)."""


_KERNELS_LOADED: set[int] = set()
"""The thread counts whose start and step kernels this process has loaded (:func:`_load_kernels`)."""


def _load_kernels(threads: int) -> None:
    """Load the compiled kernels of a model's start and of its steps on ``threads`` threads, once
    per process, by running a block on a foundation for a few steps: from Numba's cache this takes
    0.1 to 0.8 s (compiled on an empty cache, minutes), which the first run's ``runtime_s`` and
    ``kernel_s`` counted before 2026-11-29 (the first of 400 equal runs of a sweep 3.4 times the
    others, the SP/MP ratios of a study's first case off by as much). Every model has the same
    array types, so one load serves them all."""
    if threads in _KERNELS_LOADED:
        return
    _KERNELS_LOADED.add(threads)  # first: the run below would come here again
    from .materials import JointMaterial
    from .model import ModelBuilder

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e8)
    b.add_box(1.0, 1.0, 0.2, base_center=(0.0, 0.0, -0.2), driven=True, name="foundation")
    b.add_box(0.2, 0.3, 0.5, density=2000.0, name="block")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an undamped model is warned about
        model = b.finalize()
        _load_law_first(model)
        run_model(model, 1e-3, record_interval=1e-3, progress=False, threads=threads)


def _load_law_first(model: Model) -> None:
    """Load the joint law's own compiled code (:func:`rockdem.kernels.forces._law_pairs`) before
    any kernel that calls it, so that every step of the process runs it (docs/performance.md,
    "The law's own code").

    Numba links a copy of each kernel a kernel calls into the caller's compiled code, optimized
    again there, and a call runs the copy that was loaded first in the process (the copies are
    weak symbols). Compiled on an empty cache, the callee's own code comes first; loaded from the
    cache, the copy inside ``advance`` did, and the 1000-brick wall's step took 1.3 to 1.5 times as
    long (2026-11-30: 1.97 against 1.39 ms, the same process, the same answers). A call over no
    pairs loads it and computes nothing (after the first, it only finds it loaded)."""
    from .kernels.forces import _law_pairs
    from .state import _allocate

    s, sc = _allocate(model)
    _law_pairs(model.arrays, s, sc, 0, 0, 0.0, False, False, sc.poly)


def _threads(threads: int | None, blocks: int) -> int:
    """The number of threads a run uses (``threads`` of :func:`simulate`)."""
    available = numba.config.NUMBA_NUM_THREADS
    if threads is None:
        return available if blocks >= PARALLEL_MIN_BLOCKS else 1
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads must be a positive integer (or None: automatic), got {threads!r}")
    if threads > available:
        raise ValueError(f"threads = {threads} is more than the {available} threads Numba was started with: give at most "
                         f"{available}, or set NUMBA_NUM_THREADS before starting Python")
    return int(threads)


def _on_threads(n: int, step_chunk: Any, *args: Any) -> Any:
    """``step_chunk(*args)`` on ``n`` of Numba's threads (the caller's setting restored after)."""
    if n == 1:
        return step_chunk(*args)
    before = numba.get_num_threads()
    numba.set_num_threads(n)
    try:
        return step_chunk(*args)
    finally:
        numba.set_num_threads(before)


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
    if info.damping_ratio > MAX_DAMPING_RATIO:
        explicit = duration / info.dt * (math.hypot(1.0, info.damping_ratio) + info.damping_ratio)
        raise ValueError(
            f"SP damping ratio beta omega_max / 2 = {info.damping_ratio:.3g} at the highest contact frequency is "
            f"implausibly high (limit {MAX_DAMPING_RATIO:g}; explicit dashpots would need about {explicit:.3g} steps) "
            f"{where}"
        )
    steps = duration / info.dt
    if steps > max_steps:
        raise ValueError(
            f"the run of {duration:.4g} s needs about {steps:.3g} steps of {info.dt:.3g} s (limit max_steps = "
            f"{max_steps:.3g}): shorten the duration, or the contacts are implausibly stiff or the damping "
            f"implausibly high {where}; raise max_steps if this is intended"
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
        reason = "left the model's extent (fell through its support or flew away: check the joint stiffness)"
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


PROGRESS_LOG_INTERVAL = 30.0
"""Seconds between progress updates when stderr is not a terminal (a log file, a batch job): the
bar's 0.1 s updates wrote some 700 lines of carriage returns into the log of a 3 min run."""


def _progress_bar(duration: float, start: float = 0.0) -> Any:
    from tqdm.auto import tqdm

    # a terminal, or a notebook's widget (tqdm.auto picks it in Jupyter, where stderr is no tty)
    live = bool(getattr(sys.stderr, "isatty", lambda: False)()) or "notebook" in tqdm.__module__
    return tqdm(
        total=duration,
        initial=start,
        unit="s",
        desc="rockdem",
        mininterval=0.1 if live else PROGRESS_LOG_INTERVAL,
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
    floor = LIFT_1MM * float(ds.block_mass.values[ds.block_free.values.astype(bool)].sum())
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
        if not np.all(np.isfinite(p)):
            raise ValueError(f"monitor {name!r}: the point (x, y, z) must be finite [m], got {tuple(p.tolist())}")
        try:
            b = model.block_id(blk) if isinstance(blk, str) else operator.index(blk)
        except KeyError as exc:  # (raised as a KeyError from here before 2026-12-08)
            raise ValueError(f"monitor {name!r}: {exc.args[0]}") from None
        except TypeError:
            raise ValueError(f"monitor {name!r}: give its block by name or id, got {blk!r}") from None
        if not 0 <= b < model.block_count:
            raise ValueError(f"monitor {name!r}: block id {b} out of range")
        out[str(name)] = (b, p)
    return out
