"""Damping that fits the model: beta targeted to a restitution and per-interface critical beta on
the paper's cases (the two open problems of Galvez et al. 2022, §4.1 and §2.2 / §4.2).

* Table 2 block (B = 0.2, H = 2, L = 1 m, E = 1800 MPa, 2 to 15 interface points, 90 % of eta):
  the paper's beta 0.00693 s, ``beta = "auto"`` with targets 0.95 e_eta and e_eta, and
  ``beta = "critical"``; does the targeted beta make e_a independent of the point count (Fig. 9B)?
* Fig. 4 blocks (B 0.19 / 0.35 m, H 0.5 to 2 m, E 1000 / 1800 / 3600 MPa, 2 points): DeJong's beta
  (the advisor's, reusing the Fig. 4 study's stored runs) against the targeted and critical ones.
* §4.1 parapet (single block, the ``examples/parapet_free_rocking.toml`` case): where the targeted
  beta lands against the paper's best fit 0.00068 s and its formula's 0.00305 s.
* §4.2 one-sided façade (``examples/facade_free_rocking.toml``): per-interface beta against the
  paper's single values 0.00025 s (best), 0.00017 s (one-sided formula) and 0.0047 s (two-sided),
  with the return-wall and base impacts measured directly (rebound, damping ratio from the
  undamped contact duration) and the runtime of each.
"""

from __future__ import annotations

import copy
import math
import warnings
from dataclasses import dataclass
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from ..analysis import SUMMARY_PEAK_PROMINENCE, half_cycle_peaks, rest_time, wme
from ..beta_choice import housner_e_eta
from ..case import example_case, parse_case
from ..interfaces import critical_betas
from ..materials import JointMaterial
from ..model import Damping, ModelBuilder
from ..plots import save_figure
from ..simulation import simulate
from ..specimens import add_foundation, rounded_prism
from ..studies import RunSpec
from . import Context, Report, _markdown_table, paper, reproduction
from .fig4 import settings as fig4_settings
from .fig4 import sp_spec as fig4_sp_spec

__all__ = ["PARAPET_CASE", "FACADE_CASE", "wall_strike", "flat_landing", "ImpactCheck"]

TITLE = "Damping that fits the model: targeted and per-interface beta on the paper's cases"
TARGET = "0.95eta"

PARAPET_CASE: dict[str, Any] = {
    "name": "parapet-free-rocking",
    "run": {"duration": 5.0, "record_interval": 0.005},
    "damping": {"beta": paper.PARAPET_BETA},
    "specimen": {"type": "parapet", "thickness": 0.23, "base_reduction": 0.007, "height": 0.73, "length": 1.0,
                 "density": 1800.0, "youngs_modulus": 1.8e9, "poisson": 0.25, "friction_angle_deg": 30.96,
                 "cohesion": 0.0, "tension": 0.0, "points_across": 2},
    "loading": {"type": "free-rocking", "block": "parapet", "tilt_fraction": 0.5},
}
"""``examples/parapet_free_rocking.toml`` (§4.1; H = 0.73 m inferred from the paper's 0.00305 s)."""

FACADE_CASE: dict[str, Any] = {
    "name": "facade-free-rocking",
    "run": {"duration": 5.0, "record_interval": 0.005},
    "damping": {"beta": paper.FACADE_BETA},
    "specimen": {"type": "facade", "width": 0.11, "height": 0.8, "length": 1.5, "density": 1750.0, "gap": 0.004,
                 "edge_radius": 0.008, "edge_facets": 4, "slope_deg": 0.0, "youngs_modulus": 1.8e9, "poisson": 0.25,
                 "friction_angle_deg": 30.96, "points_across": 2},
    "loading": {"type": "free-rocking", "block": "facade", "tilt_fraction": 0.5, "tilt_direction": [-1.0, 0.0, 0.0]},
}
"""``examples/facade_free_rocking.toml`` (§4.2, Fig. 13): released outward, away from the return walls."""


def _auto(target: str) -> dict[str, Any]:
    return {"damping.beta": "auto", "damping.target_restitution": target}


CRITICAL = {"damping.beta": "critical"}


