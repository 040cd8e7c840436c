"""Random piles of convex hulls, seed by seed: energy created, energy balance, largest overlap.

The collapse scenarios (``collapse_scenarios.py``) are a fixed set; these suites draw a new pile
for each seed, so that a change to contacts or stepping is tried on landings nobody chose: corners
on small facets, edges across edges, hulls glancing off each other. Each suite is a generator of
hulls (random points on an ellipsoid, every point a vertex), their sizes, speeds and damping::

    python benchmarks/pile_suites.py                    # every suite, its default seeds
    python benchmarks/pile_suites.py undamped --seeds 0:40 --jobs 2

prints one line per run and, per suite, the energy created summed over the runs (J), the largest
energy balance error and the largest overlap (of the thinner block). Energy created is the largest
rise of the energy balance error, KE + PE + elastic + dissipated - initial - work, over any stretch
of the run (:func:`balance_rise`): never positive beyond round-off in a sound engine, with or
without damping. (``collapse_scenarios.energy_creation``, KE + PE above the initial energy plus
the work, misses energy created after the pile has dissipated more: a spinning hull's impact in
an undamped pile created 16 J after 148 J of friction, which that measure read as 0.)
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from collapse_scenarios import energy_creation  # noqa: E402

from rockdem.diagnostics import max_interpenetration  # noqa: E402
from rockdem.geometry import Polyhedron, convex_hull  # noqa: E402
from rockdem.materials import JointMaterial  # noqa: E402
from rockdem.model import Damping, Model, ModelBuilder  # noqa: E402
from rockdem.simulation import simulate  # noqa: E402


@dataclass(frozen=True)
class Suite:
    """A generator of random piles.

    Attributes:
        count: hulls per pile.
        sizes: (smallest, largest) extent of a hull along each of its axes [m].
        density: (lowest, highest) [kg/m^3].
        speed: downward speed at the start [m/s].
        drift: largest sideways speed at the start [m/s] (uniform in +-drift per axis).
        spin: largest angular speed at the start about each axis [rad/s].
        points: interface points per face (nx, ny).
        damping: Rayleigh damping of every run.
        duration: simulated time [s].
        seeds: default seeds, range(seeds).
    """

    count: int
    sizes: tuple[float, float]
    density: tuple[float, float]
    speed: float
    drift: float
    spin: float
    points: tuple[int, int]
    damping: Damping
    duration: float
    seeds: int


SUITES: dict[str, Suite] = {
    "undamped": Suite(8, (0.08, 0.35), (1500.0, 2600.0), 3.0, 0.5, 5.0, (2, 2), Damping(), 0.6, 20),
    "sp": Suite(8, (0.08, 0.35), (1500.0, 2600.0), 3.0, 0.5, 5.0, (3, 3), Damping(beta=2e-4), 0.6, 20),
    "slow": Suite(5, (0.12, 0.3), (2000.0, 2000.0), 2.0, 0.0, 0.0, (2, 2), Damping(), 0.5, 20),
    "fast": Suite(5, (0.12, 0.3), (2000.0, 2000.0), 4.0, 0.0, 0.0, (2, 2), Damping(), 0.5, 20),
}
"""The suites: eight hulls thrown at 3 m/s with drift and spin (undamped with 2 x 2 points, SP
damping with 3 x 3), five dropped at 2 and 4 m/s."""

KN_MODULUS = 1.8e9
"""Joint normal stiffness kn = KN_MODULUS / (mean hull size) [Pa/m]: masonry's E = 1800 MPa."""


