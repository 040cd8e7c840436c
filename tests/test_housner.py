"""Verification of the Housner reference models (DESIGN §4; Galvez et al. 2022 Eq. 6, §3.2.1).

Closed forms: energy loss e^2 per impact (Eq. 6 and its exact-energy form), the quadrature of the
energy integral, the linearised quarter period (1/p) arccosh(1/(1 - theta0/eta)), the rocking
onset |a_g| > g tan(eta). The integrator runs at rtol 1e-10, so identities of the model are
checked at 1e-7 relative (three orders of margin for event location and accumulation).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockdem.analysis import apparent_restitution, half_cycle_peaks, overturned, summarize_result
from rockdem.housner import HousnerBlock, quarter_period, quarter_period_linear, rock

SLENDER = HousnerBlock(0.19, 2.0)  # eta = 5.4 deg (Table 1)
SQUAT = HousnerBlock(0.19, 0.5)  # eta = 20.8 deg (Table 1)


@pytest.mark.parametrize("block", [SLENDER, SQUAT])
@pytest.mark.parametrize("one_sided", [False, True])
def test_apparent_restitution_of_housner_output_equals_input_e(block: HousnerBlock, one_sided: bool) -> None:
    # Each impact multiplies the energy by e^2; the peak after n impacts satisfies
    # cos(eta - th_n) - cos eta = e^(2n) (cos(eta - th0) - cos eta), so the exact-energy form of
    # Eq. 6 returns e to integration accuracy (1e-7). Eq. 6 linearises the potential energy
    # (relative error O(eta^2)), so it returns e within eta^2.
    e = 0.85
    r = rock(block, theta0=0.8 * block.eta, duration=3.0, e=e, one_sided=one_sided, dt_out=1e-3)
    assert len(r.impacts) >= 3
    th0, peaks = r.peak_rotation[0], r.peak_rotation[1:]
    exact = apparent_restitution(peaks, th0, block.eta, exact=True)
    np.testing.assert_allclose(exact.per_impact, e, rtol=1e-7)
    eq6 = apparent_restitution(peaks, th0, block.eta)
    np.testing.assert_allclose(eq6.per_impact, e, atol=block.eta**2)
    if one_sided:
        assert np.all(r.rotation >= -1e-9)


def test_sampled_peaks_give_the_same_restitution() -> None:
    # half_cycle_peaks on the sampled output (dt_out = 1 ms, parabolic refinement, error O(dt^3)
    # relative to the peak) recovers the exact-event peaks to 1e-6 rad.
    b = SLENDER
    r = rock(b, theta0=0.9 * b.eta, duration=6.0, dt_out=1e-3)
    pk = half_cycle_peaks(r.time, r.rotation)
    n = min(len(pk.value), len(r.peak_rotation))
    assert n >= 4
    np.testing.assert_allclose(pk.value[:n], r.peak_rotation[:n], atol=1e-6)
    s = summarize_result(r.to_dataset())
    assert s["e_a_mean"] == pytest.approx(b.e_eta, abs=b.eta**2)


@pytest.mark.parametrize("frac", [0.3, 0.9])
def test_quarter_period_matches_quadrature(frac: float) -> None:
    # The first impact of a release from rest happens after the quarter period of the exact
    # equation (energy integral by quadrature); the next half cycle lasts 2 T/4(theta_1).
    b = SQUAT
    th0 = frac * b.eta
    r = rock(b, theta0=th0, duration=2.0, dt_out=1e-3)
    assert r.impacts[0] == pytest.approx(quarter_period(b, th0), rel=1e-7)
    th1 = abs(r.peak_rotation[1])
    assert r.impacts[1] - r.impacts[0] == pytest.approx(2 * quarter_period(b, th1), rel=1e-7)


@pytest.mark.parametrize("frac", [0.1, 0.5, 0.95])
def test_quarter_period_linear_for_small_eta(frac: float) -> None:
    # Linearised equation theta'' = p^2 (theta - eta): T/4 = (1/p) arccosh(1/(1 - theta0/eta)).
    # Linearising sin neglects relative terms of order eta^2: accept a relative difference eta^2.
    b = HousnerBlock(0.05, 2.0)  # eta = 0.025 rad
    th0 = frac * b.eta
    assert quarter_period(b, th0) == pytest.approx(quarter_period_linear(b, th0), rel=b.eta**2)


def test_elastic_impacts_conserve_energy() -> None:
    # e = 1: every peak equals theta0 (energy conservation), to integration accuracy.
    r = rock(SQUAT, theta0=0.5 * SQUAT.eta, duration=2.0, e=1.0)
    np.testing.assert_allclose(np.abs(r.peak_rotation), 0.5 * SQUAT.eta, rtol=1e-7)


def test_overturning_is_detected_and_stops() -> None:
    # Energy above the potential barrier: released at 0.9 eta moving outward fast enough, the block
    # crosses eta moving away and overturns; the history ends at |theta| = eta.
    b = SQUAT
    r = rock(b, theta0=0.9 * b.eta, omega0=1.0, duration=2.0)
    assert r.overturned and r.overturn_time is not None
    assert abs(r.rotation[-1]) == pytest.approx(b.eta, rel=1e-9)
    assert overturned(r.rotation, b.eta)
    assert not rock(b, theta0=0.9 * b.eta, duration=1.0).overturned


def test_rocking_onset_threshold_under_ground_motion() -> None:
    # A block at rest rocks only when |a_g| > g tan(eta) (Housner): a ramp a = -k t starts it at
    # t = g tan(eta) / k, toward theta > 0 (ground pushed in -x).
    b = SLENDER
    a_crit = b.g * math.tan(b.eta)
    below = rock(b, theta0=0.0, duration=1.0, ground_acc=lambda t: -0.99 * a_crit)
    assert below.onset_time is None and np.all(below.rotation == 0.0)
    k = 2.0 * a_crit
    r = rock(b, theta0=0.0, duration=0.8, ground_acc=lambda t: -k * t, overturn_angle=0.5 * math.pi)
    assert r.onset_time == pytest.approx(a_crit / k, rel=1e-9)
    assert r.rotation[-1] > 0
    ts = np.array([0.0, 1.0])  # same ramp as a record (t, a): linear interpolation is exact
    r2 = rock(b, theta0=0.0, duration=0.8, ground_acc=(ts, -k * ts), overturn_angle=0.5 * math.pi)
    assert r2.onset_time == pytest.approx(a_crit / k, rel=1e-9)


def test_one_sided_onset_only_away_from_the_wall() -> None:
    # Wall on the -x side (wall_side=-1): a ground acceleration pushing the block toward the wall
    # does not start rocking, one pushing it away does.
    b = SLENDER
    a = 1.5 * b.g * math.tan(b.eta)
    toward = rock(b, theta0=0.0, duration=0.3, ground_acc=lambda t: a, one_sided=True)
    assert toward.onset_time is None
    away = rock(b, theta0=0.0, duration=0.3, ground_acc=lambda t: -a, one_sided=True, overturn_angle=1.5)
    assert away.onset_time == 0.0 and np.all(away.rotation >= 0) and away.rotation[-1] > 0


def test_top_displacement_and_dataset() -> None:
    r = rock(SQUAT, theta0=0.5 * SQUAT.eta, duration=0.5, dt_out=1e-2)
    np.testing.assert_allclose(r.top_displacement, SQUAT.h * np.sin(r.rotation), rtol=1e-15)
    assert r.time[0] == 0.0 and r.time[-1] == pytest.approx(0.5) and np.allclose(np.diff(r.time), 1e-2)
    ds = r.to_dataset()
    assert float(ds.block_eta[0]) == SQUAT.eta and ds.rocking_angle.shape == (len(r.time), 1)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"theta0": 0.5}, "theta0"),  # beyond eta
        ({"theta0": 0.1, "e": 1.2}, "restitution"),
        ({"theta0": -0.1, "one_sided": True}, "one-sided"),
        ({"theta0": 0.1, "duration": -1.0}, "duration"),
        ({"theta0": 0.1, "ground_acc": ([0, 1], [0])}, "ground_acc"),
    ],
)
def test_bad_input(kwargs: dict, match: str) -> None:
    kw = {"duration": 1.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        rock(SQUAT, **kw)
    with pytest.raises(ValueError, match="b must"):
        HousnerBlock(0.0, 1.0)
    with pytest.raises(ValueError, match="theta0"):
        quarter_period(SQUAT, SQUAT.eta)


def test_housner_inputs_are_checked_and_numpy_scalars_accepted():
    """A NumPy float is a number (np.float32 was refused); NaN or a negative rest criterion is
    refused naming the argument (NaN ended in 'cannot convert float NaN to integer')."""
    block = HousnerBlock(np.float32(0.2), np.int64(2))
    assert block.eta == pytest.approx(math.atan(0.2 / 2.0), rel=1e-7) and isinstance(block.b, float)
    for kw, name in ((dict(theta0=math.nan), "theta0"), (dict(theta0=0.05, omega0=math.inf), "omega0"),
                     (dict(theta0=0.05, rest_amplitude=-1.0), "rest_amplitude")):
        with pytest.raises(ValueError, match=name):
            rock(block, duration=1.0, **kw)
