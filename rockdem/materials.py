"""Joint materials (3DEC Mohr-Coulomb with tension cut-off) and stiffness helpers (paper §3)."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields
from typing import Any, Mapping

from ._warn import warn_user

#: Outside these, a value is almost surely in the wrong unit (masonry: 1500-2500 kg/m^3, E 1-20 GPa).
PLAUSIBLE_DENSITY = 100.0  # [kg/m^3]
HEAVIEST_DENSITY = 12_000.0  # [kg/m^3] heavier than lead
PLAUSIBLE_MODULUS = 1e6  # [Pa]
STIFFEST_MODULUS = 1e12  # [Pa] stiffer than any material (diamond about 1.1e12)
PLAUSIBLE_FRICTION_ANGLE = 3.0  # [deg] below this a friction angle is likely a coefficient mu

__all__ = ["JointMaterial", "check_material", "kn_from_modulus", "ks_from_kn", "real_number"]


def real_number(value: Any, what: str) -> float:
    """``value`` as a finite float, or ValueError naming ``what`` (strings, booleans, None, NaN and
    infinities are refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number, got {value!r}")
    return float(value)


def kn_from_modulus(youngs_modulus: float, joint_spacing: float) -> float:
    """Normal joint stiffness kn = E / l [Pa/m] (paper §3; l = H for one block, H/n_b for n_b blocks)."""
    if not real_number(youngs_modulus, "youngs_modulus [Pa]") > 0:
        raise ValueError(f"youngs_modulus must be positive [Pa], got {youngs_modulus!r}")
    if not real_number(joint_spacing, "joint_spacing [m]") > 0:
        raise ValueError(f"joint_spacing must be positive [m], got {joint_spacing!r}")
    return youngs_modulus / joint_spacing


def ks_from_kn(kn: float, poisson: float = 0.25) -> float:
    """Shear joint stiffness ks = kn / (2 (1 + nu)) [Pa/m] (paper §3; 0.4 kn for nu = 0.25)."""
    if not real_number(kn, "kn [Pa/m]") > 0:
        raise ValueError(f"kn must be a positive stiffness per area [Pa/m], got {kn!r}")
    if not -1.0 < real_number(poisson, "poisson") < 0.5:
        raise ValueError(f"poisson must lie in (-1, 0.5), got {poisson!r}")
    return kn / (2.0 * (1.0 + poisson))


# field -> (required, test, what it must be); None is accepted for the optional fields
_CHECKS: dict[str, tuple[bool, Any, str]] = {
    "kn": (True, lambda v: v > 0, "a positive stiffness per area [Pa/m]"),
    "ks": (False, lambda v: v > 0, "a positive stiffness per area [Pa/m]"),
    "friction_angle": (True, lambda v: 0 <= v < 90, "an angle in [0, 90) degrees"),
    "cohesion": (True, lambda v: v >= 0, "a non-negative stress [Pa]"),
    "tension": (True, lambda v: v >= 0, "a non-negative stress [Pa]"),
    "residual_friction_angle": (False, lambda v: 0 <= v < 90, "an angle in [0, 90) degrees"),
    "residual_cohesion": (True, lambda v: v >= 0, "a non-negative stress [Pa]"),
    "beta": (False, lambda v: v >= 0, "a non-negative time [s]"),
}


def check_material(values: Mapping[str, Any], where: str, names: Mapping[str, str] | None = None) -> dict[str, float | None]:
    """Check joint-material values (the :class:`JointMaterial` fields present in ``values``) and
    return them as floats; ValueError starts with ``where`` and names the field (as ``names`` calls
    it), e.g. "[specimen] friction_angle_deg must be ..."."""
    out: dict[str, float | None] = {}
    for name, value in values.items():
        required, test, what = _CHECKS[name]
        label = (names or {}).get(name, name)
        if value is None and not required:
            out[name] = None
            continue
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) or not test(value):
            raise ValueError(f"{where} {label} must be {what}, got {value!r}")
        out[name] = float(value)
    return out


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

    def __post_init__(self) -> None:
        # every path (builders, case files, ``builder.default_material``) gets a checked material;
        # NaN or a zero stiffness would otherwise stall the run at t = 0
        for name, value in check_material({f.name: getattr(self, f.name) for f in fields(self)}, "JointMaterial:").items():
            object.__setattr__(self, name, value)
        if self.residual_friction_angle is not None and self.residual_friction_angle > self.friction_angle:
            warn_user(f"JointMaterial: residual_friction_angle = {self.residual_friction_angle:g} deg exceeds "
                      f"friction_angle = {self.friction_angle:g} deg: a joint would hold more in friction after its "
                      "bond fails than before (a residual angle is normally at most the peak one)")

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
        check_material({f.name: getattr(self, f.name) for f in fields(self)}, f"{where}:")

    @property
    def tan_friction(self) -> float:
        return math.tan(math.radians(self.friction_angle))

    @property
    def tan_residual_friction(self) -> float:
        a = self.friction_angle if self.residual_friction_angle is None else self.residual_friction_angle
        return math.tan(math.radians(a))
