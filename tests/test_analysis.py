"""Verification of the analysis functions (DESIGN §4; Galvez et al. 2022 §3.1, Eq. 6).

Closed forms: WME identities, Eq. 6 inverted on synthetic peaks, free-flight parabolas for
bouncing. Tolerances follow from the sampling (linear interpolation error h^2/8 max|f''|) or are
round-off (1e-12) where the computation is exact.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import xarray as xr

from rockdem.analysis import (
    apparent_restitution,
    bouncing,
    fallen_blocks,
    first_impact_time,
    half_cycle_peaks,
    lowest_point_height,
    max_rotation,
    overturned,
    prominent_peaks,
    residual_drift,
    rocking_lift,
    rocking_onset_time,
    summarize,
    summarize_result,
    wme,
)


def _decay(t: np.ndarray) -> np.ndarray:
    return np.exp(-t) * np.sin(4 * np.pi * t)


T = np.linspace(0.0, 3.0, 3001)
X = _decay(T)


def test_wme_identities() -> None:
    # WME = sum |x - y| |x| / sum x^2 (DESIGN §4): 0 for y = x, 1 for y = 0, 2 for y = -x,
    # |1 - c| for y = c x, invariant to a common scale; exact up to round-off.
    kw = dict(cut_at_rest=False)
    assert wme(T, X, T, X, **kw) == 0.0
    assert wme(T, X, T, 0 * X, **kw) == pytest.approx(1.0, rel=1e-12)
    assert wme(T, X, T, -X, **kw) == pytest.approx(2.0, rel=1e-12)
    assert wme(T, X, T, 0.7 * X, **kw) == pytest.approx(0.3, rel=1e-12)
    y = X + 0.1 * np.cos(3 * T)
    assert wme(T, 5 * X, T, 5 * y, **kw) == pytest.approx(wme(T, X, T, y, **kw), rel=1e-12)


def test_wme_is_not_symmetric() -> None:
    # Documented: wme(x, 2x) = 1 but wme(2x, x) = 0.5.
    assert wme(T, X, T, 2 * X, cut_at_rest=False) == pytest.approx(1.0, rel=1e-12)
    assert wme(T, 2 * X, T, X, cut_at_rest=False) == pytest.approx(0.5, rel=1e-12)


def test_wme_different_sampling() -> None:
    # The same function sampled at another step: the only error is the linear interpolation of the
    # simulation, |x - y| <= h^2/8 max|f''|, so WME <= h^2/8 max|f''| sum|x| / sum x^2.
    ts = np.linspace(0.0, 3.0, 4287)
    h = ts[1] - ts[0]  # 7.0e-4 s
    f2_max = (1 + 4 * np.pi) ** 2  # |f''| <= (1 + 4 pi)^2 for exp(-t) sin(4 pi t), t >= 0
    bound = h * h / 8 * f2_max * np.sum(np.abs(X)) / np.sum(X * X)
    val = wme(T, X, ts, _decay(ts), cut_at_rest=False)
    assert 0.0 < val <= bound


def test_wme_cut_at_end_of_reference_motion() -> None:
    # §3.1: the comparison stops when the reference is at rest (|x - x_end| below 1 % of its range,
    # here e^{-2t} < 0.01, t > 2.3 s); late motion of the simulation after 2.5 s does not count.
    x = np.exp(-2 * T) * np.sin(4 * np.pi * T)
    y = x + np.where(T > 2.5, 0.3 * np.sin(20 * T), 0.0)
    assert wme(T, x, T, y) == pytest.approx(0.0, abs=1e-15)
    assert wme(T, x, T, y, cut_at_rest=False) > 0.0


def test_wme_errors() -> None:
    with pytest.raises(ValueError, match="overlap"):
        wme(T, X, T + 10.0, X)
    with pytest.raises(ValueError, match="increasing"):
        wme(T[::-1], X, T, X)
    with pytest.raises(ValueError, match="covers"):  # a warning before 2026-11-29
        wme(T, X, T[:1000], X[:1000], cut_at_rest=False)
    with pytest.warns(UserWarning, match="covers"):
        wme(T, X, T[:1000], X[:1000], cut_at_rest=False, overlap_only=True)
    # a threshold that leaves the reference "at rest" from its start compared one sample: WME 0, a
    # perfect match of two different histories
    for tol in (np.nan, np.inf):
        with pytest.raises(ValueError, match="rest_tol must be a finite threshold"):
            wme(T, X, T, 0.5 * X, rest_tol=tol)
    with pytest.raises(ValueError, match="leaves nothing to compare"):
        wme(T, X, T, 0.5 * X, rest_tol=10.0 * float(np.abs(X).max()))


def test_apparent_restitution_inverts_eq_6() -> None:
    # Eq. 6 inverted: |theta_n| = eta (1 - sqrt(1 - e^(2n) (1 - (1 - theta0/eta)^2))) gives e_a = e
    # for every n (round-off).
    eta, th0, e = 0.2, 0.15, 0.93
    n = np.arange(1, 11)
    peaks = eta * (1 - np.sqrt(1 - e ** (2 * n) * (1 - (1 - th0 / eta) ** 2)))
    res = apparent_restitution(-peaks, th0, eta)  # sign ignored
    np.testing.assert_allclose(res.per_impact, e, rtol=1e-12)
    assert res.mean == pytest.approx(e, rel=1e-12)
    with pytest.raises(ValueError, match="theta0"):
        apparent_restitution(peaks, 0.25, eta)
    with pytest.raises(ValueError, match="eta"):
        apparent_restitution(peaks, 0.1, -1.0)


def test_half_cycle_peaks_two_sided_and_one_sided() -> None:
    # Peaks of |cos(2 pi t)| e^{-0.1 t}: two-sided (sign changes) and, with abs, one-sided
    # (touches of zero) give the same peaks; the release at t = 0 is the first peak. Interior peaks
    # lie where tan(2 pi t) = -0.1 / (2 pi): t = k/2 - atan(0.1 / (2 pi)) / (2 pi); parabolic
    # refinement on a 1e-4 s grid locates them to O(dt^2) ~ 1e-6 s.
    t = np.linspace(0.0, 3.0, 30001)
    x = np.exp(-0.1 * t) * np.cos(2 * np.pi * t)
    two = half_cycle_peaks(t, x)
    one = half_cycle_peaks(t, np.abs(x))
    assert len(two.value) == len(one.value) == 6  # t = 0, 0.5, ..., 2.5 (3.0 is unfinished)
    np.testing.assert_allclose(np.abs(two.value), one.value, rtol=1e-12)
    shift = math.atan(0.1 / (2 * np.pi)) / (2 * np.pi)
    np.testing.assert_allclose(two.time[1:], np.arange(1, 6) * 0.5 - shift, atol=1e-6)
    assert two.value[0] == 1.0 and two.value[1] < 0


@pytest.mark.parametrize("kind", ["noise", "walk", "plateaus", "rising", "rocking"])
def test_prominent_peaks_match_scipy_find_peaks(kind: str) -> None:
    # The NumPy peak finder against SciPy's on random signals, for prominence thresholds from
    # "every peak" to "only the largest": the same indices. Quantised signals have flat runs
    # (plateau peaks at their middle sample); a rising sawtooth makes every base reach the start.
    from scipy.signal import find_peaks

    rng = np.random.default_rng(["noise", "walk", "plateaus", "rising", "rocking"].index(kind))
    for n in (0, 1, 2, 3, 5, 50, 2001):
        for _ in range(5):
            if kind == "noise":
                x = rng.normal(size=n)
            elif kind == "walk":
                x = np.cumsum(rng.normal(size=n))
            elif kind == "plateaus":
                x = np.round(np.cumsum(rng.normal(size=n)) * 0.7)
            elif kind == "rising":
                x = np.arange(n) * 0.01 + rng.uniform(size=n)
            else:
                t = np.linspace(0.0, 10.0, n)
                x = np.abs(np.exp(-0.3 * t) * np.cos(7.0 * t + rng.uniform(0, 6)) + 1e-3 * rng.normal(size=n))
            span = float(np.ptp(x)) if n else 1.0
            for frac in (0.0, 1e-3, 0.02, 0.3, 0.9, 2.0):
                prom = max(frac * span, np.finfo(float).tiny)
                expected, _ = find_peaks(x, prominence=prom)
                np.testing.assert_array_equal(prominent_peaks(x, prom), expected)


def test_bouncing_free_flight_parabolas() -> None:
    # A point leaving the ground with speed v flies for 2v/g and rises v^2/(2g): magnitude v/4.
    # Sampling h = 1e-5 s: amplitude error <= g h^2 / 8 (negligible); the landing between two
    # samples is interpolated toward the clipped 0, so the duration is within one step h (plus
    # 2 tol / v from the threshold, negligible); the magnitude within h / duration (< 3e-4).
    g, h = 9.81, 1e-5
    t = np.arange(0.0, 1.0, h)
    z = np.zeros_like(t)
    for t0, v in ((0.1, 0.2), (0.5, 0.5)):
        tau = t - t0
        fly = (tau > 0) & (tau < 2 * v / g)
        z[fly] = v * tau[fly] - 0.5 * g * tau[fly] ** 2
    bo = bouncing(t, z + 0.4, tol=1e-9)
    assert len(bo.magnitude) == 2
    np.testing.assert_allclose(bo.duration, [2 * 0.2 / g, 2 * 0.5 / g], rtol=0, atol=h)
    np.testing.assert_allclose(bo.amplitude, [0.2**2 / (2 * g), 0.5**2 / (2 * g)], rtol=1e-6)
    np.testing.assert_allclose(bo.magnitude, [0.05, 0.125], rtol=3e-4)
    assert bo.max_magnitude == pytest.approx(0.125, rel=3e-4)


def test_rocking_lift_is_not_bouncing() -> None:
    # A centroid that only follows the rocking kinematics (no flight) has no airborne phase once the
    # rocking lift R [cos(eta - |theta|) - cos eta] is removed (exact kinematics, round-off).
    b, h = 0.2, 1.0
    t = np.linspace(0, 2, 2001)
    theta = 0.1 * np.sin(3 * t)
    zc = h / 2 + rocking_lift(theta, b, h)
    assert len(bouncing(t, zc, tol=1e-6).magnitude) >= 1  # naive: rocking looks like flight
    assert len(bouncing(t, zc, z_contact=h / 2 + rocking_lift(theta, b, h), tol=1e-9).magnitude) == 0


def test_scalar_measures() -> None:
    t = np.linspace(0, 1, 11)
    th = np.array([0, 0, 0.001, 0.05, 0.1, -0.2, 0.1, 0.03, 0.02, 0.02, 0.02])
    assert max_rotation(th) == 0.2
    assert residual_drift(t, th) == 0.02
    assert residual_drift(t, th, tail=0.25) == pytest.approx(0.02)
    assert rocking_onset_time(t, th, 0.01) == pytest.approx(0.3)
    assert rocking_onset_time(t, th, 1.0) is None
    assert not overturned(th, 0.15)
    assert overturned(np.append(th, 0.3), 0.15)


def _dataset(theta: np.ndarray, t: np.ndarray, eta: float | None) -> xr.Dataset:
    b, h, length = 0.2, 1.0, 1.0
    v = np.array([[sx * b / 2, sy * length / 2, sz * h / 2] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    n = len(t)
    pos = np.zeros((n, 2, 3))
    pos[:, 1, 2] = h / 2 + 0.3  # block 1 on a ground at z = 0.3
    quat = np.zeros((n, 2, 4))
    quat[..., 0] = 1.0
    ds = xr.Dataset(
        {
            "rocking_angle": (("time", "block"), np.column_stack((0 * theta, theta))),
            "block_position": (("time", "block", "xyz"), pos),
            "block_quaternion": (("time", "block", "quat"), quat),
            "block_free": ("block", np.array([False, True])),
            "vertex_local": (("vertex", "xyz"), np.vstack((v, v))),
            "block_vertex_start": ("block_p1", np.array([0, 8, 16])),
        },
        coords={"time": t},
    )
    if eta is not None:
        ds["block_eta"] = ("block", np.array([0.1, eta]))
    return ds


def test_summarize_result_on_a_dataset() -> None:
    t = np.linspace(0, 3, 3001)
    x = 0.1 * np.exp(-0.3 * t) * np.cos(2 * np.pi * t)
    ds = _dataset(x, t, eta=0.2)
    z = lowest_point_height(ds, 1)
    np.testing.assert_allclose(z, 0.3, atol=1e-15)  # identity rotation: centroid - h/2
    s = summarize_result(ds)
    assert s == summarize(t, x, eta=0.2, z=z)
    assert s["max_rotation_rad"] == pytest.approx(0.1)
    assert s["half_cycles"] == 6 and not s["overturned"] and s["bounces"] == 0
    assert 0 < s["e_a_mean"] < 1
    s2 = summarize_result(_dataset(x, t, eta=None))
    assert "e_a_mean" not in s2 and "overturned" not in s2
    # e_a (Eq. 6) is the decay of free rocking: not given for a run under a ground motion (the
    # El Centro example printed e_a = 1.05, first 1.49) or a pushover
    for forced in ({"earthquake_mode": "foundation"}, {"pushover_rate": 0.05}):
        s3 = summarize_result(ds.assign_attrs(forced))
        assert "e_a_mean" not in s3 and "e_a_first" not in s3 and s3["half_cycles"] == 6
    moving = ds.assign(ground_displacement=(("time", "xyz"), np.outer(t, [0.01, 0.0, 0.0])))
    assert "e_a_mean" not in summarize_result(moving)
    with pytest.raises(ValueError, match="rocking_angle"):
        summarize_result(ds.drop_vars("rocking_angle"))
    with pytest.raises(ValueError, match="out of range"):
        summarize_result(ds, block=5)


def test_bouncing_ignores_phases_that_graze_the_threshold() -> None:
    # An elastic rattle that lifts the lowest point 0.1 um above a 10 um threshold for a few
    # microseconds is not a flight. Measured from the ground, amplitude / duration would be 0.26 m/s
    # (duration 40 us from the interpolated crossings); above the threshold it is 2.5 mm/s, half the
    # sampled rise rate of the point, while a real 0.2 mm flight keeps amplitude / duration.
    t = np.array([0.0, 0.002, 0.004, 0.006])
    z = np.array([0.0, 1.01e-5, 0.0, 0.0])
    bo = bouncing(t, z, z_rest=0.0, tol=1e-5)
    assert len(bo.magnitude) == 1 and bo.max_magnitude < 0.003
    g, v = 9.81, 0.063  # apex v^2 / 2g = 0.2 mm, flight 2 v / g = 12.8 ms
    t = np.arange(0.0, 0.05, 1e-4)
    z = np.clip(v * (t - 0.01) - 0.5 * g * (t - 0.01) ** 2, 0.0, None) * (t > 0.01)
    bo = bouncing(t, z, z_rest=0.0, tol=1e-5)
    assert bo.max_magnitude == pytest.approx(v**2 / (2 * g) / (2 * v / g), rel=0.1)


def test_reduced_parapet_base_gives_one_eta_for_tilt_summary_and_plot():
    # A 0.3 x 1.8 m parapet with a 20 mm base reduction rocks on its 0.28 m base contact face:
    # eta = atan(0.14 / z_c) ~ 0.1543 rad, not atan(0.3 / 1.8) = 0.1651 rad of the full width.
    # The release (tilt), the result's block_eta, summarize_result and plot_restitution must all
    # use the same pivot (round-off: the tilt angle is 0.9 eta).
    from rockdem.case import parse_case
    from rockdem.plots import plot_restitution
    from rockdem.run_cli import run_case

    case = {
        "run": {"duration": 0.3, "record_interval": 0.01},
        "damping": {"beta": 0.0007},
        "specimen": {"type": "parapet", "thickness": 0.3, "height": 1.8, "length": 1.0, "base_reduction": 0.02,
                     "youngs_modulus": 1.8e9, "friction_angle_deg": 31.0, "cohesion": 0.0, "tension": 0.0},
        "loading": {"type": "free-rocking", "block": "parapet", "tilt_fraction": 0.9},
    }
    ds = run_case(parse_case(case), progress=False)
    eta = float(ds.attrs["tilt_angle_rad"]) / 0.9
    assert eta == pytest.approx(math.atan(0.14 / 0.9), rel=2e-3)  # centroid a little above H/2 (chamfers)
    b = int(np.flatnonzero(ds.block_free.values)[0])
    assert float(ds.block_eta.values[b]) == pytest.approx(eta, rel=1e-12)
    assert summarize_result(ds)["eta_rad"] == pytest.approx(eta, rel=1e-12)
    assert f"η = {eta:.4f} rad" in plot_restitution(ds).axes[0].get_title()


def test_a_block_falling_off_a_stack_is_counted_as_fallen():
    # A 0.2 m cube set with its centroid 0.04 m beyond the edge of the 0.3 m block under it tips
    # off and lands on the ground, 0.3 m lower; the block under it stays. fallen_blocks agrees with
    # the positions read directly, and the run summary counts it and says whose eta it gives.
    # A little SP damping brings it to rest where it lands, on the side face it tipped onto
    # (undamped, it bounced and rolled on: on 2026-11-28 a change of the contacts' energy
    # bookkeeping sent it rolling with 5 J at 2 s where it had come down on its base by 1.2 s).
    from rockdem.materials import JointMaterial
    from rockdem.model import Damping, ModelBuilder
    from rockdem.run_cli import summary_lines
    from rockdem.simulation import simulate

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=2e9, friction_angle=35.0)
    b.add_box(3.0, 3.0, 0.3, base_center=(0, 0, -0.3), driven=True, name="ground")
    b.add_box(0.3, 0.3, 0.3, density=2000.0, name="base")
    b.add_box(0.2, 0.2, 0.2, base_center=(0.19, 0.0, 0.3), density=2000.0, name="top")
    ds = simulate(b.finalize(damping=Damping(beta=2e-4)), 1.2, record_interval=0.01, progress=False)
    z = ds.block_position.values[:, :, 2]
    assert z[0, 2] - z[-1, 2] > 0.25 and abs(z[-1, 1] - z[0, 1]) < 1e-3  # read directly
    assert abs(abs(ds.rocking_angle.values[-1, 2]) - np.pi / 2) < 0.05  # on its side face
    assert float(ds.energy_kinetic.values[-1]) < 1e-6  # at rest
    assert fallen_blocks(ds).tolist() == [2]
    assert fallen_blocks(ds, frame=0).tolist() == []
    text = "\n".join(summary_lines(ds))
    assert re.search(r"fallen blocks +1 +of 2: .*\(top\)", text)
    assert re.search(r"analysed block +top +the largest rotation; its eta and overturning are its own", text)
    # On its side face, about its own base it is past its eta.
    assert re.search(r"blocks past their eta +1 +of 2: at the end, each about its own base \(top\)", text)


def test_no_half_cycles_are_counted_below_the_rocking_onset() -> None:
    # a block vibrating at 1e-4 of its eta (a joint's elastic ringing) never rocked: 0 half cycles,
    # though the history has 40 peaks (a wall under a record used to read 68)
    t = np.linspace(0.0, 2.0, 4001)
    eta = 0.1
    s = summarize(t, 1e-5 * np.sin(2 * np.pi * 10 * t), eta=eta)
    assert s["onset_time_s"] is None and s["half_cycles"] == 0
    s = summarize(t, 0.05 * np.sin(2 * np.pi * 1 * t), eta=eta)  # rocking at half its eta: counted
    assert s["onset_time_s"] < 0.01 and s["half_cycles"] == 4


def test_blocks_that_fell_off_the_supports_are_in_the_summary() -> None:
    from rockdem.materials import JointMaterial
    from rockdem.model import Damping, ModelBuilder
    from rockdem.run_cli import summary_lines
    from rockdem.simulation import simulate

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9, friction_angle=35)
    b.add_box(1, 1, 0.3, base_center=(0, 0, -0.3), driven=True, name="ground")
    b.add_box(0.2, 0.2, 0.2, base_center=(0.57, 0, 0), density=2000, name="overhanging")  # 3/4 over the edge
    b.add_box(0.2, 0.2, 0.2, base_center=(0.0, 0, 0), density=2000, name="resting")
    with pytest.warns(RuntimeWarning, match="fell off the edge"):
        ds = simulate(b.finalize(damping=Damping(beta=1e-4)), 1.0, progress=False)
    row = [line for line in summary_lines(ds) if "fell off the supports" in line]
    assert len(row) == 1 and re.search(r"fell off the supports\s+1\s+of 2: .*\(overhanging at 0\.\d+ s\)", row[0])


def test_a_block_toppled_onto_its_side_has_fallen() -> None:
    # 0.3 x 0.3 x 0.4 m released past its instability angle: it lands on its side, its centroid
    # at most (0.4 - 0.3) / 2 = 0.05 m lower than untilted, a third of the drop criterion (half its
    # 0.3 m): its tilt of 90 deg says it fell. The block beside it, standing, has not.
    from rockdem.materials import JointMaterial
    from rockdem.model import Damping, ModelBuilder
    from rockdem.simulation import simulate

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9, friction_angle=35)
    b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.3, 0.3, 0.4, base_center=(0, 0, 0), density=2000, name="toppled")
    b.add_box(0.3, 0.3, 0.4, base_center=(0, 1, 0), density=2000, name="standing")
    b.tilt("toppled", 1.1)  # 40.6 deg: past its eta = atan(0.3 / 0.4), not yet 45
    ds = simulate(b.finalize(damping=Damping(beta=2e-4)), 1.5, progress=False)
    z = ds.block_position.values[:, :, 2]
    assert z[0, 1] - z[-1, 1] < 0.5 * 0.3  # the drop alone would not say it
    assert list(ds.block_name.values[fallen_blocks(ds)]) == ["toppled"]
    assert fallen_blocks(ds, frame=0).size == 0


def test_a_tilted_squat_stack_back_upright_has_not_fallen() -> None:
    # Released tilted, its blocks start raised; back upright they are lower than at the first frame
    # by more than the drop criterion, but at their reference (untilted) height: not fallen.
    from rockdem.materials import JointMaterial
    from rockdem.model import Damping, ModelBuilder
    from rockdem.simulation import simulate
    from rockdem.specimens import stacked_blocks

    b = ModelBuilder()
    stacked_blocks(b, width=1.0, length=1.0, heights=[0.15, 0.15], material=JointMaterial(kn=1e9, friction_angle=35))
    b.tilt(["block1", "block2"], 0.9)
    ds = simulate(b.finalize(damping=Damping(beta=2e-3)), 1.5, progress=False)
    z = ds.block_position.values[:, :, 2]
    free = np.flatnonzero(ds.block_free.values)
    assert np.all(z[0, free] - z[-1, free] > 0.5 * 0.15)  # the old criterion's fall
    assert abs(float(ds.rocking_angle.values[-1, free[0]])) < 1e-3  # back upright
    assert fallen_blocks(ds).size == 0


def test_no_restitution_is_reported_without_rocking() -> None:
    t = np.linspace(0.0, 2.0, 4001)
    s = summarize(t, 1e-4 * np.exp(-t) * np.abs(np.cos(2 * np.pi * 2 * t)), eta=0.2)  # peaks below 1 % of eta
    assert s["onset_time_s"] is None and "e_a_mean" not in s and s["half_cycles"] == 0


def test_non_finite_or_empty_histories_are_refused_by_every_measure():
    """max_rotation, overturned and apparent_restitution refuse NaN (and overturned an empty
    history) as half_cycle_peaks, wme and bouncing do, instead of answering nan or False (before
    2026-11-29 a history ending in NaN read as not overturned)."""
    from rockdem.analysis import apparent_restitution, max_rotation, overturned

    th = np.append(np.sin(np.linspace(0.0, 3.0, 50)) * 0.1, np.nan)
    for call in (lambda: max_rotation(th), lambda: overturned(th, 0.2), lambda: overturned([], 0.2),
                 lambda: apparent_restitution([0.05, np.nan], 0.1, 0.2)):
        with pytest.raises(ValueError, match="finite|empty"):
            call()


def test_a_history_ending_at_eta_has_exceeded_it():
    # Overturned (it ends at eta, within rtol) and not "exceeded eta" was a contradiction.
    t = np.linspace(0.0, 1.0, 101)
    eta = 0.2
    s = summarize(t, eta * t, eta=eta)
    assert s["overturned"] and s["exceeded_eta"]


@pytest.mark.parametrize("one_sided", [False, True])
@pytest.mark.parametrize("dt", [0.001, 0.0037])
def test_first_impact_of_two_and_one_sided_rocking_is_housners_quarter_period(one_sided, dt):
    """A block released at 0.6 eta hits at Housner's quarter period, rocking about both edges
    (a zero crossing) or one-sided against a return wall (it comes back to zero and rebounds without
    crossing: None before 2026-11-29), whatever the sampling."""
    from rockdem.analysis import first_impact_time
    from rockdem.housner import HousnerBlock, quarter_period, rock

    block = HousnerBlock(0.25, 1.2)
    r = rock(block, theta0=0.6 * block.eta, duration=2.0, e=0.8, one_sided=one_sided)
    t = np.arange(0.0, 2.0, dt)
    th = np.interp(t, r.time, r.rotation)
    assert first_impact_time(t, th) == pytest.approx(quarter_period(block, 0.6 * block.eta), abs=0.1 * dt)


def test_wme_of_a_simulation_that_does_not_cover_the_reference_is_refused():
    """A history cut short is not a match: its WME over what it has was 0 (a warning only, which a
    calibration silences) before 2026-11-29; now refused unless asked for over the overlap."""
    t = np.linspace(0.0, 4.0, 401)
    x = np.exp(-0.3 * t) * np.sin(2 * np.pi * t)
    with pytest.raises(ValueError, match="covers .* only"):
        wme(t, x, t[:200], x[:200], cut_at_rest=False)
    with pytest.warns(UserWarning, match="outside it are ignored"):
        assert wme(t, x, t[:200], x[:200], cut_at_rest=False, overlap_only=True) == 0.0


@pytest.mark.parametrize("call, message", [
    (lambda t, th: apparent_restitution(half_cycle_peaks(t, th), 0.05, 0.1), r"value\[1:\], not the HalfCyclePeaks"),
    (lambda t, th: apparent_restitution(np.full((2, 2), 0.01), 0.05, 0.1), "1-D array"),
    (lambda t, th: residual_drift(t, th, tail=np.nan), "tail"),
    (lambda t, th: half_cycle_peaks(t, th, min_prominence=-1.0), "min_prominence"),
    (lambda t, th: half_cycle_peaks(t, th, min_prominence=np.nan), "min_prominence"),
    (lambda t, th: bouncing(t, th, tol=np.nan), "tol"),
    (lambda t, th: bouncing(t, th, z_rest=np.nan), "z_rest"),
    (lambda t, th: first_impact_time(t, th, threshold=-1.0), "threshold"),
    (lambda t, th: rocking_lift(0.1, -1.0, 1.0), "b"),
    (lambda t, th: summarize(t, th, eta=-1.0), "eta"),
])
def test_analysis_parameters_that_would_give_a_silent_answer_are_refused(call, message):
    """Each of these returned None, NaN, no peaks, no phases or a negative lift without a word."""
    t = np.linspace(0.0, 1.0, 101)
    with pytest.raises(ValueError, match=message):
        call(t, 0.05 * np.cos(10.0 * t))
