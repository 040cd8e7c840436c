"""The explicit release share of implicit SP dashpots, step by step (docs/dashpots.md, "What the
two corrections cost"). Run: ``python benchmarks/dashpot_release.py [BETA ...]`` (default 0.05 2 5).

The Table 2 block (0.2 x 1 x 2 m, E = 1800 MPa, 2 x 2 points) rocks freely from 0.9 eta with frames
every 0.5 ms (about one step each). Prints, per beta [s], every frame over which the cumulative SP
dissipation fell, with the frame before it: the release share gives back what the last step's
dashpot did past the opening, and the two together should still dissipate.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulation import simulate


def main(betas: list[float]) -> None:
    for beta in betas:
        b = ModelBuilder(points=(2, 2))
        b.default_material = JointMaterial.from_modulus(1.8e9, 2.0, friction_angle=80)
        b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
        b.add_box(0.2, 1.0, 2.0, density=1800, name="wall")
        b.tilt("wall", 0.9)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # far beyond critical damping: warned about
            ds = simulate(b.finalize(damping=Damping(beta=beta)), 4.0, record_interval=0.0005, progress=False)
        sp = ds.energy_damping_stiffness.values
        d = np.diff(sp)
        fell = np.flatnonzero(d < -1e-9)
        status = f"stopped at {float(ds.time[-1]):.3f} s (diverged)" if ds.attrs.get("diverged") else "ran to 4 s"
        print(f"beta = {beta:g} s: {ds.attrs['steps']} steps, {status}, SP dissipation {sp[-1]:.4g} J, "
              f"{fell.size} frame(s) where it fell")
        for k in fell:
            print(f"    t = {float(ds.time[k + 1]):.4f} s: {d[k - 1]:+.4g} J then {d[k]:+.4g} J (sum {d[k - 1] + d[k]:+.4g} J)")


if __name__ == "__main__":
    main([float(a) for a in sys.argv[1:]] or [0.05, 2.0, 5.0])
