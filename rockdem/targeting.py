"""beta targeted to a restitution: the SP damping for which the model's own impacts give a target e.

The paper's DeJong rule beta = 2 / omega_e over-damped the §4.1 parapet (0.00305 s against the best
fit 0.00068 s) and, as measured with rockdem, the apparent restitution it gives grows with the number
of interface points (Fig. 9B). Instead of a formula, ask the model: release its rocking body from a
tilt, let it rock, measure the apparent restitution e_a from the rotation peaks (paper Eq. 6) and
adjust beta until e_a equals the target (Housner's e_eta, 0.95 e_eta as Sorrentino
et al. suggest, or a measured value).

**The probe.** A copy of the model (:meth:`rockdem.model.ModelBuilder.released_copy`) with the
released body (the blocks of the model's own free-rocking release, else every free block, as one
rigid assembly) on its supports only (the blocks whose faces carry its base; others such as a
façade's return walls are left out, so the probe isolates the rocking interface), at rest, no
ground motion, all else as in the model (geometry, interface points, materials, alpha). It is
released from ``fraction`` x eta (the model's own release fraction when it was tilted, else
:data:`DEFAULT_RELEASE_FRACTION`) towards the model's tilt direction (else rocking_axis x up).

**The run.** Housner's exact quarter period t_q(theta) of the assembly (p^2 = M g R / I_pivot,
:func:`rockdem.housner.quarter_period`) predicts when the peaks come if every impact had the
target restitution: t_q(theta_0) + 2 sum_k t_q(theta_k) up to the last peak measured; the probe
runs :data:`DURATION_MARGIN` times that (the elastic base makes the DEM block rock a little slower),
twice as long again while it has not made them, at most :data:`MAX_PROBE_QUARTERS` release quarter
periods. Frames every t_q of the smallest measured half cycle / :data:`SAMPLES_PER_QUARTER` (the
peaks are refined by a parabola through three samples: far below the 0.1 % that matters here).
e_a is the mean of Eq. 6's e_a(1..n) over the half-cycle peaks of the released blocks' mass-weighted
rotation, peaks below 2 % of theta_0 not counted, exactly as :func:`rockdem.analysis.summarize`
(and ``rockdem run``) measures a free-rocking run. By default (``probe_impacts = 0``) the probe
measures its whole free-rocking decay: in the DEM the impacts of small amplitude lose relatively
more energy (e_a(n) of the paper's Table 2 block falls from 0.936 to 0.896 over 13 impacts at a
constant beta), so matching only the first two impacts left the free-rocking runs' mean e_a of the benchmark
up to 2.2 % below the target; ``probe_impacts = N`` matches the first N
impacts only (the large-amplitude ones, shorter probes). A search takes 0.3 to 5 s
(``benchmarks/bench_damping.py``).

**The search.** e_a(beta) falls with beta over the range that matters, but not near beta = 0 (an
undamped squat block can lose more energy by bouncing than a lightly damped one). So the bracket
starts from the rocking pair's critical beta 2 / omega (:mod:`rockdem.interfaces`) and steps by
:data:`BRACKET_FACTOR` up (to at most xi = beta omega_max / 2 = :data:`MAX_XI`) or down until e_a
crosses the target, then :func:`scipy.optimize.brentq` finds the root in ln beta to
:data:`LOG_BETA_TOL` (0.5 % of beta). e_a(beta) of a DEM model has small steps (the timestep and
contact events change with beta; a squat block's bounce is chaotic), so the beta kept is the probe
run closest to the target, with a warning when it is more than :data:`CLOSE` off. A target outside
the reachable range is an error that lists the e_a the probes reached.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from ._warn import warn_user
from .analysis import SUMMARY_PEAK_PROMINENCE, apparent_restitution, half_cycle_peaks
from .beta_choice import BETA_CRITICAL, BetaChoice, PairBeta, RestitutionTarget
from .housner import HousnerBlock, quarter_period
from .interfaces import Body, critical_pair_betas, face_contacts, model_bodies
from .kernels.rotation import quats_to_matrices
from .model import Damping, Model, ModelBuilder, ReleaseGeometry
from .simulation import simulate
from .timestep import stable_timestep

__all__ = [
    "DEFAULT_RELEASE_FRACTION",
    "Probe",
    "ProbeResult",
    "make_probe",
    "probe_restitution",
    "choose_beta",
]

DEFAULT_RELEASE_FRACTION = 0.5
"""Release of the probe when the model has no free-rocking release of its own [-]: half of eta,
the middle of the amplitudes a rocking body goes through, safely below overturning even where a
soft base with many interface points lowers the effective instability angle."""
MAX_PROBE_QUARTERS = 40
"""Longest probe run, in quarter periods of the release amplitude (10 full cycles)."""
DURATION_MARGIN = 1.3
"""Probe duration over Housner's time to the last measured peak."""
SAMPLES_PER_QUARTER = 50
"""Recorded frames per quarter period of the smallest measured half cycle."""
BRACKET_FACTOR = 3.0
"""Step of the bracketing search on beta."""
BRACKET_STEPS = 7
"""Most bracketing steps down from the critical beta (3^-7 ~ 1/2000 of it)."""
MAX_XI = 30.0
"""Largest beta tried: xi = beta omega_max / 2 at most this (omega_max the probe's highest frequency
at the release), i.e. an SP timestep reduction sqrt(1 + xi^2) - xi of at least 1/60 with explicit
dashpots: heavier damping would make every explicit run of the model over 60 times longer than an
undamped one (implicit dashpots, the default, keep the undamped step, but a damping ratio of 30 at the
highest contact frequency is far past any restitution target). The 0.95 e_eta targets
of blocks of H/B = 1.5 to 20 with 2 to 15 points need xi = 2 to 7 (benchmarks/bench_damping.py)."""
MAX_PROBE_WORK = 5e8
"""Largest probe run, in interface points of the probe model x steps (only a block's contacting
faces' points work at each step: a single block's probe runs ~1e6 steps per second, a few seconds at
most). The single blocks of the benchmark need 1e5 to 1e8 (E = 18 GPa with 15 points: 6e7); the §4.1
parapet discretised brick by brick needs 3e9 at its first trial (stiff brick joints, a small step that
SP damping shrinks further: hours for a search), so its search is refused with the estimate and the
way around it."""
CLOSE = 0.01
"""A targeted e_a further than this from the target (relative) is reported with a warning: e_a(beta)
jumps there (a block that stops rebounding, a squat block's chaotic bounce)."""
LOG_BETA_TOL = 0.005
"""Tolerance of the root in ln(beta) (0.5 % of beta)."""


