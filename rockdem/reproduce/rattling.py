"""§2.1 and Fig. 1 of Galvez et al. 2022: the "rattling effect", free vibration under gravity alone.

Columns and walls of 370 x 250 x 120 mm blocks (L along the wall y, W thickness x, H) stand on the
fixed foundation block, every joint bonded (c = 1.4 MPa, ft = 0.84 MPa, mu = 0.7), kn = E / block
height with E = 1800 MPa, no damping. Released at rest with every joint touching but unloaded,
gravity sets them vibrating about their static settlement: the "rattling". Per case we measure the
vertical and horizontal amplitude of the top (half the peak-to-peak of the monitor ``top`` over
the second half of the run) and the dominant frequency (FFT of the vertical displacement), and
compare them with the paper's printed values and with an independent closed form: the chain of
rigid courses on bed-joint springs (:func:`chain_response`, modal superposition), which is exact
for rigid blocks whose courses move as layers.

Cases (Fig. 1): columns of 2 and 7 blocks (A, B; and of 1 and 6, the same columns if the paper
counted the fixed block), the 7-block column height with taller blocks (C, 3 x 0.28 m), longer
blocks (D, 1.11 m), walls with head joints (E, 3 bricks per course, running bond) 0.84 m (7
courses) and 3.00 m (25 courses) tall, the walls with a cohesionless base joint, and the 7-block
column and the 0.84 m wall with SP damping at the advisor's beta (:func:`rockdem.advisor.advise`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from matplotlib import rc_context
from matplotlib.figure import Figure
from numpy.typing import NDArray

from ..advisor import advise
from ..plots import STYLE, save_figure
from ..studies import RunSpec
from . import Context, Report, _markdown_table, paper, reproduction

__all__ = ["RattleCase", "CASES", "rattle_case", "chain_response", "uniform", "dominant_frequency", "amplitude"]

TITLE = "§2.1 and Fig. 1: rattling of columns and walls under gravity alone (amplitude, frequency, SP damping)"
RECORD_INTERVAL = 1e-4  # s: 5 kHz Nyquist, above every chain mode of the cases
FULL_DURATION = 2.0  # s
FULL_DURATION_SP = 0.25  # s: SP damping at beta ~ 3 ms divides the step by about 50; the rattling is gone in ms
REDUCED_DURATION = 0.1  # s
REDUCED_DURATION_SP = 0.05  # s
POINTS = (2, 3)  # interface points (across, along): odd along for running bond
QUIET = 1e-3
"""An amplitude below this fraction of the static settlement is no rattling (no frequency is given)."""


@dataclass(frozen=True)
class RattleCase:
    """One structure of Fig. 1: ``courses`` of ``bricks`` bricks (1: a column) of length ``length``
    and height ``height`` [m], running or stack ``bond``, a cohesive or cohesionless base, SP damping
    at the advisor's beta or none. ``panel`` is the paper's Fig. 1 panel or reading."""

    name: str
    panel: str
    courses: int
    bricks: int = 1
    length: float = paper.RATTLING_BLOCK[0]
    height: float = paper.RATTLING_BLOCK[2]
    cohesive_base: bool = True
    sp: bool = False

    @property
    def width(self) -> float:
        return paper.RATTLING_BLOCK[1]

    @property
    def total_height(self) -> float:
        return self.courses * self.height

    @property
    def bond(self) -> str:
        return "running" if self.bricks > 1 else "stack"

    @property
    def beta(self) -> float:
        """The advisor's SP beta [s] for this structure (0 unless ``sp``): a single block, or
        ``courses`` stacked blocks, of its width, height and length."""
        if not self.sp:
            return 0.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return float(advise(width=self.width, height=self.total_height, length=self.length * self.bricks,
                                density=paper.RATTLING_DENSITY, youngs_modulus=paper.RATTLING_E, blocks=self.courses).beta_sp)


CASES: tuple[RattleCase, ...] = (
    RattleCase("column 1", "A, if the fixed block is counted", 1),
    RattleCase("column 2", "A", 2),
    RattleCase("column 6", "B, if the fixed block is counted", 6),
    RattleCase("column 7", "B", 7),
    RattleCase("column 3 x 0.28 m", "C (taller blocks)", 3, height=0.28),
    RattleCase("column 7, 1.11 m long", "D (longer blocks)", 7, length=1.11),
    RattleCase("wall 0.84 m", "E (head joints)", 7, bricks=3),
    RattleCase("wall 3.00 m", "E, 3.00 m tall", 25, bricks=3),
    RattleCase("wall 0.84 m, cohesionless base", "E, cohesionless base", 7, bricks=3, cohesive_base=False),
    RattleCase("wall 3.00 m, cohesionless base", "E, 3.00 m, cohesionless base", 25, bricks=3, cohesive_base=False),
    RattleCase("column 7, SP", "B with SP damping", 7, sp=True),
    RattleCase("wall 0.84 m, SP", "E with SP damping", 7, bricks=3, sp=True),
)
REDUCED_CASES = ("column 2", "column 7", "column 7, SP")


def rattle_case(c: RattleCase) -> dict[str, Any]:
    """Case dict of ``c``: a ``wall`` specimen (a column is one brick per course), gravity only."""
    mu = math.degrees(math.atan(paper.RATTLING_FRICTION))
    joint = {"youngs_modulus": paper.RATTLING_E, "poisson": 0.25, "friction_angle_deg": mu,
             "cohesion": paper.RATTLING_COHESION, "tension": paper.RATTLING_TENSION}
    base = dict(joint) if c.cohesive_base else {**joint, "cohesion": 0.0, "tension": 0.0}
    return {
        "description": f"Rattling (paper §2.1): {c.name}, gravity only",
        "run": {"record_interval": RECORD_INTERVAL},
        "damping": {"alpha": 0.0, "beta": c.beta},
        "specimen": {"type": "wall", "brick": [c.width, c.length, c.height], "courses": c.courses,
                     "bricks_per_course": c.bricks, "bond": c.bond, "density": paper.RATTLING_DENSITY,
                     "points_across": POINTS[0], "points_along": POINTS[1], "joint": joint, "base": base},
        "loading": {"type": "gravity"},
    }


def chain_response(n: int, height: float, t: NDArray[np.float64], *, beta: float = 0.0,
                   youngs_modulus: float = paper.RATTLING_E, density: float = paper.RATTLING_DENSITY,
                   g: float = 9.81) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Closed form: ``n`` rigid courses of ``height`` [m] on bed-joint springs kn = E / height
    (per unit area, so the plan size drops out), released at rest with unloaded joints under gravity,
    with SP (stiffness-proportional) damping C = beta K.

    Returns:
        (natural frequencies [Hz] (n,), static settlement of each course [m] (n,, negative: down),
        vertical displacement of the top course at times ``t`` [m] (len(t),)).
    """
    k = youngs_modulus / height  # Pa/m = N/m per m^2 of joint
    m = density * height  # kg per m^2
    kk = np.zeros((n, n))
    for s in range(n):  # spring s below course s
        kk[s, s] += k
        if s > 0:
            kk[s - 1, s - 1] += k
            kk[s, s - 1] -= k
            kk[s - 1, s] -= k
    w2, modes = np.linalg.eigh(kk / m)  # mass-normalised: modes.T @ modes = I (uniform masses)
    w = np.sqrt(w2)
    u_static = np.linalg.solve(kk, -m * g * np.ones(n))
    q0 = modes.T @ (-u_static)  # modal coordinates of the start (u = 0) about the static state
    t = np.asarray(t, dtype=float)
    xi = 0.5 * beta * w
    root = np.sqrt((xi**2 - 1.0).astype(complex))
    r1, r2 = w * (-xi + root), w * (-xi - root)
    same = np.isclose(r1, r2)
    r2 = np.where(same, r2 * (1 + 1e-9) - 1e-9, r2)  # critical damping: split the double root
    a, b = q0 * r2 / (r2 - r1), -q0 * r1 / (r2 - r1)
    q = (a[None, :] * np.exp(np.outer(t, r1)) + b[None, :] * np.exp(np.outer(t, r2))).real
    return w / (2.0 * math.pi), u_static, u_static[-1] + q @ modes[-1, :]


