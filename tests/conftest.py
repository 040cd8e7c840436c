"""Shared builders for the engine tests."""

from __future__ import annotations

import numpy as np
import pytest

from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder


def rocking_block(
    b: float = 0.2,
    h: float = 2.0,
    *,
    length: float = 1.0,
    density: float = 1800.0,
    youngs_modulus: float = 1.8e9,
    kn: float | None = None,
    ks: float | None = None,
    friction_angle: float = 80.0,
    points: tuple[int, int] = (2, 2),
    tilt: float = 0.9,
    damping: Damping = Damping(),
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81),
):
    """A block on a fixed foundation tilted to ``tilt`` of its instability angle (paper §3.1)."""
    bld = ModelBuilder(points=points, gravity=gravity)
    kn = youngs_modulus / h if kn is None else kn
    bld.default_material = JointMaterial(kn=kn, ks=ks, friction_angle=friction_angle)
    size = 2.0 * max(b, h, length)
    bld.add_box(size, size, 0.25 * size, base_center=(0, 0, -0.25 * size), driven=True, name="ground", group="ground")
    bld.add_box(b, length, h, density=density, name="block")
    if tilt:
        bld.tilt("block", tilt)
    return bld.finalize(damping=damping)


def peaks(theta: np.ndarray) -> np.ndarray:
    """|theta| at the start and the largest |theta| of each following half cycle."""
    idx = np.flatnonzero(np.diff(np.sign(theta)) != 0)
    edges = np.r_[0, idx, len(theta) - 1]
    out = [abs(theta[0])] + [np.max(np.abs(theta[edges[i] : edges[i + 1] + 1])) for i in range(1, len(edges) - 1)]
    return np.array(out)


def restitution(pk: np.ndarray, eta: float) -> np.ndarray:
    """Apparent coefficient of restitution per impact, paper Eq. 6."""
    n = np.arange(1, len(pk))
    return ((1 - (1 - pk[1:] / eta) ** 2) / (1 - (1 - pk[0] / eta) ** 2)) ** (1 / (2 * n))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20221)