def random_hull(rng: np.random.Generator, sizes: tuple[float, float], name: str) -> Polyhedron:
    """A convex hull of 8 to 20 random points on an ellipsoid whose axes are drawn from ``sizes``
    [m], turned at random, centred on the origin."""
    d = rng.normal(size=(int(rng.integers(8, 21)), 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    v = (d * rng.uniform(*sizes, 3) / 2.0) @ q.T
    return convex_hull(v - v.mean(axis=0), name=name)


def pile(suite: Suite, seed: int) -> Model:
    """Pile ``seed`` of ``suite``: the hulls in a loose column over a driven ground, four per layer,
    far enough apart that no two touch at the start."""
    rng = np.random.default_rng(seed)
    b = ModelBuilder(points=suite.points)
    b.default_material = JointMaterial(kn=KN_MODULUS / float(np.mean(suite.sizes)), friction_angle=30.0)
    b.add_box(4.0, 4.0, 0.5, base_center=(0.0, 0.0, -0.5), driven=True, name="ground")
    gap = 1.8 * suite.sizes[1]
    for k in range(suite.count):
        layer, slot = divmod(k, 4)
        poly = random_hull(rng, suite.sizes, f"hull{k}")
        low = poly.vertices[:, 2].min()
        at = np.array([(slot % 2 - 0.5) * gap, (slot // 2 - 0.5) * gap, 0.02 - low + layer * gap])
        v = (rng.uniform(-suite.drift, suite.drift), rng.uniform(-suite.drift, suite.drift), -suite.speed)
        b.add_block(poly.transformed(np.eye(3), at), density=float(rng.uniform(*suite.density)), name=f"hull{k}",
                    velocity=v, angular_velocity=tuple(rng.uniform(-suite.spin, suite.spin, 3)))
    return b.finalize(damping=suite.damping)


def balance_rise(error: np.ndarray) -> tuple[float, float]:
    """(largest rise, largest fall) [J] of the energy balance error (T,) [J] over any stretch of the
    run: energy created, and energy lost without being booked."""
    rise = float(np.max(error - np.minimum.accumulate(error))) if error.size else 0.0
    fall = float(np.max(np.maximum.accumulate(error) - error)) if error.size else 0.0
    return rise, fall


def run_one(name: str, seed: int) -> dict[str, float]:
    """Run pile ``seed`` of suite ``name``; its figures (energies [J], shares, overlap)."""
    suite = SUITES[name]
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ds = simulate(pile(suite, seed), suite.duration, record_interval=2e-3, progress=False)
    _, scale = energy_creation(ds)
    created, lost = balance_rise(ds.energy_balance_error.values)
    pen = max_interpenetration(ds)
    return {"seed": seed, "runtime_s": time.perf_counter() - t0, "steps": int(ds.attrs["steps"]),
            "diverged": bool(ds.attrs.get("diverged", 0)), "created_J": created, "lost_J": lost, "scale_J": scale,
            "balance": float(np.max(np.abs(ds.energy_balance_error_relative.values))),
            "overlap": pen.relative, "overlap_blocks": "-".join(pen.blocks)}


def _line(name: str, r: dict) -> str:
    return (f"{name:9s} seed {r['seed']:3d}  {r['runtime_s']:6.1f} s {r['steps']:7d} steps{' DIVERGED' if r['diverged'] else ''}"
            f"  E created {r['created_J']:8.4f} J ({100 * r['created_J'] / r['scale_J']:6.3f} %) lost {r['lost_J']:7.4f} J"
            f"  balance {100 * r['balance']:5.2f} %  overlap {100 * r['overlap']:5.2f} % {r['overlap_blocks']}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("suites", nargs="*", help=f"suites to run: {', '.join(SUITES)} (default all)")
    p.add_argument("--seeds", help="a:b, the seeds range(a, b) (default each suite's)")
    p.add_argument("--jobs", type=int, default=1, help="processes (default 1)")
    a = p.parse_args(argv)
    unknown = [n for n in a.suites if n not in SUITES]
    if unknown:
        p.error(f"unknown suite(s) {', '.join(unknown)}: choose from {', '.join(SUITES)}")
    for name in a.suites or list(SUITES):
        seeds = range(*map(int, a.seeds.split(":"))) if a.seeds else range(SUITES[name].seeds)
        if not seeds:
            p.error(f"--seeds {a.seeds}: no seeds in that range; give a:b with a < b")
        with ProcessPoolExecutor(a.jobs) as pool:
            rows = []
            for r in pool.map(run_one, [name] * len(seeds), seeds):
                print(_line(name, r), flush=True)
                rows.append(r)
        created = sum(r["created_J"] for r in rows)
        worst = max(rows, key=lambda r: r["overlap"])
        print(f"{name:9s} {len(rows)} runs: energy created {created:.3f} J summed, largest balance "
              f"{100 * max(r['balance'] for r in rows):.2f} %, largest overlap {100 * worst['overlap']:.1f} % "
              f"(seed {worst['seed']}), diverged {sum(r['diverged'] for r in rows)}", flush=True)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
