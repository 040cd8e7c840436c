"""Earthquake loading (foundation vs inertial frame), pushover (paper §3.3, Fig. 9A), examples.

Verification by frame invariance (the same relative motion in the absolute and the relative frame)
and by statics of a block on an elastic Winkler base of discrete springs (sub-contacts).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from rockdem.case import CaseTemplate, load_case, parse_case
from rockdem.kernels.rotation import quats_to_matrices
from rockdem.loading import _velocity_table, apply_earthquake, capacity_curve, earthquake_record, load_carried, pushover, resolve_record, rigid_rod_load_factor
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.records import read_record
from rockdem.run_cli import run_case, summary_lines
from rockdem.simulation import simulate

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
B, H, L, RHO, E = 0.2, 2.0, 1.0, 1800.0, 1.8e9  # the §3.3 block


def _block_builder(b: float, h: float, length: float, *, points: int, kn: float, ground: str | bool) -> ModelBuilder:
    bld = ModelBuilder(points=(points, 2))
    bld.default_material = JointMaterial(kn=kn, friction_angle=80.0)  # no sliding (paper: mu > 5)
    s = 2.0 * max(b, h, length)
    bld.add_box(s, s, 0.25 * s, base_center=(0, 0, -0.25 * s), driven=ground, name="foundation", points=(2, 2))
    bld.add_box(b, length, h, density=RHO, name="block")
    return bld


def test_velocity_table_is_exact_for_piecewise_linear_acceleration():
    # v(t) = integral of the linearly interpolated a(t): exact quadratic within each interval.
    t = np.array([0.0, 0.1, 0.2])
    acc = np.array([[0.0, 0, 0], [2.0, 0, 0], [2.0, 0, 0]])
    vel = np.array([[0.0, 0, 0], [0.1, 0, 0], [0.3, 0, 0]])  # trapezoid
    tt, vv = _velocity_table(t, acc, vel, 4)
    expect = np.where(tt <= 0.1, 10.0 * tt**2, 0.1 + 2.0 * (tt - 0.1))  # a = 20 t, then 2
    assert np.allclose(vv[:, 0], expect, atol=1e-14)
    assert vv[0, 0] == 0.0  # starts from rest


def test_earthquake_tables_are_bounded_before_they_are_built():
    """A tail or substep count whose input table would take gigabytes is refused, naming the field,
    before any memory is taken (a 2000 s tail on a 0.0024 s record built a 13.6 million row table,
    1.1 GB; 1e5 s exhausted the machine's memory)."""
    gm = read_record(resolve_record("RSN6_IMPVALL.I_I-ELC180.AT2"))  # dt 0.01 s
    bld = _block_builder(0.2, 1.0, 0.5, points=2, kn=1e9, ground="ground")
    with pytest.raises(ValueError, match="input table would have .* the tail of 20000 s included, 16 substeps each.*shorten the tail"):
        apply_earthquake(bld, gm, tail=2e4)
    for substeps in (0, 2000, 2.5, math.nan, "16", True):
        with pytest.raises(ValueError, match="substeps must be an integer from 1 to 1024"):
            apply_earthquake(bld, gm, substeps=substeps)
    with pytest.raises(ValueError, match="earthquake tail must be >= 0 s"):
        apply_earthquake(bld, gm, tail=math.inf)
    info = apply_earthquake(bld, gm, tail=5.0)  # an ordinary tail: zeros at the record's dt
    assert info.time[-1] == pytest.approx(gm.duration + 5.0) and np.all(info.acceleration[-500:] == 0.0)


def test_foundation_and_inertial_modes_give_the_same_rocking():
    # Frame invariance: contact forces and SP dashpots see only relative motion, so a block on a
    # rigid foundation moved by v_g(t) rocks like a block on a fixed one under -m a_g(t).
    # alpha = 0: absolute MP damping would act on v_rel + v_g in one frame and v_rel in the other.
    # beta = 2 / omega_e (DeJong, paper §2.2) damps the impacts. Discretisation differences: the
    # driven velocity is interpolated linearly between sub-samples of the exact quadratic
    # (O(1/substeps^2): measured 1.6 % of the elastic response with 1 sub-sample, 0.1 % with 4),
    # taken at mid-step while the body force is taken at the step start, and contact detection runs
    # at other times (the foundation's own motion triggers it). Rocking impacts amplify such
    # differences chaotically (a 1 % change of beta changes the 3 s history by up to 10 %), so the
    # histories are compared point by point over the strong pulse (first 2 s, measured <= 0.1 % of
    # the peak; tolerance 1 %) and by their peak over the whole 3 s (measured 0.003 %; 1 %).
    b, h, length = 0.2, 1.0, 0.5
    gm = read_record(resolve_record("RSN6_IMPVALL.I_I-ELC180.AT2"))  # El Centro 1940, PGA 0.28 g
    beta = 2.0 / math.sqrt(E * b / (RHO * h * h))  # omega_e = sqrt(E B^2 / (m_b H)), paper Eq. 3
    theta = {}
    for mode in ("foundation", "inertial"):
        bld = _block_builder(b, h, length, points=2, kn=E / h, ground="ground")
        info = apply_earthquake(bld, gm, mode=mode, window=(1.0, 4.0))  # holds the 2.18 s peak
        assert np.all(info.velocity[0] == 0.0)
        ds = simulate(bld.finalize(damping=Damping(beta=beta)), 3.0, record_interval=0.005)
        theta[mode] = ds.rocking_angle.values[:, 1]
    peak = np.max(np.abs(theta["inertial"]))
    assert peak > 0.05 * math.atan(b / h)  # it really rocked (elastic tilt is ~1e-4 rad)
    pulse = slice(0, 401)  # t <= 2.0 s of the window (record 1..3 s), rocking from ~1.2 s
    assert np.max(np.abs(theta["foundation"][pulse] - theta["inertial"][pulse])) < 0.01 * peak
    assert np.max(np.abs(theta["foundation"])) == pytest.approx(peak, rel=0.01)


def _pushover(points: int, kn: float, max_load_factor: float, rate: float = 0.02):
    bld = _block_builder(B, H, L, points=points, kn=kn, ground=True)
    ds = pushover(bld, rate=rate, max_load_factor=max_load_factor, monitors={"top": ("block", (B / 2, 0.0, H))},
                  record_interval=0.002)
    lam, u = capacity_curve(ds, "top")
    return ds, lam, u


def _onset(ds, lam) -> float:
    """Load factor at which the first base sub-contact opens (frame 0 precedes detection)."""
    act = ds.contacts_active.values
    full = act[1:].max()
    k = 1 + int(np.flatnonzero(act[1:] < full)[0])
    return float(lam[k])


def test_rocking_onset_at_load_factor_b_over_h():
    # Rigid block under a uniform lateral acceleration lambda g: overturning moment lambda W H/2
    # equals the restoring W B/2 at lambda = B/H. With 2 points across (corner sub-contacts) the
    # heel springs unload exactly then; stiff contacts (kn = 10 E/H) make the P-Delta of the elastic
    # tilt negligible (theta_u H/B ~ 4e-4). Ramp 0.02/s (~100 elastic periods per 0.1 of lambda)
    # with local damping 0.8 keeps the lag small. Record resolution 4e-5 in lambda. Tolerance 2 %.
    ds, lam, u = _pushover(2, 10 * E / H, 1.2 * B / H)
    assert _onset(ds, lam) == pytest.approx(B / H, rel=0.02)
    lr, _ = capacity_curve(ds, "top", source="reaction")
    assert lr.max() == pytest.approx(B / H, rel=0.03)  # the measured base shear tops out there too


def _base_moments(points: int) -> tuple[float, float]:
    """S = sum A x^2 [m^4] and A [m^2] of the block's base sub-contacts, x from the base centre."""
    bld = _block_builder(B, H, L, points=points, kn=E / H, ground=True)
    m = bld.finalize()
    a = m.arrays
    r = quats_to_matrices(m.quaternion0[1])
    for f in range(a.block_face_start[1], a.block_face_start[2]):
        if (r @ a.face_normal[f])[2] < -0.99:
            s, e = a.face_point_start[f], a.face_point_start[f + 1]
            x = m.world_points(1, a.point_local[s:e])[:, 0]
            area = a.point_area[s:e]
            return float((area * x**2).sum()), float(area.sum())
    raise AssertionError("no base face")


def test_pushover_curve_with_more_points_is_softer():
    # Paper §3.3 / Fig. 9A: fewer integration points "showed higher resistance to initiate rotation,
    # closer to the ideal rigid block". In rockdem the points span the face *including its edges*
    # (trapezoidal rule), so the toe point is always on the edge and the ultimate rigid capacity B/H
    # is the same for any count; what changes is the elastic base before full uplift:
    #  - rotational stiffness of the Winkler base k_theta = kn sum(A x^2): the corner points of the
    #    2-point base give L B^3/4, 10 points ~L B^3/12 (exact sums from the model), so the elastic
    #    top displacement at the same lambda is larger by the ratio S2/S10 = 2.93 (within 10 %:
    #    shear compliance and the quasi-static lag, both ~1 %);
    #  - the heel opens when the resultant leaves the kern, at lambda = (2/H) S/(A x_max):
    #    0.34 B/H for 10 points, B/H for 2 points (within 10 %: the heel unloads gradually);
    #  - so the 10-point curve departs early and is far softer near B/H (E = 1800 MPa, kn = E/H).
    s2, a2 = _base_moments(2)
    s10, a10 = _base_moments(10)
    ds2, lam2, u2 = _pushover(2, E / H, 0.95 * B / H)
    ds10, lam10, u10 = _pushover(10, E / H, 0.95 * B / H)
    at = lambda lam_, u_, x: float(np.interp(x * B / H, lam_, u_))  # noqa: E731  (frames ~ steps)
    assert at(lam10, u10, 0.25) / at(lam2, u2, 0.25) == pytest.approx(s2 / s10, rel=0.10)
    assert _onset(ds10, lam10) == pytest.approx(2.0 * s10 / (a10 * B / 2) / H, rel=0.10)
    assert int(ds2.contacts_active.values[-1]) == int(ds2.contacts_active.values[1:].max())  # 2 points: no uplift
    assert at(lam10, u10, 0.9) > 5.0 * at(lam2, u2, 0.9)
    # the 2-point curve stays on its elastic line u = lambda (W H/2) / (kn S2) * H up to 0.9 B/H
    w = RHO * B * H * L * 9.81
    assert at(lam2, u2, 0.9) == pytest.approx(0.9 * B / H * w * H / 2 / (E / H * s2) * H, rel=0.05)


FREE_BLOCKS = {"block": 1}
EXAMPLE_FILES = sorted(EXAMPLES.glob("*.toml"))


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=[p.stem for p in EXAMPLE_FILES])
def test_examples_parse_and_run(path, tmp_path, monkeypatch):
    # every example, from an unrelated working folder and without ROCKDEM_DATA (records are shipped)
    monkeypatch.delenv("ROCKDEM_DATA", raising=False)
    monkeypatch.chdir(tmp_path)
    case = parse_case(load_case(path))
    ds = run_case(case, duration=0.05, progress=False)
    assert ds.sizes["time"] >= 2
    assert np.all(np.isfinite(ds.block_position.values))
    assert np.all(np.isfinite(ds.monitor_displacement.values))
    assert int(ds.block_free.values.sum()) >= 1
    kind = case.data["specimen"]["type"]
    if kind in FREE_BLOCKS:  # one block on the foundation (and a pushing rod)
        assert int(ds.block_free.values.sum()) == FREE_BLOCKS[kind]