@dataclass(frozen=True)
class Probe:
    """A released body on its supports, ready for trial betas.

    Attributes:
        model: the probe model (beta 0 everywhere; trials replace ``mat_beta``).
        released: (k,) ids of the released blocks in ``model``. weights: (k,) their masses [kg].
        geometry: the release (theta_0, eta, pivot, axis).
        fraction: release as a fraction of eta [-].
        p: Housner's frequency parameter of the assembly sqrt(M g R / I_pivot) [rad/s].
        rocking_pairs: the group pairs (sorted names) between the released body and its supports.
    """

    model: Model
    released: NDArray[np.int64]
    weights: NDArray[np.float64]
    geometry: ReleaseGeometry
    fraction: float
    p: float
    rocking_pairs: tuple[tuple[str, str], ...]

    def quarter(self, theta: float) -> float:
        """Housner's exact time from a rest at ``theta`` [rad] to the impact [s]."""
        eta = self.geometry.eta
        r = 1.0  # any R: the shape of the motion depends on eta only; time scales with 1 / p
        block = HousnerBlock(2.0 * r * math.sin(eta), 2.0 * r * math.cos(eta))
        return quarter_period(block, min(theta, 0.999 * eta)) * block.p / self.p

    def duration(self, e: float, impacts: int) -> tuple[float, float]:
        """(run duration [s], smallest measured quarter period [s]) to the ``impacts``-th peak (0: the
        first peak below :data:`~rockdem.analysis.SUMMARY_PEAK_PROMINENCE` of the release) if every
        impact had Housner's restitution ``e``; at most :data:`MAX_PROBE_QUARTERS` release quarter periods."""
        eta, th0 = self.geometry.eta, self.geometry.angle
        energy0 = 1.0 - (1.0 - th0 / eta) ** 2  # Eq. 6's linearised energy
        floor = SUMMARY_PEAK_PROMINENCE * th0
        q0 = self.quarter(th0)
        total, last, k = q0, q0, 0
        while total < MAX_PROBE_QUARTERS * q0:
            k += 1
            th = eta * (1.0 - math.sqrt(max(1.0 - e ** (2 * k) * energy0, 0.0)))
            last = self.quarter(max(th, 1e-3 * th0))
            total += last
            if (impacts and k >= impacts) or (not impacts and th < floor):
                break
            total += last
        return DURATION_MARGIN * min(total, MAX_PROBE_QUARTERS * q0), last


