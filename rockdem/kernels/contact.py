"""Joint law per sub-contact: 3DEC Mohr-Coulomb with tension cut-off and bond breakage (paper §3).

Per sub-contact of area A with normal overlap u_n (compression > 0):
  F_n = kn A u_n, tension only while bonded and down to -ft A (else the bond fails in tension);
  |F_s| <= c A + F_n tan(phi) while bonded, c_r A + F_n tan(phi_r) after failure (else slip, and a
  bonded point fails in shear, dropping to its residual strength);
  SP dashpots beta kn A du_n/dt and beta ks A du_s/dt act on active sub-contacts; as Rayleigh
  damping is proportional to the tangent stiffness, the shear dashpot is off while a point slips
  (and both are off while it is open).
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def normal_force(kn: float, area: float, overlap: float) -> float:
    """Elastic normal force kn A u_n [N] (compression positive)."""
    return kn * area * overlap


@njit(cache=True, inline="always")
def coulomb_limit(cohesion: float, tan_friction: float, area: float, fn: float) -> float:
    """Shear strength c A + max(F_n, 0) tan(phi) [N]."""
    return cohesion * area + max(fn, 0.0) * tan_friction


@njit(cache=True, inline="always")
def slip_dissipation(f_trial: float, f_max: float, ks_area: float) -> float:
    """Energy dissipated by a slip that reduces |F_s| from f_trial to f_max [J]: f_max (f_trial - f_max) / (ks A)."""
    return f_max * (f_trial - f_max) / ks_area


@njit(cache=True, inline="always")
def spring_energy(force: float, stiffness: float) -> float:
    """Energy stored in a linear spring F^2 / (2 k) [J]."""
    return 0.5 * force * force / stiffness if stiffness > 0.0 else 0.0


@njit(cache=True, inline="always")
def sp_critical_factor(beta: float, omega_max: float) -> float:
    """Timestep reduction sqrt(1 + xi^2) - xi, xi = beta omega_max / 2 (Belytschko, SP damping)."""
    xi = 0.5 * beta * omega_max
    return math.sqrt(1.0 + xi * xi) - xi
