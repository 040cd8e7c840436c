"""``simulate()``: the one entry point that owns the time loop, the recording and the progress.

The loop runs in compiled chunks (:func:`rockdem.kernels.step.advance`); Python only sees chunk
boundaries, where it updates the progress bar. An interrupted run (Ctrl-C) returns the frames
computed so far, flagged ``interrupted``.
"""

from __future__ import annotations

import math
import warnings
import time as _time
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from .kernels.layout import Records, new_records
from .kernels.step import advance
from .model import Model
from .results import build_dataset
from .snapshots import ContactSnapshots
from .state import initial_state
from .timestep import TimestepInfo, stable_timestep

__all__ = ["simulate", "Monitor"]

Monitor = tuple[int | str, Sequence[float]]
"""A monitor point: (block id or name, world coordinates in the reference configuration [m])."""

_MAX_RECORD_BYTES = 2 * 1024**3


def simulate(
    model: Model,
    duration: float,
    *,
    dt: float | None = None,
    timestep_rule: str = "bound",
    safety: float = 0.9,
    record_interval: float = 0.002,
    monitors: Mapping[str, Monitor] | None = None,
    progress: bool | None = None,
    contact_interval: float | None = None,
) -> xr.Dataset:
    """Run ``model`` for ``duration`` seconds and return the recorded histories.

    Args:
        model: a finalized model.
        duration: simulated time [s].
        dt: timestep [s]; default automatic (see :mod:`rockdem.timestep`); refused above the bound.
        timestep_rule: "bound" (default) or "3dec" (0.2 sqrt(m_min/k_max)).
        safety: fraction of the stable bound for the automatic timestep.
        record_interval: time between recorded frames [s] (rounded to whole steps).
        monitors: named points whose world displacement is recorded, e.g.
            ``{"top": ("wall", (0.1, 0.0, 2.0))}``: block and world position [m] in the reference
            configuration (before any initial tilt); displacements are measured from there.
        progress: show a progress bar; default: only for runs expected to last over 2 s.
        contact_interval: time between sub-contact snapshots [s] (see :mod:`rockdem.snapshots`);
            default None: none recorded.

    Returns:
        An xarray Dataset (see :func:`rockdem.results.build_dataset` for the variables).
    """
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be a positive time [s], got {duration!r}")
    if not (math.isfinite(record_interval) and record_interval > 0):
        raise ValueError(f"record_interval must be a positive time [s], got {record_interval!r}")
    mon = _check_monitors(model, monitors or {})
    snaps = ContactSnapshots(model, contact_interval)
    info: TimestepInfo = stable_timestep(model, rule=timestep_rule, safety=safety, dt=dt)
    frames = int(math.floor(duration / record_interval + 1e-9)) + 1
    need = frames * model.block_count * 13 * 8
    if need > _MAX_RECORD_BYTES:
        raise ValueError(
            f"recording {frames} frames of {model.block_count} blocks needs {need / 1e9:.1f} GB; "
            f"raise record_interval (now {record_interval} s)"
        )
    wall0 = _time.perf_counter()
    state, scratch = initial_state(model)
    state.clock[1] = state.clock[2] = state.clock[4] = info.dt
    state.clock[3] = safety
    snaps.take(state)
    rec = new_records(frames, model.block_count, int(np.count_nonzero(~model.arrays.block_free.astype(bool))))
    m = model.arrays
    frame = 0
    chunk = 2000 * info.dt  # simulated seconds per compiled call, adapted to ~0.25 s of wall time
    bar = None
    interrupted = False
    try:
        t_end = duration + 0.5 * info.dt  # one step past the end records the frame at t = duration
        while state.clock[0] < t_end and frame < frames:
            t_before = float(state.clock[0])
            stop = snaps.clip(min(t_end, t_before + chunk))
            t0 = _time.perf_counter()
            frame = advance(m, state, scratch, stop, record_interval, rec, frame)
            elapsed = _time.perf_counter() - t0
            snaps.take(state)
            chunk = min(chunk * 4.0, max(state.clock[1], chunk * 0.25 / max(elapsed, 1e-6)))
            if bar is None and (progress or (progress is None and _time.perf_counter() - wall0 > 2.0)):
                from tqdm.auto import tqdm

                bar = tqdm(total=round(duration, 6), unit="s", desc="rockdem", initial=round(float(state.clock[0]), 6))
            elif bar is not None:
                bar.update(round(float(state.clock[0]) - t_before, 6))
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if bar is not None:
            bar.close()
    runtime = _time.perf_counter() - wall0
    rec = Records(*(a[:frame] for a in rec))
    attrs = {
            "dt": info.dt,
            "dt_min": float(state.clock[4]),
            "dt_critical": info.critical,
            "omega_max": info.omega_max,
            "sp_factor": info.sp_factor,
            "timestep_rule": info.rule,
            "steps": int(state.step[0]),
            "runtime_s": runtime,
            "duration": duration,
            "record_interval": record_interval,
            "interrupted": int(interrupted),
    }
    ds = build_dataset(model, rec, monitors=mon, attrs=attrs)
    bad = first_diverged_frame(ds)
    if bad is not None:
        t_bad = float(rec.time[bad])
        warnings.warn(
            f"the simulation diverged at t = {t_bad:.4g} s (energy balance broken or non-finite state); "
            "the result holds the frames before it (attrs diverged = 1). Check the contact tolerance, "
            "the timestep safety and the joint strengths.",
            RuntimeWarning,
            stacklevel=2,
        )
        rec = Records(*(a[:bad] for a in rec))
        ds = build_dataset(model, rec, monitors=mon, attrs={**attrs, "diverged": 1, "diverged_time": t_bad})
    return snaps.attach(ds)


DIVERGENCE_ERROR = 0.2
"""Energy-balance error, as a fraction of the run's energy scale so far, that marks a divergence."""


def first_diverged_frame(ds: xr.Dataset) -> int | None:
    """Index of the first frame with a non-finite state or an energy-balance error above
    :data:`DIVERGENCE_ERROR` of the energy scale reached so far (kinetic + elastic + |potential| +
    dissipated + |work|, at least the work of lifting the free blocks by 1 mm); None if the run stayed
    sound. A converged explicit run keeps the error
    near 1e-3; a numerical blow-up (e.g. a contact cascade) breaks it before the state overflows."""
    err = np.abs(ds.energy_balance_error.values)
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