@dataclass(frozen=True)
class ProbeResult:
    """One probe run.

    Attributes:
        beta: the trial beta [s]. e_a: mean of Eq. 6's e_a(1..n) [-]. per_impact: (n,) e_a(n).
        peaks: (n,) the peak rotations after impacts 1..n [rad]. runtime: wall time [s]. steps.
        duration: simulated time [s].
    """

    beta: float
    e_a: float
    per_impact: NDArray[np.float64]
    peaks: NDArray[np.float64]
    runtime: float
    steps: int
    duration: float


def _pair_key(a: str, b: str) -> tuple[str, str]:
    return (a, b) if a <= b else (b, a)


def make_probe(
    builder: ModelBuilder,
    model: Model,
    *,
    fraction: float | None = None,
    bodies: list[Body] | None = None,
    damping: Damping | None = None,
) -> Probe:
    """The free-rocking probe of a model (module docstring).

    Args:
        builder: the builder ``model`` was finalized from.
        model: the finalized model (its rocking axis, damping, contact tolerance).
        fraction: release as a fraction of eta; default the model's own release, else
            :data:`DEFAULT_RELEASE_FRACTION`.
        bodies: the model's blocks in their reference pose (default :func:`model_bodies`).
        damping: the damping whose alpha and local damping the probe keeps (default the model's).

    Raises:
        ValueError: no gravity, or the released body rests on nothing.
    """
    rel = builder.release
    g = float(np.linalg.norm(model.arrays.gravity))
    if not g > 0:
        raise ValueError("beta = 'auto' needs gravity (a rocking body released from a tilt); this model has none: "
                         "give damping.beta as a number or 'critical'")
    up = -model.arrays.gravity / g
    if rel is not None:
        names, direction = list(rel.blocks), rel.direction
        frac = rel.fraction if fraction is None else fraction
    else:
        names = builder.block_names(driven=False)
        direction = np.cross(model.rocking_axis, up)
        frac = DEFAULT_RELEASE_FRACTION if fraction is None else fraction
    if not 0.0 < frac < 1.0:
        raise ValueError(f"damping.release_fraction must lie in (0, 1), got {frac!r} (the model's release fraction, or give one)")
    bodies = model_bodies(model) if bodies is None else bodies
    index = {b.name: k for k, b in enumerate(bodies)}
    released = {index[n] for n in names}
    supports: set[int] = set()
    pairs: set[tuple[str, str]] = set()
    for c in face_contacts(bodies):
        for own, other, n in ((c.a, c.b, c.normal), (c.b, c.a, -c.normal)):
            if own in released and other not in released and float(n @ up) < -0.5:
                supports.add(other)
                pairs.add(_pair_key(bodies[own].group, bodies[other].group))
    if not supports:
        raise ValueError(
            f"beta = 'auto': the released blocks {names[:4]} rest on no other block (no face below them within the "
            "interface gap): nothing to impact; give damping.beta as a number or 'critical'"
        )
    keep = names + [bodies[k].name for k in sorted(supports)]
    probe_builder, geo = builder.released_copy(names, frac, direction, keep=keep)
    d = model.damping if damping is None else damping
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the model's own warnings were given when it was finalized
        pm = probe_builder.finalize(
            damping=Damping(alpha=d.alpha, alpha_relative=d.alpha_relative, local=d.local),
            rocking_axis=geo.axis, contact_tolerance=model.arrays.contact_tol,
        )
    ids = np.array([pm.block_id(n) for n in names], dtype=np.int64)
    m = pm.arrays
    mass = m.block_mass[ids]
    rot = quats_to_matrices(pm.quaternion0[ids])
    rel_c = pm.position0[ids] - geo.pivot
    perp = rel_c - np.outer(rel_c @ geo.axis, geo.axis)
    inertia = sum(float(geo.axis @ (rot[k] * m.block_inertia[ids[k]]) @ rot[k].T @ geo.axis) for k in range(len(ids)))
    i_pivot = inertia + float(np.sum(mass * np.sum(perp**2, axis=1)))
    c = (mass @ rel_c) / mass.sum()
    r = float(np.linalg.norm(c - geo.axis * (c @ geo.axis)))
    p = math.sqrt(float(mass.sum()) * float(np.linalg.norm(m.gravity)) * r / i_pivot)
    return Probe(pm, ids, mass, geo, float(frac), p, tuple(sorted(pairs)))


