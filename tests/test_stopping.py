"""Stopping a run once its outcome is decided (rockdem.stopping): collapse and rest criteria."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from rockdem.case import apply_overrides, example_case, parse_case
from rockdem.kernels.layout import new_records
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.results import rocking_pivots
from rockdem.simulation import run_model, simulate
from rockdem.stopping import REST_ROTATION, REST_SPEED, REST_WINDOW, Stopper, StopRule, input_end_time, stop_rule

G = 9.81
# the paper's Fig. 6A block: 0.19 x 0.5 m (eta = 20.8 deg), MP damping (no SP step reduction: fast)
SMALL = {"run.record_interval": 0.005, "specimen.height": 0.5, "specimen.width": 0.19, "damping.beta": 0.0}


def _case(**over):
    return parse_case(apply_overrides(example_case("free-rocking"), [f"{k}={v}" for k, v in {**SMALL, **over}.items()]))


def _run(case, duration, stop, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(case.model, duration, record_interval=case.run.record_interval, monitors=case.monitors,
                        progress=False, stop=stop, **kw)


def test_stop_modes_are_checked():
    assert stop_rule("off") is None and stop_rule("decided") == StopRule(True, True)
    assert stop_rule("rest") == StopRule(collapse=False, rest=True)
    with pytest.raises(ValueError, match="stop must be one of"):
        stop_rule("sometimes")
    with pytest.raises(ValueError, match=r"\[run\] stop must be one of"):
        _case(**{"run.stop": '"soon"'})


def test_block_released_beyond_eta_stops_at_the_first_frame_past_eta():
    """Free rocking from 1.02 eta: with no ground motion phi_c = 0, so the collapse is decided at the
    first frame past eta moving away (frame 1: it starts there). The full run ends fallen (it tumbles about pi/2 and
    bounces on its side on the ground); the stopped run's frames are the full run's up to there, bit for bit."""
    case = _case(**{"loading.tilt_fraction": 1.02})
    full = _run(case, 3.0, "off")
    stopped = _run(case, 3.0, "decided")
    eta = float(full.block_eta.values[1])
    theta = full.rocking_angle.values[:, 1]
    # Undamped, it keeps bouncing on its side: it lies on the ground within the last second.
    late = full.time.values > full.time.values[-1] - 1.0
    assert abs(theta[-1]) > 3 * eta and full.block_position.values[late, 1, 2].min() < 0.5 * full.block_position.values[0, 1, 2]
    a = stopped.attrs
    assert a["stop_reason"] == "overturned" and a["stop_block"] == "block"
    n = stopped.sizes["time"]
    first = max(int(np.flatnonzero(np.abs(theta) > eta)[0]), 1)  # a result keeps two frames at least
    assert n == first + 1 and a["stop_time"] == pytest.approx(float(full.time[first]))
    np.testing.assert_array_equal(stopped.block_quaternion.values, full.block_quaternion.values[:n])
    assert stopped.attrs["steps"] < 0.3 * full.attrs["steps"]


def test_decision_does_not_depend_on_the_check_interval():
    case = _case(**{"loading.tilt_fraction": 1.02})
    runs = [_run(case, 3.0, StopRule(check_steps=n)) for n in (150, 4000)]
    assert runs[0].sizes["time"] == runs[1].sizes["time"]
    assert runs[0].attrs["stop_time"] == runs[1].attrs["stop_time"]
    np.testing.assert_array_equal(runs[0].rocking_angle.values, runs[1].rocking_angle.values)


def test_rocking_block_stops_at_rest_with_the_full_runs_residual():
    """MP-damped free rocking (alpha = 8) dies out within 4 s: the stopped run ends at rest, and the
    full run stays within the rest tolerance of the stopped run's last rotation from there on."""
    case = _case(**{"damping.alpha": 8.0})
    full = _run(case, 4.0, "off")
    stopped = _run(case, 4.0, "rest")
    a = stopped.attrs
    assert a["stop_reason"] == "rest" and REST_WINDOW <= a["stop_time"] < 3.5
    t_s = a["stop_time"]
    theta = full.rocking_angle.values[:, 1]
    after = full.time.values >= t_s - 1e-9
    assert np.max(np.abs(theta[after] - stopped.rocking_angle.values[-1, 1])) <= 2 * REST_ROTATION
    v_tol = REST_SPEED * math.sqrt(G * 0.19)
    assert np.max(np.linalg.norm(full.block_velocity.values[after, 1], axis=1)) <= v_tol  # and it stays at rest
    # not late either: within a second of the last rocking above the rotation tolerance
    moving = full.time.values[np.abs(theta - theta[-1]) > REST_ROTATION]
    assert t_s < moving[-1] + REST_WINDOW + 1.0