def uniform(t: NDArray[np.float64], x: NDArray[np.float64], interval: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Resample a history recorded at the first step after each ``interval`` [s] onto exact
    multiples of it (linear interpolation): the FFT needs uniform samples."""
    tu = np.arange(t[0], t[-1] + 0.5 * interval, interval)
    tu = tu[tu <= t[-1]]
    return tu, np.interp(tu, t, x)


def dominant_frequency(t: NDArray[np.float64], x: NDArray[np.float64], interval: float = RECORD_INTERVAL) -> float:
    """Frequency [Hz] of the largest peak of the spectrum of ``x`` (mean removed, Hann window, zero
    padded 16 x; uniform resampling first); NaN if ``x`` is constant."""
    tu, xu = uniform(t, x, interval)
    xu = xu - xu.mean()
    if len(xu) < 8 or not np.any(xu):
        return float("nan")
    nfft = 16 * len(xu)
    spec = np.abs(np.fft.rfft(xu * np.hanning(len(xu)), nfft))
    f = np.fft.rfftfreq(nfft, interval)
    return float(f[1 + int(np.argmax(spec[1:]))])


def spectrum(t: NDArray[np.float64], x: NDArray[np.float64], interval: float = RECORD_INTERVAL) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One-sided amplitude spectrum of ``x`` (mean removed, Hann window): (frequency [Hz], amplitude [m])."""
    tu, xu = uniform(t, x, interval)
    xu = xu - xu.mean()
    w = np.hanning(len(xu))
    return np.fft.rfftfreq(len(xu), interval), 2.0 * np.abs(np.fft.rfft(xu * w)) / w.sum()


def amplitude(t: NDArray[np.float64], x: NDArray[np.float64]) -> float:
    """Rattling amplitude [m]: half the peak-to-peak of ``x`` over the second half of the run."""
    late = t >= 0.5 * t[-1]
    return 0.5 * float(np.ptp(x[late])) if np.any(late) else float("nan")


@dataclass(frozen=True)
class Rattle:
    """A case and its run's row."""

    case: RattleCase
    row: dict[str, Any]

    def top(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Time [s] and displacement (x, y, z) of the monitor ``top`` [m], shape (T, 3)."""
        h = self.row["history"]
        return np.asarray(h["time"], dtype=float), np.asarray(h["monitor_xyz"], dtype=float)[:, 0, :]


def _durations(ctx: Context) -> tuple[float, float]:
    return (REDUCED_DURATION, REDUCED_DURATION_SP) if ctx.reduced else (FULL_DURATION, FULL_DURATION_SP)


def rattling_runs(ctx: Context) -> list[Rattle]:
    """Run (or read from the store) the cases (the reduced set with ``ctx.reduced``)."""
    cases = [c for c in CASES if c.name in REDUCED_CASES] if ctx.reduced else list(CASES)
    dur, dur_sp = _durations(ctx)
    specs = [RunSpec.make(rattle_case(c), duration=dur_sp if c.sp else dur, history=True, history_xyz=True) for c in cases]
    return [Rattle(c, r) for c, r in zip(cases, ctx.execute("rattling", specs))]


def _summary(r: Rattle) -> dict[str, Any]:
    c = r.case
    t, u = r.top()
    freqs, _, z_chain = chain_response(c.courses, c.height, t, beta=c.beta)
    amp = amplitude(t, u[:, 2])
    settle = abs(float(np.mean(u[t >= 0.5 * t[-1], 2])))
    f = dominant_frequency(t, u[:, 2]) if amp > QUIET * settle else float("nan")
    row = r.row
    standard = c.bricks == 1 and (c.length, c.height) == (paper.RATTLING_BLOCK[0], paper.RATTLING_BLOCK[2]) and not c.sp
    paper_v = paper.RATTLING_VERTICAL.get(c.courses) if standard else None
    if c.bricks > 1 and not c.sp:
        paper_v = paper.RATTLING_WALL_VERTICAL if c.cohesive_base else paper.RATTLING_COHESIONLESS_BASE
        if c.courses != 7:
            paper_v = None
    return {
        "case": c.name, "Fig. 1": c.panel, "courses": c.courses, "bricks per course": c.bricks,
        "block L x H [m]": f"{c.length:g} x {c.height:g}", "height [m]": c.total_height,
        "base": "cohesive" if c.cohesive_base else "cohesionless", "beta [s]": c.beta,
        "paper vertical amplitude [mm]": paper_v * 1e3 if paper_v else float("nan"),
        "vertical amplitude [mm]": 1e3 * amp,
        "chain model amplitude [mm]": 1e3 * amplitude(t, z_chain),
        "static settlement [mm]": 1e3 * settle,
        "frequency (FFT) [Hz]": f,
        "chain fundamental [Hz]": float(freqs[0]),
        "out-of-plane (x) amplitude [mm]": 1e3 * amplitude(t, u[:, 0]),
        "in-plane (y) amplitude [mm]": 1e3 * amplitude(t, u[:, 1]),
        "failed tension [%]": 100.0 * row["failed_tension_fraction"],
        "failed shear [%]": 100.0 * row["failed_shear_fraction"],
        "top drift at the end [mm]": 1e3 * float(math.hypot(u[-1, 0], u[-1, 1])),
        "energy created [J]": row.get("energy_created_J", float("nan")), "energy scale [J]": row.get("energy_scale_J", float("nan")),
        "duration [s]": float(t[-1]),
        "diverged": row.get("status") == "diverged",
        "runtime [s]": row["runtime_s"],
    }


def _figure(runs: Sequence[Rattle], df: pd.DataFrame) -> Figure:
    """(A) top vertical displacement, first 20 ms, with the chain model; (B) spectra with the chain
    modes and the paper's 300-1600 Hz band; (C) amplitudes: ours, chain model, paper; (D) SP damping."""
    by = {r.case.name: r for r in runs}
    with rc_context(STYLE):
        fig = Figure(figsize=(11.0, 8.0), layout="constrained")
        (a, b), (c, d) = fig.subplots(2, 2)
        show = [n for n in ("column 2", "column 7", "column 3 x 0.28 m", "wall 0.84 m", "wall 3.00 m") if n in by]
        for k, name in enumerate(show):
            r = by[name]
            t, u = r.top()
            keep = t <= 0.02
            _, _, zc = chain_response(r.case.courses, r.case.height, t[keep])
            a.plot(t[keep] * 1e3, u[keep, 2] * 1e3, color=f"C{k}", lw=1.0, label=name)
            a.plot(t[keep] * 1e3, zc * 1e3, color=f"C{k}", lw=0.8, ls="--")
            f, amp = spectrum(t, u[:, 2])
            b.semilogy(f, amp * 1e3, color=f"C{k}", lw=0.9, label=name)
            for fm in chain_response(r.case.courses, r.case.height, t[:1])[0][:3]:
                b.axvline(fm, color=f"C{k}", lw=0.6, ls=":")
        a.set(xlabel="time [ms]", ylabel="top vertical displacement [mm]", title="A: rattling (solid) and chain model (dashed)")
        a.legend(fontsize=7)
        b.axvspan(*paper.RATTLING_FREQUENCY_RANGE, color="0.85", zorder=0, label="paper: 300-1600 Hz")
        b.set(xlabel="frequency [Hz]", ylabel="amplitude [mm]", xlim=(0, 3000), title="B: spectra of the top vertical displacement (dotted: chain modes)")
        b.legend(fontsize=7)
        und = df[df["beta [s]"] == 0.0]
        x = np.arange(len(und))
        c.bar(x - 0.27, und["vertical amplitude [mm]"], 0.27, label="ours, vertical")
        c.bar(x, und["chain model amplitude [mm]"], 0.27, label="chain model, vertical")
        c.bar(x + 0.27, und["paper vertical amplitude [mm]"].fillna(0.0), 0.27, label="paper, vertical")
        c.plot(x, und["out-of-plane (x) amplitude [mm]"].clip(lower=1e-16), "kv", ms=5, label="ours, out of plane (x)")
        c.axhline(paper.RATTLING_WALL_OUT_OF_PLANE * 1e3, color="C3", ls="--", lw=0.8, label="paper: walls, out of plane 4e-3 mm")
        c.set_yscale("log")
        c.set_xticks(x, und["case"], rotation=35, ha="right", fontsize=7)
        c.set(ylabel="amplitude [mm]", title="C: rattling amplitude (half peak-to-peak, second half of the run)")
        c.legend(fontsize=7)
        for k, name in enumerate([n for n in ("column 7", "wall 0.84 m") if n in by and f"{n}, SP" in by]):
            for r, ls in ((by[name], "-"), (by[f"{name}, SP"], "--")):
                t, u = r.top()
                keep = t <= 0.02
                d.plot(t[keep] * 1e3, u[keep, 2] * 1e3, color=f"C{k}", ls=ls, lw=1.0,
                       label=f"{r.case.name}" + (f" (beta = {r.case.beta * 1e3:.2f} ms)" if r.case.sp else ", no damping"))
        d.set(xlabel="time [ms]", ylabel="top vertical displacement [mm]", title="D: SP damping at the advisor's beta")
        d.legend(fontsize=7)
    return fig


def _fmt(v: float) -> str:
    return f"{v:.2g}"


def _comment(df: pd.DataFrame) -> str:
    und = df[df["beta [s]"] == 0.0]
    ratio = und["vertical amplitude [mm]"] / und["chain model amplitude [mm]"]
    ferr = (und["frequency (FFT) [Hz]"] / und["chain fundamental [Hz]"] - 1.0).abs()
    get = und.set_index("case")
    lines = [
        f"Every undamped case rattles exactly as the closed-form chain of rigid courses on bed-joint springs "
        f"predicts: measured vertical amplitude / chain model {ratio.min():.3f} to {ratio.max():.3f}, dominant "
        f"frequency within {100 * ferr.max():.1f} % of the chain's fundamental. The amplitude is the static "
        "settlement (the joints start unloaded, so gravity sets the courses vibrating about it), rho g H^2 (1 + 1/n) / (2 E) "
        "for n courses of a column of height H."
    ]
    if {"column 2", "column 7"} <= set(get.index):
        c2, c7 = get.loc["column 2"], get.loc["column 7"]
        lines.append(
            f"Columns of 2 and 7 blocks: {_fmt(c2['vertical amplitude [mm]'])} and {_fmt(c7['vertical amplitude [mm]'])} mm at "
            f"{c2['frequency (FFT) [Hz]']:.0f} and {c7['frequency (FFT) [Hz]']:.0f} Hz (paper: 2e-4 and 22e-4 mm, 300-1600 Hz)."
        )
    if {"column 1", "column 6"} <= set(get.index):
        c1, c6 = get.loc["column 1"], get.loc["column 6"]
        lines.append(
            f"If the paper counted the fixed block in its two and seven blocks, the columns are of 1 and 6 free blocks: "
            f"{_fmt(c1['vertical amplitude [mm]'])} and {_fmt(c6['vertical amplitude [mm]'])} mm at {c1['frequency (FFT) [Hz]']:.0f} "
            f"and {c6['frequency (FFT) [Hz]']:.0f} Hz, the paper's 300-1600 Hz range end to end and amplitudes within a factor "
            f"{max(c1['vertical amplitude [mm]'] / 2e-4, 2e-4 / c1['vertical amplitude [mm]'], c6['vertical amplitude [mm]'] / 22e-4, 22e-4 / c6['vertical amplitude [mm]']):.1f} "
            "of its 2e-4 and 22e-4 mm: we take this as the paper's reading."
        )
    if {"column 7", "column 3 x 0.28 m"} <= set(get.index):
        c7, ct = get.loc["column 7"], get.loc["column 3 x 0.28 m"]
        lower_f = ct["frequency (FFT) [Hz]"] < c7["frequency (FFT) [Hz]"]
        lower_a = ct["vertical amplitude [mm]"] < c7["vertical amplitude [mm]"]
        lines.append(
            f"Taller blocks, same 0.84 m column: frequency {c7['frequency (FFT) [Hz]']:.0f} -> {ct['frequency (FFT) [Hz]']:.0f} Hz "
            f"({'lower, as in the paper' if lower_f else 'not lower, unlike the paper'}), amplitude {_fmt(c7['vertical amplitude [mm]'])} -> "
            f"{_fmt(ct['vertical amplitude [mm]'])} mm ({'lower, as in the paper' if lower_a else 'higher: the paper found it lower'}; "
            "with kn = E / block height the settlement rho g H^2 (1 + 1/n) / (2 E) grows as the block count n falls)."
        )
    if {"column 7", "column 7, 1.11 m long"} <= set(get.index):
        c7, cl = get.loc["column 7"], get.loc["column 7, 1.11 m long"]
        lines.append(
            f"Longer blocks: {_fmt(cl['vertical amplitude [mm]'])} mm at {cl['frequency (FFT) [Hz]']:.0f} Hz against "
            f"{_fmt(c7['vertical amplitude [mm]'])} mm at {c7['frequency (FFT) [Hz]']:.0f} Hz: no effect, as in the paper "
            "(stiffness and mass both scale with the plan area)."
        )
    walls = und[und["bricks per course"] > 1]
    if len(walls):
        lines.append(
            f"Walls with head joints: vertical amplitudes {', '.join(_fmt(v) for v in walls['vertical amplitude [mm]'])} mm "
            f"({', '.join(walls['case'])}), the chain model's again; the taller wall rattles more and slower, as in the paper. "
            f"Horizontal rattling stays at round-off, at most {_fmt(walls['out-of-plane (x) amplitude [mm]'].max())} mm out of plane "
            f"and {_fmt(walls['in-plane (y) amplitude [mm]'].max())} mm in plane, where 3DEC gave 4e-3 mm out of plane (the paper's y) "
            "and 1e-3 mm vertically: in our model the wall and its loads are symmetric about its mid-plane, so nothing drives "
            "an out-of-plane motion; 3DEC's came from a source the paper does not identify. "
            f"No joint failed in any of our runs (largest failed share {max(und['failed tension [%]'].max(), und['failed shear [%]'].max()):.2g} %), "
            f"and the largest top drift at the end is {_fmt(und['top drift at the end [mm]'].max())} mm: the 3.00 m wall's base joint, "
            "which failed in tension in 3DEC after a few seconds (drift 14e-3 mm), stays in compression here, as it must in a "
            "vibration that only ever unloads a joint back to zero force. The cohesionless base changes nothing for the same "
            "reason (the paper: 3e-4 mm with a cohesionless base against 4e-3 mm with a cohesive one)."
        )
    sp = df[df["beta [s]"] > 0.0]
    for _, r in sp.iterrows():
        base = r["case"].removesuffix(", SP")
        if base in get.index:
            w1 = 2.0 * math.pi * r["chain fundamental [Hz]"]
            xi1 = 0.5 * r["beta [s]"] * w1
            lines.append(
                f"SP damping at the advisor's beta = {r['beta [s]'] * 1e3:.2f} ms ({base}): amplitude over the second half of the run "
                f"{_fmt(r['vertical amplitude [mm]'])} mm against {_fmt(get.loc[base, 'vertical amplitude [mm]'])} mm undamped, as the "
                f"chain model with C = beta K gives ({_fmt(r['chain model amplitude [mm]'])} mm): the fundamental rattling mode gets a "
                f"damping ratio beta omega / 2 = {xi1:.2f} and dies out within about {1e3 * 3.0 / (xi1 * w1):.0f} ms, the higher ones are "
                "over-damped, and the column settles into its static position."
            )
    return " ".join(lines)


def _notes(df: pd.DataFrame, reduced: bool) -> str:
    dur, dur_sp = (REDUCED_DURATION, REDUCED_DURATION_SP) if reduced else (FULL_DURATION, FULL_DURATION_SP)
    und = df[df["beta [s]"] == 0.0]

    def ours(case: str, col: str) -> str:
        v = und[und["case"] == case][col]
        return _fmt(float(v.iloc[0])) if len(v) else "not run (reduced version)"

    paper_rows = pd.DataFrame([
        {"quantity": "frequency, columns (cases in table order)", "paper": "300-1600 Hz (2 and 7 blocks)",
         "ours": ", ".join(f"{v:.0f}" for v in und[und["bricks per course"] == 1]["frequency (FFT) [Hz]"]) + " Hz"},
        {"quantity": "vertical amplitude, 2 blocks / 7 blocks", "paper": "2e-4 / 22e-4 mm",
         "ours": " / ".join(_fmt(v) for v in und[und["case"].isin(["column 2", "column 7"])]["vertical amplitude [mm]"]) + " mm"},
        {"quantity": "horizontal amplitude, columns", "paper": "1e-17 mm",
         "ours": _fmt(und[und["bricks per course"] == 1][["out-of-plane (x) amplitude [mm]", "in-plane (y) amplitude [mm]"]].to_numpy().max()) + " mm"},
        {"quantity": "0.84 m wall: out of plane / vertical", "paper": "4e-3 / 1e-3 mm",
         "ours": " / ".join(ours("wall 0.84 m", k) for k in ("out-of-plane (x) amplitude [mm]", "vertical amplitude [mm]")) + " mm"},
        {"quantity": "base joint failing in tension, drift", "paper": "after a few seconds, 14e-3 mm",
         "ours": f"no failure in {dur:g} s; largest drift {_fmt(und['top drift at the end [mm]'].max())} mm"},
        {"quantity": "cohesionless base, 0.84 m wall, vertical", "paper": "3e-4 mm (cohesive: 4e-3 mm)",
         "ours": ours("wall 0.84 m, cohesionless base", "vertical amplitude [mm]") + " mm"},
    ])
    return f"""
## The paper's numbers beside ours

{_markdown_table(paper_rows)}

## Setup and definitions

- Blocks L x W x H = 0.37 x 0.25 x 0.12 m (L along the wall, y; W the thickness, x), 1800 kg/m^3 (not stated in
  §2.1), `wall` specimens (a column is one brick per course) on the fixed foundation block, {POINTS[0]} x {POINTS[1]}
  interface points per face; kn = E / block height, ks = 0.4 kn; joints c = 1.4 MPa, ft = 0.84 MPa, mu = 0.7;
  the cohesionless base has c = ft = 0. Walls: 3 bricks of 0.37 m per course (1.11 m long), running bond with half
  bricks at the ends. Gravity only; no damping unless "beta" is given (SP, the advisor's beta of the structure as
  a single block or as a stack of its courses).
- {dur:g} s per run ({dur_sp:g} s with SP damping), recorded every {RECORD_INTERVAL * 1e3:g} ms at the first step after
  each interval and resampled onto exact multiples of it for the FFT (Hann window, zero-padded 16 x).
- Amplitude: half the peak-to-peak of the top monitor's displacement (the centre of the top course's +x top edge)
  over the second half of the run. Frequency: the largest spectral peak of its vertical displacement.
- Chain model: n rigid courses of mass rho h per unit area on springs kn = E / h, released at rest with unloaded
  joints (modal superposition, `chain_response`); with SP damping C = beta K. It is independent of the engine.
- The paper's "y" is the direction perpendicular to the wall, our x.
"""


@reproduction("rattling", TITLE)
def rattling(ctx: Context) -> Report:
    """Reproduce §2.1 (Fig. 1): rattling amplitudes and frequencies, with and without SP damping."""
    runs = rattling_runs(ctx)
    df = pd.DataFrame([_summary(r) for r in runs])
    save_figure(_figure(runs, df), ctx.out / "rattling.png")
    return Report("rattling", TITLE, df, ["rattling.png"], _comment(df), notes=_notes(df, ctx.reduced))
