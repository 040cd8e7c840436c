"""Implicit vs explicit SP dashpots against the converged answer (issue 12).

Run: ``python benchmarks/dashpot_accuracy.py [table2] [fig4] [quake] [--quick]`` (prints a table).

For each case four runs: the converged answer (implicit dashpots at a twentieth of their default
step throughout the run), the explicit scheme at a tenth of its default step (the former
reference, shown to check that both schemes converge to the same answer), today's explicit scheme
at its default step (Belytschko-reduced) and the implicit scheme at its default step (the undamped
step with the impact resolution, :mod:`rockdem.timestep`). Each run is compared with the converged
one on the rocking angle of the free block: WME (:func:`rockdem.analysis.wme`, amplitude-weighted,
cut at the end of the converged motion), mean apparent restitution e_a (Eq. 6, peaks above 2 % of
the largest), time of the first impact, and the energy balance error relative to the energy scale:
at the end of the run and its largest value over the recorded frames (which includes the transient
of the mid-step kinetic energy during impacts, ``docs/dashpots.md``).

Why the implicit scheme refined: it is second order in the step, the explicit one first order (the
dashpot force lags half a step). Under El Centro the explicit scheme at 1/10, 1/20, 1/40, 1/80 and
1/160 of its default step is 0.020, 0.012, 0.0055, 0.0023, 0.0011 in WME from the implicit one at
1/40, which is 0.00004 from the implicit one at 1/20: the explicit run at a tenth of its step is
not converged under an earthquake (free rocking forgives it, an earthquake amplifies it;
``benchmarks/quake_convergence.py``, ``docs/dashpots.md``).

Cases: the paper's Table 2 block (0.2 x 1 x 2 m, E = 1800 MPa, beta = 0.00693 s, 10 s) with 2 to 15
interface points; the Fig. 4 grid (B 0.19 / 0.35 m, H 0.5 to 2.0 m, E 1000 / 1800 / 3600 MPa,
DeJong's beta = 2 / omega_e, 2 points); a 0.2 x 1.0 m block under El Centro 1940 (foundation mode,
beta = 0.0045 s, 25 s). ``--quick``: 2 and 15 points, 4 Fig. 4 blocks at E = 1800 MPa, 6 s of the
record.
"""

from __future__ import annotations

import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from rockdem.analysis import first_impact_time, summarize_result, wme
from rockdem.case import load_case, parse_case
from rockdem.model import Damping, Model
from rockdem.reproduce.fig4 import sp_spec
from rockdem.simulation import simulate
from rockdem.timestep import DEFAULT_RESOLUTION, DEFAULT_SAFETY

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_engine import BETA, table2_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_REFINEMENT = 20
"""The converged answer: implicit dashpots at 1 / REFERENCE_REFINEMENT of their default step."""

EXPLICIT_REFINEMENT = 10
"""The explicit check: explicit dashpots at 1 / EXPLICIT_REFINEMENT of their default step (the
reference before the earthquake cases showed it unconverged)."""

FIG4_BLOCKS = tuple((b, h) for b in (0.19, 0.35) for h in (0.5, 0.9, 1.5, 2.0))
FIG4_MODULI = (1000e6, 1800e6, 3600e6)


@dataclass(frozen=True)
class Errors:
    """A run against the converged one: WME [-], mean e_a and first-impact errors [%] (None where
    not defined: e_a under an earthquake), energy balance error at the end and largest [% of the
    energy scale], steps and runtime [s]."""

    wme: float
    e_a: float | None
    first_impact: float | None
    balance_end: float
    balance_max: float
    steps: int
    runtime: float


def free_block(ds: xr.Dataset) -> int:
    """Index of the (first) free block of a result."""
    return int(np.flatnonzero(ds.block_free.values)[0])


def errors(ds: xr.Dataset, ref: xr.Dataset, *, free_rocking: bool = True) -> Errors:
    """:class:`Errors` of run ``ds`` against the converged run ``ref``."""
    b = free_block(ds)
    t, th = ds.time.values, ds.rocking_angle.values[:, b]
    tr, thr = ref.time.values, ref.rocking_angle.values[:, b]
    e_a = fi = None
    if free_rocking:
        e_a = 100.0 * (summarize_result(ds, b)["e_a_mean"] / summarize_result(ref, b)["e_a_mean"] - 1.0)
    t1, t1r = first_impact_time(t, th), first_impact_time(tr, thr)
    if t1 is not None and t1r is not None:
        fi = 100.0 * (t1 / t1r - 1.0)
    bal = ds.energy_balance_error_relative.values
    return Errors(wme(tr, thr, t, th), e_a, fi, 100.0 * abs(float(bal[-1])), 100.0 * float(np.abs(bal).max()),
                  int(ds.attrs["steps"]), float(ds.attrs["runtime_s"]))