def _beta_table(probe: Probe, beta: float, fixed: dict[tuple[str, str], float]) -> NDArray[np.float64]:
    """mat_beta of the probe: ``fixed`` betas on their pairs, ``beta`` on every other pair."""
    names = probe.model.group_names
    return np.array([[fixed.get(_pair_key(a, b), beta) for b in names] for a in names])


def probe_restitution(
    probe: Probe,
    beta: float,
    target: float,
    *,
    impacts: int = 0,
    fixed: dict[tuple[str, str], float] | None = None,
) -> ProbeResult:
    """Run the probe with ``beta`` [s] and measure e_a (module docstring).

    Args:
        probe: from :func:`make_probe`.
        beta: trial SP damping [s] on every pair not in ``fixed``.
        target: the target e, which sets the run's length [-].
        impacts: impacts to measure; 0: every half cycle down to 2 % of the release.
        fixed: betas [s] of pairs that do not vary (materials' own, per-interface critical ones).

    Raises:
        ValueError: the released body overturned or the run diverged.
    """
    model = replace(probe.model, arrays=probe.model.arrays._replace(mat_beta=_beta_table(probe, beta, fixed or {})))
    duration, quarter = probe.duration(min(max(target, 0.05), 0.999), impacts)
    work = duration / stable_timestep(model).dt * model.point_count
    if work > MAX_PROBE_WORK:
        raise ValueError(
            f"beta = 'auto': a probe run of this model with beta = {beta:.3g} s would take about {duration / stable_timestep(model).dt:.3g} "
            f"steps of {model.point_count} interface points ({work:.2g} point-steps, more than {MAX_PROBE_WORK:.0e}: minutes "
            "to hours for the search). Search on the equivalent single block (the same geometry and joint stiffness as one "
            "block, beta = 'auto') and give the beta found as a number, or use beta = 'critical'"
        )
    longest = DURATION_MARGIN * MAX_PROBE_QUARTERS * probe.quarter(probe.geometry.angle)
    eta, th0 = probe.geometry.eta, probe.geometry.angle
    floor = SUMMARY_PEAK_PROMINENCE * th0
    runtime = 0.0
    while True:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = simulate(model, duration, record_interval=min(quarter / SAMPLES_PER_QUARTER, duration / 50.0), progress=False)
        runtime += time.perf_counter() - t0
        if int(ds.attrs.get("diverged", 0)):
            raise ValueError(f"beta = 'auto': the probe run with beta = {beta:.4g} s stopped: {ds.attrs.get('diverged_message')}")
        t = ds.time.values
        theta = np.abs(ds.rocking_angle.values[:, probe.released] @ probe.weights / probe.weights.sum())
        if theta[-1] > eta:
            raise ValueError(
                f"beta = 'auto': the probe released from {probe.fraction:g} eta overturned (beta = {beta:.4g} s): on this "
                "model's elastic base the release is beyond its effective instability angle; give a smaller "
                "damping.release_fraction"
            )
        pk = half_cycle_peaks(t, theta, min_prominence=floor)
        after = np.abs(pk.value[1:])  # the first peak is the release at t = 0
        done = len(after) >= impacts if impacts else float(theta[t >= 0.75 * t[-1]].max()) < floor
        if done or duration >= longest:
            break
        duration = min(2.0 * duration, longest)
    after = after[:impacts] if impacts else after
    if len(after) == 0:  # came to rest after the first impact: no rebound at all
        return ProbeResult(beta, 0.0, np.zeros(1), np.zeros(0), runtime, int(ds.attrs["steps"]), duration)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ea = apparent_restitution(after, th0, eta)
    return ProbeResult(beta, ea.mean, ea.per_impact, after, runtime, int(ds.attrs["steps"]), duration)


