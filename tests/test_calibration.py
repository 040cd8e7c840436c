"""Calibration reports the best point it evaluated, consistent with its own table.

The optimiser runs on a synthetic WME surface (no engine): a smooth bowl with its minimum at
beta = 1e-3 and a narrow, deeper notch at 1.1e-3, as the rough WME surfaces of rocking have
(observed: ``calibrate --duration 3`` reported beta = 0.006416, WME 0.0079, while its curve held
0.007058 with WME 0.00003). The curve around the optimum samples +10 % and finds the notch.
"""

from __future__ import annotations

import numpy as np
import pytest

import rockdem.calibration as cal
from rockdem.calibration import Reference, calibrate

NOTCH = 1.1e-3


def _surface(beta: float) -> float:
    bowl = 0.05 * abs(np.log(beta / 1e-3))
    return bowl + 0.02 - (0.0199 if abs(beta / NOTCH - 1.0) < 0.01 else 0.0)


@pytest.fixture
def synthetic(monkeypatch: pytest.MonkeyPatch) -> None:
    def row(spec):
        return {"id": spec.id, "status": "ok", "beta": dict(spec.overrides)["damping.beta"]}

    monkeypatch.setattr(cal, "execute", lambda specs, *a, **k: [row(s) for s in specs])
    monkeypatch.setattr(cal, "wme_of_row", lambda r, ref: _surface(r["beta"]))


REF = Reference(np.linspace(0.0, 1.0, 11), 0.1 * np.cos(20.0 * np.linspace(0.0, 1.0, 11)))  # it moves (a flat one is refused)


def test_reported_optimum_is_the_best_evaluated_point(synthetic) -> None:
    res = calibrate("free-rocking", "damping.beta", (2e-4, 5e-3), REF, scan_points=9, executor="serial")
    ev = res.evaluations
    best = ev.loc[ev["wme"].idxmin()]
    assert res.optimum["damping.beta"] == best["damping.beta"]
    assert res.wme == best["wme"] == pytest.approx(_surface(NOTCH * (1 + 1e-3)), abs=0.01)
    assert abs(res.optimum["damping.beta"] / NOTCH - 1.0) < 0.01  # found the notch
    # the curve is centred on the optimum: its 0 % row is the optimum and the lowest of the curve
    zero = res.curve[res.curve["relative_change"] == 0.0].iloc[0]
    assert zero["damping.beta"] == res.optimum["damping.beta"] and zero["wme"] == res.curve["wme"].min()
    assert all(v >= 0.0 for v in res.sensitivity.values())
    assert f"damping.beta = {res.optimum['damping.beta']:.6g}" in res.report() and not res.notes


def test_a_better_point_outside_the_bounds_is_reported_not_taken(synthetic) -> None:
    # bounds that stop just below the notch: the curve's +10 % point falls outside them
    res = calibrate("free-rocking", "damping.beta", (2e-4, 1.05e-3), REF, scan_points=9, executor="serial")
    assert res.optimum["damping.beta"] <= 1.05e-3
    inside = res.evaluations[res.evaluations["damping.beta"] <= 1.05e-3]
    assert res.wme == inside["wme"].min()
    assert any("outside the bounds" in n for n in res.notes) and "widen the bounds" in res.report()