# -- Table 2 block: the point count ----------------------------------------------------------------
def _table2_runs(ctx: Context) -> pd.DataFrame:
    points = (2, 10) if ctx.reduced else paper.TABLE2_POINTS
    duration = 4.0 if ctx.reduced else 10.0
    b, h, length = paper.TABLE2_BLOCK
    fixed = {"specimen.width": b, "specimen.height": h, "specimen.length": length, "specimen.density": paper.DENSITY,
             "specimen.youngs_modulus": paper.TABLE2_E, "specimen.friction_angle_deg": 80.0, "damping.alpha": 0.0}
    choices = {"paper 0.00693 s": {"damping.beta": paper.TABLE2_BETA}, "targeted 0.95 e_eta": _auto("0.95eta"),
               "targeted e_eta": _auto("eta"), "critical": CRITICAL}
    if ctx.reduced:
        choices.pop("targeted e_eta")
    specs, keys = [], []
    for n in points:
        for label, over in choices.items():
            specs.append(RunSpec.make(example_case("free-rocking"), {**fixed, "specimen.points_across": n, **over},
                                      duration=duration))
            keys.append((n, label))
    rows = ctx.execute("damping", specs)
    e_eta = housner_e_eta(math.atan(b / h))
    out: dict[int, dict[str, Any]] = {n: {"points across": n} for n in points}
    for (n, label), row in zip(keys, rows):
        beta = row.get("beta_s", row.get("damping.beta"))
        out[n][f"beta {label} [s]"] = float(beta)
        out[n][f"e_a/e_eta {label}"] = row["e_a_mean"] / e_eta
        if "beta_iterations" in row and label == "targeted 0.95 e_eta":
            out[n]["probe runs"] = int(row["beta_iterations"])
            out[n]["search [s]"] = float(row["beta_search_time_s"])
    return pd.DataFrame(list(out.values()))


# -- Fig. 4 blocks ---------------------------------------------------------------------------------
def _fig4_runs(ctx: Context) -> pd.DataFrame:
    s = fig4_settings(ctx)
    cases = [(b, h, e) for e in s.moduli for b, h in s.blocks][: 1 if ctx.reduced else None]
    dejong = ctx.execute("fig4", [fig4_sp_spec(b, h, e, s.duration) for b, h, e in cases])  # the Fig. 4 study's runs
    ours = []
    for b, h, e in cases:
        base = fig4_sp_spec(b, h, e, s.duration)
        over = {k: v for k, v in base.overrides if k != "damping.beta"}
        ours += [RunSpec.make(base.base, {**over, **_auto(TARGET)}, duration=s.duration),
                 RunSpec.make(base.base, {**over, **CRITICAL}, duration=s.duration)]
    rows = ctx.execute("damping", ours)
    out = []
    for k, ((b, h, e), dj) in enumerate(zip(cases, dejong)):
        tg, cr = rows[2 * k], rows[2 * k + 1]
        e_eta = housner_e_eta(math.atan(b / h))
        out.append({"B [m]": b, "H [m]": h, "E [MPa]": e / 1e6, "eta [deg]": math.degrees(math.atan(b / h)), "e_eta": e_eta,
                    "beta DeJong [s]": float(dj["damping.beta"]), "e_a/e_eta DeJong": dj["e_a_mean"] / e_eta,
                    "beta targeted 0.95 e_eta [s]": tg["beta_s"], "e_a/e_eta targeted": tg["e_a_mean"] / e_eta,
                    "probe runs": int(tg["beta_iterations"]), "beta critical [s]": cr["beta_s"],
                    "e_a/e_eta critical": cr["e_a_mean"] / e_eta})
    return pd.DataFrame(out)


