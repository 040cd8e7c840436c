"""Reduced reproductions of the paper's Fig. 4 (alpha matched to beta, SP/MP runtime) and Fig. 16."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from rockdem.calibration import reference_from_row, wme_of_row
from rockdem.reproduce import Context, run_reproduction
from rockdem.reproduce.fig4 import QUANTITY, matched_runs, mp_spec, sp_spec


@pytest.fixture(scope="module")
def ctx(tmp_path_factory: pytest.TempPathFactory) -> Context:
    root = tmp_path_factory.mktemp("fig4")
    return Context(out=root / "out", cache=root / "cache", reduced=True, executor="serial", progress=False)


@pytest.fixture(scope="module")
def reports(ctx: Context) -> dict[str, object]:
    return {name: run_reproduction(name, ctx) for name in ("fig4", "fig16")}


@pytest.fixture(scope="module")
def matched(ctx: Context, reports: dict[str, object]) -> pd.DataFrame:
    return matched_runs(ctx)  # every run cached by the reports


def test_reports_written_with_paper_columns(ctx: Context, reports: dict[str, object]) -> None:
    for name in ("fig4", "fig16"):
        assert (ctx.out / f"{name}.md").is_file() and (ctx.out / f"{name}.png").is_file()
    t4 = pd.read_csv(ctx.out / "fig4.csv")
    for col in ("beta [s] (DeJong)", "alpha best [1/s]", "paper line 22.4 beta + 0.05 [1/s]", "SP/MP runtime",
                "paper SP/MP runtime (3DEC, all cases)", "WME at alpha best", "WME at alpha = 0"):
        assert col in t4.columns
    assert set(t4["paper SP/MP runtime (3DEC, all cases)"]) == {"50-350"}
    md = (ctx.out / "fig4.md").read_text()
    assert "22.4 beta + 0.05" in md and "fig4.png" in md
    t16 = pd.read_csv(ctx.out / "fig16.csv")
    assert {"slope [1/s^2]", "intercept [1/s]", "R^2", "paper slope [1/s^2]"} <= set(t16.columns)


def test_sp_needs_more_steps_than_mp(matched: pd.DataFrame) -> None:
    """SP damping reduces the stable timestep (sqrt(1 + xi^2) - xi): many more steps per second."""
    per_s_sp = matched["steps_sp"] / matched["duration_sp"]
    per_s_mp = matched["steps_mp"] / matched["duration_mp"]
    assert (per_s_sp > 3.0 * per_s_mp).all()
    assert (matched["dt_sp"] < matched["dt_mp"]).all()
    assert (matched["bounce_sp"] <= matched["bounce_mp"] + 1e-9).all()  # SP damps the high-frequency bouncing


def test_matched_alpha_is_a_minimum_for_the_slender_block(ctx: Context, matched: pd.DataFrame) -> None:
    row = matched[(matched["B"] == 0.19) & (matched["H"] == 2.0)].iloc[0]
    alpha = float(row["alpha"])
    assert alpha > 0.0
    assert row["wme_best"] < 0.5 * row["wme_alpha0"]
    sp = ctx.execute("fig4", [sp_spec(0.19, 2.0, row["E"], float(row["duration_sp"]))])[0]
    ref = reference_from_row(sp, QUANTITY)
    triple = ctx.execute("fig4-test", [mp_spec(0.19, 2.0, row["E"], 3.0 * alpha, float(row["duration_mp"]))])[0]
    assert row["wme_best"] < wme_of_row(triple, ref)
    # the SP reference is a damped rocking motion that the matched MP run follows closely
    assert row["wme_best"] < 0.1
    assert 0.5 < row["e_a_sp"] < 1.0 and 0.5 < row["e_a_mp"] < 1.0


def test_fig16_fit(reports: dict[str, object], matched: pd.DataFrame) -> None:
    table = reports["fig16"].table  # type: ignore[attr-defined]
    ours = table.iloc[0]
    assert ours["points"] == (matched["flag"] == "").sum() >= 2
    assert math.isfinite(ours["slope [1/s^2]"]) and ours["slope [1/s^2]"] > 0.0
    assert math.isfinite(ours["intercept [1/s]"])
    assert table.iloc[2]["slope [1/s^2]"] == 22.4 and table.iloc[2]["intercept [1/s]"] == 0.05


def test_rerun_reuses_the_store(ctx: Context, matched: pd.DataFrame) -> None:
    again = matched_runs(ctx)
    pd.testing.assert_frame_equal(again.drop(columns=["runtime_sp", "runtime_mp", "runtime_ratio"]),
                                  matched.drop(columns=["runtime_sp", "runtime_mp", "runtime_ratio"]))
    assert (again["runtime_sp"] == matched["runtime_sp"]).all()  # same stored rows, not new runs