def _fixed_pairs(model: Model, critical: dict[tuple[str, str], PairBeta], per_interface: bool,
                 rocking: tuple[tuple[str, str], ...]) -> dict[tuple[str, str], PairBeta]:
    """The pairs whose beta the search does not vary: materials' own, and with ``per_interface``
    every non-rocking pair at its critical beta."""
    out = {}
    for (ga, gb), mat in model.materials.items():
        key = _pair_key(ga, gb)
        if mat.beta is not None:
            out[key] = PairBeta(key, float(mat.beta), "material", how="the joint material's own beta")
        elif per_interface and key not in rocking:
            out[key] = critical[key]
    return out


def choose_beta(builder: ModelBuilder, model: Model, damping: Damping | None = None) -> BetaChoice:
    """Resolve ``damping.beta`` = ``"critical"`` or ``"auto"`` on ``model`` (called by ``finalize``;
    ``damping`` defaults to the model's own). Depends on the geometry, materials, gravity, release
    and contact tolerance of ``builder`` / ``model`` and on ``damping``, not on the loading's
    ground motion or body acceleration (the probe has none), so a model that differs in these only
    (:meth:`rockdem.model.Model.with_inputs`) reuses the choice.

    Returns:
        The :class:`~rockdem.beta_choice.BetaChoice`: a beta per group pair and how it was found.

    Raises:
        ValueError: the target cannot be reached, or no probe can be made (the message says why).
    """
    d: Damping = model.damping if damping is None else damping
    if d.beta_mode is None:
        raise ValueError(f"choose_beta: damping.beta is {d.beta!r}, not 'auto' or 'critical': nothing to choose")
    bodies = model_bodies(model)
    critical = critical_pair_betas(bodies, lambda a, b: model.materials[(a, b)].kn, damping_ratio=d.damping_ratio)
    if d.beta == BETA_CRITICAL:
        fixed = _fixed_pairs(model, critical, True, ())
        pairs = tuple(fixed.get(k, p) for k, p in sorted(critical.items()))
        return BetaChoice(BETA_CRITICAL, max(p.beta for p in pairs), pairs, per_interface=True)
    t_start = time.perf_counter()
    probe = make_probe(builder, model, fraction=d.release_fraction, bodies=bodies, damping=d)
    target_spec = RestitutionTarget.parse(d.target_restitution)
    target = target_spec.resolve(probe.geometry.eta)
    fixed_pairs = _fixed_pairs(model, critical, d.per_interface, probe.rocking_pairs)
    fixed = {k: p.beta for k, p in fixed_pairs.items()}
    seeds = [critical[k].beta for k in probe.rocking_pairs if critical[k].beta > 0]
    beta0 = min(seeds) if seeds else 1e-3
    beta, achieved, evals = _search(probe, target, beta0, fixed, int(d.probe_impacts), str(target_spec))
    pairs = []
    for key, crit in sorted(critical.items()):
        if key in fixed_pairs:
            pairs.append(fixed_pairs[key])
        elif crit.source != "critical":  # never acts (no free block): its beta does not matter
            pairs.append(crit)
        elif not d.per_interface or key in probe.rocking_pairs:
            how = (f"targeted: the probe's mean e_a = {achieved:.4f} for target {target_spec} = {target:.4f} "
                   f"(zeta = beta omega / 2 = {0.5 * beta * crit.omega:.3g} at this pair's omega = {crit.omega:.5g} rad/s)"
                   if math.isfinite(crit.omega) else "targeted")
            pairs.append(PairBeta(key, beta, "targeted", crit.omega, crit.area, crit.mass, crit.kn, crit.blocks, how))
        else:
            pairs.append(crit)
    return BetaChoice(
        "auto", beta, tuple(pairs), per_interface=bool(d.per_interface), target=str(target_spec), target_value=target,
        achieved=achieved, evaluations=np.array([[r.beta, r.e_a] for r in evals]),
        search_time=time.perf_counter() - t_start, release_fraction=probe.fraction, eta=probe.geometry.eta,
        impacts=next(len(r.peaks) for r in evals if r.beta == beta), whole_decay=not d.probe_impacts, probe_duration=max(r.duration for r in evals),
        released=tuple(probe.model.block_names[i] for i in probe.released),
        rocking_pairs=tuple(f"{a}-{b}" for a, b in probe.rocking_pairs),
    )