@pytest.mark.parametrize("text", ["", "time,rotation\n", "0.1\n0.2\n", "# only a comment\n", "0.0,0.1\n"])
def test_an_unusable_reference_file_is_refused_with_what_it_needs(tmp_path, text) -> None:
    # an empty file, a header alone, one column or one row used to fail deep inside calibrate
    p = tmp_path / "ref.csv"
    p.write_text(text)
    with pytest.raises(ValueError, match=r"reference .*ref\.csv.*need rows of time \[s\] and value"):
        cal.load_reference(p)
    for good in ("time,rotation\n0.0,0.1\n0.1,0.2\n", "   0.000   0.100\n   0.100  -0.200\n",  # np.savetxt's fmt='%8.3f'
                 "t;x\n0.0; 0.1\n0.1; -0.2 # note\n", "t;x\n0,0;0,1\n0,1;-0,2\n", "0,0\t0,1\n0,1\t-0,2\n"):
        p.write_text(good)
        ref = cal.load_reference(p)
        assert list(ref.time) == [0.0, 0.1] and list(np.abs(ref.value)) == [0.1, 0.2]
    for partial in ("t,a\n0.0,0.1\n0.05,,9\n0.1,-0.2\n", "0.0 0.1\n0.05 nan\n0.1 -0.2\n"):
        p.write_text(partial)  # a row with an empty field or a NaN is left out, not shifted or kept
        ref = cal.load_reference(p)
        assert list(ref.time) == [0.0, 0.1] and list(ref.value) == [0.1, -0.2]
    p.write_text("0.0\n0.1\n0.2\n")
    with pytest.raises(ValueError, match=r"found 1 column"):
        cal.load_reference(p)
    p.write_text("0.0,0.1\n1.0,0.2\n0.5,0.3\n")
    with pytest.raises(ValueError, match=r"times must increase, but 0.5 s follows 1 s"):
        cal.load_reference(p)
    p.write_text("0,0 0,1\n0,1 0,2\n")  # decimal commas between spaces: ambiguous, refused rather than misread
    with pytest.raises(ValueError, match=r"0 numeric row"):
        cal.load_reference(p)
    with pytest.raises(ValueError, match="is a folder"):
        cal.load_reference(tmp_path)


def test_failed_runs_are_counted_and_a_calibration_of_failures_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """Runs that fail (an error, a divergence) are not silently WME 1000: the result counts and
    names them, and a calibration whose runs all fail is refused instead of reporting the lower
    bound as its optimum (before 2026-11-29: "optimum damping.beta = 0.0005, WME 1000", exit 0)."""
    def rows(specs, *a, **k):
        out = []
        for s in specs:
            beta = dict(s.overrides)["damping.beta"]
            out.append({"id": s.id, "status": "ok", "beta": beta} if beta > 2e-3 else
                       {"id": s.id, "status": "error", "error": "ValueError: dt above the stable bound"})
        return out

    monkeypatch.setattr(cal, "execute", rows)
    monkeypatch.setattr(cal, "wme_of_row", lambda r, ref: cal.FAILED_WME if r["status"] != "ok" else _surface(r["beta"]))
    res = calibrate("free-rocking", "damping.beta", (2e-4, 5e-3), REF, scan_points=9, executor="serial")
    assert res.optimum["damping.beta"] > 2e-3 and res.failed > 0
    assert res.failed == int(res.evaluations["error"].notna().sum())
    assert any("runs failed" in n and "dt above the stable bound" in n for n in res.notes)
    with pytest.raises(ValueError, match="every run so far failed"):
        calibrate("free-rocking", "damping.beta", (2e-4, 1e-3), REF, scan_points=9, executor="serial")


def test_a_parameter_both_calibrated_and_fixed_is_refused(synthetic) -> None:
    """``--set damping.beta=...`` beside ``--parameter damping.beta``: the fixed value was ignored."""
    with pytest.raises(ValueError, match=r"\['damping.beta'\] both calibrated and fixed"):
        calibrate("free-rocking", "damping.beta", (0.001, 0.01), REF, fixed={"damping.beta": 0.003})


def test_calibration_inputs_are_checked(synthetic, tmp_path) -> None:
    """A reference given as a path is read; mismatched bounds, a time column given as the value
    column and rows of NaN get a message (an AttributeError, a TypeError and silence before)."""
    ref = tmp_path / "ref.csv"
    ref.write_text("t,theta\n" + "".join(f"{0.1 * k:.1f},{0.01 * k}\n" for k in range(11)) + "1.1,nan\n")
    with pytest.warns(UserWarning, match="1 row\\(s\\) with NaN or infinite values left out"):
        res = calibrate("free-rocking", "damping.beta", (2e-4, 5e-3), str(ref), scan_points=5, executor="serial")
    assert 2e-4 <= res.optimum["damping.beta"] <= 5e-3
    with pytest.raises(ValueError, match=r"one \(low, high\) pair .* \(2 parameter"):
        calibrate("free-rocking", ["damping.beta", "damping.alpha"], (0.001, 0.01), REF)
    for column in (0, -1):
        with pytest.raises(ValueError, match="column must be 1 or more"):
            cal.load_reference(ref, column=column)