def _pulse_model(amp_g: float, t_pulse: float = 1.0) -> tuple:
    """The 0.19 x 0.5 m block on a fixed base under a one-cycle sine of the ground acceleration
    (inertial mode: body acceleration -a_g), ending at t_pulse; SP damping (without damping its
    contact springs vibrate for ever: never at rest)."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial.from_modulus(1.8e9, 0.5, friction_angle=80)
    b.add_box(2, 2, 0.25, base_center=(0, 0, -0.25), driven=True, name="ground")
    b.add_box(0.19, 1.0, 0.5, density=1800, name="block")
    t = np.linspace(0.0, t_pulse, 201)
    a = amp_g * G * np.sin(2 * np.pi * t / t_pulse)
    b.set_body_acceleration(t, -np.column_stack([a, 0 * a, 0 * a]))
    return b.finalize(damping=Damping(beta=0.0005)), t_pulse


def test_no_rest_stop_while_the_input_goes_on():
    """A ground motion too weak to rock the block: at rest throughout, but the run may only stop one
    rest window after the input ended."""
    model, t_end = _pulse_model(0.02)
    assert input_end_time(model) == pytest.approx(t_end)
    out = run_model(model, 3.0, record_interval=0.005, stop="decided", progress=False)
    assert out.attrs["stop_reason"] == "rest"
    assert t_end + REST_WINDOW <= out.attrs["stop_time"] <= t_end + REST_WINDOW + 0.02


def _records_at(model, theta: float, omega: float, t: float):
    """One recorded frame of the model's free block rotated by theta about the rocking axis, spinning at omega."""
    from rockdem.kernels.rotation import axis_angle_matrix, matrix_to_quat, quats_to_matrices

    rec = new_records(2, model.block_count, 1)  # frame 0: the start; frame 1: the state judged
    rec.time[:] = (0.0, t)
    r = axis_angle_matrix(model.rocking_axis, theta) @ quats_to_matrices(model.quaternion_ref[1])
    rec.quaternion[:] = model.quaternion0
    rec.quaternion[1, 1] = matrix_to_quat(r)
    rec.omega[1, 1] = omega * model.rocking_axis
    rec.position[:] = model.position0
    return rec


def test_overturn_criterion_against_the_rigid_block_energy_barrier():
    """phi_c = atan(a / g) with a the largest ground acceleration still to come; moving back, the
    block must climb m R [g (cos phi_c - cos phi) - a (sin phi - sin phi_c)] to come back."""
    amp = 0.3
    model, t_end = _pulse_model(amp)
    plus, _ = rocking_pivots(model, 1)
    eta, r, i_o, m = plus
    a = amp * G * np.max(np.abs(np.sin(2 * np.pi * np.linspace(0, 1, 201))))
    phi_c = math.atan2(a, G)

    def decided(phi: float, omega: float, t: float) -> bool:
        st = Stopper(model, StopRule(rest=False), 0.005)
        return st.check(_records_at(model, eta + phi, omega, t), 2) is not None

    assert not decided(0.9 * phi_c, 0.0, 0.0)  # the record can still push it back
    assert decided(1.1 * phi_c, 0.0, 0.0)  # beyond what the record can oppose
    assert decided(0.9 * phi_c, 0.0, t_end + 0.1)  # the record is over: past eta is enough
    assert decided(0.5 * phi_c, 0.0, t_end + 0.1) and not decided(-0.01, 0.0, t_end + 0.1)
    phi = 1.5 * phi_c
    barrier = m * r * (G * (math.cos(phi_c) - math.cos(phi)) - a * (math.sin(phi) - math.sin(phi_c)))
    w = math.sqrt(2 * barrier / i_o)  # the angular speed that just climbs back to phi_c
    assert decided(phi, -0.99 * w, 0.0) and not decided(phi, -1.01 * w, 0.0)
    assert decided(phi, +1.01 * w, 0.0)  # moving away: falls on