# -- §4.1 parapet ----------------------------------------------------------------------------------
def _parapet_runs(ctx: Context) -> tuple[pd.DataFrame, dict[str, Any]]:
    duration = 2.0 if ctx.reduced else 5.0
    choices = {"paper best fit": {"damping.beta": paper.PARAPET_BETA},
               "paper formula (§2.2)": {"damping.beta": paper.PARAPET_BETA_FORMULA},
               "critical (per interface)": CRITICAL, "targeted e_eta": _auto("eta"), "targeted 0.95 e_eta": _auto(TARGET)}
    if ctx.reduced:
        choices.pop("critical (per interface)")
        choices.pop("targeted 0.95 e_eta")
    specs = [RunSpec.make(PARAPET_CASE, over, duration=duration, history=True) for over in choices.values()]
    rows = dict(zip(choices, ctx.execute("damping", specs)))
    eta = math.atan((0.23 - 0.007) / 0.73)  # about the chamfered base's edge
    ref = rows["paper best fit"]["history"]
    out = []
    for label, row in rows.items():
        h = row["history"]
        out.append({"beta": label, "beta [s]": float(row.get("beta_s", row.get("damping.beta"))),
                    "e_a mean": row["e_a_mean"], "e_a/e_eta": row["e_a_mean"] / housner_e_eta(eta),
                    "WME vs the paper's best fit": wme(ref["time"], ref["displacement"], h["time"], h["displacement"], overlap_only=True),
                    "rest time [s]": rest_time(h["time"], h["displacement"])})
    return pd.DataFrame(out), rows


# -- §4.2 façade: impacts measured directly --------------------------------------------------------
@dataclass(frozen=True)
class ImpactCheck:
    """One impact of a free block on a fixed one, measured from the recorded motion.

    Attributes:
        rebound: speed after / speed before of the striking point, normal to the struck face [-]
            (after: as it leaves the struck face; 0 if it stays on it).
        contact_time: how long the striking point stayed beyond first contact [s] (with beta = 0:
            half a period of the contact, pi / omega).
    """

    rebound: float
    contact_time: float


def _facade_material() -> JointMaterial:
    s = FACADE_CASE["specimen"]
    return JointMaterial.from_modulus(s["youngs_modulus"], s["height"], friction_angle=s["friction_angle_deg"])


def wall_strike(damping: Damping, *, rocking_velocity: float = 0.3) -> ImpactCheck:
    """The §4.2 façade rocking into its return walls at ``rocking_velocity`` [rad/s] from upright:
    the top's rebound from the walls and how long it stays on them (recorded every 20 us)."""
    from ..specimens import facade

    s = FACADE_CASE["specimen"]
    b = ModelBuilder(points=(s["points_across"], 2))
    b.default_material = _facade_material()
    facade(b, width=s["width"], height=s["height"], length=s["length"], density=s["density"], gap=s["gap"],
           edge_radius=s["edge_radius"], edge_facets=s["edge_facets"], rocking_velocity=rocking_velocity)
    top = (0.5 * s["width"], 0.5 * s["length"] - 0.05, s["height"])  # inner top edge, in front of a return wall
    ds = simulate(b.finalize(damping=damping), 0.04, record_interval=2e-5, monitors={"top": ("facade", top)}, progress=False)
    t, x = ds.time.values, ds.monitor_displacement.values[:, 0, 0]
    v = np.gradient(x, t)
    on = int(np.flatnonzero(x >= s["gap"])[0])  # the top closes the gap
    off = np.flatnonzero(x[on:] < s["gap"])  # ... and leaves the walls
    if len(off) == 0:
        return ImpactCheck(0.0, float(t[-1] - t[on]))
    return ImpactCheck(float(-v[on + off[0]] / v[on - 1]), float(t[on + off[0]] - t[on]))


def flat_landing(damping: Damping, *, speed: float = 0.1) -> ImpactCheck:
    """The §4.2 façade (rounded bottom edges) moving flat onto its foundation at ``speed`` [m/s]
    without gravity: its base impact alone, the edge impact of DeJong (§2.2)."""
    s = FACADE_CASE["specimen"]
    b = ModelBuilder(points=(s["points_across"], 2), gravity=(0.0, 0.0, 0.0))
    b.default_material = _facade_material()
    add_foundation(b, 2.0)
    poly = rounded_prism(s["width"], s["length"], s["height"], radius=s["edge_radius"], facets=s["edge_facets"], z0=0.0002,
                         name="facade")
    b.add_block(poly, density=s["density"], group="facade", name="facade", velocity=(0.0, 0.0, -speed))
    model = b.finalize(damping=damping)
    omega = critical_betas(model)[("facade", "foundation")].omega
    dt = math.pi / omega / 200.0
    ds = simulate(model, 0.0002 / speed + 12.0 / omega, dt=dt, record_interval=dt * 5, progress=False)
    t, z = ds.time.values, ds.block_displacement.values[:, 1, 2] - (-0.0002)
    touching = np.flatnonzero(z < 0.0)
    contact = float(t[touching[-1]] - t[touching[0]]) if len(touching) else 0.0
    return ImpactCheck(float(ds.block_velocity.values[-1, 1, 2]) / speed, contact)


