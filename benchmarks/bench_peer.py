"""rockdem beside MuJoCo on free rocking (issue 12). Run: ``python benchmarks/bench_peer.py`` (prints a table).

The same rigid blocks released from the same tilt rock for 10 s on a rigid base, in one process:

- rockdem: the paper's joint (E = 1800 MPa, kn = E / H, 2 x 2 interface points), SP damping with
  DeJong's beta (the Fig. 4 blocks) or the paper's 0.00693 s (the Table 2 block), the default
  implicit dashpots and automatic step;
- MuJoCo (``pip install 'rockdem[bench]'``; skipped when missing): a box on a plane with stiff,
  critically damped soft contacts (solref = (2 dt, 1), the stiffest MuJoCo recommends for its step
  dt; elliptic friction cone, mu = 1, so the block rocks without sliding), dt = 1e-4 s. A critically
  damped contact does not bounce, the condition under which Housner's model holds.

For both: wall time per simulated second (the best of ``REPEAT`` runs after a warm-up; compilation
excluded) and the mean apparent restitution e_a (paper Eq. 6, from the rocking peaks) against
Housner's e_eta = 1 - 1.5 sin^2(eta).
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from rockdem.analysis import summarize, summarize_result
from rockdem.beta_choice import housner_e_eta
from rockdem.case import parse_case
from rockdem.model import Damping
from rockdem.reproduce.fig4 import sp_spec
from rockdem.simulation import simulate

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_engine import BETA, table2_block  # noqa: E402

DURATION = 10.0
"""Simulated time [s]."""
REPEAT = 3
"""Timed runs of each engine per block (the best is printed)."""
MUJOCO_DT = 1e-4
"""MuJoCo's step [s]."""
DENSITY = 1800.0
"""Block density [kg/m^3] (paper)."""


def mujoco_rocking(width: float, height: float, length: float, theta0: float) -> tuple[np.ndarray, np.ndarray, float]:
    """A width x length x height box [m] tilted by theta0 [rad] about its base edge, rocking on a plane
    in MuJoCo for DURATION: (time (n,) [s], rotation about the length axis (n,) [rad], best wall time [s])."""
    import mujoco

    xml = f"""<mujoco>
  <option timestep="{MUJOCO_DT}" cone="elliptic" gravity="0 0 -9.81"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1" friction="1 0.005 0.0001" solref="{2 * MUJOCO_DT} 1"/>
    <body name="block">
      <freejoint/>
      <geom type="box" size="{width / 2} {length / 2} {height / 2}" density="{DENSITY}" friction="1 0.005 0.0001"
            solref="{2 * MUJOCO_DT} 1"/>
    </body>
  </worldbody>
</mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    # Tilted about the base edge at x = +width/2 (rotation about y), the centroid raised accordingly.
    c, s = math.cos(theta0), math.sin(theta0)
    rx, rz = -width / 2, height / 2  # centroid from the pivot, upright
    pos = (width / 2 + c * rx + s * rz, 0.0, -s * rx + c * rz)
    steps = int(round(DURATION / MUJOCO_DT))
    every = 10
    best = math.inf
    for _ in range(REPEAT + 1):  # the first is a warm-up
        mujoco.mj_resetData(model, data)
        data.qpos[:3] = pos
        data.qpos[3:7] = (math.cos(theta0 / 2), 0.0, math.sin(theta0 / 2), 0.0)
        mujoco.mj_forward(model, data)
        theta = np.empty(steps // every + 1)
        t0 = time.perf_counter()
        for k in range(steps + 1):
            if k % every == 0:
                w, y = data.qpos[3], data.qpos[5]
                theta[k // every] = 2.0 * math.atan2(y, w)
            mujoco.mj_step(model, data)
        best = min(best, time.perf_counter() - t0)
    return np.arange(theta.size) * every * MUJOCO_DT, theta, best


def blocks() -> list[tuple[str, float, float, float, object]]:
    """(label, B, H, L [m], rockdem model) of the compared blocks."""
    out = [("Table 2 block 0.2 x 2.0 m", 0.2, 2.0, 1.0, table2_block(2, Damping(beta=BETA)))]
    for b, h in ((0.19, 0.5), (0.19, 2.0), (0.35, 0.5), (0.35, 2.0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out.append((f"Fig. 4 block {b} x {h} m", b, h, 1.0, parse_case(sp_spec(b, h, 1800e6, DURATION).case_dict()).model))
    return out


def main() -> None:
    try:
        import mujoco
    except ImportError:
        mujoco = None
        print("MuJoCo not installed (pip install 'rockdem[bench]'): rockdem only")
    print(f"{DURATION:g} s of free rocking; wall time per simulated second (best of {REPEAT}) and mean e_a vs Housner's e_eta")
    print(f"{'block':28s} {'e_eta':>6s} | {'rockdem [s/s]':>13s} {'e_a err':>8s} | "
          f"{'MuJoCo ' + (mujoco.__version__ if mujoco else '-'):>13s} {'e_a err':>8s} | {'rockdem / MuJoCo':>16s}")
    for label, b, h, length, model in blocks():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            simulate(model, 0.05, progress=False)  # compiled and warm
            runs = [simulate(model, DURATION, record_interval=0.001, progress=False) for _ in range(REPEAT)]
        ds = min(runs, key=lambda d: d.attrs["runtime_s"])
        eta = math.atan2(b, h)
        e_eta = housner_e_eta(eta)
        ours = ds.attrs["runtime_s"] / DURATION
        ea = summarize_result(ds, eta=eta)["e_a_mean"]
        line = f"{label:28s} {e_eta:6.3f} | {ours:13.4f} {100 * (ea / e_eta - 1):+7.2f}% | "
        if mujoco is None:
            print(line + f"{'-':>13s} {'-':>8s} | {'-':>16s}")
            continue
        b_free = int(np.flatnonzero(ds.block_free.values)[0])
        theta0 = abs(float(ds.rocking_angle.values[0, b_free]))
        t, th, wall = mujoco_rocking(b, h, length, theta0)
        ea_mj = summarize(t, th, eta=eta).get("e_a_mean", math.nan)
        theirs = wall / DURATION
        print(line + f"{theirs:13.4f} {100 * (ea_mj / e_eta - 1):+7.2f}% | {ours / theirs:16.2f}", flush=True)


if __name__ == "__main__":
    main()
