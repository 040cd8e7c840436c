"""The batch path of studies: summary rows of many runs without what a single run needs.

A single run (:func:`rockdem.studies.run_spec`, ``rockdem run``) parses its case, builds its model,
runs it, assembles the full xarray Dataset (and saves it) and summarises that. A study wants only
the summary row, many times over models that differ in a record, a scale factor or a damping value.
:func:`run_batch` keeps, per process, a :class:`rockdem.case.CaseTemplate` per distinct specimen
(:func:`rockdem.case.template_key`): the next run of the same specimen swaps its damping and input
arrays (ground motion, body acceleration) into the model's ``ModelArrays`` instead of rebuilding
blocks, interface points and contact geometry; ground-motion files are read once per process. It
runs :func:`rockdem.simulation.run_model` (no Dataset, no NetCDF) and summarises the raw frames.

Both paths build their rows with :func:`summary_row` on :class:`Frames` computed by the same
functions (:func:`rockdem.results.reference_rotations` and friends, called by ``build_dataset`` as
well), from the same models (``CaseTemplate.derive`` gives :func:`rockdem.case.parse_case`'s
arrays), so a spec's row is identical, bit for bit (timings aside), whichever path computed it
(``tests/test_batch.py``).
"""

from __future__ import annotations

import json
import signal
import threading
import time
import warnings
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

from .analysis import block_thickness_of, eta_of, fallen, free_rocking_run, lowest_vertex_height, summarize
from .case import Case, CaseTemplate, template_key
from .kernels.layout import COUNT_FAILED_SHEAR, COUNT_FAILED_TENSION, E_POTENTIAL, ENERGY_NAMES
from .results import block_eta, damping_attrs, energy_check, ground_displacement, monitor_displacements, reference_rotations, rocking_angles

__all__ = ["Frames", "frames_from_dataset", "frames_from_run", "summary_row", "run_batch", "batch_row", "case_of", "TEMPLATE_CACHE"]

TEMPLATE_CACHE = 16
"""Case templates (distinct specimens) kept per process."""

_TEMPLATES: OrderedDict[str, CaseTemplate] = OrderedDict()
_LOCK = threading.Lock()  # Dask workers may run several tasks in threads


class Frames(NamedTuple):
    """What a summary row reads of a run (T recorded frames, nb blocks, nm monitors).

    Attributes:
        time: (T,) [s].
        rocking: (T, nb) rotation about the rocking axis [rad].
        position: (T, nb, 3) centroids [m].
        quaternion: (T, nb, 4) orientations.
        monitor: (T, nm, 3) monitor displacements relative to the ground [m].
        failed_shear, failed_tension: sub-contacts failed at the last frame.
        block_free: (nb,) bool.
        block_eta: (nb,) instability angle of each free block [rad] (NaN for driven ones).
        vertex_local: (nv, 3) vertices in the body frames [m]; block_vertex_start: (nb+1,).
        energy: (T, len(ENERGY_NAMES)) recorded energies [J], columns as ``ENERGY_NAMES``, the
            potential energy counted from the first frame (as the Dataset stores it).
        attrs: the result's attributes (steps, dt, runtime_s, diverged..., stop_reason..., the loading's).
        position_reference: (nb, 3) centroids in the reference (untilted) pose [m].
        rotation_end: (nb, 3) rotation vectors from the reference pose at the last frame [rad].
        ground_end: (3,) displacement of the ground at the last frame [m].
    """

    time: np.ndarray
    rocking: np.ndarray
    position: np.ndarray
    quaternion: np.ndarray
    monitor: np.ndarray
    failed_shear: int
    failed_tension: int
    block_free: np.ndarray
    block_eta: np.ndarray
    vertex_local: np.ndarray
    block_vertex_start: np.ndarray
    energy: np.ndarray
    attrs: Mapping[str, Any]
    position_reference: np.ndarray
    rotation_end: np.ndarray
    ground_end: np.ndarray