def _search(probe: Probe, target: float, beta0: float, fixed: dict[tuple[str, str], float], impacts: int, label: str) -> tuple[float, float, list[ProbeResult]]:
    """Bracket e_a(beta) = target from ``beta0`` by factors of :data:`BRACKET_FACTOR`, then brentq on ln beta."""
    evals: list[ProbeResult] = []
    cache: dict[float, ProbeResult] = {}

    def run(beta: float) -> ProbeResult:
        key = round(math.log(beta), 9)  # brentq passes exp(log(beta)), a few ulps from beta
        if key not in cache:
            cache[key] = probe_restitution(probe, beta, target, impacts=impacts, fixed=fixed)
            evals.append(cache[key])
        return cache[key]

    beta_max = 2.0 * MAX_XI / stable_timestep(probe.model).omega_max
    beta0 = min(beta0, beta_max)
    lo_b = hi_b = beta0
    first = run(beta0)
    if first.e_a > target:  # under-damped: raise beta until e_a falls below the target
        while True:
            if hi_b >= beta_max:
                raise ValueError(_unreached(label, target, evals, "below",
                                            f"beta is capped at {beta_max:.3g} s, xi = beta omega_max / 2 = {MAX_XI:g}"))
            lo_b, hi_b = hi_b, min(hi_b * BRACKET_FACTOR, beta_max)
            if run(hi_b).e_a <= target:
                break
    else:
        for _ in range(BRACKET_STEPS):
            hi_b, lo_b = lo_b, lo_b / BRACKET_FACTOR
            if run(lo_b).e_a > target:
                break
        else:
            raise ValueError(_unreached(label, target, evals, "above", "the model loses more energy by its impacts alone"))
    if run(lo_b).e_a == target:
        return lo_b, target, evals
    brentq(lambda x: run(math.exp(x)).e_a - target, math.log(lo_b), math.log(hi_b), xtol=LOG_BETA_TOL, maxiter=60)
    # e_a(beta) of a DEM model has small steps (timestep and contact events change with beta): of the
    # runs inside the final bracket, keep the one closest to the target
    best = min(evals, key=lambda r: abs(r.e_a - target))
    if abs(best.e_a - target) > CLOSE * target:
        near = sorted(evals, key=lambda r: r.beta)
        warn_user(
            f"damping.target_restitution = {label}: the closest apparent restitution reached is {best.e_a:.4f} (target "
            f"{target:.4f}) at beta = {best.beta:.4g} s; e_a jumps across the target between probe runs ("
            + ", ".join(f"{r.beta:.4g} s: {r.e_a:.4f}" for r in near) + ")")
    return best.beta, best.e_a, evals


def _unreached(label: str, target: float, evals: list[ProbeResult], side: str, why: str) -> str:
    rng = ", ".join(f"beta {r.beta:.3g} s: {r.e_a:.4f}" for r in sorted(evals, key=lambda r: r.beta))
    return (
        f"damping.target_restitution = {label} (e = {target:.4f}) is {side} every apparent restitution this model reaches "
        f"({why}); probe runs gave e_a = {rng}. Give a target within that range, or damping.beta as a number or 'critical'"
    )
