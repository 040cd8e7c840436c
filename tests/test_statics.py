"""Static checks: settlement, base reaction, friction onset on an incline (closed forms)."""

import math

import numpy as np
import pytest

from rockdem.kernels.rotation import axis_angle_matrix
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulation import simulate


def test_static_settlement_and_base_reaction():
    # Settlement u = m g / (kn A_base); base reaction = weight. MP damping settles the bounce;
    # after 40 periods of the vertical mode the residual oscillation is < 1e-6 of u.
    b, l, h, rho, kn = 0.3, 0.5, 1.0, 2000.0, 1e9
    bld = ModelBuilder()
    bld.default_material = JointMaterial(kn=kn, friction_angle=35)
    bld.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground", group="g")
    bld.add_box(b, l, h, density=rho, name="block", points=(3, 4))
    omega = math.sqrt(kn * b * l / (rho * b * l * h))
    model = bld.finalize(damping=Damping(alpha=2 * 0.5 * omega))  # 50 % of critical
    ds = simulate(model, 40 * 2 * math.pi / omega, record_interval=1e-3)
    m = rho * b * l * h
    settlement = -float(ds.block_displacement[-1, 1, 2])
    assert settlement == pytest.approx(m * 9.81 / (kn * b * l), rel=1e-4)
    np.testing.assert_allclose(ds.base_reaction.values[-1], [0, 0, m * 9.81], rtol=1e-4, atol=1e-6 * m * 9.81)
    assert abs(float(ds.rocking_angle[-1, 1])) < 1e-9


def _incline(theta_deg: float, phi_deg: float, duration: float):
    """A block on a foundation inclined by theta about y; gravity vertical."""
    r = axis_angle_matrix([0, 1, 0], math.radians(theta_deg))
    bld = ModelBuilder()
    bld.default_material = JointMaterial(kn=5e9, friction_angle=phi_deg)
    g = bld.add_box(4, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground", group="g")
    blk = bld.add_box(0.4, 0.4, 0.2, density=2000, name="block")
    bld.transform_block(g, r)
    bld.transform_block(blk, r)
    model = bld.finalize(damping=Damping(beta=2e-5))
    ds = simulate(model, duration, record_interval=2e-3)
    slope = r @ np.array([1.0, 0, 0])  # down-slope direction is -slope for a positive tilt about y
    u = ds.block_displacement.values[:, 1] @ slope
    return ds.time.values, u


def test_block_on_incline_below_friction_angle_stays():
    # tan(theta) < tan(phi): static friction holds; only the elastic shear m g sin(theta)/(ks A).
    t, u = _incline(20.0, 30.0, 0.5)
    assert np.max(np.abs(u)) < 1e-5


@pytest.mark.parametrize("theta,phi", [(30.0, 20.0), (25.0, 10.0)])
def test_block_on_incline_above_friction_angle_slides_with_coulomb_acceleration(theta, phi):
    # a = g (sin theta - tan phi cos theta), fitted on u(t) = a t^2 / 2 + v0 t + u0 after the
    # elastic transient (first 0.05 s); tolerance 1 % covers the fit and the dashpot.
    t, u = _incline(theta, phi, 0.6)
    sel = t > 0.05
    a_fit = 2 * np.polyfit(t[sel], u[sel], 2)[0]
    th, ph = math.radians(theta), math.radians(phi)
    a = 9.81 * (math.sin(th) - math.tan(ph) * math.cos(th))
    assert abs(a_fit) == pytest.approx(a, rel=0.01)


def test_free_fall_from_rest_follows_g_t2_over_2_at_every_frame():
    """The leapfrog's first velocity update is half a step's (v_1/2 = v_0 + a dt / 2: the initial
    velocities are those at t = 0); under constant gravity it is then exact, every recorded
    position and velocity on z0 - g t^2 / 2 and -g t to roundoff. Before 2026-11-29 the first
    update was a whole step's and every trajectory from rest ran half a step early (here 1.1e-5 s:
    3.3e-5 m below z0 - g t^2 / 2 at 0.3 s), the Housner first impact 0.12 to 0.16 % early."""
    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e10, friction_angle=35)
    b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.3, 0.3, 0.3, base_center=(0, 0, 2.0), density=2000, name="cube")
    with pytest.warns(UserWarning, match="no damping"):  # none wanted: nothing touches
        model = b.finalize()
    ds = simulate(model, 0.3, record_interval=0.01, progress=False)
    t = ds.time.values
    z = ds.block_position.sel(block="cube").values[:, 2]
    vz = ds.block_velocity.sel(block="cube").values[:, 2]
    assert ds.attrs["steps"] > 10_000  # many steps: a start error of half a step would show
    assert np.max(np.abs(z - (2.15 - 0.5 * 9.81 * t**2))) < 1e-8
    assert np.max(np.abs(vz + 9.81 * t)) < 1e-10