def test_examples_exist():
    assert len(EXAMPLE_FILES) >= 27


def _rod_pushover_case(b: float, h: float, rod_height: float, displacement: float, duration: float = 10.0) -> dict:
    return {
        "run": {"duration": duration, "record_interval": 0.02},
        "damping": {"local": 0.8},
        "specimen": {"type": "block", "width": b, "height": h, "length": 0.8, "kn": 2 * E / h, "friction_angle_deg": 80.0},
        "loading": {"type": "pushover", "mode": "displacement", "displacement": displacement, "velocity": displacement / (duration - 1.0), "rod_height": rod_height},
    }


def test_displacement_controlled_pushover_follows_the_rigid_softening_branch():
    # A rod pushes a 0.3 x 1.2 m block (not the paper's) at 0.9 m height, below the top and not at
    # the centre of mass; displacement control follows the capacity curve past its peak, down to
    # the rigid-block curve lambda(theta) of moment balance. Contacts 2 E / H, 2 points, local
    # damping 0.8, a 20 s push. Tolerance 2 % of the peak B / (2 z_rod) over 0.15 eta .. 0.9 eta;
    # the peak itself within 3 % (the stiff elastic phase is loaded in ~0.5 s and lags a little).
    b, h, z = 0.3, 1.2, 0.9
    eta = math.atan(b / h)
    theta_end = 0.95 * eta
    disp = z * math.sin(theta_end) + b * (1 - math.cos(theta_end))  # rod travel to reach theta_end
    ds = run_case(parse_case(_rod_pushover_case(b, h, z, disp, duration=20.0)), progress=False)
    lam, u = capacity_curve(ds)
    theta = ds.rocking_angle.values[:, 1]
    expected = rigid_rod_load_factor(b, h, z, theta)
    sel = (theta > 0.15 * eta) & (theta < 0.9 * eta)
    assert sel.sum() > 50
    assert np.max(np.abs(lam[sel] - expected[sel])) < 0.02 * b / (2 * z)
    assert lam.max() == pytest.approx(b / (2 * z), rel=0.03)  # rigid capacity for a rod at z
    # the rod's force is the base's reaction: per-driven-block reactions add up
    assert np.allclose(ds.driven_reaction.values.sum(axis=1), ds.base_reaction.values, atol=1e-6 * lam.max() * 1e4)
    assert ds.attrs["pushover_rod"] == "rod_pushover" and "rod" in list(ds.monitor.values)


