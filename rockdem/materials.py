"""Joint materials (3DEC Mohr-Coulomb with tension cut-off) and stiffness helpers (paper §3)."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["JointMaterial", "kn_from_modulus", "ks_from_kn"]


def kn_from_modulus(youngs_modulus: float, joint_spacing: float) -> float:
    """Normal joint stiffness kn = E / l [Pa/m] (paper §3; l = H for one block, H/n_b for n_b blocks)."""
    if not youngs_modulus > 0:
        raise ValueError(f"youngs_modulus must be positive [Pa], got {youngs_modulus!r}")
    if not joint_spacing > 0:
        raise ValueError(f"joint_spacing must be positive [m], got {joint_spacing!r}")
    return youngs_modulus / joint_spacing


def ks_from_kn(kn: float, poisson: float = 0.25) -> float:
    """Shear joint stiffness ks = kn / (2 (1 + nu)) [Pa/m] (paper §3; 0.4 kn for nu = 0.25)."""
    if not -1.0 < poisson < 0.5:
        raise ValueError(f"poisson must lie in (-1, 0.5), got {poisson!r}")
    return kn / (2.0 * (1.0 + poisson))


@dataclass(frozen=True)
class JointMaterial:
    """Properties of an interface between two block groups.

    Attributes:
        kn: normal stiffness per unit area [Pa/m].
        ks: shear stiffness per unit area [Pa/m]; default ``ks_from_kn(kn)`` (nu = 0.25).
        friction_angle: peak friction angle [deg].
        cohesion: peak cohesion c [Pa] (bonded joints only).
        tension: tensile strength ft [Pa] (bonded joints only).
        residual_friction_angle: friction angle after bond failure and for contacts formed during
            the run [deg]; default: the peak value.
        residual_cohesion: cohesion after failure [Pa]; default 0.
        beta: stiffness-proportional damping of this joint [s]; ``None`` uses the model's beta.
    """

    kn: float
    ks: float | None = None
    friction_angle: float = 30.0
    cohesion: float = 0.0
    tension: float = 0.0
    residual_friction_angle: float | None = None
    residual_cohesion: float = 0.0
    beta: float | None = None

    @classmethod
    def from_modulus(
        cls, youngs_modulus: float, joint_spacing: float, *, poisson: float = 0.25, **kwargs: float
    ) -> "JointMaterial":
        """Material with kn = E/l and ks = kn/(2(1+nu)) (paper §3)."""
        kn = kn_from_modulus(youngs_modulus, joint_spacing)
        return cls(kn=kn, ks=ks_from_kn(kn, poisson), **kwargs)

    @property
    def shear_stiffness(self) -> float:
        """ks [Pa/m], defaulting to 0.4 kn."""
        return ks_from_kn(self.kn) if self.ks is None else self.ks

    @property
    def bonded(self) -> bool:
        """Whether joints of this material carry tension or cohesion when in contact at the start."""
        return self.cohesion > 0.0 or self.tension > 0.0

    def validate(self, where: str) -> None:
        """Raise ValueError naming ``where`` and the field for any non-physical value."""
        checks = [
            ("kn", self.kn, self.kn is not None and self.kn > 0, "a positive stiffness per area [Pa/m]"),
            ("ks", self.ks, self.ks is None or self.ks > 0, "a positive stiffness per area [Pa/m]"),
            ("friction_angle", self.friction_angle, 0 <= self.friction_angle < 90, "an angle in [0, 90) degrees"),
            ("cohesion", self.cohesion, self.cohesion >= 0, "a non-negative stress [Pa]"),
            ("tension", self.tension, self.tension >= 0, "a non-negative stress [Pa]"),
            ("residual_cohesion", self.residual_cohesion, self.residual_cohesion >= 0, "a non-negative stress [Pa]"),
            (
                "residual_friction_angle",
                self.residual_friction_angle,
                self.residual_friction_angle is None or 0 <= self.residual_friction_angle < 90,
                "an angle in [0, 90) degrees",
            ),
            ("beta", self.beta, self.beta is None or self.beta >= 0, "a non-negative time [s]"),
        ]
        for field, value, ok, what in checks:
            if value is not None and not math.isfinite(value):
                ok = False
            if not ok:
                raise ValueError(f"{where}: {field} must be {what}, got {value!r}")

    @property
    def tan_friction(self) -> float:
        return math.tan(math.radians(self.friction_angle))

    @property
    def tan_residual_friction(self) -> float:
        a = self.friction_angle if self.residual_friction_angle is None else self.residual_friction_angle
        return math.tan(math.radians(a))