def test_a_flat_reference_and_a_duration_short_of_its_motion_are_refused_before_any_run(monkeypatch) -> None:
    """Before 2026-11-30 both failed at the first run's comparison, naming wme's Python options
    (cut_at_rest=False, overlap_only=True) that the command does not have."""
    monkeypatch.setattr(cal, "execute", lambda *a, **k: pytest.fail("a run was started"))
    flat = Reference(np.linspace(0.0, 1.0, 11), np.ones(11))
    with pytest.raises(ValueError, match=r"the reference's rotation never moves .* nothing to calibrate against"):
        calibrate("free-rocking", "damping.beta", (2e-4, 5e-3), flat, executor="serial")
    moving = Reference(np.linspace(0.0, 4.0, 401), 0.1 * np.exp(-0.5 * np.linspace(0.0, 4.0, 401)) * np.cos(np.linspace(0.0, 40.0, 401)))
    with pytest.raises(ValueError, match=r"duration = 1 s ends before the reference's motion does \(3.\d+ s\).*--duration"):
        calibrate("free-rocking", "damping.beta", (2e-4, 5e-3), moving, duration=1.0, executor="serial")


def test_a_stop_signal_while_the_files_are_written_is_held_until_they_are_complete(synthetic, tmp_path, monkeypatch, capsys) -> None:
    """Ctrl-C as ``rockdem calibrate`` writes its files (here: as it draws wme.png, the third of
    five) is held until report.txt is written, then ends the command with 130 (before 2026-12-01
    it left evaluations.csv and curve.csv without calibration.json and report.txt)."""
    import os
    import signal

    from rockdem.cli import main

    draw = cal.plot_calibration

    def interrupted_draw(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)
        return draw(*args, **kwargs)

    monkeypatch.setattr(cal, "plot_calibration", interrupted_draw)
    ref = tmp_path / "ref.csv"
    ref.write_text("time,rotation\n" + "".join(f"{t:.3f},{v:.6f}\n" for t, v in zip(REF.time, REF.value)))
    out = tmp_path / "cal"
    assert main(["calibrate", str(ref), "--bounds", "2e-4", "5e-3", "--scan", "9", "--executor", "serial", "--out", str(out)]) == 130
    assert sorted(p.name for p in out.iterdir() if p.suffix != ".jsonl") == [
        "calibration.json", "curve.csv", "evaluations.csv", "report.txt", "wme.png"]
    assert "WME" in (out / "report.txt").read_text()
    err = capsys.readouterr().err
    assert "rockdem: writing the calibration's files; interrupt again to abandon" in err
    assert "SIGINT came as the calibration ended; its files are complete" in err


def test_a_wme_that_does_not_depend_on_the_parameter_calibrates_nothing(synthetic, monkeypatch, tmp_path, capsys) -> None:
    """A WME the parameter does not move (a reference of two samples 0.2 s apart: 4.322 at every
    point to 3e-7, measured 2026-12-01) is reported as such, with a warning and exit status 1,
    and none of the notes that compare equal values (a better point outside the bounds, a rough
    surface) that it gave before."""
    from rockdem.cli import main

    monkeypatch.setattr(cal, "wme_of_row", lambda r, ref: 4.322 * (1.0 + 3e-7 * np.sin(1e4 * r["beta"])))
    with pytest.warns(UserWarning, match="the WME does not depend on damping.beta over the bounds"):
        res = calibrate("free-rocking", "damping.beta", (1e-3, 1e-2), REF, scan_points=9, executor="serial")
    assert res.flat and len(res.notes) == 1 and "nothing was calibrated" in res.notes[0]
    ref = tmp_path / "ref.csv"
    ref.write_text("time,rotation\n" + "".join(f"{t:.3f},{v:.6f}\n" for t, v in zip(REF.time, REF.value)))
    assert main(["calibrate", str(ref), "--bounds", "1e-3", "1e-2", "--scan", "9", "--executor", "serial"]) == 1
    captured = capsys.readouterr()
    assert "note: the WME does not depend on damping.beta" in captured.out
    assert "warning: calibration: the WME does not depend on damping.beta" in captured.err
    monkeypatch.setattr(cal, "wme_of_row", lambda r, ref: _surface(r["beta"]))
    assert not calibrate("free-rocking", "damping.beta", (2e-4, 5e-3), REF, scan_points=9, executor="serial").flat