def _facade_runs(ctx: Context) -> tuple[pd.DataFrame, pd.DataFrame]:
    duration = 2.0 if ctx.reduced else 5.0
    choices = {
        "paper best fit (one value)": {"damping.beta": paper.FACADE_BETA},
        "paper one-sided formula (one value)": {"damping.beta": paper.FACADE_BETA_ONE_SIDED},
        "paper two-sided formula (one value)": {"damping.beta": paper.FACADE_BETA_TWO_SIDED},
        "critical at the return walls (one value)": None,  # filled below: rockdem's own return-wall beta
        "critical per interface": CRITICAL,
        "targeted 0.95 e_eta base + critical return walls": {**_auto(TARGET), "damping.per_interface": True},
    }
    if ctx.reduced:
        for k in ("paper one-sided formula (one value)", "paper two-sided formula (one value)",
                  "targeted 0.95 e_eta base + critical return walls"):
            choices.pop(k)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        crit = critical_betas(parse_case(copy.deepcopy(FACADE_CASE)).model)
    beta_ret = crit[("facade", "return")].beta
    choices["critical at the return walls (one value)"] = {"damping.beta": beta_ret}
    specs = [RunSpec.make(FACADE_CASE, over, duration=duration, history=True) for over in choices.values()]
    rows = dict(zip(choices, ctx.execute("damping", specs)))
    single = rows["paper best fit (one value)"]
    out = []
    for label, row in rows.items():
        h = row["history"]
        t, signed = np.asarray(h["time"]), np.asarray(h["rotation"])
        th, th0 = np.abs(signed), abs(signed[0])
        pk = half_cycle_peaks(t, signed, min_prominence=SUMMARY_PEAK_PROMINENCE * th0)
        later = pk.value[1:]
        outward = np.abs(later[np.sign(later) == np.sign(signed[0])])  # the inward peaks stop at the walls (gap / H)
        pairs = row.get("beta_pairs", "")
        out.append({
            "beta": label,
            "beta foundation [s]": _pair_beta(pairs, "facade-foundation", row),
            "beta return walls [s]": _pair_beta(pairs, "facade-return", row),
            "first outward peak / release": float(outward[0] / th0) if len(outward) else 0.0,
            "outward peaks above 2 %": int(len(outward)),
            "late motion (t > 60 % of run) / release": float(th[t > 0.6 * t[-1]].max() / th0),
            "steps": row["steps"], "runtime [s]": row["runtime_s"],
            "steps / the best-fit run's": row["steps"] / single["steps"],
        })
    checks = []
    for label, damping in (("no damping", Damping()), ("paper best fit 0.00025 s", Damping(beta=paper.FACADE_BETA)),
                           ("critical per interface", Damping(beta="critical"))):
        wall, base = wall_strike(damping), flat_landing(damping)
        checks.append({"beta": label, "return walls: rebound": wall.rebound, "return walls: contact [ms]": 1e3 * wall.contact_time,
                       "base, flat landing: rebound": base.rebound, "base: contact [ms]": 1e3 * base.contact_time})
    return pd.DataFrame(out), pd.DataFrame(checks)


def _pair_beta(pairs: str, label: str, row: dict[str, Any]) -> float:
    for item in pairs.split("; "):
        if item.startswith(label + ":"):
            return float(item.split(":")[1].split(" s")[0])
    return float(row["damping.beta"])


