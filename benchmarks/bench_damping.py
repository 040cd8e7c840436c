"""Targeted beta on a grid of blocks (issue 14). Run: ``python benchmarks/bench_damping.py [--quick]``.

For blocks B = 0.2 m, L = 1 m, 1800 kg/m^3, E = 1800 MPa (kn = E / H) of slenderness H/B = 1.5 to 20
with 2 to 15 interface points across, released from ``--release`` x eta (default 0.9, the paper's):
``beta = "auto"`` with target 0.95 e_eta (and ``--target``), then a free-rocking run of the same
model until its half-cycle peaks fall below 2 % of the release (``--probe-release`` searches from
another release than the run's, a check that is not true by construction); prints per case the targeted beta,
the search's probe runs and wall time, the probe's e_a and the run's mean e_a (paper Eq. 6, as
``rockdem run`` reports it) against the target, and beside them DeJong's beta (the advisor's) with
its mean e_a. The check: the run's mean e_a within 2 % of the target on every case. Then (or
alone, ``--facade``) the §4.2 one-sided façade's free rocking with per-interface critical betas against
one beta: steps and best-of-3 wall time (the check: per-interface at most 1.5 times one critical beta).
"""

from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np

from rockdem.analysis import summarize_result
from rockdem.housner import HousnerBlock, rock
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulation import simulate

WIDTH = 0.2
SLENDERNESS = (1.5, 2.0, 3.0, 5.0, 10.0, 20.0)
POINTS = (2, 3, 5, 10, 15)
TOLERANCE = 0.02


def block_builder(width: float, height: float, points: int, release: float, modulus: float = 1.8e9) -> ModelBuilder:
    """A B x 1 x H block on a fixed foundation, tilted to ``release`` x eta."""
    b = ModelBuilder(points=(points, 2))
    b.default_material = JointMaterial.from_modulus(modulus, height, friction_angle=80.0)
    size = 2.0 * max(width, height, 1.0) + 3.0 * height
    b.add_box(size, size, 0.25 * size, base_center=(0, 0, -0.25 * size), driven=True, name="ground", group="foundation")
    b.add_box(width, 1.0, height, density=1800.0, name="block")
    b.tilt("block", release)
    return b


def rest_duration(width: float, height: float, release: float, e: float, floor: float = 0.02, cap: float = 30.0) -> float:
    """1.3 x Housner's time until the half-cycle peaks fall below ``floor`` of the release at restitution e [s]."""
    blk = HousnerBlock(width, height)
    resp = rock(blk, theta0=release * blk.eta, duration=cap, e=e, dt_out=0.01)
    low = np.flatnonzero(np.abs(resp.peak_rotation) < floor * release * blk.eta)
    return min(cap, 1.3 * (float(resp.peak_time[low[0]]) if len(low) else cap))


def run_case(hb: float, points: int, release: float, target: str, probe_release: float | None) -> dict[str, float]:
    height = hb * WIDTH
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        damping = Damping(beta="auto", target_restitution=target, release_fraction=probe_release)
        model = block_builder(WIDTH, height, points, release).finalize(damping=damping)
        search = time.perf_counter() - t0
        choice = model.beta_choice
        dur = rest_duration(WIDTH, height, release, choice.target_value)
        ds = simulate(model, dur, record_interval=dur / 4000.0, progress=False)
        mean = summarize_result(ds).get("e_a_mean", math.nan)
        eta = math.atan(WIDTH / height)
        omega = math.sqrt(1.8e9 * WIDTH / (1800.0 * height * height))  # the advisor's (paper Eq. 3) omega_e
        dejong = block_builder(WIDTH, height, points, release).finalize(damping=Damping(beta=2.0 / omega))
        dj = summarize_result(simulate(dejong, dur, record_interval=dur / 4000.0, progress=False)).get("e_a_mean", math.nan)
    return {"hb": hb, "points": points, "eta_deg": math.degrees(eta), "beta": choice.beta, "runs": choice.iterations,
            "search_s": search, "target": choice.target_value, "probe": choice.achieved, "mean": mean,
            "ratio": mean / choice.target_value, "beta_dejong": 2.0 / omega, "mean_dejong": dj, "duration": dur}


