"""``rockdem reproduce damping --reduced``: targeted and per-interface beta on the paper's cases
(issue 14; paper §2.2, §3.3 Fig. 9B, §4.1, §4.2)."""

from __future__ import annotations

import pandas as pd
import pytest

from rockdem.reproduce import Context, run_reproduction


def test_damping_reduced_report(tmp_path):
    ctx = Context(out=tmp_path / "out", cache=tmp_path / "cache", reduced=True, executor="serial", progress=False)
    rep = run_reproduction("damping", ctx)
    t = rep.table.set_index("points across")
    assert list(t.index) == [2, 10]
    # Fig. 9B: one beta damps 2 points more than 10; the targeted beta grows with the points and
    # keeps the mean e_a on its target (0.95 e_eta; 4 s runs: fewer small impacts than the probe's)
    paper, targeted = t["e_a/e_eta paper 0.00693 s"], t["e_a/e_eta targeted 0.95 e_eta"]
    assert paper[10] > paper[2]
    assert t.loc[10, "beta targeted 0.95 e_eta [s]"] > t.loc[2, "beta targeted 0.95 e_eta [s]"]
    assert abs(targeted[10] / targeted[2] - 1) < abs(paper[10] / paper[2] - 1)
    assert targeted.to_numpy() == pytest.approx(0.95, abs=0.02)
    md = (tmp_path / "out" / "damping.md").read_text()
    for section in ("## Fig. 4 blocks", "## §4.1 parapet", "## §4.2 one-sided façade", "Damping ratio of the per-interface betas"):
        assert section in md
    assert "reduced" in md
    assert pd.read_csv(tmp_path / "out" / "damping.csv").shape[0] == 2
    assert (tmp_path / "out" / "damping.png").stat().st_size > 10_000
