"""Checkpoints (rockdem.checkpoint): a continued run is bit-identical to an uninterrupted one,
also after a stop signal mid-run; a checkpoint refuses another model; a settled state starts new
loadings at t = 0."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest
import xarray as xr

import rockdem.simulation as simulation
from rockdem.case import apply_overrides, example_case, parse_case
from rockdem.checkpoint import Checkpoint, model_hash, structure_hash
from rockdem.cli import main
from rockdem.kernels.layout import State
from rockdem.model import Damping
from rockdem.results import load
from rockdem.simulation import simulate

RUN = {"record_interval": 0.01, "contact_interval": 0.05, "progress": False}


@pytest.fixture(scope="module")
def case():
    """The built-in free-rocking block (a 0.2 x 2 m block released from 90 % of its instability angle)."""
    return parse_case(example_case("free-rocking"))


@pytest.fixture(scope="module")
def uninterrupted(case):
    return simulate(case.model, 0.8, monitors=case.monitors, **RUN)


def assert_identical(a: xr.Dataset, b: xr.Dataset) -> None:
    """Every variable and coordinate of two results equal bit for bit (NaN where NaN)."""
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        x, y = a[name].values, b[name].values
        assert x.shape == y.shape, name
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), f"{name} differs"


def test_continued_run_is_bit_identical_to_an_uninterrupted_one(case, uninterrupted, tmp_path):
    first = simulate(case.model, 0.4, monitors=case.monitors, checkpoint=tmp_path / "half.npz", **RUN)
    assert first.attrs["checkpoint"] == str(tmp_path / "half.npz")
    ck = Checkpoint.load(tmp_path / "half.npz")
    assert ck.frame == first.sizes["time"] == 41 and 0.4 <= ck.time <= 0.4 + ck.timestep.dt * (1 + 1e-9)
    cont = simulate(case.model, 0.8, monitors=case.monitors, initial=tmp_path / "half.npz", progress=False)
    assert cont.attrs["continued_from_time"] == ck.time
    assert cont.sizes["time"] == 81 and cont.sizes["contact_time"] == 17
    assert_identical(uninterrupted, cont)
    assert cont.attrs["steps"] == uninterrupted.attrs["steps"]


def test_a_stop_signal_mid_run_writes_a_checkpoint_that_continues_exactly(case, uninterrupted, tmp_path, monkeypatch):
    # SIGINT arrives while the compiled chunk runs (sent from inside it); the run must stop at a chunk
    # boundary with its state, frame counter and snapshots consistent, and save them. Chunks end at
    # the contact snapshots (every 0.05 s), so the third ends near 0.15 s.
    real, calls = simulation.advance, []

    def advance_then_signal(*args):
        out = real(*args)
        calls.append(1)
        if len(calls) == 3:
            os.kill(os.getpid(), signal.SIGINT)
        return out

    monkeypatch.setattr(simulation, "advance", advance_then_signal)
    part = simulate(case.model, 0.8, monitors=case.monitors, checkpoint=tmp_path / "stop.npz", **RUN)
    monkeypatch.undo()
    assert part.attrs["interrupted"] == 1
    ck = Checkpoint.load(tmp_path / "stop.npz")
    assert 0.0 < ck.time < 0.8 and ck.frame == part.sizes["time"] < 81
    cont = simulate(case.model, 0.8, monitors=case.monitors, initial=ck, progress=False)
    assert_identical(uninterrupted, cont)


def test_periodic_checkpoints_are_written_during_the_run(case, tmp_path, monkeypatch):
    saved = []
    real = Checkpoint.save
    monkeypatch.setattr(Checkpoint, "save", lambda self, path: saved.append(self.time) or real(self, path))
    simulate(case.model, 0.3, checkpoint=tmp_path / "p.npz", checkpoint_every=1e-9, **RUN)
    assert len(saved) >= 2 and saved == sorted(saved)  # during the run, then at the end
    assert saved[-1] >= 0.3


def test_checkpoint_refuses_another_model_or_other_options(case, tmp_path):
    simulate(case.model, 0.1, checkpoint=tmp_path / "c.npz", **RUN)
    damped = parse_case(apply_overrides(example_case("free-rocking"), ["damping.beta=0.001"])).model
    assert structure_hash(damped) == structure_hash(case.model) and model_hash(damped) != model_hash(case.model)
    # ... saying what differs (before 2026-12-08 only the hashes and the same block names)
    with pytest.raises(ValueError, match=r"another model.*reset_clock.*; what differs: the damping \(mat_beta\)$"):
        simulate(damped, 0.2, initial=tmp_path / "c.npz", progress=False)
    taller = parse_case(apply_overrides(example_case("free-rocking"), ["specimen.height=2.5"])).model
    with pytest.raises(ValueError, match=r"another model.*what differs: the blocks' geometry, size or density \(block_mass, .*"
                                         r"the interface points \(.*the blocks' starting poses"):
        simulate(taller, 0.2, initial=tmp_path / "c.npz", progress=False)
    with pytest.raises(ValueError, match="blocks, geometry, joint materials or starting poses.*what differs: the blocks' geometry"):
        simulate(taller, 0.2, initial=Checkpoint.load(tmp_path / "c.npz").reset_clock(), progress=False)
    # a settled start lists only what it may not differ in: not the damping, which it may
    taller_damped = parse_case(apply_overrides(example_case("free-rocking"), ["specimen.height=2.5", "damping.beta=0.001"])).model
    with pytest.raises(ValueError, match=r"what differs: (?!.*damping).*\(position0"):
        simulate(taller_damped, 0.2, initial=Checkpoint.load(tmp_path / "c.npz").reset_clock(), progress=False)
    with pytest.raises(ValueError, match="record_interval = 0.02 differs"):
        simulate(case.model, 0.2, initial=tmp_path / "c.npz", record_interval=0.02, progress=False)
    # a finished run: its last frame is at its end, 0.1 s (the state a step past it); an end that
    # records no later frame is refused with the first end time that does
    interval = Checkpoint.load(tmp_path / "c.npz").record_interval
    for end in (0.05, 0.1, 0.1 + 0.5 * interval):
        with pytest.raises(ValueError, match=rf"frames up to t = 0.1 s .*a run to {end:.6g} s records no later one.*"
                                             rf"at least {0.1 + interval:.6g} s"):
            simulate(case.model, end, initial=tmp_path / "c.npz", progress=False)
    assert simulate(case.model, 0.1 + interval, initial=tmp_path / "c.npz", progress=False).time.values[-1] == pytest.approx(0.1 + interval)


def test_a_checkpoint_path_that_cannot_be_written_is_refused_before_the_run(case, tmp_path, monkeypatch):
    # refused after the whole run before 2026-12-08 (IsADirectoryError, FileExistsError), the result lost
    ran = []
    monkeypatch.setattr(simulation, "_load_kernels", lambda *a: ran.append(a))  # (nothing must be run)
    (tmp_path / "afile").write_text("x")
    for path, match in ((tmp_path, "is a folder; give a file path in it"),
                        (tmp_path / "afile" / "c.npz", "which is a file, not a folder")):
        with pytest.raises(ValueError, match=match):
            simulate(case.model, 0.05, checkpoint=path, progress=False)
    assert not ran


def test_checkpoint_of_another_engine_layout_is_refused_by_name(case, tmp_path):
    simulate(case.model, 0.05, checkpoint=tmp_path / "c.npz", **RUN)
    with np.load(tmp_path / "c.npz") as z:
        arrays = {k: z[k] for k in z.files if k != f"state/{State._fields[-1]}"}
    np.savez(tmp_path / "old.npz", **arrays)
    with pytest.raises(ValueError, match=f"engine State differs.*missing \\['{State._fields[-1]}'\\]"):
        Checkpoint.load(tmp_path / "old.npz")
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="not a rockdem checkpoint"):
        Checkpoint.load(tmp_path / "junk.npz")


def test_settled_state_starts_new_loadings_at_rest(tmp_path):
    # A block settled under gravity: its contacts carry its weight. Started again at t = 0 from
    # that state, under gravity, it stays at rest (no settling transient); under another damping
    # (a new loading on the same blocks) the run starts from the same poses and contact forces.
    data = {**example_case("free-rocking"), "loading": {"type": "gravity"}}
    model = parse_case(data).model
    raw = simulate(model, 0.3, checkpoint=tmp_path / "settled.npz", **RUN)
    settled = Checkpoint.load(tmp_path / "settled.npz").reset_clock()
    assert settled.time == 0.0 and settled.frame == 0
    again = simulate(model, 0.1, initial=settled, **RUN)
    assert again.time.values[0] == 0.0
    np.testing.assert_array_equal(again.block_position.values[0], settled.state.position)
    weight = float(model.arrays.block_mass[1]) * 9.81
    assert np.nansum(again.point_normal_force.values[0]) == pytest.approx(weight, rel=1e-3)
    # at rest: far below the kinetic energy of the first run's settling transient
    assert again.energy_kinetic.max() < 1e-3 * raw.energy_kinetic.max()
    damped = parse_case(apply_overrides(data, ["damping.beta=0.001"])).model
    other = simulate(damped, 0.1, initial=settled, **RUN)
    np.testing.assert_array_equal(other.block_position.values[0], settled.state.position)


@pytest.mark.parametrize("options", [[], ["run.dt=2e-4"], ['run.timestep_rule="3dec"']], ids=["automatic", "dt", "3dec"])
def test_cli_run_from_checkpoint_equals_one_run(tmp_path, options):
    # also with a step or rule of the user's: the command line passes the case's default rule and
    # resolution, which such a run does not use (refused as changed options before 2026-12-08)
    args = ["run", "--example", "free-rocking", "--quiet", "--no-plot", "--set", "run.record_interval=0.01",
            *[a for o in options for a in ("--set", o)]]
    assert main(args + ["--duration", "0.4", "--out", str(tmp_path / "one")]) == 0
    assert main(args + ["--duration", "0.2", "--out", str(tmp_path / "two")]) == 0
    ck = tmp_path / "two" / "checkpoint.npz"
    assert main(args + ["--duration", "0.4", "--out", str(tmp_path / "two"), "--from", str(ck)]) == 0
    assert_identical(load(tmp_path / "one" / "result.nc"), load(tmp_path / "two" / "result.nc"))
    assert main(args + ["--duration", "0.4", "--out", str(tmp_path / "three"), "--from", str(ck), "--settled", str(ck)]) == 2
    assert main(args + ["--set", "damping.beta=0.002", "--out", str(tmp_path / "four"), "--from", str(ck)]) == 2
    assert main(args + ["--set", "run.dt=1e-4", "--out", str(tmp_path / "five"), "--from", str(ck)]) == 2  # another step


def test_settled_state_starts_an_earthquake_case(tmp_path):
    # settle the El Centro example's block under gravity alone, then run the earthquake case from it
    from pathlib import Path

    from rockdem.case import load_case

    quake = load_case(Path(__file__).resolve().parents[1] / "examples" / "elcentro_block_foundation.toml")
    gravity = parse_case({**quake, "loading": {"type": "gravity"}}).model
    model = parse_case(quake).model
    assert structure_hash(gravity) == structure_hash(model) and model_hash(gravity) != model_hash(model)
    simulate(gravity, 0.2, checkpoint=tmp_path / "s.npz", **RUN)
    start = Checkpoint.load(tmp_path / "s.npz").reset_clock()
    ds = simulate(model, 0.3, initial=start, **RUN)
    np.testing.assert_array_equal(ds.block_position.values[0], start.state.position)
    assert ds.attrs["steps"] > 0 and ds.time.values[0] == 0.0


# --- checkpoints of runs with a stop rule (rockdem.stopping) ---------------------------------------
# The paper's Fig. 6A block (0.19 x 0.5 m) released from 90 % of eta, MP damped (alpha = 8): it comes
# to rest at about 2.5 s, so stop="rest" decides it there; snapshots every 0.05 s cut chunks as well.
STOP_RUN = {"record_interval": 0.005, "contact_interval": 0.05, "progress": False}


@pytest.fixture(scope="module")
def resting():
    over = {"run.record_interval": 0.005, "specimen.height": 0.5, "specimen.width": 0.19, "damping.beta": 0.0,
            "damping.alpha": 8.0}
    return parse_case(apply_overrides(example_case("free-rocking"), [f"{k}={v}" for k, v in over.items()])).model


@pytest.fixture(scope="module")
def stopped(resting):
    """The uninterrupted run with stop="rest" (to 4 s) and without a stop rule."""
    return simulate(resting, 4.0, stop="rest", **STOP_RUN), simulate(resting, 4.0, **STOP_RUN)


def test_continued_run_with_a_stop_rule_is_bit_identical(resting, stopped, tmp_path):
    # cut at 1.02 s, before the decision and between two contact snapshots (which end chunks too):
    # the continuation with the same rule gives the decision, the frames, the snapshots and the steps
    # past the decision of the uninterrupted run (a chunk cut short by the end of a run: see
    # test_stop_decided_in_the_chunk_cut_by_the_end_of_a_run)
    one, _ = stopped
    assert one.attrs["stop_reason"] == "rest" and 1.5 < one.attrs["stop_time"] < 3.5
    first = simulate(resting, 1.02, stop="rest", checkpoint=tmp_path / "a.npz", **STOP_RUN)
    assert "stop_reason" not in first.attrs
    ck = Checkpoint.load(tmp_path / "a.npz")
    assert ck.check_target is not None and ck.check_target > ck.time
    cont = simulate(resting, 4.0, stop="rest", initial=ck, progress=False)
    assert_identical(one, cont)
    for key in ("steps", "dt_min", "stop_reason", "stop_time", "stop_block"):
        assert cont.attrs[key] == one.attrs[key], key


def test_checkpoint_of_a_stopped_run_continues_as_decided_or_runs_on(resting, stopped, tmp_path):
    one, full = stopped
    again = simulate(resting, 4.0, stop="rest", checkpoint=tmp_path / "s.npz", **STOP_RUN)
    ck = Checkpoint.load(tmp_path / "s.npz")
    # the checkpoint holds the state where the loop ended and every frame computed up to there
    assert ck.frame >= again.sizes["time"] and ck.time > again.attrs["stop_time"]
    assert int(ck.state.step[0]) == again.attrs["steps"]
    # the same rule: decided from the saved frames, nothing stepped
    same = simulate(resting, 4.0, stop="rest", initial=ck, progress=False)
    assert_identical(one, same)
    assert same.attrs["steps"] == one.attrs["steps"] and same.attrs["stop_time"] == one.attrs["stop_time"]
    # without a stop rule it runs on to the end: the uninterrupted run without one
    on = simulate(resting, 4.0, initial=ck, progress=False)
    assert "stop_reason" not in on.attrs and on.attrs["stop_rule"] == "off"
    assert_identical(full, on)
    assert on.attrs["steps"] == full.attrs["steps"]


def test_stop_decided_in_the_chunk_cut_by_the_end_of_a_run(resting, tmp_path):
    # the first run ends 1 ms after the decided frame, inside the chunk of check_steps steps where the
    # uninterrupted run decided it (no snapshots here to cut that chunk): it stops at its own end;
    # continued, it computes the rest of that chunk first, so that its state (the steps past the
    # decision) is the uninterrupted run's
    run = {**STOP_RUN, "contact_interval": None}
    one = simulate(resting, 4.0, stop="rest", **run)
    short = simulate(resting, one.attrs["stop_time"] + 0.001, stop="rest", checkpoint=tmp_path / "c.npz", **run)
    assert short.attrs["stop_time"] == one.attrs["stop_time"] and short.attrs["steps"] < one.attrs["steps"]
    ck = Checkpoint.load(tmp_path / "c.npz")
    assert ck.check_target is not None
    cont = simulate(resting, 4.0, stop="rest", initial=ck, progress=False)
    assert_identical(one, cont)
    assert cont.attrs["steps"] == one.attrs["steps"]


def test_a_saved_state_still_moving_that_starts_a_new_run_is_warned_about(case, tmp_path):
    """--settled starts a new run at t = 0 with the saved velocities: a state saved mid-rocking is
    not settled, and the run says so (before 2026-11-29 it started silently); a settled one does not."""
    import warnings

    simulate(case.model, 0.5, checkpoint=tmp_path / "moving.npz", **RUN)
    with pytest.warns(UserWarning, match="is not at rest: kinetic energy"):
        simulate(case.model, 0.05, initial=Checkpoint.load(tmp_path / "moving.npz").reset_clock(), **RUN)
    data = {**example_case("free-rocking"), "loading": {"type": "gravity"}, "damping": {"beta": 0.005}}
    model = parse_case(data).model
    simulate(model, 0.5, checkpoint=tmp_path / "settled.npz", **RUN)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(model, 0.05, initial=Checkpoint.load(tmp_path / "settled.npz").reset_clock(), **RUN)


def test_a_stop_signal_while_the_start_loads_is_held_until_it_is_ready(case, monkeypatch, capsys):
    """A SIGTERM while the start's kernels load (a first run compiles them, minutes) waits until they
    are ready, then stops the run: raised inside Numba's compiler it left a half-built kernel
    ("no compiled object yet") and a traceback, exit 1 (before 2026-11-29)."""
    from rockdem.cli import stop_on_signals

    real = simulation._fresh_run
    finished = []

    def slow_start(*args, **kwargs):
        os.kill(os.getpid(), signal.SIGTERM)  # arrives while the kernels "load"
        run = real(*args, **kwargs)
        finished.append(True)
        return run

    monkeypatch.setattr(simulation, "_fresh_run", slow_start)
    with stop_on_signals(), pytest.raises(KeyboardInterrupt):
        simulate(case.model, 0.2, **RUN)
    assert finished == [True]
    assert "stopping once the compiled kernels are loaded" in capsys.readouterr().err


def _pulse_case(tmp_path, **run):
    """A 1 x 1 x 0.5 m block (friction 0.3), undamped, under a 0.25 g inertial step of 0.5 s:
    below its sliding threshold of 0.3 g."""
    record = tmp_path / "step_g.txt"
    t = np.arange(0.0, 1.0 + 5e-4, 1e-3)
    record.write_text("".join(f"{x:.3f} {0.25 if x <= 0.5 else 0.0}\n" for x in t))
    return {"run": {"duration": 0.8, "record_interval": 0.002, **run}, "damping": {"beta": 0.0},
            "specimen": {"type": "block", "width": 1.0, "height": 0.5, "length": 1.0, "density": 2000.0,
                         "youngs_modulus": 1.8e9, "friction_angle_deg": 16.69924423},
            "loading": {"type": "earthquake", "record": str(record), "units": "g", "mode": "inertial", "baseline": False}}


def test_run_settle_starts_a_case_with_its_joints_carrying_the_weight(tmp_path):
    """Gravity loads the joints' springs from zero at t = 0: undamped they ring between no force and
    twice the weight for ever (mass-proportional damping hardly slows it), and a block pushed below
    its sliding threshold slips (0.25 g on a 0.3 friction: 0.79 mm, 0.75 mm with alpha = 0.5; a new
    user's review found it). With ``[run] settle = true`` the case starts from its blocks settled
    under gravity alone: the base carries the weight from the first frame and the block stays stuck
    (its springs' elastic deflection only: 7 um)."""
    import warnings

    from rockdem.run_cli import run_case

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        plain = run_case(parse_case(_pulse_case(tmp_path)), progress=False)
        settled = run_case(parse_case(_pulse_case(tmp_path, settle=True)), progress=False)
    weight = 1000.0 * 9.81
    def base(ds):
        return ds.base_reaction.values[:, 2]
    def slip(ds):
        x = ds.block_position.values[:, 1, 0]
        return float(np.max(np.abs(x - x[0])))
    assert base(plain).max() > 1.5 * weight and slip(plain) > 2e-4  # the ring: up to twice the weight; it slipped
    np.testing.assert_allclose(base(settled)[:50], weight, rtol=0.01)  # at rest from t = 0
    assert slip(settled) < 5e-5
    assert settled.attrs["settled_s"] < 1.0 and "settled_s" not in plain.attrs  # at rest in 0.5 s of stillness
    with pytest.raises(ValueError, match="settle must be true, false or the longest settling time"):
        parse_case(_pulse_case(tmp_path, settle="yes"))
    for short_or_long in (0.001, 1e9):
        with pytest.raises(ValueError, match=r"settle = .* s: give from 1 s \(rest is judged over 0.5 s of stillness\) to 60 s, or true \(2 s at most\)"):
            parse_case(_pulse_case(tmp_path, settle=short_or_long))
    # A façade on a 10 deg slope, beyond its 7.8 deg limit, falls under its own weight: it cannot start settled.
    facade = {**_pulse_case(tmp_path, settle=True), "damping": {"beta": 0.00025}}
    facade["specimen"] = {"type": "facade", "width": 0.11, "height": 0.8, "length": 1.5, "density": 1750.0,
                          "gap": 0.004, "slope_deg": 10.0, "youngs_modulus": 1.8e9, "friction_angle_deg": 30.96}
    with pytest.raises(ValueError, match=r"settle: the blocks did not come to rest within 2 s .*does not stand"):
        run_case(parse_case(facade), progress=False)

    free = {**example_case("free-rocking"), "run": {"duration": 0.1, "settle": True}}
    with pytest.raises(ValueError, match=r"\[run\] settle: the free-rocking loading changes the blocks"):
        run_case(parse_case(free), progress=False)
