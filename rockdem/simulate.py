"""``simulate()``: the one entry point that owns the time loop, the recording and the progress.

The loop runs in compiled chunks (:func:`rockdem.kernels.step.advance`); Python only sees chunk
boundaries, where it updates the progress bar. An interrupted run (Ctrl-C) returns the frames
computed so far, flagged ``interrupted``.
"""

from __future__ import annotations

import math
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
    ds = build_dataset(
        model,
        rec,
        monitors=mon,
        attrs={
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
        },
    )
    return snaps.attach(ds)


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