def _measured_zeta(checks: pd.DataFrame, betas: dict[str, float]) -> dict[str, float]:
    """zeta = beta omega / 2 with omega = pi / (undamped contact time): the damping ratio each
    per-interface beta gives at the impact actually recorded."""
    free = checks.set_index("beta").loc["no damping"]
    return {"return walls": 0.5 * betas["return"] * math.pi / (1e-3 * free["return walls: contact [ms]"]),
            "base": 0.5 * betas["foundation"] * math.pi / (1e-3 * free["base: contact [ms]"])}


# -- the report ------------------------------------------------------------------------------------
@reproduction("damping", TITLE)
def damping(ctx: Context) -> Report:
    """Targeted and per-interface beta on the Table 2 block, the Fig. 4 blocks, the parapet and the façade."""
    t2 = _table2_runs(ctx)
    f4 = _fig4_runs(ctx)
    par, par_rows = _parapet_runs(ctx)
    fac, checks = _facade_runs(ctx)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        crit = critical_betas(parse_case(copy.deepcopy(FACADE_CASE)).model)
    zeta = _measured_zeta(checks, {"return": crit[("facade", "return")].beta, "foundation": crit[("facade", "foundation")].beta})
    figures = [_figure(ctx, t2, f4, par_rows)]
    notes = "\n\n".join([
        "## Fig. 4 blocks (2 points, 90 % of eta; DeJong's beta = the advisor's, from the Fig. 4 study's runs)",
        _markdown_table(f4),
        "## §4.1 parapet (single block, released from 50 % of eta; the test's record is not published: the paper's "
        "best-fitting run stands in for it in the WME)",
        _markdown_table(par),
        "## §4.2 one-sided façade (released outward from 50 % of eta)",
        _markdown_table(fac),
        "Impacts recorded directly (the façade rocking into its return walls at 0.3 rad/s; the façade moving flat onto "
        "its foundation at 0.1 m/s without gravity): rebound = speed after / speed before of the striking point.",
        _markdown_table(checks),
        f"Damping ratio of the per-interface betas at the recorded impacts, zeta = beta (pi / undamped contact time) / 2: "
        f"return walls {zeta['return walls']:.2f}, base {zeta['base']:.2f}.",
    ])
    return Report("damping", TITLE, t2, figures, comment=_comment(ctx, t2, f4, par, fac, checks, zeta), notes=notes)


def _figure(ctx: Context, t2: pd.DataFrame, f4: pd.DataFrame, par_rows: dict[str, Any]) -> str:
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(15, 4.2))
    for label, style in (("paper 0.00693 s", "s--"), ("targeted 0.95 e_eta", "o-"), ("targeted e_eta", "^-"), ("critical", "d:")):
        if f"e_a/e_eta {label}" in t2:
            ax1.plot(t2["points across"], t2[f"e_a/e_eta {label}"], style, label=label)
    ax1.axhline(0.95, color="0.6", lw=0.8)
    ax1.axhline(1.0, color="0.6", lw=0.8)
    ax1.set(xlabel="interface points across", ylabel="mean e_a / e_eta", title="(A) Table 2 block: e_a vs points")
    ax2.plot(f4["eta [deg]"], f4["e_a/e_eta DeJong"], "s", mfc="none", label="DeJong (advisor)")
    ax2.plot(f4["eta [deg]"], f4["e_a/e_eta targeted"], "o", label="targeted 0.95 e_eta")
    ax2.plot(f4["eta [deg]"], f4["e_a/e_eta critical"], "d", mfc="none", label="critical (kn A / m)")
    ax2.axhline(0.95, color="0.6", lw=0.8)
    ax2.set(xlabel="eta [deg]", ylabel="mean e_a / e_eta", title="(B) Fig. 4 blocks")
    for label, row in par_rows.items():
        h = row["history"]
        ax3.plot(h["time"], np.asarray(h["displacement"]) * 1e3, lw=1.0,
                 label=f"{label}: {float(row.get('beta_s', row.get('damping.beta'))):.2g} s")
    ax3.set(xlabel="time [s]", ylabel="top displacement [mm]", title="(C) §4.1 parapet, free rocking")
    for ax in (ax1, ax2, ax3):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    name = "damping.png"
    save_figure(fig, ctx.out / name)
    plt.close(fig)
    return name


