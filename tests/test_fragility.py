"""Fragility fits: synthetic lognormal data, and a small IDA on a synthetic record."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

from rockdem.fragility import (
    Fragility,
    _cut_short,
    collapse_capacities,
    failed,
    fit_all,
    fit_fragility_capacities,
    fit_fragility_mle,
    ida_counts,
    ida_specs,
    run_ida,
    separated,
    write_report,
)

THETA, BETA = 0.4, 0.35  # median [g] and dispersion of the synthetic capacities


def test_capacity_fit_recovers_lognormal():
    rng = np.random.default_rng(1)
    c = np.exp(np.log(THETA) + BETA * rng.standard_normal(4000))
    f = fit_fragility_capacities(c)
    # standard errors: theta ~ THETA*BETA/sqrt(n) = 0.2 %, beta ~ BETA/sqrt(2n) = 1 %: 3 % margins
    assert f.theta == pytest.approx(THETA, rel=0.03) and f.beta == pytest.approx(BETA, rel=0.03)


def test_binomial_mle_recovers_lognormal():
    rng = np.random.default_rng(2)
    im = np.repeat(np.linspace(0.1, 1.2, 12), 300)
    fail = rng.random(im.size) < norm.cdf(np.log(im / THETA) / BETA)
    f = fit_fragility_mle(im, fail)
    assert f.theta == pytest.approx(THETA, rel=0.05) and f.beta == pytest.approx(BETA, rel=0.10)
    # grouped counts give the same fit
    levels = np.unique(im)
    counts = np.array([fail[im == x].sum() for x in levels])
    g = fit_fragility_mle(levels, counts, trials=np.full(levels.size, 300))
    assert g.theta == pytest.approx(f.theta, rel=1e-3) and g.beta == pytest.approx(f.beta, rel=1e-3)
    assert Fragility(THETA, BETA).probability(THETA) == pytest.approx(0.5)


def test_fit_needs_failures_and_survivals():
    with pytest.raises(ValueError, match="both failures and survivals"):
        fit_fragility_mle([0.1, 0.2, 0.3], [0, 0, 0])


def _pulses(tmp_path, freqs=(1.0, 2.0)) -> list[str]:
    recs = []
    for f_hz in freqs:
        t = np.arange(0, 1.0 / f_hz, 0.005)
        a = np.sin(2 * np.pi * f_hz * t)
        p = tmp_path / f"pulse{f_hz:g}.csv"
        np.savetxt(p, np.column_stack((t, a)), delimiter=",")
        recs.append(str(p))
    return recs


FIXED = {"run.record_interval": 0.01, "specimen.height": 0.5, "specimen.width": 0.19, "damping.beta": 0.0,
         "damping.alpha": 2.0, "loading.units": "g"}


def test_small_ida_on_synthetic_pulse(tmp_path):
    """Sine pulses (1 Hz and 2 Hz) on the 0.19 x 0.5 m block: more PGA -> more rotation, then overturning."""
    recs = _pulses(tmp_path)
    fixed = FIXED
    df, frag = run_ida("free-rocking", recs, [0.2, 0.5, 1.0, 2.0], tmp_path / "ida", fixed=fixed, duration=2.0,
                       executor="serial", progress=False)
    assert len(df) == 8 and (df["status"] == "ok").all()
    for _, g in df.groupby("record"):
        g = g.sort_values("pga_g")
        assert not g["failed"].iloc[0] and g["failed"].iloc[-1]  # 0.2 g: no rocking of eta 0.36; 2 g: collapse
    # e_a (paper Eq. 6) is the restitution of free rocking only: forced rocking's read 1.01 to 1.18
    # in IDA tables before 2026-11-29, as if energy were created
    assert df["e_a_mean"].isna().all()
    cap = collapse_capacities(df)
    assert cap.notna().all()
    for name in ("table.csv", "ida.png", "fragility.png", "spectra.png", "report.md", "fragility.csv"):
        assert (tmp_path / "ida" / name).exists(), name
    # every run's input has its intensity measures: they grow with the PGA, in proportion
    # (Arias with its square), and Sa is taken at the block's rocking period
    for _, g in df.groupby("record"):
        g = g.sort_values("pga_g")
        ratio = g["pga_g"] / g["pga_g"].iloc[0]
        for im, power in (("pgv_m_s", 1), ("sa_g", 1), ("arias_m_s", 2)):
            np.testing.assert_allclose(g[im] / g[im].iloc[0], ratio**power, rtol=1e-9)
    assert df["sa_period_s"].iloc[0] == pytest.approx(2 * np.pi / np.sqrt(3 * 9.81 / (4 * np.hypot(0.095, 0.25))))
    fits = pd.read_csv(tmp_path / "ida" / "fragility.csv")
    assert list(fits["im"]) == ["pga_g", "pgv_m_s", "arias_m_s", "sa_g"] and (fits["n"] == 8).all()
    assert "| Sa(T) [g] |" in (tmp_path / "ida" / "report.md").read_text()


def test_separated_outcomes_are_flagged_as_not_identifiable(tmp_path):
    # Every failure above every survival: the likelihood grows as beta -> 0, so the fit's beta
    # (0.008 here) says how far apart the levels are, not the dispersion. It is flagged.
    im = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
    table = pd.DataFrame({"id": list("abcdef"), "status": "ok", "record": "r", "pga_g": im,
                          "failed": [False, False, False, True, True, True]})
    fits = fit_all(table)
    assert bool(fits["separated"].iloc[0]) and fits["beta"].iloc[0] < 0.05
    report = write_report(table, fits, tmp_path).read_text()
    assert "(separated: not identifiable)" in report
    tied = table.assign(pga_g=[0.1, 0.2, 0.3, 0.3, 0.5, 0.6])  # a failure and a survival at 0.3: still separated
    assert bool(fit_all(tied)["separated"].iloc[0])
    mixed = table.assign(failed=[False, False, True, False, True, True])  # overlapping outcomes: a dispersion
    fits = fit_all(mixed)
    assert not bool(fits["separated"].iloc[0]) and fits["beta"].iloc[0] > 0.1
    assert "not identifiable" not in write_report(mixed, fits, tmp_path).read_text()


def test_runs_ending_before_their_record_s_strong_motion_are_noted(tmp_path):
    # A 1 Hz sine pulse of 1 s peaks at 0.25 s and 0.75 s and has 95 % of its Arias intensity at
    # about 0.95 s: runs of 0.85 s end before it (after the peaks), runs of 2 s after.
    recs = _pulses(tmp_path, (1.0,))
    notes = _cut_short(ida_specs("free-rocking", recs, [0.5], fixed=FIXED, duration=0.85))
    assert len(notes) == 1 and "Arias intensity" in notes[0] and "its PGA" not in notes[0]
    assert _cut_short(ida_specs("free-rocking", recs, [0.5], fixed=FIXED, duration=2.0)) == []
    assert len(_cut_short(ida_specs("free-rocking", recs, [0.5], fixed=FIXED, duration=0.2))) == 1  # before the PGA too
    # a window of the record's second half runs from t = 0: its strong motion has arrived by 0.48 s
    windowed = {**FIXED, "loading.window": [0.5, 1.0]}
    assert _cut_short(ida_specs("free-rocking", recs, [0.5], fixed=windowed, duration=0.6)) == []
    assert len(_cut_short(ida_specs("free-rocking", recs, [0.5], fixed=windowed, duration=0.3))) == 1


def _unreadable(tmp_path) -> str:
    bad = tmp_path / "broken.csv"
    bad.write_text("0.0,0.1\n0.005,0.12E-\n")  # truncated mid-number
    return str(bad)


def test_errored_runs_are_reported_apart_and_stay_out_of_the_fit(tmp_path):
    # An unreadable record errors at every PGA: those runs have no outcome. They used to count as
    # failures (NaN 'overturned' read as True) and enter the fit.
    levels = [0.2, 0.5, 1.0, 2.0]
    good = _pulses(tmp_path, (1.0,))
    df, frag = run_ida("free-rocking", good + [_unreadable(tmp_path)], levels, tmp_path / "ida", fixed=FIXED,
                       duration=2.0, executor="serial", progress=False)
    errors = df[df["status"] == "error"]
    assert len(errors) == 4 and errors["failed"].isna().all()
    ok = df[df["status"] == "ok"]
    counts = ida_counts(df)
    assert (counts.runs, counts.errors, counts.failures + counts.survivals) == (8, 4, 4)
    assert counts.failures == int(ok["failed"].sum()) < 4  # 0.2 g does not even rock the block
    assert "4 errored (no outcome: not in the fit)" in counts.line()
    # the fit is that of the completed runs alone
    alone, frag_alone = run_ida("free-rocking", good, levels, tmp_path / "ida_ok", fixed=FIXED, duration=2.0,
                                executor="serial", progress=False)
    assert (frag is None) == (frag_alone is None)
    if frag is not None:
        assert (frag.theta, frag.beta, frag.n) == (frag_alone.theta, frag_alone.beta, frag_alone.n) and frag.n == 4
    assert list(collapse_capacities(df).index) == good  # no capacity for a record that never ran


def test_all_runs_errored_gives_a_clear_error(tmp_path):
    # Every run starts and errors in the engine (a timestep far too short for the step limit).
    with pytest.raises(ValueError, match=r"none of the 4 IDA runs completed.*4 errored.*first error: .*max_steps"):
        run_ida("free-rocking", _pulses(tmp_path), [0.2, 0.5], tmp_path / "ida", fixed={**FIXED, "run.dt": 1e-9},
                duration=2.0, executor="serial", progress=False)
    assert (tmp_path / "ida" / "table.csv").exists()  # the table with the errors is kept for inspection


def test_an_ida_none_of_whose_runs_can_start_is_refused_before_running(tmp_path):
    """A bad ``fixed`` value, or records none of which can be read, is refused before any run
    starts, nothing written; one unreadable record among good ones errors only its own runs
    (test_errored_runs_are_reported_apart_and_stay_out_of_the_fit)."""
    with pytest.raises(ValueError, match=r"no run of the IDA can start \(none of its 2 records.*\[damping\] beta.*'abc'"):
        run_ida("free-rocking", _pulses(tmp_path), [0.2, 0.5], tmp_path / "ida", fixed={**FIXED, "damping.beta": "abc"},
                duration=0.5, executor="serial", progress=False)
    with pytest.raises(ValueError, match=r"no run of the IDA can start \(its record gives no valid case.*broken\.csv"):
        run_ida("free-rocking", [_unreadable(tmp_path)], [0.2, 0.5], tmp_path / "ida", fixed=FIXED, duration=0.5,
                executor="serial", progress=False)
    for records, levels in (([], [0.2]), (_pulses(tmp_path), []), ("pulse1.csv", [0.2])):
        with pytest.raises(ValueError, match="at least one record and one PGA level"):
            run_ida("free-rocking", records, levels, tmp_path / "ida", fixed=FIXED, executor="serial", progress=False)
    assert not (tmp_path / "ida").exists()


@pytest.mark.parametrize("command", ["fragility", "calibrate"])
def test_study_cli_refuses_a_bad_override_before_running(tmp_path, capsys, command):
    from rockdem.cli import main

    ref = tmp_path / "ref.csv"
    ref.write_text("time,rotation\n" + "\n".join(f"{0.01 * i},{0.001 * i}" for i in range(11)) + "\n")
    head = (["fragility", *_pulses(tmp_path), "--pga", "0.1", "0.2", "2"] if command == "fragility"
            else ["calibrate", str(ref), "--bounds", "0.001", "0.01"])
    for item, said in (("damping.beta", "use table.key=value"), ("=5", "use table.key=value"),
                       ("specimen.kn=abc", "kn must be a finite number"), ("damping.bogus=1", "unknown key(s) ['bogus']")):
        out = tmp_path / f"out_{command}"
        assert main([*head, "--duration", "0.5", "--executor", "serial", "--no-progress", "--out", str(out), "--set", item]) == 2
        assert said in capsys.readouterr().err
        assert not out.exists()


def test_a_run_stopped_because_it_collapsed_is_a_failure():
    """A run stopped as collapsed (a block of an assembly fell) fails even if the analysed block's
    last rotation is below eta; a run stopped at rest does not."""
    from rockdem.fragility import failed

    t = pd.DataFrame({"status": ["ok"] * 4, "overturned": [False, False, True, False],
                      "stop_reason": ["fell", "rest", None, None], "max_rotation_over_eta": [0.2, 0.2, 1.5, 0.7]})
    assert list(failed(t)) == [True, False, True, False]
    assert list(failed(t, drift_limit=0.5)) == [True, False, True, True]


def test_a_run_with_a_fallen_block_is_a_failure_also_without_stopping():
    """A slender block tilted past its eta on a squat one topples off it onto the ground; the squat
    block (the one a row analyses: the first free block) stays upright, so it is not "overturned".
    The run's row, with no stop rule, counts the fallen block (``fallen_blocks``, by
    rockdem.analysis.fallen, as ``rockdem run``'s summary counts it) and fragility counts the run
    as a failure, as the "fell" stop would have. Before 2026-11-28 it was a survival."""
    from rockdem.analysis import fallen_blocks
    from rockdem.batch import frames_from_dataset, summary_row
    from rockdem.case import example_case
    from rockdem.fragility import failed
    from rockdem.materials import JointMaterial
    from rockdem.model import Damping, ModelBuilder
    from rockdem.simulation import simulate
    from rockdem.studies import RunSpec

    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial.from_modulus(1e9, 0.5, friction_angle=35)
    b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.6, 0.6, 0.3, density=2000, name="base")
    b.add_box(0.15, 0.4, 0.9, base_center=(0.2, 0, 0.3), density=2000, name="top")
    b.tilt("top", 1.3)  # past its slenderness: it topples towards +x, off the base
    ds = simulate(b.finalize(damping=Damping(beta=5e-4)), 2.0, progress=False, record_interval=0.01)
    assert ds.attrs.get("diverged", 0) == 0
    assert list(ds.block_name.values[fallen_blocks(ds)]) == ["top"]
    row = summary_row(RunSpec.make(example_case("free-rocking")), {}, frames_from_dataset(ds))
    assert row["status"] == "ok" and not row["overturned"] and row["max_rotation_rad"] < 0.05  # the base stayed
    assert row["fallen_blocks"] == 1
    t = pd.DataFrame([row])
    assert list(failed(t)) == [True]
    assert list(failed(t.drop(columns="fallen_blocks"))) == [False]  # what the row said before


def test_fallen_blocks_count_in_the_failure_of_table_rows():
    from rockdem.fragility import failed

    t = pd.DataFrame({"status": ["ok"] * 3, "overturned": [False, False, False], "stop_reason": [None, None, "rest"],
                      "fallen_blocks": [0, 3, None], "max_rotation_over_eta": [0.2, 0.2, 0.2]})
    assert list(failed(t)) == [False, True, False]


def test_the_ida_plot_keeps_small_rotations_apart():
    """Survivals at 2e-4 and 6e-4 eta were both drawn at 1e-3 (the plot's fixed floor); the axis now
    starts at the smallest, and a block at rest (0) is drawn there."""
    from rockdem.fragility import ROTATION_FLOOR, rotation_floor

    assert rotation_floor(pd.Series([6e-4, 2e-4, 0.3, 0.0])) == 2e-4
    assert rotation_floor(pd.Series([0.01, 0.5])) == 1e-3
    assert rotation_floor(pd.Series([0.0, np.nan])) == 1e-3
    assert rotation_floor(pd.Series([1e-12, 0.2])) == ROTATION_FLOOR


def test_the_mle_fit_flags_separated_outcomes_and_refuses_bad_ones():
    """Outcomes separated by the intensity (every failure above every survival, per analysis or per
    group) give a fit whose beta says only how far apart the levels were: the fit says so (it said
    separated=False with beta = 0.016). Non-finite intensities and outcomes other than 0/1 (or
    counts beyond the trials) are refused naming what is wrong, and so is a negative drift limit."""
    sep = fit_fragility_mle([0.1, 0.2, 0.3, 0.4], [0, 0, 1, 1])
    assert sep.separated and separated([0.1, 0.2, 0.3, 0.4], [0, 0, 1, 1])
    mixed = fit_fragility_mle([0.1, 0.2, 0.3, 0.4], [0, 1, 0, 1])
    assert not mixed.separated and 0.3 < mixed.beta < 3.0
    assert not fit_fragility_mle([0.1, 0.2, 0.3], [1, 3, 4], [5, 5, 5]).separated
    assert fit_fragility_mle([0.1, 0.2, 0.3], [0, 0, 5], [5, 5, 5]).separated
    with pytest.raises(ValueError, match="intensities must be finite"):
        fit_fragility_mle([0.1, np.nan, 0.3], [0, 1, 1])
    for outcome in ([0, 2, 1], [0, -1, 1]):
        with pytest.raises(ValueError, match="outcomes must be 0 or 1"):
            fit_fragility_mle([0.1, 0.2, 0.3], outcome)
    with pytest.raises(ValueError, match="drift_limit must be a positive multiple of eta"):
        failed(pd.DataFrame({"overturned": [False]}), drift_limit=-1.0)


@pytest.mark.parametrize("im, outcome", [
    ([0.2, 0.2, 0.4, 0.4, 0.6, 0.6], [1, 0, 0, 0, 0, 0]),  # the only failure at the lowest level
    ([0.25272, 0.30888], [1, 0]),  # rockdem fragility's two levels: failed at the lower one
])
def test_outcomes_whose_failures_do_not_rise_with_intensity_have_no_fragility(im, outcome):
    """Before 2026-11-30 such outcomes gave a median of 0.0047 g and a dispersion of 4.9e18 (or
    inf with an overflow warning), reported as a fragility."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow from the likelihood either
        with pytest.raises(ValueError, match=r"the failures do not rise with the intensity .* no fragility"):
            fit_fragility_mle(im, outcome)
    table = pd.DataFrame({"pga_g": im, "failed": [bool(v) for v in outcome], "status": "ok"})
    fits = fit_all(table)
    assert np.isnan(fits.set_index("im").loc["pga_g", "theta"])


@pytest.mark.parametrize("records, message", [
    (["elcentro-rsn6", "ELCENTRO-RSN6"], r"records 'elcentro-rsn6' and 'ELCENTRO-RSN6' are the same file"),
    (["elcentro-rsn6", "RSN6_IMPVALL.I_I-ELC180.AT2"], r"are the same file \(RSN6_IMPVALL.I_I-ELC180.AT2\)"),
    (["elcentro-rsn6", "nosuch"], r"record 'nosuch': no record 'nosuch'"),
])
def test_an_ida_refuses_a_record_given_twice_or_missing_before_any_run(tmp_path, records, message):
    with pytest.raises(ValueError, match=message):
        run_ida("free-rocking", records, [0.3], tmp_path / "ida", duration=0.1, executor="serial", progress=False)
    assert not (tmp_path / "ida").exists()  # nothing run, nothing written