def frames_from_dataset(ds: Any) -> Frames:
    """The frames of a result Dataset (a single run, or a result file read back)."""
    return Frames(
        np.asarray(ds.time.values, dtype=float), ds.rocking_angle.values, ds.block_position.values,
        ds.block_quaternion.values, ds.monitor_displacement.values, int(ds.contacts_failed_shear.values[-1]),
        int(ds.contacts_failed_tension.values[-1]), np.asarray(ds.block_free.values, dtype=bool),
        ds.block_eta.values if "block_eta" in ds else np.full(ds.sizes["block"], np.nan),
        ds.vertex_local.values, ds.block_vertex_start.values,
        np.stack([np.asarray(ds[n].values, dtype=float) for n in ENERGY_NAMES], axis=1), dict(ds.attrs),
        # results before 2026-11-27 lack the reference pose: the first frame stands for it
        ds.block_position_reference.values if "block_position_reference" in ds else ds.block_position.values[0],
        ds.block_rotation.values[-1] if "block_rotation" in ds else np.zeros((ds.sizes["block"], 3)),
        ds.ground_displacement.values[-1] if "ground_displacement" in ds else np.zeros(3),
    )


def frames_from_run(case: Case, out: Any) -> Frames:
    """The frames of a :func:`rockdem.simulation.run_model` output, computed as
    :func:`rockdem.results.build_dataset` computes them; attrs as ``run_case`` gives them."""
    model, rec = case.model, out.records
    rel_ref, rotvec = reference_rotations(model, rec.quaternion)
    u_ground = ground_displacement(model, rec.position)
    mon = monitor_displacements(model, rel_ref, rec.position, out.monitors) - u_ground[:, None]
    m = model.arrays
    attrs = {**out.attrs, **damping_attrs(model), "point_count": model.point_count, "gravity": m.gravity.tolist(), **case.attrs}
    energy = np.array(rec.energy, dtype=float)
    if len(energy):
        energy[:, E_POTENTIAL] -= energy[0, E_POTENTIAL]  # as build_dataset stores it
    return Frames(
        rec.time, rocking_angles(model, rotvec), rec.position, rec.quaternion, mon, int(rec.counts[-1, COUNT_FAILED_SHEAR]),
        int(rec.counts[-1, COUNT_FAILED_TENSION]), np.asarray(m.block_free, dtype=bool), block_eta(model),
        m.vertex_local, m.block_vertex_start, energy, attrs, model.position_ref, rotvec[-1], u_ground[-1],
    )