def bench_facade(repeat: int = 3) -> None:
    """The §4.2 façade's 5 s free rocking: one beta (the paper's 0.00025 s; critical at the return walls)
    against per-interface critical betas; best wall time of ``repeat`` serial runs each."""
    import copy

    from rockdem.case import parse_case
    from rockdem.reproduce.damping import FACADE_CASE
    from rockdem.run_cli import run_case

    def case(beta: float | str, dashpots: str = "auto"):
        data = copy.deepcopy(FACADE_CASE)
        data["damping"] = {"beta": beta}
        data.setdefault("run", {})["dashpots"] = dashpots
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return parse_case(data)

    ret = case("critical").model.beta_choice.pair("facade", "return").beta
    for dashpots in ("implicit", "explicit"):
        print(f"\n§4.2 façade, 5 s of one-sided free rocking, {dashpots} dashpots (best of {repeat} serial runs)")
        print(f"{'beta':<50} {'steps':>8} {'wall [s]':>9} {'steps ratio':>11} {'wall ratio':>10}")
        rows = []
        for label, beta in (("paper best fit, one value 0.00025 s", 0.00025),
                            (f"critical at the return walls, one value {ret:.4g} s", ret), ("critical per interface", "critical")):
            c = case(beta, dashpots)
            best = min((run_case(c, progress=False) for _ in range(repeat)), key=lambda ds: ds.attrs["runtime_s"])
            rows.append((label, best.attrs["steps"], best.attrs["runtime_s"]))
        for label, steps, wall in rows:
            print(f"{label:<50} {steps:>8} {wall:>9.3f} {steps / rows[0][1]:>11.2f} {wall / rows[0][2]:>10.2f}")
        print(f"per interface / one critical value: steps {rows[2][1] / rows[1][1]:.2f}, wall {rows[2][2] / rows[1][2]:.2f} "
              "(check: <= 1.5)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="H/B 1.5, 5, 20 with 2 and 15 points only")
    ap.add_argument("--release", type=float, default=0.9, help="release as a fraction of eta (default 0.9)")
    ap.add_argument("--target", default="0.95eta", help="target restitution (default 0.95eta)")
    ap.add_argument("--probe-release", type=float, default=None,
                    help="release of the search's probe (default: the model's own, --release); another value checks "
                         "how far a beta found at one amplitude carries to a run from another")
    ap.add_argument("--facade", action="store_true", help="only the §4.2 façade timings (per-interface vs one beta)")
    args = ap.parse_args()
    if args.facade:
        simulate(block_builder(WIDTH, 2.0, 2, 0.5).finalize(damping=Damping(beta=0.001)), 0.01, progress=False)
        bench_facade()
        return
    grid = [(hb, n) for hb in ((1.5, 5.0, 20.0) if args.quick else SLENDERNESS) for n in ((2, 15) if args.quick else POINTS)]
    block_builder(WIDTH, 2.0, 2, 0.5).finalize(damping=Damping(beta=0.001))  # compile outside the timings
    simulate(block_builder(WIDTH, 2.0, 2, 0.5).finalize(damping=Damping(beta=0.001)), 0.01, progress=False)
    probe = args.release if args.probe_release is None else args.probe_release
    print(f"targeted beta, target {args.target}, run released from {args.release} eta, probe from {probe} eta, "
          f"B = {WIDTH} m, E = 1800 MPa")
    head = (f"{'H/B':>5} {'pts':>4} {'eta':>6} {'beta [s]':>10} {'runs':>4} {'search':>7} {'target':>7} {'probe':>7} "
            f"{'run mean':>8} {'ratio':>6} {'DeJong beta':>11} {'its mean':>8} {'run [s]':>7}")
    print(head)
    worst, fails = 0.0, []
    for hb, n in grid:
        try:
            r = run_case(hb, n, args.release, args.target, args.probe_release)
        except ValueError as exc:
            print(f"{hb:>5g} {n:>4} search refused: {exc}")
            fails.append((hb, n))
            continue
        worst = max(worst, abs(r["ratio"] - 1.0))
        print(f"{r['hb']:>5g} {r['points']:>4} {r['eta_deg']:>6.2f} {r['beta']:>10.4g} {r['runs']:>4} {r['search_s']:>6.2f}s "
              f"{r['target']:>7.4f} {r['probe']:>7.4f} {r['mean']:>8.4f} {r['ratio']:>6.3f} {r['beta_dejong']:>11.4g} "
              f"{r['mean_dejong'] / r['target']:>8.3f} {r['duration']:>7.2f}", flush=True)
    print(f"largest |run mean e_a / target - 1| = {worst:.4f} (check: <= {TOLERANCE}); refused: {fails or 'none'}")
    print("'its mean' is the DeJong run's mean e_a over the same target (1 = on target).")
    bench_facade()


if __name__ == "__main__":
    main()