def _spread(col: pd.Series) -> float:
    return float(col.max() / col.min() - 1.0)


def _comment(ctx: Context, t2: pd.DataFrame, f4: pd.DataFrame, par: pd.DataFrame, fac: pd.DataFrame,
             checks: pd.DataFrame, zeta: dict[str, float]) -> str:
    p = par.set_index("beta")
    f = fac.set_index("beta")
    c = checks.set_index("beta")
    tg = "targeted 0.95 e_eta"
    paper_col, tg_col = "e_a/e_eta paper 0.00693 s", f"e_a/e_eta {tg}"
    lo_dj, hi_dj = f4.loc[f4["e_a/e_eta DeJong"].idxmin()], f4.loc[f4["e_a/e_eta DeJong"].idxmax()]
    beta_e = p.loc["targeted e_eta", "beta [s]"]
    best, formula = paper.PARAPET_BETA, paper.PARAPET_BETA_FORMULA
    crit, light = f.loc["critical per interface"], f.loc["paper best fit (one value)"]
    one_value = f.loc["critical at the return walls (one value)"]
    wme_col, steps_col = "WME vs the paper's best fit", "steps / the best-fit run's"
    zeta_light = _measured_zeta(checks, {"return": paper.FACADE_BETA, "foundation": paper.FACADE_BETA})
    text = f"""
**Point count (Table 2 block, Fig. 9B).** With the paper's beta 0.00693 s the mean e_a / e_eta goes from
{t2[paper_col].iloc[0]:.3f} with {int(t2['points across'].iloc[0])} points to {t2[paper_col].iloc[-1]:.3f} with
{int(t2['points across'].iloc[-1])} (spread {_spread(t2[paper_col]):.1%}): one beta damps the stiffer springs of fewer
points more, as in the paper's Fig. 9B. The targeted beta (0.95 e_eta) grows with the point count, from
{t2[f'beta {tg} [s]'].iloc[0]:.4g} to {t2[f'beta {tg} [s]'].iloc[-1]:.4g} s, and the runs' mean e_a / e_eta stays at
{t2[tg_col].min():.3f} to {t2[tg_col].max():.3f} (spread {_spread(t2[tg_col]):.1%}): yes, targeting makes e_a independent
of the point count, which is what it is built to do (each search: {int(t2['probe runs'].min())} to
{int(t2['probe runs'].max())} probe runs, {t2['search [s]'].min():.1f} to {t2['search [s]'].max():.1f} s). The
per-interface critical beta ({t2['beta critical [s]'].iloc[0]:.4g} s, zeta = 1 at omega = sqrt(kn A / m)) is the same for
every point count, so it leaves the Fig. 9B trend (spread {_spread(t2['e_a/e_eta critical']):.1%}).

**Fig. 4 blocks.** DeJong's beta (the advisor's, paper Eq. 3) gives mean e_a / e_eta from {lo_dj['e_a/e_eta DeJong']:.3f}
({lo_dj['B [m]']:g} x {lo_dj['H [m]']:g} m at {lo_dj['E [MPa]']:.0f} MPa) to {hi_dj['e_a/e_eta DeJong']:.3f}
({hi_dj['B [m]']:g} x {hi_dj['H [m]']:g} m at {hi_dj['E [MPa]']:.0f} MPa): its energy loss per impact depends on the
block and on E. The targeted runs all end at {f4['e_a/e_eta targeted'].min():.3f} to {f4['e_a/e_eta targeted'].max():.3f}
of e_eta (target 0.95) with betas of {f4['beta targeted 0.95 e_eta [s]'].min():.3g} to
{f4['beta targeted 0.95 e_eta [s]'].max():.3g} s that hardly depend on E (DeJong's: {f4['beta DeJong [s]'].min():.3g} to
{f4['beta DeJong [s]'].max():.3g} s, as 1 / sqrt(E)). The per-interface critical beta (the model's springs, sqrt(B / 1 m)
times DeJong's: see docs/damping.md on the paper's Eq. 2) gives {f4['e_a/e_eta critical'].min():.3f} to
{f4['e_a/e_eta critical'].max():.3f}: critical damping of the contact does not fix the restitution.

**§4.1 parapet.** Targeted to e_eta the beta is {beta_e:.3g} s, {beta_e / best:.2g} times the paper's best fit
{best} s, and its history is close to the best-fitting run's (WME {p.loc['targeted e_eta', wme_col]:.3f};
the paper's formula value {formula} s: {p.loc['paper formula (§2.2)', wme_col]:.3f}). Targeted to
0.95 e_eta it is {p.loc[tg, 'beta [s]'] if tg in p.index else float('nan'):.3g} s, beyond the formula value the paper found
over-damped. The paper's best-fit beta gives a mean e_a of {p.loc['paper best fit', 'e_a/e_eta']:.3f} e_eta on this model:
as far as this model stands for the test, the test lost about Housner's e_eta per impact, so the e_eta target
lands on it and the 0.95 e_eta target over-damps. The
parapet's height (0.73 m) and release (50 % of eta) are inferred and assumed (the case file says how), so this
agreement is indicative; for a test with a measured restitution, give that number as the target.

**§4.2 one-sided façade.** The critical frequencies are
{2 / crit['beta foundation [s]']:.0f} rad/s at the base (landing flat, omega = sqrt(kn A / m)) and {2 / crit['beta return walls [s]']:.0f} rad/s
at the return walls (the gap closed by the top row of points, half the walls' end faces, on the free façade:
1 / m_eff = (1 + 3 H^2 / (B^2 + H^2)) / m; kn = E / H on both), so per-interface critical betas of
{crit['beta foundation [s]']:.3g} and {crit['beta return walls [s]']:.3g} s: the paper's factor of 28
between its one-sided (0.00017 s) and two-sided (0.0047 s) values comes from its horizontally stacked
formula (B and H swapped), not from this contact. On the recorded impacts the per-interface betas give
zeta = {zeta['base']:.2f} at the base (flat landing) and {zeta['return walls']:.2f} at the return walls (from the undamped
contact times); the top does not rebound from the walls ({c.loc['critical per interface', 'return walls: rebound']:.3f}
of its approach speed: the slow peel-off under gravity) where the paper's 0.00025 s lets it rebound with
{c.loc['paper best fit 0.00025 s', 'return walls: rebound']:.2f} (zeta about 0.2). In free rocking the first cycle (base impact, wall
strike, base impact) takes most of the energy whatever beta: the first outward peak is
{f['first outward peak / release'].min():.3f} to {f['first outward peak / release'].max():.3f} of the release. beta decides
the tail: {int(light['outward peaks above 2 %'])} outward peaks above 2 % of the release with 0.00025 s, still
{light['late motion (t > 60 % of run) / release']:.2g} of it late in the run (the paper's undamped tail), against
{int(crit['outward peaks above 2 %'])} with critical damping per interface and none late: the paper's over-damped
regime (beta >= 0.002 s, "over-damped after the first impact"). So critical damping of both impacts does
not reproduce the test either: the paper's best fit, 0.00025 s, is zeta = {zeta_light['base']:.2f} at the base and
{zeta_light['return walls']:.2f} at the return walls here (from the same contact times),
and what its tail lacks is damping at small amplitudes, which one viscous beta per pair cannot add. Fitting
the test needs its own measured restitution as the target (beta = "auto" with a number); the paper does not
print it, so that fit is left open here.

**Cost.** The per-interface run took {crit[steps_col]:.2f} times the steps of the 0.00025 s run and
{crit['steps'] / one_value['steps']:.2f} times those of one beta critical at the return walls: per-interface damping costs
what a single critical beta costs. With the default implicit dashpots the step does not depend on beta, so
critical damping costs what the paper's light 0.00025 s costs; with explicit dashpots (3DEC's scheme,
`run.dashpots = "explicit"`) it costs the SP timestep reduction sqrt(1 + xi^2) - xi (the engine's bound
takes each block's largest beta).
Wall times of these sub-second runs, two at a time on a shared machine, are noisy: see
benchmarks/bench_damping.py --facade for timed runs.
"""
    if ctx.reduced:
        text += "\n(Reduced version: fewer cases and shorter runs; see docs/reproduction/damping.md for the full one.)"
    return text
