"""Step convergence of SP-damped rocking under earthquakes (issue 12, "equal answers").

Run: ``python benchmarks/quake_convergence.py [--explicit] [--sensitivity] [CASE ...]`` (prints tables;
CASE: a label prefix, default all).

Each case is the El Centro example (``examples/elcentro_block_foundation.toml``: a block on its
driven foundation, DeJong's beta = 2 / omega_e) with another record, scale or block. The converged
answer is the implicit scheme at 1/40 of its default step (resolution 0.3 / 40); the implicit scheme
is run at the resolutions ``RESOLUTIONS`` (the default 0.3 first; the step is proportional to it)
and the explicit scheme at a tenth of its default step (``--explicit``: also 1/40). Each run is
compared with the converged one by WME of the free block's rocking angle (:func:`rockdem.analysis.wme`).
Column "windows" is the default run (resolution 0.3 with its impact windows, the step divided by 6
around each impact: :func:`rockdem.timestep.impact_windows`); every other run has no windows.

``--sensitivity``: how far the converged response itself moves, in WME, when the record is scaled by
1.001 or beta by 1.01 (implicit at 1/10 of its step): the size of a numerical error that matters.

Figures (2026-11-25, 2-core machine): ``docs/dashpots.md`` ("Measured").
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

from rockdem.analysis import wme
from rockdem.case import load_case, parse_case
from rockdem.simulation import simulate
from rockdem.timestep import DEFAULT_RESOLUTION, DEFAULT_SAFETY

ROOT = Path(__file__).resolve().parents[1]
REFERENCE_REFINEMENT = 40
RESOLUTIONS = (0.3, 0.2, 0.15, 0.1, 0.075, 0.05, 0.03)
RECORD_INTERVAL = 0.001

CASES: tuple[tuple[str, dict], ...] = (
    ("El Centro, 0.2 x 1.0 m", {}),
    ("El Centro, 0.2 x 1.0 m, inertial", {"mode": "inertial"}),
    ("El Centro x1.2, 0.35 x 1.5 m", {"width": 0.35, "height": 1.5, "scale": 1.2}),
    ("El Centro, 0.19 x 0.9 m", {"width": 0.19, "height": 0.9}),
    ("Sturno, 0.2 x 1.0 m", {"record": "sturno", "window": [0.0, 25.0]}),
    ("Pacoima x0.35, 0.2 x 1.0 m", {"record": "pacoima", "window": [0.0, 15.0], "scale": 0.35}),
    ("Nahanni x0.7, 0.2 x 1.0 m", {"record": "nahanni", "window": [0.0, 12.0], "scale": 0.7}),
    ("Nahanni x0.5, 0.2 x 1.0 m", {"record": "nahanni", "window": [0.0, 12.0], "scale": 0.5}),
)
"""(label, changes to the El Centro example): record, window [s], scale, mode, width and height [m]
(beta then DeJong's 2 / omega_e, omega_e = sqrt(E B / (rho H^2))); every run lasts the example's 25 s
(the motion has ended by then in every case)."""


def case_dict(changes: dict, *, scale: float = 1.0, beta: float = 1.0) -> dict:
    """The El Centro example with ``changes``, its record scaled by ``scale`` and beta by ``beta``."""
    d = load_case(ROOT / "examples" / "elcentro_block_foundation.toml")
    ld, sp = d["loading"], d["specimen"]
    if "record" in changes:
        ld["record"] = changes["record"]
    if "window" in changes:
        ld["window"] = list(changes["window"])
    ld["scale"] = changes.get("scale", ld.get("scale", 1.0)) * scale
    ld["mode"] = changes.get("mode", ld["mode"])
    if "width" in changes or "height" in changes:
        sp["width"], sp["height"] = changes.get("width", sp["width"]), changes.get("height", sp["height"])
        omega_e = np.sqrt(sp["youngs_modulus"] * sp["width"] / (sp["density"] * sp["height"] ** 2))
        d["damping"]["beta"] = 2.0 / omega_e
    d["damping"]["beta"] *= beta
    return d


def rocking(d: dict, dashpots: str, refinement: float, windows: bool = False) -> tuple[np.ndarray, np.ndarray, int, float]:
    """(time, rocking angle of the free block, steps, runtime [s]) of case ``d`` at 1 / ``refinement``
    of the default step of ``dashpots``, with the default impact windows or (``windows`` False) none."""
    case = parse_case(d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(case.model, case.run.duration, dashpots=dashpots, safety=DEFAULT_SAFETY / refinement,
                      resolution=DEFAULT_RESOLUTION / refinement, record_interval=RECORD_INTERVAL, progress=False,
                      impact_refinement=None if windows else 1.0)
    b = int(np.flatnonzero(ds.block_free.values)[0])
    return ds.time.values, ds.rocking_angle.values[:, b], int(ds.attrs["steps"]), float(ds.attrs["runtime_s"])


def main(argv: list[str]) -> None:
    explicit = "--explicit" in argv
    sensitivity = "--sensitivity" in argv
    chosen = [a for a in argv if not a.startswith("--")]
    cases = [(lab, ch) for lab, ch in CASES if not chosen or any(lab.startswith(c) for c in chosen)]
    runs = ([("implicit", 1.0, True)] + [("implicit", DEFAULT_RESOLUTION / r, False) for r in RESOLUTIONS]
            + [("explicit", 10.0, False)])
    if explicit:
        runs.append(("explicit", 40.0, False))
    head = ["windows"] + [f"imp {r:g}" for r in RESOLUTIONS] + ["exp 1/10"] + (["exp 1/40"] if explicit else [])
    print(f"WME against the implicit scheme at 1/{REFERENCE_REFINEMENT} of its step; implicit at resolution r, explicit at a "
          "fraction of its default step")
    print(f"{'case':34s} {'max|theta|':>10s} " + " ".join(f"{h:>8s}" for h in head))
    steps: dict[str, list[str]] = {}
    worst = np.zeros(len(runs))
    for label, changes in cases:
        t0 = time.perf_counter()
        d = case_dict(changes)
        tr, xr, _, _ = rocking(d, "implicit", REFERENCE_REFINEMENT)
        row, cost = [], []
        for j, (mode, refinement, windows) in enumerate(runs):
            t, x, n, rt = rocking(d, mode, refinement, windows)
            e = wme(tr, xr, t, x)
            worst[j] = max(worst[j], e)
            row.append(f"{e:8.4f}")
            cost.append(f"{n:>9d} {rt:6.2f}")
        steps[label] = cost
        print(f"{label:34s} {np.abs(xr).max():10.4f} " + " ".join(row) + f"   ({time.perf_counter() - t0:.0f} s)", flush=True)
    print(f"{'worst':34s} {'':10s} " + " ".join(f"{w:8.4f}" for w in worst))
    print("\nsteps and runtime [s] of each run")
    print(f"{'case':34s} " + " ".join(f"{h:>16s}" for h in head))
    for label, cost in steps.items():
        print(f"{label:34s} " + " ".join(f"{c:>16s}" for c in cost))
    if sensitivity:
        print("\nsensitivity of the converged response (implicit at 1/10 of its step): WME of a perturbed run")
        print(f"{'case':34s} {'record x1.001':>14s} {'beta x1.01':>11s}")
        for label, changes in cases:
            t, x, _, _ = rocking(case_dict(changes), "implicit", 10.0)
            out = []
            for kw in ({"scale": 1.001}, {"beta": 1.01}):
                t2, x2, _, _ = rocking(case_dict(changes, **kw), "implicit", 10.0)
                out.append(wme(t, x, t2, x2))
            print(f"{label:34s} {out[0]:14.4f} {out[1]:11.4f}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
