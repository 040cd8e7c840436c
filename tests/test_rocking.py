"""Free rocking against closed forms: Housner's period and restitution, energy, invariance."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from conftest import peaks, restitution, rocking_block
from rockdem.kernels.rotation import axis_angle_matrix
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulation import simulate


def housner_quarter_period(b: float, h: float, theta0: float) -> float:
    """Time from theta0 to the first impact of Housner's exact equation theta'' = -p^2 sin(eta - theta),
    p^2 = 3 g / (4 R) for a rectangular block (Housner 1963)."""
    eta, r = math.atan(b / h), 0.5 * math.hypot(b, h)
    p2 = 3 * 9.81 / (4 * r)
    hit = lambda t, y: y[0]  # noqa: E731
    hit.terminal = True
    sol = solve_ivp(lambda t, y: [y[1], -p2 * math.sin(eta - y[0])], (0, 20), [theta0, 0.0], events=hit, rtol=1e-11, atol=1e-13)
    return float(sol.t_events[0][0])


def first_zero(ds) -> float:
    th = ds.rocking_angle.values[:, 1]
    t = ds.time.values
    i = int(np.flatnonzero(np.diff(np.sign(th)) != 0)[0])
    return float(t[i] - th[i] * (t[i + 1] - t[i]) / (th[i + 1] - th[i]))


@pytest.mark.parametrize("b,h", [(0.2, 2.0), (0.19, 0.9)])
def test_quarter_period_matches_housner(b, h):
    # Housner's nonlinear quarter period from 0.9 eta; stiff contacts (kn = 10 E/H) make the
    # elastic base's extra compliance negligible: 2 % as the issue asks.
    model = rocking_block(b, h, kn=10 * 1.8e9 / h, damping=Damping(beta=1e-4))
    ds = simulate(model, 2.5, record_interval=5e-4)
    theta0 = float(ds.rocking_angle[0, 1])
    assert theta0 == pytest.approx(0.9 * math.atan(b / h), rel=1e-9)
    assert first_zero(ds) == pytest.approx(housner_quarter_period(b, h, theta0), rel=0.02)


def test_undamped_elastic_rocking_conserves_energy():
    # No damping, no slip: KE + PE + elastic is constant to 0.5 % over 5 s. The shear springs are
    # stiff (ks = 10 kn) because the energy stored in a shear spring is lost when its point lifts
    # off (3DEC's law resets it); that loss, ~F_s^2 / (2 ks A), is counted as friction and with
    # ks = 10 kn stays below 0.1 %. dt = a quarter of the automatic one (leapfrog error ~ dt^2).
    kn = 1.8e9 / 2.0
    model = rocking_block(kn=kn, ks=10 * kn, friction_angle=89.0)
    from rockdem.timestep import stable_timestep

    ds = simulate(model, 5.0, dt=0.25 * stable_timestep(model).dt, record_interval=2e-3)
    mech = (ds.energy_kinetic + ds.energy_potential + ds.energy_elastic).values
    scale = -float(ds.energy_potential.min())  # the energy released by the fall, ~35 J
    assert scale > 30.0
    assert np.max(np.abs(mech - mech[0])) < 0.005 * scale
    assert len(peaks(ds.rocking_angle.values[:, 1])) >= 3  # it kept rocking (half cycle ~2.2 s)


@pytest.mark.parametrize(
    "damping",
    [Damping(beta=0.00693), Damping(alpha=2.0), Damping(alpha=0.5, beta=0.002)],
    ids=["SP", "MP", "Rayleigh"],
)
def test_damped_rocking_energy_balance_closes(damping):
    # KE + PE + elastic + dissipated (MP, SP, friction) = initial energy within 1 %.
    ds = simulate(rocking_block(damping=damping), 5.0, record_interval=2e-3)
    assert np.max(np.abs(ds.energy_balance_error_relative.values)) < 0.01
    dissipated = float(ds.energy_damping_mass[-1] + ds.energy_damping_stiffness[-1])
    assert dissipated > 0.2 * float(-ds.energy_potential.min())  # damping did real work


def _restitution_with_dejong_beta(b, h, points):
    e = 1.8e9
    mb = 1800.0 * b * h
    omega_e = math.sqrt(e * b**2 / (mb * h))  # paper Eq. 3
    model = rocking_block(b, h, points=points, damping=Damping(beta=2.0 / omega_e))
    ds = simulate(model, 5.0, record_interval=5e-4)
    eta = math.atan(b / h)
    return restitution(peaks(ds.rocking_angle.values[:, 1])[:5], eta), 1 - 1.5 * math.sin(eta) ** 2


def test_sp_damping_at_dejong_beta_gives_housner_restitution():
    # beta = 2 / omega_e (critical damping of the edge impact, paper §2.2, DESIGN §3): the apparent
    # restitution (Eq. 6) of a slender block (H/B = 4.3) is within 3 % of Housner's
    # e_eta = 1 - 1.5 sin^2(eta), impact after impact.
    e_a, e_eta = _restitution_with_dejong_beta(0.35, 1.5, (5, 2))
    assert len(e_a) >= 4
    np.testing.assert_allclose(e_a, e_eta, rtol=0.03)


def test_very_slender_block_is_closer_to_95_percent_of_e_eta():
    # For H/B = 10 the same beta damps more: e_a ~ 0.95 e_eta, as the paper found for its SP runs
    # (§3.2.1: "closer to 95 % of e_eta"). Asserted within 3 % of 0.95 e_eta.
    e_a, e_eta = _restitution_with_dejong_beta(0.2, 2.0, (2, 2))
    np.testing.assert_allclose(e_a, 0.95 * e_eta, rtol=0.03)


def test_rigid_motion_of_the_whole_model_gives_the_same_motion():
    # Invariance: rotate and translate every block and gravity; the trajectory is the same motion
    # seen in the moved frame (to round-off amplified over one impact).
    rot = axis_angle_matrix([0.3, -0.5, 0.8], 0.7)
    shift = np.array([10.0, -3.0, 2.5])

    def build(r, t):
        bld = ModelBuilder(gravity=r @ np.array([0, 0, -9.81]))
        bld.default_material = JointMaterial(kn=9e8, friction_angle=80)
        g = bld.add_box(4, 4, 1, base_center=(0, 0, -1), driven=True, name="ground", group="g")
        k = bld.add_box(0.2, 1.0, 2.0, density=1800, name="block")
        for i in (g, k):
            bld.transform_block(i, r, translation=t)
        bld.tilt(k, 0.9, direction=r @ np.array([1.0, 0, 0]))
        return bld.finalize(damping=Damping(beta=0.00693), rocking_axis=r @ np.array([0, 1.0, 0]))

    a = simulate(build(np.eye(3), np.zeros(3)), 1.6, dt=1e-4, record_interval=1e-2)
    b = simulate(build(rot, shift), 1.6, dt=1e-4, record_interval=1e-2)
    pa = a.block_position.values[:, 1]
    pb = b.block_position.values[:, 1]
    np.testing.assert_allclose(pb, pa @ rot.T + shift, atol=1e-7)
    np.testing.assert_allclose(b.rocking_angle.values[:, 1], a.rocking_angle.values[:, 1], atol=1e-7)


def test_toppling_block_lands_and_comes_to_rest():
    # Tilted past its instability angle, the block overturns, lands on its side face (new contacts
    # between faces that never touched) and stops: no blow-up, resting on the side face.
    b, h = 0.3, 1.0
    bld = ModelBuilder()
    bld.default_material = JointMaterial(kn=1.8e9 / h, friction_angle=40)
    bld.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground", group="g")
    bld.add_box(b, 1.0, h, density=1800, name="block")
    bld.tilt("block", 1.3)
    model = bld.finalize(damping=Damping(beta=0.002))
    ds = simulate(model, 4.0, record_interval=1e-2)
    assert np.all(np.isfinite(ds.block_position.values))
    assert abs(float(ds.rocking_angle[-1, 1])) == pytest.approx(math.pi / 2, abs=0.02)
    assert float(ds.block_position[-1, 1, 2]) == pytest.approx(b / 2, abs=0.01)
    assert float(ds.energy_kinetic[-1]) < 1e-3 * float(-ds.energy_potential.min())
    assert ds.attrs["dt_min"] < ds.attrs["dt"]  # the stiffer side-face contact lowered the step


@pytest.mark.parametrize("direction,axis", [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)),
                                            ((0, 1, 0), (-1, 0, 0)), ((0, -1, 0), (-1, 0, 0))])
def test_rocking_angle_is_measured_about_the_tilt_s_own_line(direction, axis):
    # A block 0.3 x 0.2 x 1.2 m tilted to half its instability angle about the base edge on the
    # side of ``direction`` (eta = atan(b / h) of the side it tips over: b = 0.3 along x, 0.2 along
    # y). The rocking angle is measured about that line, positive towards +x (or +y).
    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9, friction_angle=80)
    b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.3, 0.2, 1.2, density=2000, name="block")
    angle = b.tilt("block", 0.5, direction=direction)
    model = b.finalize(damping=Damping(beta=1e-4))
    np.testing.assert_allclose(model.rocking_axis, axis, atol=1e-12)
    eta = math.atan((0.3 if direction[0] else 0.2) / 1.2)
    assert angle == pytest.approx(0.5 * eta, rel=1e-9)
    ds = simulate(model, 0.01, record_interval=0.005)
    assert float(ds.rocking_angle.values[0, 1]) == pytest.approx(sum(direction) * 0.5 * eta, rel=1e-9)