def test_loading_context_reaches_the_result():
    # TOML runs keep what the loading applied: the pushover ramp (so capacity_curve uses it) and
    # the earthquake's record, mode and PGA, with the input acceleration as a variable.
    ds = run_case(parse_case(load_case(EXAMPLES / "pushover_0.2x2.0_points2.toml")), duration=0.2, progress=False)
    assert ds.attrs["pushover_rate"] == 0.02 and ds.attrs["loading"] == "pushover"
    lam, _ = capacity_curve(ds)
    assert np.allclose(lam, 0.02 * ds.time.values)
    data = load_case(EXAMPLES / "elcentro_block_foundation.toml")
    case = parse_case(data)
    with pytest.warns(UserWarning, match=r"ends at 0.5 s .*before the record's peak ground acceleration \(at 2.1"):
        ds = run_case(case, duration=0.5, progress=False)  # El Centro's PGA at 2.14 s (a run cut there felt nothing of it)
    assert ds.attrs["earthquake_mode"] == "foundation"
    assert ds.attrs["earthquake_pga_time_s"] == pytest.approx(ds.attrs.get("earthquake_delay_s", 0.0) + 2.14, abs=0.05)
    gm = read_record(resolve_record(data["loading"]["record"]))
    scale = data["loading"].get("scale", 1.0)
    t = ds.time.values
    ag = ds.ground_acceleration.values[:, 0]
    assert np.allclose(ag[t < gm.time[-1]], scale * np.interp(t, gm.time, gm.acceleration)[t < gm.time[-1]], atol=0.02 * gm.pga)


