"""``rockdem reproduce``: the framework and the reduced Fig. 9 / Table 2 study (paper §3.3)."""

from __future__ import annotations

import pandas as pd
import pytest

from rockdem.cli import main
from rockdem.reproduce import Context, names, run_reproduction


def test_studies_are_listed_and_an_unknown_one_is_refused(capsys, tmp_path):
    assert {"table2"} <= set(names())
    assert main(["reproduce", "--list"]) == 0
    assert "table2" in capsys.readouterr().out
    assert main(["reproduce", "nope", "--out", str(tmp_path), "--cache", str(tmp_path)]) == 2
    assert "unknown study 'nope'" in capsys.readouterr().err


def test_table2_reduced_pushover_and_free_rocking(tmp_path):
    # Paper §3.3: with 2 points the block behaves as a rigid block on a rigid base; with 10 points
    # the elastic base is softer (lower load factor at small displacement), the curve reaches the
    # rigid softening branch only late, and free rocking is less damped (Fig. 9B: "more damped
    # oscillations ... when fewer contact points were implemented").
    ctx = Context(out=tmp_path / "out", cache=tmp_path / "cache", reduced=True, executor="serial", progress=False)
    rep = run_reproduction("table2", ctx)
    t = rep.table.set_index("points across")
    assert list(t.index) == [2, 10]
    assert t.loc[2, "lambda at 40 mm"] == pytest.approx(t.loc[2, "rigid lambda at 40 mm"], rel=0.02)
    assert t.loc[10, "lambda at u_top = 2 mm"] < 0.8 * t.loc[2, "lambda at u_top = 2 mm"]
    assert t.loc[10, "joins the rigid branch at u_top [mm]"] > 5 * t.loc[2, "joins the rigid branch at u_top [mm]"]
    assert t.loc[10, "e_a mean (free rocking)"] > t.loc[2, "e_a mean (free rocking)"]
    md = (tmp_path / "out" / "table2.md").read_text()
    assert "paper 3DEC runtime [h]" in md and "| 10 | 34 |" in md and "reduced" in md
    assert pd.read_csv(tmp_path / "out" / "table2.csv").shape[0] == 2
    assert (tmp_path / "out" / "table2.png").stat().st_size > 10_000
    # a rerun reuses the stored free-rocking runs (same rows, nothing recomputed)
    stored = (tmp_path / "cache" / "table2.jsonl").read_text()
    run_reproduction("table2", ctx)
    assert (tmp_path / "cache" / "table2.jsonl").read_text() == stored


def test_fig5_7_reduced_bouncing(tmp_path):
    # Paper §3.1 (Fig. 5B): SP-damped blocks do not bounce, MP-damped ones may; §3.2.1 (Fig. 7A):
    # discretised undamped blocks bounce too. Every run of fig4 and table1 appears once.
    ctx = Context(out=tmp_path / "out", cache=tmp_path / "cache", reduced=True, executor="process", workers=2, progress=False)
    rep = run_reproduction("fig5_7", ctx)
    t = rep.table
    assert set(t["run"]) == {"MP (matched alpha)", "SP (DeJong beta)", "discretised, no damping"}
    sp = t[t["run"] == "SP (DeJong beta)"]["bouncing [m/s]"].to_numpy()
    mp = t[t["run"] == "MP (matched alpha)"]["bouncing [m/s]"].to_numpy()
    assert len(sp) == len(mp) >= 2 and (sp <= mp + 1e-12).all()
    assert (sp < 1e-3).all()  # no visible SP bouncing
    dis = t[t["run"] == "discretised, no damping"]
    assert len(dis) >= 2 and (dis["paper: bouncing critical (eta/R > 45 deg/m)"]).all()  # the squat 0.19 x 0.5 block
    assert (tmp_path / "out" / "fig5_7.png").exists()
