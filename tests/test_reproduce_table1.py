"""Reduced reproductions of Table 1 / Fig. 6 / Fig. 7B and Fig. 8 (paper §3.2): physics and reports."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockdem.reproduce import Context, Report, paper, run_reproduction
from rockdem.reproduce.fig8 import top_rotation
from rockdem.reproduce.table1 import discretised_runs


@pytest.fixture(scope="module")
def ctx(tmp_path_factory: pytest.TempPathFactory) -> Context:
    base = tmp_path_factory.mktemp("reproduce")
    return Context(out=base / "out", cache=base / "cache", reduced=True, executor="process", workers=2, progress=False)


@pytest.fixture(scope="module")
def table1(ctx: Context) -> Report:
    return run_reproduction("table1", ctx)


@pytest.fixture(scope="module")
def fig8(ctx: Context) -> Report:
    return run_reproduction("fig8", ctx)


def test_table1_physics(ctx: Context, table1: Report) -> None:
    df = discretised_runs(ctx)  # read back from the store, no rerun
    assert {"B", "H", "kn", "eta_deg", "R", "eta_over_R", "e_a_mean", "bounce_max_m_s", "runtime_s", "sp_runtime_s"} <= set(df.columns)
    assert len(df) == 2
    assert np.allclose(df.eta_deg, math.degrees(math.atan2(0.19, 0.5)))
    assert np.all((df.e_a_mean > 0.0) & (df.e_a_mean <= 1.0))
    assert np.all(df.impacts >= 2)
    assert not df.overturned.any()
    assert np.all(np.isfinite(df.wme_e_eta) & (df.wme_e_eta >= 0.0))
    # bonds "sufficiently strong for no bond to fail" (§3.2.1): none fails
    assert np.all(df.failed_shear_fraction + df.failed_tension_fraction == 0.0)
    assert np.all(df.sp_runtime_s > 0.0)


def test_table1_report(ctx: Context, table1: Report) -> None:
    md = (ctx.out / "table1.md").read_text()
    for kn in (5000e6, 20000e6):
        for v in paper.TABLE1[(0.19, 0.5)][kn]:
            assert f"{v:.4g}" in md
    assert "paper mean e_a" in md and "brick size" in md
    for f in table1.figures:
        assert (ctx.out / f).stat().st_size > 10_000
    assert (ctx.out / "table1.csv").exists()


def test_fig8_weak_bonds_fail_and_dissipate(ctx: Context, fig8: Report) -> None:
    t = fig8.table
    weak = t[t["c [MPa]"] == 0.1].iloc[0]
    strong = t[t["c [MPa]"] == 0.5].iloc[0]
    assert weak["failed shear [%]"] + weak["failed tension [%]"] > 0.0
    assert strong["failed shear [%]"] + strong["failed tension [%]"] == 0.0
    assert 0.0 < weak["e_a(1)"] < strong["e_a(1)"] <= 1.0
    assert (t["agrees"] == "yes").all()
    assert (ctx.out / "fig8.png").stat().st_size > 10_000
    assert "no visible joint failure" in (ctx.out / "fig8.md").read_text()


def test_top_rotation_inverts_rigid_rocking() -> None:
    b, h = 0.19, 2.0
    theta = np.linspace(-0.09, 0.09, 19)
    u = np.where(theta >= 0, h * np.sin(theta), b * (np.cos(theta) - 1.0) + h * np.sin(theta))
    assert np.allclose(top_rotation(u, b, h), theta, atol=1e-12)