def refined(model: Model, duration: float, dashpots: str, refinement: float, **run) -> xr.Dataset:
    """A run at 1 / ``refinement`` of the default step throughout: safety and resolution scaled
    together, so that the step the engine lowers to when more contacts form is refined too (a user
    dt is lowered to the default bound, not below it)."""
    return simulate(model, duration, dashpots=dashpots, safety=DEFAULT_SAFETY / refinement,
                    resolution=DEFAULT_RESOLUTION / refinement, **run)


def compare(model: Model, duration: float, record_interval: float, *, free_rocking: bool = True) -> dict[str, Errors]:
    """The explicit run at a tenth of its step and the explicit and implicit default runs of
    ``model`` against the converged run, and the converged run against itself (its steps, runtime
    and balance)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = dict(record_interval=record_interval, progress=False)
        ref = refined(model, duration, "implicit", REFERENCE_REFINEMENT, **run)
        out = {"converged": errors(ref, ref, free_rocking=free_rocking)}
        out[f"exp 1/{EXPLICIT_REFINEMENT}"] = errors(refined(model, duration, "explicit", EXPLICIT_REFINEMENT, **run), ref,
                                                   free_rocking=free_rocking)
        for mode in ("explicit", "implicit"):
            out[mode] = errors(simulate(model, duration, dashpots=mode, **run), ref, free_rocking=free_rocking)
    return out


def cases(which: list[str], quick: bool) -> list[tuple[str, Model, float, float, bool]]:
    """(label, model, duration [s], record interval [s], free rocking) of the selected cases."""
    out = []
    if "table2" in which:
        for n in ((2, 15) if quick else (2, 3, 4, 5, 10, 15)):
            out.append((f"Table 2, {n} points", table2_block(n, Damping(beta=BETA)), 10.0, 0.0005, True))
    if "fig4" in which:
        grid = [(b, h, 1800e6) for b, h in ((0.19, 0.5), (0.19, 2.0), (0.35, 0.5), (0.35, 2.0))] if quick else [
            (b, h, e) for e in FIG4_MODULI for b, h in FIG4_BLOCKS]
        for b, h, e in grid:
            model = parse_case(sp_spec(b, h, e, 10.0).case_dict()).model
            out.append((f"Fig. 4 {b} x {h} m, E {e / 1e6:.0f} MPa", model, 10.0, 0.0005, True))
    if "quake" in which:
        case = parse_case(load_case(ROOT / "examples" / "elcentro_block_foundation.toml"))
        out.append(("El Centro, 0.2 x 1.0 m block", case.model, 6.0 if quick else case.run.duration, 0.001, False))
    return out


def _fmt(v: float | None, spec: str) -> str:
    return "-" if v is None else format(v, spec)


def main(argv: list[str]) -> None:
    quick = "--quick" in argv
    which = [a for a in argv if not a.startswith("--")] or ["table2", "fig4", "quake"]
    print(f"{'case':34s} {'scheme':9s} {'steps':>8s} {'time [s]':>8s} {'WME':>7s} {'e_a [%]':>8s} "
          f"{'impact1 [%]':>11s} {'bal end/max [%]':>15s}")
    worst: dict[str, dict[str, float]] = {f"exp 1/{EXPLICIT_REFINEMENT}": {}, "explicit": {}, "implicit": {}}
    for label, model, duration, rec, free in cases(which, quick):
        t0 = time.perf_counter()
        res = compare(model, duration, rec, free_rocking=free)
        for mode, e in res.items():
            print(f"{label:34s} {mode:9s} {e.steps:8d} {e.runtime:8.3f} {e.wme:7.4f} {_fmt(e.e_a, '+8.3f')} "
                  f"{_fmt(e.first_impact, '+11.4f')} {e.balance_end:7.3f}/{e.balance_max:<7.3f}")
            if mode in worst:
                w = worst[mode]
                for key, val in (("WME", e.wme), ("|e_a| %", e.e_a), ("|first impact| %", e.first_impact),
                                 ("balance end %", e.balance_end), ("balance max %", e.balance_max)):
                    if val is not None:
                        w[key] = max(w.get(key, 0.0), abs(val))
        print(f"{'':34s} ({time.perf_counter() - t0:.1f} s)", flush=True)
    for mode, w in worst.items():
        print(f"worst {mode}: " + ", ".join(f"{k} {v:.4g}" for k, v in w.items()))


if __name__ == "__main__":
    main(sys.argv[1:])