def test_a_block_riding_on_a_moving_foundation_is_not_lost():
    """The model's extent moves with the driven blocks: a block carried 4.75 m by its foundation
    (ramped to 1 m/s in 0.5 s, then steady: 0.2 g, below the friction and rocking thresholds of the
    squat block) rides along, where it used to be reported to have left the extent (fixed at 3 m)."""
    from rockdem.model import Motion

    bld = ModelBuilder()
    bld.default_material = JointMaterial.from_modulus(1e9, 0.25, friction_angle=35)
    bld.add_box(2.0, 2.0, 0.5, base_center=(0.0, 0.0, -0.5), driven="ground", group="ground", name="ground")
    bld.add_box(0.5, 0.5, 0.25, base_center=(0.0, 0.0, 0.0), density=2000, name="block")
    bld.set_ground_motion(Motion(time=[0.0, 0.5, 10.0], velocity=[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))
    ds = simulate(bld.finalize(damping=Damping()), 5.0, record_interval=0.05, progress=False)
    assert not ds.attrs.get("diverged"), ds.attrs.get("diverged_message")
    x = ds.block_position.values[:, :, 0]
    assert x[-1, 0] == pytest.approx(4.75, abs=1e-3)  # the foundation moved past the extent of the start
    np.testing.assert_allclose(x[:, 1], x[:, 0], atol=1e-3)  # the block moved with it
    np.testing.assert_allclose(ds.block_position.values[:, 1, 2], 0.125, atol=1e-4)


def test_an_earthquake_delayed_past_the_run_is_refused():
    # A delay at or past the run's end would leave the record unapplied: refused, naming both keys;
    # a delay inside the run starts the record then (its samples shifted by the delay), the
    # ground still before it.
    data = load_case(EXAMPLES / "elcentro_block_foundation.toml")
    data["run"]["duration"] = 0.3
    data["loading"]["delay"] = 0.3
    with pytest.raises(ValueError, match=r"delay = 0.3 s is not before the run's end \(0.3 s, \[run\] duration or --duration\)"):
        run_case(parse_case(data), progress=False)
    with pytest.raises(ValueError, match=r"delay = 0.3 s is not before the run's end \(0.25 s"):
        run_case(parse_case(data), duration=0.25, progress=False)
    data["run"]["duration"] = 0.2  # lengthened by the override: accepted
    assert run_case(parse_case(data), duration=0.32, progress=False).ground_acceleration.values[-1, 0] != 0.0
    data["run"]["duration"] = 0.3
    data["loading"]["delay"] = 0.2
    ds = run_case(parse_case(data), progress=False)
    t, ag = ds.time.values, ds.ground_acceleration.values[:, 0]
    gm = earthquake_record(data["loading"])
    late = t >= 0.2
    np.testing.assert_allclose(ag[late], np.interp(t[late] - 0.2, gm.time, gm.acceleration), rtol=1e-9, atol=1e-12)
    assert np.all(ag[t < 0.2 - 1e-5] == 0.0)
    assert np.max(np.abs(ds.ground_displacement.values[t < 0.2])) < 1e-9
    assert np.max(np.abs(ds.ground_displacement.values[-1])) > 1e-5


@pytest.mark.parametrize("max_load_factor, rate, duration", [(0.08, 0.1, 1.5), (0.12, 0.1, 1.5), (0.05, 1.0, 0.25), (0.2, 0.1, 4.0)])
def test_a_load_past_the_capacity_is_not_read_as_carried(max_load_factor, rate, duration):
    # A 0.2 x 2 m block (rigid capacity B/H = 0.1) under a ramp to max_load_factor, then held.
    # Below the capacity at 0.1/s the base reaction carries the load (within 5 %). Above it the
    # block accelerates (0.12) or overturns and lies on its side, where the reaction again equals
    # the load (0.2): the capacity was exceeded, not before the ramp reached B/H (1.0 s). A ramp
    # of 1/s to 0.05 leaves the reaction behind only while it rises: not quasi-static, but carried.
    data = load_case(EXAMPLES / "pushover_0.2x2.0_points2.toml")
    data["loading"].update(max_load_factor=max_load_factor, rate=rate)
    data["run"].update(duration=duration, record_interval=0.01)
    ds = run_case(parse_case(data), progress=False)
    carried = load_carried(ds)
    lines = "\n".join(summary_lines(ds))
    assert carried.applied == max_load_factor and carried.peak_time <= duration
    if max_load_factor < 0.1:
        assert carried.exceeded is None and "EXCEEDED" not in lines
        assert carried.carried == pytest.approx(max_load_factor, rel=0.1)
    if max_load_factor == 0.08:
        assert carried.lag is None and "QUASI" not in lines
        assert carried.carried == pytest.approx(0.08, rel=0.01)
    elif max_load_factor == 0.05:
        assert carried.too_fast is not None and carried.too_fast < 0.05  # while the ramp rises (0 .. 0.05 s)
        assert f"NOT QUASI-STATIC from t = {carried.too_fast:.4g} s" in lines
    else:
        assert 1.0 <= carried.exceeded < 1.5 and carried.too_fast is None
        assert carried.carried < 0.95 * max_load_factor
        assert max_load_factor == 0.2 or carried.peak < max_load_factor  # (0.2: impacts of the fall)
        assert f"LOAD EXCEEDED THE CAPACITY from t = {carried.exceeded:.4g} s" in lines
    assert load_carried(run_case(parse_case(_rod_pushover_case(0.2, 2.0, 1.0, 0.01, duration=2.0)), duration=0.2, progress=False)) is None


@pytest.mark.parametrize("loading", [
    {"type": "pushover", "max_load_factor": 0.1},
    {"type": "earthquake", "record": "elcentro-rsn6", "window": [0.0, 1.0]},
])
def test_a_load_along_y_rocks_the_block_about_x(loading):
    # A 0.2 (x) x 1.0 (y) x 2.0 m block loaded along y rocks about x over its 1.0 m side: the
    # result's rocking angle, eta and overturning are about that axis (they were about y, the
    # x-direction's, whatever the load's direction). The axis is up x d: positive along the load.
    data = load_case(EXAMPLES / "pushover_0.2x2.0_points2.toml")
    data["loading"] = {**loading, "direction": [0.0, 1.0, 0.0]}
    case = parse_case(data)
    assert tuple(case.model.rocking_axis) == (-1.0, 0.0, 0.0)
    ds = run_case(case, duration=0.02, progress=False)
    assert ds.attrs["rocking_axis"] == [-1.0, 0.0, 0.0]
    assert float(ds.block_eta.values[1]) == pytest.approx(math.atan(1.0 / 2.0), rel=1e-9)
    data["loading"]["direction"] = [1.0, 0.0, 0.0]
    assert tuple(parse_case(data).model.rocking_axis) == (0.0, 1.0, 0.0)  # as before for x
    if loading["type"] == "earthquake":  # a study's template swaps the direction with the record
        template = CaseTemplate(data)
        derived = template.derive({**data, "loading": {**data["loading"], "direction": [0.0, -1.0, 0.0]}})
        assert tuple(derived.model.rocking_axis) == (1.0, 0.0, 0.0)


@pytest.mark.parametrize("direction", [(0.0, 1.0, 0.0), (-1.0, 0.0, 0.0)])
def test_pushover_measures_rocking_about_up_cross_the_load(direction):
    """pushover() along d measures the rocking about up x d, positive along the load, with the
    slenderness about that axis, as a case file's pushover does (before 2026-11-29 the Python
    function measured it about y whatever d: a block toppled along +y read 4e-6 rad, eta 0.785)."""
    import warnings

    from rockdem.loading import pushover

    d = np.asarray(direction)
    b = ModelBuilder(points=(3, 2))
    b.default_material = JointMaterial.from_modulus(1.8e9, 1.0, friction_angle=80)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven="ground", group="foundation", name="foundation")
    thin = 0.25
    size = (1.0, thin) if d[1] else (thin, 1.0)  # thin along the load
    b.add_box(size[0], size[1], 1.0, density=2000, name="block")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = pushover(b, rate=0.1, max_load_factor=1.1 * thin, direction=direction, duration=4.0)
    np.testing.assert_allclose(ds.attrs["rocking_axis"], np.cross((0.0, 0.0, 1.0), d), atol=1e-12)
    assert float(ds.block_eta.sel(block="block")) == pytest.approx(np.arctan(thin / 1.0), rel=1e-9)
    assert float(ds.rocking_angle.sel(block="block")[-1]) > 0.05  # overloaded: rocking (toppling) along d, positive


