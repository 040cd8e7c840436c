"""Figures of docs/contacts.md: supported area while sliding off an edge, impact energy vs dt.

    python benchmarks/contact_figures.py [out_dir]      (default docs/figures)

Prints the figures it plots (the impact energy error at each timestep fraction).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rockdem.geometry import box  # noqa: E402
from rockdem.kernels.forces import compute_forces  # noqa: E402
from rockdem.materials import JointMaterial  # noqa: E402
from rockdem.model import Damping, ModelBuilder  # noqa: E402
from rockdem.simulation import simulate  # noqa: E402
from rockdem.state import initial_state  # noqa: E402
from rockdem.timestep import stable_timestep  # noqa: E402


def _intersection_area(pa: np.ndarray, pb: np.ndarray) -> float:
    """Area of the intersection of two convex counter-clockwise polygons (n, 2) [m^2]."""
    from scipy.optimize import linprog
    from scipy.spatial import ConvexHull, HalfspaceIntersection

    hs = []
    for poly in (pa, pb):
        e = np.roll(poly, -1, axis=0) - poly
        out = np.column_stack([e[:, 1], -e[:, 0]])
        out /= np.linalg.norm(out, axis=1, keepdims=True)
        hs.append(np.column_stack([out, -np.einsum("ij,ij->i", out, poly)]))
    h = np.vstack(hs)
    res = linprog(c=[0, 0, -1], A_ub=np.column_stack([h[:, :2], np.ones(len(h))]), b_ub=-h[:, 2], bounds=[(None, None)] * 2 + [(None, 1.0)])
    if -res.fun <= 1e-9:
        return 0.0
    return float(ConvexHull(HalfspaceIntersection(h, res.x[:2]).intersections).volume)


def area_curve(turn_deg: float = 27.0, kn: float = 1e9, overlap: float = 2e-4, n: int = 63):
    """Offsets [m], supported force / (kn overlap) [m^2], exact face intersection area [m^2]."""
    c, s = np.cos(np.radians(turn_deg)), np.sin(np.radians(turn_deg))
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    lower = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    offsets = np.linspace(0.0, 0.62, n)
    supported, exact = [], []
    for dx in offsets:
        bld = ModelBuilder(gravity=(0, 0, 0), points=(3, 4))
        bld.default_material = JointMaterial(kn=kn, friction_angle=30)
        bld.add_box(0.6, 0.6, 0.2, base_center=(0, 0, -0.2), driven=True, name="lower")
        bld.add_block(box(0.4, 0.3, 0.2).transformed(rot, (dx, 0.05, 0.1 - overlap)), name="upper")
        model = bld.finalize(damping=Damping())
        st, sc = initial_state(model, check_overlap=False)
        compute_forces(model.arrays, st, sc, 0.0, 1e-6)
        supported.append(float(sc.force[1, 2]) / (kn * overlap))
        corners = np.array([[-0.2, -0.15, 0], [0.2, -0.15, 0], [0.2, 0.15, 0], [-0.2, 0.15, 0]]) @ rot.T
        exact.append(_intersection_area(corners[:, :2] + [dx, 0.05], lower))
    return offsets, np.array(supported), np.array(exact)


def impact_errors(fractions: list[float]) -> tuple[float, list[float]]:
    """Default fraction of the critical step and the energy error after the first impacts of the
    undamped 0.5 x 0.8 m block (2 points, mu = 5.7) at each fraction of the critical step
    (relative to the largest kinetic energy)."""
    bld = ModelBuilder(points=(2, 2))
    bld.default_material = JointMaterial(kn=2.25e9, friction_angle=80.0)
    bld.add_box(1.6, 1.6, 0.4, base_center=(0, 0, -0.4), driven=True, name="ground")
    bld.add_box(0.5, 1.0, 0.8, density=1800, name="block")
    bld.tilt("block", 0.9)
    model = bld.finalize()
    info = stable_timestep(model)
    errs = []
    for f in fractions:
        ds = simulate(model, 0.8, dt=f * info.critical, record_interval=0.002, progress=False)
        errs.append(float(ds.energy_balance_error.values[-1] / ds.energy_kinetic.values.max()))
    return info.dt / info.critical, errs


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    x, sup, ex = area_curve()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.plot(x, ex, "k-", lw=2, label="area of the face intersection (exact)")
    ax.plot(x, sup, "o", ms=3.5, color="C1", label="rockdem: supported force / (kn overlap)")
    ax.set_xlabel("offset of the upper block's centre [m]")
    ax.set_ylabel("area [m$^2$]")
    ax.set_title("0.4 x 0.3 m block (3 x 4 points, turned 27°) sliding off a 0.6 m block", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "contacts_area.png", dpi=130)
    print(f"area: largest |supported - exact| = {np.max(np.abs(sup - ex)):.3g} m^2 of {ex.max():.3g}")

    fractions = [0.9, 0.6, 0.45, 0.3, 0.2, 0.1, 0.05]
    default, errs = impact_errors(fractions)
    for f, e in zip(fractions, errs):
        print(f"impact: dt = {f:4.2f} critical -> energy error {100 * e:+.3f} % of the largest KE")
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.loglog(fractions, np.abs(100 * np.array(errs)), "o-", label="|energy error| after the impacts")
    ax.loglog(fractions, 100 * np.abs(errs[0]) * (np.array(fractions) / fractions[0]) ** 2, "k:", label="slope 2")
    ax.axvline(default, color="C2", ls="--", label=f"default (undamped): {default:.2g} of critical")
    ax.axhline(1.0, color="C3", lw=0.8, label="1 %")
    ax.set_xlabel("dt / critical dt")
    ax.set_ylabel("% of the largest kinetic energy")
    ax.set_title("undamped 0.5 x 0.8 m block, 2 points, released at 0.9 of its instability angle", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "contacts_impact.png", dpi=130)


if __name__ == "__main__":  # pragma: no cover
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / "docs" / "figures")