def test_ida_outcomes_are_the_same_with_and_without_stopping():
    """Overturning decided early must be the overturning a full run ends in: El Centro (Peknold) at
    five PGA levels, 6 s, the 0.19 x 0.5 m block."""
    from rockdem.batch import run_batch
    from rockdem.fragility import failed, ida_specs

    import pandas as pd

    levels = [0.15, 0.3, 0.45, 0.6, 0.9]
    fixed = {**SMALL, "damping.alpha": 2.0}
    out = {}
    for stop in ("off", "decided"):
        rows = pd.DataFrame(run_batch(ida_specs("free-rocking", ["elcentro-peknold"], levels, fixed=fixed, duration=6.0, stop=stop)))
        out[stop] = rows.assign(failed=failed(rows)).set_index("pga_g")
    assert (out["off"]["status"] == "ok").all() and (out["decided"]["status"] == "ok").all()
    assert list(out["off"]["failed"]) == list(out["decided"]["failed"])
    assert out["off"]["failed"].any() and not out["off"]["failed"].all()
    stopped = out["decided"]["stop_reason"] == "overturned"
    assert stopped.any() and (out["decided"].loc[stopped, "steps"] < out["off"].loc[stopped, "steps"]).all()


def test_a_falling_block_of_an_assembly_stops_the_run():
    """A stack of two blocks released beyond the assembly's instability angle: the top block falls."""
    data = example_case("free-rocking")
    data["specimen"] = {"type": "stack", "width": 0.19, "heights": [0.25, 0.25], "youngs_modulus": 1.8e9,
                        "friction_angle_deg": 80.0}
    data["damping"] = {"alpha": 2.0}
    data["loading"] = {"type": "free-rocking", "tilt_fraction": 1.1}
    data["run"] = {"duration": 3.0, "record_interval": 0.005, "stop": "decided"}
    case = parse_case(data)
    ds = _run(case, 3.0, "decided")
    a = ds.attrs
    assert a["stop_reason"] == "fell" and a["stop_time"] < 3.0
    b = list(ds.block_name.values).index(a["stop_block"])
    thickness = 0.19  # the smaller dimension of both blocks
    assert float(ds.block_position.values[0, b, 2] - ds.block_position.values[-1, b, 2]) > 0.5 * thickness


def test_studies_stop_by_default_and_keep_their_ids_when_off():
    """Study files and make_specs add run.stop = "decided" unless told otherwise; with stop = "off"
    nothing is added, so a study's runs keep the ids (and stored rows) they had before stopping."""
    from rockdem.studies import RunSpec, parse_study

    study = {"base": "free-rocking", "duration": 1.0, "grid": {"damping.alpha": [1.0]}}
    on = parse_study({"study": study}).specs[0]
    assert dict(on.overrides)["run.stop"] == "decided"
    off = parse_study({"study": {**study, "stop": "off"}}).specs[0]
    assert off.id == RunSpec.make(example_case("free-rocking"), {"damping.alpha": 1.0}, duration=1.0).id
    with pytest.raises(ValueError, match=r"\[study\] stop must be one of"):
        parse_study({"study": {**study, "stop": "maybe"}})


def _thrown(resting: bool):
    """A 0.3 m cube thrown clear of a 0.6 m foundation at 6 m/s (it leaves the supports about 0.07 s
    later), and, with ``resting``, a 0.2 m cube resting on the foundation's far corner."""
    from rockdem.specimens import add_foundation

    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e9 / 0.3, friction_angle=30)
    add_foundation(b, 0.6)
    b.add_box(0.3, 0.3, 0.3, base_center=(0.1, 0.1, 0), density=2000, name="cube", velocity=(6.0, 0, 0))
    if resting:
        b.add_box(0.2, 0.2, 0.2, base_center=(-0.2, -0.2, 0), density=2000, name="resting")
    return b.finalize(damping=Damping(beta=2e-4))


def test_a_block_thrown_clear_of_the_supports_has_fallen_and_the_rest_may_come_to_rest():
    """A block that left the supports falls for ever: the collapse rule decides "fell" at the frame
    the engine noted it (also for a single free block, judged otherwise by overturning), and the
    rest rule leaves it out, so that the block still on the foundation can be found at rest. Before
    2026-11-28 both runs went on to their end (the falling block never rests, nor overturns)."""
    for stop in ("collapse", "decided"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = simulate(_thrown(False), 3.0, record_interval=0.005, progress=False, stop=stop)
        t_off = float(np.atleast_1d(ds.attrs["fell_off_times"])[0])
        assert ds.attrs["stop_reason"] == "fell" and ds.attrs["stop_block"] == "cube"
        assert ds.attrs["stop_time"] == pytest.approx(t_off, abs=1e-9) and t_off < 0.5
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(_thrown(True), 6.0, record_interval=0.005, progress=False, stop="rest")
    assert ds.attrs["stop_reason"] == "rest" and ds.attrs["stop_time"] < 3.0
    assert ds.attrs["fell_off_blocks"] == "cube"
    v = ds.block_velocity.sel(block="resting").values[-1]
    assert np.linalg.norm(v) < REST_SPEED * math.sqrt(G * 0.2)