def summary_row(spec: Any, data: Mapping[str, Any], f: Frames) -> dict[str, Any]:
    """The summary row of a run of ``spec`` (a :class:`rockdem.studies.RunSpec`) with case dict
    ``data`` (keys: see :func:`rockdem.studies.run_spec`); ``wall_s`` is added by the caller.

    Raises:
        rockdem.cli.Interrupted: the run was interrupted, or a stop signal arrived as it finished
            (a KeyboardInterrupt: the study stops and stores no row of this run)."""
    a = f.attrs
    if a.get("interrupted") or a.get("stop_signal"):
        # Cut short by a stop signal (or with one pending): no row, so that a resumed study runs it
        # again, and the study stops as the signal asked.
        from .cli import Interrupted

        raise Interrupted(int(a.get("stop_signal") or signal.SIGINT))
    free = np.flatnonzero(f.block_free)
    b = int(free[0])
    t = f.time
    theta = np.asarray(f.rocking[:, b], dtype=float)
    # The block's own angle about the run's rocking axis (the result's block_eta, as rockdem run's
    # summary): before 2026-11-30 a block specimen took atan(width / height) whatever the load's
    # direction, so a block rocking along y (about its length) was judged against its width's angle.
    eta_used = eta_of(f.attrs, f.block_eta, b)
    starts = f.block_vertex_start
    z = lowest_vertex_height(f.position[:, b], f.quaternion[:, b], f.vertex_local[starts[b] : starts[b + 1]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # e_a (paper Eq. 6) only for free rocking, as rockdem run's summary (an earthquake's read 1.01 to 1.18)
        free_rocking = free_rocking_run(a, released=bool(np.any(f.rocking[0, free] != 0.0)),
                                        ground_moved=bool(np.any(f.ground_end != 0.0)))
        s = summarize(t, theta, eta=eta_used, z=z, free_rocking=free_rocking)
    npts = max(int(a.get("point_count", 1)), 1)
    row: dict[str, Any] = {"id": spec.id, **spec.inputs, "status": "diverged" if a.get("diverged") else "ok"}
    if a.get("diverged"):
        row["diverged_time_s"] = float(a["diverged_time"])
    if a.get("stop_rule", "off") != "off":
        row["stop_reason"] = a.get("stop_reason")
        row["stop_time_s"] = float(a["stop_time"]) if a.get("stop_reason") else None
        if a.get("stop_reason") in ("overturned", "fell"):
            row["stop_block"] = a.get("stop_block")
    row["max_rotation_rad"] = float(s["max_rotation_rad"])
    eta = eta_used or s.get("eta_rad")
    row["max_rotation_over_eta"] = float(s["max_rotation_rad"] / eta) if eta else None
    row["overturned"] = bool(s.get("overturned", False))
    row["fallen_blocks"] = int(np.count_nonzero(fallen(
        f.position_reference[free], f.position[-1, free], block_thickness_of(f.vertex_local, starts, free), ground=f.ground_end,
        rotation=f.rotation_end[free], eta=f.block_eta[free], gravity=a.get("gravity", (0.0, 0.0, -9.81)))))
    row["residual_rad"] = float(s["residual_rad"])
    if f.monitor.shape[1]:
        u = np.asarray(f.monitor[:, 0, :], dtype=float)
        uh = np.linalg.norm(u[:, :2], axis=1)
        row["max_disp_m"] = float(uh.max())
        row["residual_disp_m"] = float(u[-1, 0])
    row["e_a_mean"] = float(s["e_a_mean"]) if "e_a_mean" in s else None
    row["bounce_max_m_s"] = float(s["bounce_max_m_s"]) if "bounce_max_m_s" in s else None
    row["failed_shear_fraction"] = f.failed_shear / npts
    row["failed_tension_fraction"] = f.failed_tension / npts
    check = energy_check(f.energy)
    row["energy_created_J"] = check.created
    row["energy_error_J"] = check.balance_error
    row["energy_scale_J"] = check.scale
    row["steps"] = int(a["steps"])
    row["dt"] = float(a["dt"])
    row["dt_min"] = float(a["dt_min"])
    row["runtime_s"] = float(a["runtime_s"])
    row["kernel_s"] = float(a.get("kernel_s", a["runtime_s"]))
    if a.get("beta_mode"):  # an automatic beta: the value chosen and how (rockdem.beta_choice)
        row["beta_s"] = float(a["beta"])
        row["beta_pairs"] = str(a["beta_pairs"])
        for key in ("beta_target_value", "beta_achieved_e_a", "beta_iterations", "beta_search_time_s"):
            if key in a:
                row[key] = float(a[key])
    if spec.history:
        row["history"] = _history(spec, t, theta, f.monitor, a)
    return row


def _history(spec: Any, t: np.ndarray, theta: np.ndarray, monitor: np.ndarray, attrs: Mapping[str, Any]) -> dict[str, Any]:
    """Decimated history (time, rotation, first monitor's x displacement; with ``spec.history_xyz``
    every monitor's three components as ``monitor_xyz``). A run stopped at rest is continued at
    rest to its duration (same interval), so that it compares with full runs."""
    step = 1
    if spec.history_interval and len(t) > 1:
        step = max(1, int(round(spec.history_interval / (t[1] - t[0]))))
    tt, rot = t[::step], theta[::step]
    disp = monitor[::step, 0, 0].astype(float) if monitor.shape[1] else None
    xyz = monitor[::step].astype(float) if getattr(spec, "history_xyz", False) else None
    if attrs.get("stop_reason") == "rest" and len(t) > 1:
        h = step * float(attrs["record_interval"])
        n = int(np.floor((float(attrs["duration"]) - tt[-1]) / h + 1e-9))
        if n > 0:
            tt = np.concatenate([tt, tt[-1] + h * np.arange(1, n + 1)])
            rot = np.concatenate([rot, np.full(n, theta[-1])])
            if disp is not None:
                disp = np.concatenate([disp, np.full(n, float(monitor[-1, 0, 0]))])
            if xyz is not None:
                xyz = np.concatenate([xyz, np.repeat(monitor[-1:].astype(float), n, axis=0)])
    hist: dict[str, Any] = {"time": tt.tolist(), "rotation": rot.tolist()}
    if disp is not None:
        hist["displacement"] = disp.tolist()
    if xyz is not None:
        hist["monitor_xyz"] = xyz.tolist()
    return hist


def case_of(data: Mapping[str, Any]) -> Case:
    """The case of a case dict, through this process's template cache (see the module notes)."""
    key = template_key(data)
    with _LOCK:
        tpl = _TEMPLATES.get(key)
        if tpl is not None:
            _TEMPLATES.move_to_end(key)
    if tpl is not None:
        return tpl.derive(data)
    tpl = CaseTemplate(data)
    with _LOCK:
        _TEMPLATES[key] = tpl
        while len(_TEMPLATES) > TEMPLATE_CACHE:
            _TEMPLATES.popitem(last=False)
    return tpl.case


_STARTS: OrderedDict[str, Any] = OrderedDict()


def _start(data: Mapping[str, Any], case: Case) -> Any:
    """The run's :class:`rockdem.simulation.Start` (a copy), kept per specimen, damping (with the
    per-pair betas of an automatic beta) and timestep options: a derived case's model differs from
    its template's in the inputs only."""
    from .simulation import prepare_start

    r = case.run
    key = json.dumps([template_key(data), case.model.damping.__dict__, case.model.arrays.mat_beta.tolist(), r.timestep_rule,
                      r.safety, r.resolution, r.dt, r.dashpots], sort_keys=True, default=str)
    start = _cached(_STARTS, key, lambda: prepare_start(case.model, timestep_rule=r.timestep_rule, safety=r.safety,
                                                        resolution=r.resolution, dt=r.dt, dashpots=r.dashpots))
    return start.copy()


_SETTLED: OrderedDict[str, Any] = OrderedDict()


def _cached(store: OrderedDict[str, Any], key: str, make: Any) -> Any:
    """``store[key]``, made by ``make()`` when absent (outside the lock: it may run a model); the
    last :data:`TEMPLATE_CACHE` used are kept."""
    with _LOCK:
        value = store.get(key)
        if value is not None:
            store.move_to_end(key)
    if value is None:
        value = make()
        with _LOCK:
            store[key] = value
            while len(store) > TEMPLATE_CACHE:
                store.popitem(last=False)
    return value


def _settled(data: Mapping[str, Any], case: Case) -> Any:
    """The settled start of a case with ``[run] settle`` (:func:`rockdem.run_cli.settled_start`, a
    copy), kept per specimen and timestep options: the settling does not depend on the loading."""
    from .run_cli import settled_start

    r = case.run
    key = json.dumps([template_key(data), r.settle, r.timestep_rule, r.safety, r.resolution, r.dt], sort_keys=True, default=str)
    ck = _cached(_SETTLED, key, lambda: settled_start(case)[0])
    return ck.reset_clock()


def batch_row(spec: Any) -> dict[str, Any]:
    """The summary row of one spec by the batch path (raises as :func:`rockdem.studies.run_spec`)."""
    from .run_cli import run_options
    from .simulation import run_model

    t0, c0 = time.perf_counter(), time.process_time()
    data = spec.case_dict()
    case = case_of(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # One thread per run: a study spreads its runs over the cores (and Numba's default
        # workqueue threads must not be started from two Dask worker threads at once).
        if case.run.settle > 0.0:  # from the blocks settled under gravity ([run] settle), once per specimen
            out = run_model(case.model, **run_options(case), progress=False, initial=_settled(data, case), threads=1)
        else:
            out = run_model(case.model, **run_options(case), progress=False, start=_start(data, case), threads=1)
    row = summary_row(spec, data, frames_from_run(case, out))
    row["wall_s"] = time.perf_counter() - t0
    row["cpu_s"] = time.process_time() - c0
    return row


def run_batch(specs: Sequence[Any]) -> list[dict[str, Any]]:
    """Summary rows of many specs in this process (a task of a study): one row per spec, an error
    row (status "error") instead of an exception."""
    return [_safe(batch_row, s) for s in specs]


def _safe(fn: Any, spec: Any) -> dict[str, Any]:
    try:
        return fn(spec)
    except Exception as exc:  # noqa: BLE001 - a failed run is recorded, not fatal
        return {"id": spec.id, **spec.inputs, "status": "error", "error": f"{type(exc).__name__}: {exc}"}