def test_pushover_arguments_are_checked_and_numpy_numbers_accepted():
    """A rate given as a string is refused naming it (a TypeError before), a NumPy displacement is
    taken (it was refused as not positive), a load-controlled pushover without gravity is refused
    (its load factor is a fraction of the weight: it silently used 9.81 m/s^2)."""
    from rockdem.loading import apply_pushover, apply_rod_pushover

    with pytest.raises(ValueError, match=r"pushover rate \[1/s\] must be a finite number"):
        apply_pushover(_block_builder(0.2, 1.0, 0.5, points=2, kn=1e9, ground=True), rate="0.1", max_load_factor=0.3)
    rod = apply_rod_pushover(_block_builder(0.2, 1.0, 0.5, points=2, kn=1e9, ground=True), displacement=np.float32(0.1),
                             velocity=np.float64(0.01))
    assert rod.displacement == pytest.approx(0.1)
    b = ModelBuilder(gravity=(0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="no gravity"):
        apply_pushover(b, rate=0.1, max_load_factor=0.3)


def test_a_record_ending_at_rest_is_applied_as_it_is():
    """A one-sine pulse (0.3 g, Tp = 0.5 s) followed by 3.5 s of zeros ends at rest: the default
    baseline correction used to fit a line to its velocity bump and add 0.0039 g throughout, so the
    applied PGA was 0.3039 g and the ground's final displacement 0.39 m instead of the pulse's
    A Tp^2 / (2 pi) = 0.117 m. Such a record is now applied as it is; a record with an offset is
    still corrected (brought to rest at its end)."""
    from rockdem.loading import prepare_record
    from rockdem.records import STANDARD_GRAVITY, GroundMotion

    dt, tp, amp = 0.005, 0.5, 0.3 * STANDARD_GRAVITY
    t = np.arange(0.0, 4.0 + dt / 2, dt)
    acc = np.where(t <= tp, amp * np.sin(2 * np.pi * t / tp), 0.0)
    gm = prepare_record(GroundMotion.from_samples(acc, dt=dt, units="m/s2", name="pulse"))
    np.testing.assert_array_equal(gm.acceleration[: acc.size], acc)
    assert gm.displacement()[-1] == pytest.approx(amp * tp**2 / (2 * np.pi), rel=1e-3)
    offset = prepare_record(GroundMotion.from_samples(acc + 0.01, dt=dt, units="m/s2", name="offset"))
    assert abs(offset.velocity()[-1]) < 1e-9 and not np.allclose(offset.acceleration[: t.size], acc + 0.01)


def test_a_pushover_cut_short_by_its_duration_is_warned_about():
    """A pushover whose run ends before its load reaches max_load_factor (load control), or before
    the rod's push ends (displacement control), says so, as an earthquake run ended before the
    record's peak does (before 2026-12-01 only the summary's applied factor showed it)."""
    for name, end in (("pushover_0.2x2.0_points2", "its max_load_factor (at 4.75 s)"),
                      ("pushover_rod_0.2x2.0_points10", "its full displacement (at 12 s)")):
        case = parse_case(load_case(EXAMPLES / f"{name}.toml"))
        with pytest.warns(UserWarning, match=re.escape(f"the run ends at 0.02 s ([run] duration or --duration), before the "
                                                       f"pushover reaches {end}")):
            run_case(case, duration=0.02, progress=False)
