"""Reduced reproduction of §2.1 / Fig. 1 (rattling): the chain closed form and the engine against it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockdem.reproduce import Context, Report, paper, run_reproduction
from rockdem.reproduce.rattling import amplitude, chain_response, dominant_frequency

E, RHO, G = paper.RATTLING_E, paper.RATTLING_DENSITY, 9.81


def test_chain_closed_form_single_course():
    """One course of height h on a spring kn = E / h: f = sqrt(E / (rho h^2)) / (2 pi), settlement
    rho g h^2 / E, released from the unloaded joint it reaches twice the settlement; SP damping
    C = beta K lets it creep into the settlement (over-damped for beta omega / 2 > 1)."""
    h = 0.12
    w = math.sqrt(E / (RHO * h * h))
    us = RHO * G * h * h / E
    t = np.array([0.0, math.pi / w, 2 * math.pi / w])
    f, u_static, z = chain_response(1, h, t)
    assert f[0] == pytest.approx(w / (2 * math.pi), rel=1e-12)
    assert u_static[-1] == pytest.approx(-us, rel=1e-12)
    assert z == pytest.approx([0.0, -2 * us, 0.0], abs=1e-12 * us)
    _, _, zd = chain_response(1, h, np.array([0.0, 0.2]), beta=0.01)  # xi = 41.7: creeps at w / (2 xi) = 100 /s
    assert zd[0] == pytest.approx(0.0, abs=1e-15) and zd[1] == pytest.approx(-us, rel=1e-3)


def test_chain_closed_form_fixed_free_frequencies():
    """n equal masses on n springs (fixed-free chain): omega_k = 2 omega_1 sin((2k - 1) pi / (2 (2n + 1)))."""
    n, h = 7, 0.12
    w1 = math.sqrt(E / (RHO * h * h))
    f, u_static, _ = chain_response(n, h, np.zeros(1))
    k = np.arange(1, n + 1)
    assert 2 * math.pi * f == pytest.approx(2 * w1 * np.sin((2 * k - 1) * math.pi / (2 * (2 * n + 1))), rel=1e-10)
    assert -u_static[-1] == pytest.approx(RHO * G * h * h / E * n * (n + 1) / 2, rel=1e-12)


def test_dominant_frequency_with_jittered_samples():
    """A 1326 Hz sine sampled at the first step after every 0.1 ms (steps of 27.8 us) is found within
    the FFT's resolution once resampled (the raw samples read as uniform give ~10 % off)."""
    dt, f0 = 2.777e-5, 1326.0
    steps = np.arange(0.0, 0.2, dt)
    t = np.unique(steps[np.searchsorted(steps, np.arange(0.0, 0.2, 1e-4))])
    x = np.sin(2 * np.pi * f0 * t)
    assert dominant_frequency(t, x) == pytest.approx(f0, abs=1.0 / 0.2)
    assert amplitude(t, x) == pytest.approx(1.0, rel=0.01)


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> tuple[Context, Report]:
    base = tmp_path_factory.mktemp("rattling")
    ctx = Context(out=base / "out", cache=base / "cache", reduced=True, executor="serial", progress=False)
    return ctx, run_reproduction("rattling", ctx)


def test_rattling_matches_the_chain_model(report: tuple[Context, Report]) -> None:
    _, rep = report
    t = rep.table.set_index("case")
    und = t[t["beta [s]"] == 0.0]
    assert set(und.index) == {"column 2", "column 7"}
    assert und["vertical amplitude [mm]"].to_numpy() == pytest.approx(und["chain model amplitude [mm]"].to_numpy(), rel=0.01)
    assert und["frequency (FFT) [Hz]"].to_numpy() == pytest.approx(und["chain fundamental [Hz]"].to_numpy(), rel=0.01)
    # the paper's range: 300-1600 Hz; the 7-block column below the 2-block one, with a larger amplitude
    assert t.loc["column 7", "frequency (FFT) [Hz]"] < t.loc["column 2", "frequency (FFT) [Hz]"]
    assert t.loc["column 7", "vertical amplitude [mm]"] > 5 * t.loc["column 2", "vertical amplitude [mm]"]
    # symmetric columns: horizontal rattling at round-off only (paper: 1e-17 mm)
    assert (und["out-of-plane (x) amplitude [mm]"] < 1e-9 * und["vertical amplitude [mm]"]).all()
    assert (t["failed tension [%]"] == 0.0).all() and (t["failed shear [%]"] == 0.0).all()
    assert (t["energy created [J]"] <= 1e-3 * t["energy scale [J]"]).all()  # leapfrog: bounded energy oscillation only


def test_sp_damping_removes_the_rattling(report: tuple[Context, Report]) -> None:
    ctx, rep = report
    t = rep.table.set_index("case")
    sp = t.loc["column 7, SP"]
    assert sp["beta [s]"] > 0.0
    assert sp["vertical amplitude [mm]"] < 1e-3 * t.loc["column 7", "vertical amplitude [mm]"]
    assert sp["vertical amplitude [mm]"] == pytest.approx(sp["chain model amplitude [mm]"], rel=0.2, abs=1e-9)
    assert sp["static settlement [mm]"] == pytest.approx(t.loc["column 7", "static settlement [mm]"], rel=0.01)
    md = (ctx.out / "rattling.md").read_text()
    assert "2e-4 / 22e-4 mm" in md and "300-1600 Hz" in md and "reduced" in md
    assert (ctx.out / "rattling.png").stat().st_size > 10_000
