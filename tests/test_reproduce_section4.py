"""Reduced reproductions of the paper's §4: the parapet (Figs. 10-11), the one-sided façade
(Figs. 12-15) and the two-block wall (Figs. 17-18): physics, the paper's findings, reports."""

from __future__ import annotations

import math

import pytest

from rockdem.analysis import apparent_restitution
from rockdem.housner import HousnerBlock, rock
from rockdem.reproduce import Context, Report, paper, run_reproduction
from rockdem.reproduce.facade import earthquake_runs, outward_peaks, quake_table
from rockdem.reproduce.parapet import release_energy
from rockdem.reproduce.two_block_wall import D0, formula_beta


@pytest.fixture(scope="module")
def ctx(tmp_path_factory: pytest.TempPathFactory) -> Context:
    base = tmp_path_factory.mktemp("section4")
    return Context(out=base / "out", cache=base / "cache", reduced=True, executor="serial", progress=False)


@pytest.fixture(scope="module")
def parapet(ctx: Context) -> Report:
    return run_reproduction("parapet", ctx)


@pytest.fixture(scope="module")
def facade(ctx: Context) -> Report:
    return run_reproduction("facade", ctx)


@pytest.fixture(scope="module")
def wall(ctx: Context) -> Report:
    return run_reproduction("two_block_wall", ctx)


def test_parapet_free_rocking(ctx: Context, parapet: Report) -> None:
    t = parapet.table.set_index("model")
    sp, spf, mp = t.loc["SP beta = 0.00068"], t.loc["SP beta = 0.00305 (formula)"], t.loc["MP alpha = 0.0753"]
    # the formula's beta damps more than the best fit (paper: over-damped)
    assert spf["mean e_a"] < sp["mean e_a"] - 0.02 and spf["impacts"] <= sp["impacts"]
    # the best-fitting SP block follows Housner's model with e_eta closely; MP is not far from it
    assert sp["WME vs Housner e_eta"] < 0.1 and mp["WME vs SP beta = 0.00068"] < 0.3
    for name in ("SP beta = 0.00068", "SP beta = 0.00305 (formula)", "MP alpha = 0.0753"):
        assert t.loc[name, "energy created [J]"] < 0.01 * release_energy()
    assert t.loc["SP beta = 0.00068", "paper failed tension [%]"] != t.loc["SP beta = 0.00068", "paper failed tension [%]"]  # NaN


def test_parapet_release_energy_closed_form() -> None:
    """m g (R cos(eta - theta0) - H / 2) equals m g times the rise of the centroid of a block tilted
    by theta0 about its base edge."""
    half, h = 0.1115, 0.73
    eta = math.atan2(half, 0.5 * h)
    th0 = 0.5 * eta
    rise = half * math.sin(th0) + 0.5 * h * math.cos(th0) - 0.5 * h  # centroid height above the pivot, tilted minus upright
    m = paper.DENSITY * paper.PARAPET_THICKNESS * h * 1.0
    assert release_energy() == pytest.approx(m * 9.81 * rise, rel=1e-12)


def test_parapet_discretised_and_earthquake(ctx: Context, parapet: Report) -> None:
    t = parapet.table.set_index("model")
    disc = t.loc["discretised, c = 0.5, ft = 0.1 MPa"]
    assert disc["paper failed shear [%]"] == 35.0 and disc["paper failed tension [%]"] == 55.0
    assert disc["failed tension [%]"] > 5.0  # weak joints fail at the first impact (paper: extensive damage)
    md = (ctx.out / "parapet.md").read_text()
    # MP alpha = 0.0753 cracks the bonded base (ft = 0.10 MPa) and overturns under El Centro at 2.6 g where SP does not crack:
    # the paper's "tendency of the MP damping simulation to collapse at an early stage"
    assert "| elcentro-rsn6 | 0.1 | MP | 0.0753 | 0.1 | 2.6 | 2.6 |" in md
    assert "| elcentro-rsn6 | 0.1 | SP | 0.00068 | 0.06 |  |  | - / - |" in md
    assert (ctx.out / "parapet.png").stat().st_size > 10_000 and "H = 0.73 m" in md


def test_outward_peaks_recover_housners_restitution() -> None:
    """One-sided Housner rocking with restitution e: the outward peaks give e back through the exact
    energy form of Eq. 6."""
    blk, e = HousnerBlock(0.094, 0.8), 0.8
    th0 = -0.5 * blk.eta
    r = rock(blk, theta0=th0, duration=3.0, e=e, one_sided=True, wall_side=1, dt_out=1e-4)
    _, pk = outward_peaks(r.time, r.rotation, -1.0)
    assert len(pk) >= 4 and pk[0] == pytest.approx(abs(th0))
    ea = apparent_restitution(pk[1:4], abs(th0), blk.eta, exact=True).per_impact
    assert ea == pytest.approx(e, abs=2e-3)


def test_facade_findings(ctx: Context, facade: Report) -> None:
    t = facade.table.set_index("model")
    lo, hi = t.loc["SP beta = 0.00025"], t.loc["SP beta = 0.004"]
    # the double impact on base and return walls takes most of the energy (far below Housner's e_eta)
    assert lo["1st rebound / release"] < 0.2 and lo["WME vs Housner one-sided (e_eta)"] > 0.3
    # paper: beta = 0.00025 leaves the late motion undamped, beta >= 0.002 is over-damped after the first impact
    assert hi["late motion / release"] < 0.5 * lo["late motion / release"]
    # a large MP alpha slows the first quarter cycle (paper: "affected ... the period of the first quarter cycle")
    assert t.loc["MP alpha = 1", "first quarter cycle [s]"] > lo["first quarter cycle [s]"] + 0.01
    disc = t.loc["discretised, E = 18 MPa"]
    assert disc["E [MPa]"] == 18.0
    md = (ctx.out / "facade.md").read_text()
    assert "R1168EW" in md and "not available" in md
    # small alpha changes change the history; SP halved or doubled does not (the paper's point, as a number)
    _, spread = quake_table(earthquake_runs(ctx))  # the stored runs
    row = spread.set_index("record").loc["bagnoli"]
    assert row["SP beta x 0.5-2: spread"] < 0.25  # halved or doubled, beta moves the peak little
    # Whether MP (alpha matched to the free rocking) lets the façade rock further than SP, and which
    # alpha tips it, is chaotic in this engine (the full study: MP peaks above SP in some record-scale
    # sets, below in others): reported as numbers in docs/reproduction/facade.md, not asserted.


def test_two_block_wall(ctx: Context, wall: Report) -> None:
    # the paper's beta = 0.0032 s is the formula's with E = 1800 MPa; beta scales as 1 / sqrt(E)
    assert formula_beta(1.8e9) == pytest.approx(paper.TWO_BLOCK_BETA, rel=0.01)
    assert formula_beta(paper.TWO_BLOCK_E) == pytest.approx(formula_beta(1.8e9) * math.sqrt(1800 / 48), rel=1e-9)
    t = wall.table.set_index("model")
    sp, mp = t.loc["SP beta = 0.0032"], t.loc["MP alpha = 0.7539"]
    assert sp["d at release [mm]"] == pytest.approx(1e3 * D0, rel=0.05)
    for r in (sp, mp):
        assert 0.3 < r["first peak / d0"] < 1.0 and r["peaks above 5 % of d0"] >= 3
    assert mp["WME vs SP beta = 0.0032"] < 0.5  # the matched MP run follows the SP one
    md = (ctx.out / "two_block_wall.md").read_text()
    assert "0.0196" in md and "nahanni" in md and (ctx.out / "two_block_wall.png").stat().st_size > 10_000
