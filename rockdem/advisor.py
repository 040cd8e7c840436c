"""Damping advisor: which damping to use for a rocking DEM model, and with which values.

Implements the guidance of Galvez et al. 2022 (the founding paper, "§" below) for a block of width
B (rocking direction), height H and length L:

* m_b = rho B H, k_j = E B / H, k_s = E B^2 / (2 H) per metre of length (Eq. 2);
* omega_c, omega_e, omega_r (Eq. 1, 3; omega_r from Eq. 1 with Eq. 2: the paper's Eq. 3 prints
  B^3 where Eq. 1 + 2 give B^4, a typo, B^3 is not dimensionally a frequency); omega_crit = omega_e for a single block (H/B > sqrt 2),
  x sqrt 2 for stacked blocks with coinciding corners, B and H swapped plus the stacked factor for
  one-sided rocking against return walls (§2.2);
* SP damping beta = 2 zeta / omega_crit (Eq. 4 with alpha = 0); Rayleigh pair with its minimum
  zeta at omega_crit, alpha = zeta omega, beta = zeta / omega (Eq. 5); pragmatic MP estimate
  alpha = 22.4 beta + 0.05 (§4.3, Fig. 16), a first approximation only;
* kn = E / l with l = H / n_b, ks = kn / (2 (1 + nu)) (§3);
* eta = atan(B/H), semi-diagonal R, eta/R with a bouncing warning above 45 deg/m (§3.1);
* Housner e_eta = 1 - 1.5 sin^2 eta and 0.95 e_eta (§3.2.1);
* stable timesteps for MP and SP runs and the expected SP/MP cost ratio (central differences,
  with Belytschko's reduction for SP damping with explicit dashpots, 3DEC's scheme; the default
  implicit dashpots keep the MP step, docs/dashpots.md); only these depend on the length L;
* on request, the beta of the model itself (a block, a stack or a one-sided façade with these
  inputs, built with :mod:`rockdem.specimens`): targeted to a restitution (``target_restitution``:
  short free-rocking runs, :mod:`rockdem.targeting`) and/or per joint group pair from each pair's
  own critical impact (``per_interface``: beta = 2 zeta / sqrt(kn A / m), a face across a gap struck by
  one row of points with the block's effective mass there, :mod:`rockdem.interfaces`).

Geometry of the rocking body: the whole element B x H for ``single`` and ``one-sided``; one block
B x (H / blocks) for ``stacked`` (each block of the stack rocks and impacts its neighbours). More
than one block implies ``stacked`` unless ``single`` is given: a discretised element that rocks as
a whole (paper §3.2.2, the discretised parapet of §4.1), whose joints only set kn = E / (H / blocks).
"""

from __future__ import annotations

import argparse
import enum
import json
import math
import warnings
from dataclasses import asdict, dataclass, field, fields
from typing import TYPE_CHECKING, Any, Iterator

import numpy as np

from ._warn import warn_user
from .beta_choice import BetaChoice, RestitutionTarget
from .kernels.contact import sp_critical_factor
from .materials import HEAVIEST_DENSITY, PLAUSIBLE_DENSITY, STIFFEST_MODULUS

if TYPE_CHECKING:
    from .model import ModelBuilder

__all__ = [
    "Configuration", "AdviceInput", "Advice", "advise", "impact_frequencies", "omega_max_bound", "model_builder",
    "model_beta", "register_cli",
]

BOUNCING_LIMIT_DEG_PER_M = 45.0
"""eta/R above which bouncing was critical with under-damped impacts [deg/m] (§3.1, Fig. 5B)."""
SAFETY = 0.9
"""Fraction of the stable step used by the engine."""
PROBE_FRICTION_DEG = 80.0
"""Friction angle of the model the advisor simulates for its targeted beta [deg]: no sliding, so
the probe measures the rocking impacts alone (the paper's Table 2 block: mu > 5)."""


class Configuration(str, enum.Enum):
    """How the rocking body interacts with its neighbours (paper Fig. 2)."""

    SINGLE = "single"
    STACKED = "stacked"
    ONE_SIDED = "one-sided"


PLAUSIBLE_BLOCK = 100.0
"""[m] the largest width, height or length the advisor takes: a masonry wall or tower is tens of
metres; "--width 200 --height 2000" was mm typed as m (and got beta = 0.28 s)."""


@dataclass(frozen=True, kw_only=True)
class AdviceInput:
    """Inputs of the advisor (SI units).

    Attributes:
        width: B, block dimension in the rocking direction (wall thickness) [m].
        height: H, total height of the element [m].
        length: L, dimension along the rocking axis [m] (default 1, per metre of wall); only the
            timestep estimate (omega_max, dt) depends on it, not beta or alpha.
        density: rho [kg/m^3].
        youngs_modulus: E [Pa].
        poisson: nu [-], in (-1, 0.5).
        blocks: n_b, number of blocks over the height [-] (joint spacing l = H / n_b).
        configuration: single, stacked (needs blocks >= 2) or one-sided; default stacked when
            blocks > 1, else single (``configuration_implied`` is then True).
        damping_ratio: target zeta at the critical frequency [-] (1 = critical).
        points: interface points across the thickness (2 = the corners) [-].
        target_restitution: None, or the restitution the model's own impacts should give
            (``"eta"``, ``"0.95eta"`` or a number): the advisor then simulates the model and finds
            its beta (``Damping(beta="auto")``).
        per_interface: give every joint group pair of the model its own critical beta
            (``Damping(beta="critical")``, or with ``target_restitution`` the targeted beta on the
            rocking interface and the critical one elsewhere).
        release_fraction: release of the targeted search's probe as a fraction of eta [-]
            (default :data:`rockdem.targeting.DEFAULT_RELEASE_FRACTION`).
    """

    width: float
    height: float
    length: float = 1.0
    density: float
    youngs_modulus: float
    poisson: float = 0.25
    blocks: int = 1
    configuration: Configuration | str | None = None
    damping_ratio: float = 1.0
    points: int = 2
    target_restitution: str | float | None = None
    per_interface: bool = False
    release_fraction: float | None = None
    configuration_implied: bool = field(default=False, init=False)

    def __post_init__(self) -> None:
        for name in ("width", "height", "length", "density", "youngs_modulus", "damping_ratio"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise ValueError(f"{name} must be a positive finite number (SI units), got {v!r}")
        if not (-1.0 < self.poisson < 0.5):
            raise ValueError(f"poisson must lie in (-1, 0.5), got {self.poisson!r} (masonry: about 0.25)")
        for name in ("blocks", "points"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise ValueError(f"{name} must be a positive integer, got {v!r}")
        if self.points < 2:  # as the engine's builders refuse it (rockdem run: [specimen] points_across)
            raise ValueError("points = 1 puts the base's only point at its middle: the block balances on a knife edge and "
                             "cannot rock about its edges; give 2 or more (the paper uses 2 to 15)")
        for name in ("width", "height", "length"):
            if getattr(self, name) > PLAUSIBLE_BLOCK:
                raise ValueError(f"{name} = {getattr(self, name):g} m is larger than any masonry block or wall "
                                 f"(at most {PLAUSIBLE_BLOCK:g} m here): lengths are in metres, not mm")
        if self.configuration is None:
            object.__setattr__(self, "configuration_implied", True)
            object.__setattr__(self, "configuration", Configuration.STACKED if self.blocks > 1 else Configuration.SINGLE)
        try:
            conf = Configuration(self.configuration)
        except ValueError:
            choices = ", ".join(c.value for c in Configuration)
            raise ValueError(f"configuration must be one of {choices}, got {self.configuration!r}") from None
        object.__setattr__(self, "configuration", conf)
        if conf is Configuration.STACKED and self.blocks < 2:
            raise ValueError("configuration 'stacked' needs blocks >= 2 (height is the total height, each block height/blocks)")
        if self.target_restitution is not None:
            RestitutionTarget.parse(self.target_restitution)
        if not isinstance(self.per_interface, bool):
            raise ValueError(f"per_interface must be True or False, got {self.per_interface!r}")
        if self.release_fraction is not None and not (
            isinstance(self.release_fraction, (int, float)) and not isinstance(self.release_fraction, bool)
            and 0.0 < self.release_fraction < 1.0
        ):
            raise ValueError(f"release_fraction must lie in (0, 1) (a fraction of eta), got {self.release_fraction!r}")
        if self.release_fraction is not None and self.target_restitution is None:
            raise ValueError("release_fraction is the release of the target_restitution probe; give target_restitution "
                             "too (on the command line --target-restitution, e.g. 0.95eta), or leave it out")
        if self.youngs_modulus < 1e6:
            raise ValueError(
                f"youngs_modulus = {self.youngs_modulus!r} Pa is below 1 MPa: E is in Pa "
                "(1800 MPa = 1.8e9 Pa; on the command line use --youngs-modulus-mpa for MPa)"
            )
        if self.youngs_modulus > STIFFEST_MODULUS:
            raise ValueError(
                f"youngs_modulus = {self.youngs_modulus:g} Pa is stiffer than any material (steel 2e11 Pa, masonry "
                "1e9 to 2e10 Pa): E is in Pa (on the command line --youngs-modulus-mpa takes MPa: 1800, not 1.8e9)"
            )
        if not PLAUSIBLE_DENSITY <= self.density <= HEAVIEST_DENSITY:
            raise ValueError(
                f"density = {self.density:g} kg/m^3 is outside the range of building materials ({PLAUSIBLE_DENSITY:g} "
                f"to {HEAVIEST_DENSITY:g} kg/m^3; masonry 1500 to 2500): density is in kg/m^3 (1.8 t/m^3 is 1800)"
            )


def _out(unit: str, source: str, label: str) -> Any:
    return field(metadata={"unit": unit, "source": source, "label": label})


@dataclass(frozen=True)
class Advice:
    """Outputs of the advisor; every number has a unit and a source (see :meth:`rows`)."""

    inputs: AdviceInput
    rocking_height: float = _out("m", "§2.2: H for single/one-sided, H/n_b for stacked", "rocking body height h")
    mass_per_length: float = _out("kg/m", "Eq. 2: m_b = rho B h", "m_b")
    k_j: float = _out("N/m/m", "Eq. 2: k_j = E B / h", "k_j")
    k_s: float = _out("N/m/m", "Eq. 2: k_s = E B^2 / (2 h)", "k_s")
    omega_c: float = _out("rad/s", "Eq. 1, 3: sqrt(k_s / m_b)", "omega_c (corner)")
    omega_e: float = _out("rad/s", "Eq. 1, 3: sqrt(2 k_s / m_b)", "omega_e (edge)")
    omega_r: float = _out("rad/s", "Eq. 1 + 2: sqrt(3 k_s B^2 / (m_b (B^2 + h^2))) (Eq. 3's B^3 is a typo)", "omega_r (rotational)")
    omega_crit: float = _out("rad/s", "§2.2: omega_e (the largest of the three for H/B <= sqrt 2); x sqrt 2 stacked; "
                             "B<->h and x sqrt 2 one-sided", "omega_crit")
    beta_sp: float = _out("s", "Eq. 4 (alpha = 0): beta = 2 zeta / omega_crit", "beta (SP only)")
    rayleigh_alpha: float = _out("1/s", "Eq. 5: alpha = zeta omega_crit", "Rayleigh alpha (min at omega_crit)")
    rayleigh_beta: float = _out("s", "Eq. 5: beta = zeta / omega_crit", "Rayleigh beta (min at omega_crit)")
    alpha_mp: float = _out("1/s", "§4.3, Fig. 16: alpha = 22.4 beta + 0.05 (FIRST APPROXIMATION)", "alpha (MP estimate)")
    kn: float = _out("Pa/m", "§3: kn = E / l, l = H / n_b", "kn")
    ks: float = _out("Pa/m", "§3: ks = kn / (2 (1 + nu))", "ks")
    eta: float = _out("deg", "§3.1: eta = atan(B / h)", "slenderness eta")
    semi_diagonal: float = _out("m", "R = sqrt(B^2 + h^2) / 2", "semi-diagonal R")
    eta_over_r: float = _out("deg/m", "§3.1, Fig. 5B: bouncing critical above 45 deg/m", "eta / R")
    e_eta: float = _out("-", "§3.2.1: e_eta = 1 - 1.5 sin^2 eta", "Housner e_eta")
    e_eta_95: float = _out("-", "§3.2.1: 0.95 e_eta (closer to experiments)", "0.95 e_eta")
    omega_max: float = _out("rad/s", "Gershgorin bound of the sub-contact springs (estimate; depends on L)", "omega_max")
    dt_mp: float = _out("s", "central differences: 0.9 x 2 / omega_max", "dt, MP or no damping")
    dt_sp: float = _out("s", "Belytschko: 0.9 x 2/omega_max x (sqrt(1+xi^2) - xi), xi = beta omega_max / 2 (implicit: dt_MP)",
                        "dt, SP explicit dashpots")
    cost_ratio: float = _out("-", "dt_MP / dt_SP (1 with the default implicit dashpots)", "SP/MP cost, explicit")
    dt_3dec_mp: float = _out("s", "§3: 0.2 sqrt(m_min / k_max)", "dt 3DEC rule, MP")
    dt_3dec_sp: float = _out("s", "§3 + Belytschko: 3DEC dt x SP reduction", "dt 3DEC rule, SP")
    cost_ratio_3dec: float = _out("-", "dt_3DEC_MP / dt_3DEC_SP", "SP/MP cost, 3DEC rule")
    bouncing_expected: bool = False
    recommendations: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    beta_choice: BetaChoice | None = None
    recommended_beta: float = math.nan
    recommended_why: str = ""

    def rows(self) -> Iterator[tuple[str, float, str, str]]:
        """(label, value, unit, source) for every numeric output, in table order."""
        for f in fields(self):
            if "unit" in f.metadata:
                yield f.metadata["label"], float(getattr(self, f.name)), f.metadata["unit"], f.metadata["source"]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: inputs, outputs {name: {value, unit, source}}, recommendations, warnings."""
        inputs = asdict(self.inputs)
        inputs["configuration"] = self.inputs.configuration.value
        outputs = {
            f.name: {"value": float(getattr(self, f.name)), "unit": f.metadata["unit"], "source": f.metadata["source"]}
            for f in fields(self)
            if "unit" in f.metadata
        }
        out: dict[str, Any] = {
            "inputs": inputs,
            "outputs": outputs,
            "recommended_beta": {"value": self.recommended_beta, "unit": "s", "why": self.recommended_why},
            "bouncing_expected": self.bouncing_expected,
            "recommendations": list(self.recommendations),
            "warnings": list(self.warnings),
        }
        c = self.beta_choice
        if c is not None:
            out["model_beta"] = {
                "mode": c.mode, "beta_s": c.beta, "per_interface": c.per_interface or c.mode == "critical",
                "target": c.target, "target_value": _number(c.target_value), "achieved_e_a": _number(c.achieved),
                "probe_runs": c.iterations, "search_time_s": c.search_time, "release_fraction": _number(c.release_fraction),
                "pairs": [{"pair": p.label, "beta_s": p.beta, "source": p.source, "omega_rad_s": _number(p.omega),
                           "zeta": _number(p.zeta), "how": p.how} for p in c.pairs],
                "explanation": c.lines(),
            }
        return out

    def table(self) -> str:
        """Readable text table with units and sources, then recommendations and warnings."""
        i = self.inputs
        head = (
            f"rockdem advise: B = {i.width:g} m, H = {i.height:g} m, L = {i.length:g} m, rho = {i.density:g} kg/m3, "
            f"E = {i.youngs_modulus / 1e6:g} MPa, nu = {i.poisson:g}, {i.blocks} block(s), {_configuration_text(i)}, "
            f"zeta = {i.damping_ratio:g}, {i.points} points across"
        )
        lines = [head, ""]
        rows = list(self.rows())
        w = max(len(r[0]) for r in rows)
        for label, value, unit, source in rows:
            lines.append(f"  {label:<{w}}  {value:>12.5g}  {unit:<6}  {source}")
        if self.beta_choice is not None:
            lines += ["", "Beta of the model itself (simulated with rockdem; block(s) built from these inputs):"]
            lines += [f"  {line}" for line in self.beta_choice.lines()]
        lines += ["", f"Recommended beta: {self.recommended_beta:.4g} s. {self.recommended_why}"]
        lines += ["", "Recommendations:"] + [f"  - {r}" for r in self.recommendations]
        if self.warnings:
            lines += ["", "Warnings:"] + [f"  ! {r}" for r in self.warnings]
        return "\n".join(lines)


def _number(v: float) -> float | None:
    """A float for JSON, None for nan (strict JSON has no NaN)."""
    return float(v) if math.isfinite(v) else None


def _configuration_text(i: AdviceInput) -> str:
    conf = Configuration(i.configuration).value
    if i.configuration_implied and i.blocks > 1:
        return (f"{conf} (implied by {i.blocks} blocks; configuration single: a discretised element that "
                "rocks as a whole)")
    return conf


def impact_frequencies(b: float, h: float, density: float, e: float) -> tuple[float, float, float, float, float, float]:
    """m_b [kg/m], k_j, k_s [N/m per m] and omega_c, omega_e, omega_r [rad/s] (paper Eq. 1-3)."""
    m_b = density * b * h
    k_j = e * b / h
    k_s = k_j * b / 2.0
    return (
        m_b,
        k_j,
        k_s,
        math.sqrt(k_s / m_b),
        math.sqrt(2.0 * k_s / m_b),
        math.sqrt(3.0 * k_s * b * b / (m_b * (b * b + h * h))),
    )


def _base_points(b: float, length: float, h: float, n_across: int) -> tuple[np.ndarray, np.ndarray]:
    """Interface points of the base face (n_across x 2, trapezoidal areas) relative to the centroid."""
    if n_across == 1:
        xs, wx = np.array([0.0]), np.array([b])
    else:
        xs = np.linspace(-0.5 * b, 0.5 * b, n_across)
        wx = np.full(n_across, b / (n_across - 1))
        wx[[0, -1]] *= 0.5
    ys, wy = np.array([-0.5 * length, 0.5 * length]), np.array([0.5 * length, 0.5 * length])
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    pts = np.column_stack((gx.ravel(), gy.ravel(), np.full(gx.size, -0.5 * h)))
    areas = np.outer(wx, wy).ravel()
    return pts, areas


def omega_max_bound(
    b: float, length: float, h: float, density: float, kn: float, ks: float, n_across: int, *, coupling: float = 1.0
) -> float:
    """Gershgorin-type bound of the highest frequency of a block on its base [rad/s].

    omega_max^2 <= coupling x sum_i A_i [kn f_i(n) + ks (f_i(t1) + f_i(t2))], with
    f_i(d) = 1/m + sum_j ((r_i x d)_j)^2 / I_j, r_i the point from the centroid, I_j the principal
    moments of the full 3D block B x L x h of mass rho B L h. ``coupling`` = 2 for a block between
    two others (the engine's factor for several free blocks). An estimate of the engine's bound,
    which uses the contacts actually present.
    """
    m = density * b * length * h
    inertia = m / 12.0 * np.array([length**2 + h**2, b**2 + h**2, b**2 + length**2])
    r, area = _base_points(b, length, h, n_across)

    def flex(d: np.ndarray) -> np.ndarray:
        return 1.0 / m + (np.cross(r, d) ** 2) @ (1.0 / inertia)

    ex, ey, ez = np.eye(3)
    total = np.sum(area * (kn * flex(ez) + ks * (flex(ex) + flex(ey))))
    return math.sqrt(coupling * total)


def advise(inputs: AdviceInput | None = None, **kwargs: Any) -> Advice:
    """Damping advice for a rocking block (module docstring).

    Args:
        inputs: an AdviceInput, or None and its fields as keyword arguments.

    Returns:
        Advice; its ``warnings`` are also emitted with :func:`warnings.warn`.

    Raises:
        ValueError: bad input, naming the field and the fix.
    """
    if inputs is None:
        try:
            inputs = AdviceInput(**kwargs)
        except TypeError as exc:
            raise ValueError(f"advise: {exc}") from None
    elif kwargs:
        raise ValueError("advise: pass either an AdviceInput or keyword arguments, not both")
    i = inputs
    conf = i.configuration
    b, big_h = i.width, i.height
    h = big_h / i.blocks if conf is Configuration.STACKED else big_h
    warn: list[str] = []
    if h / b < 1.0:
        warn.append(
            f"H/B = {h / b:.3g} < 1: a squat body; the rocking formulas assume a slender block "
            "(it may slide or rock on its long side; Housner e_eta and Eq. 6 lose meaning)"
        )
    elif h / b <= math.sqrt(2.0):
        warn.append(
            f"H/B = {h / b:.3g} <= sqrt 2: omega_r > omega_c, the paper's ordering (§2.2) does not hold; "
            "omega_crit is the largest of the three impact frequencies"
        )
    m_b, k_j, k_s, w_c, w_e, w_r = impact_frequencies(b, h, i.density, i.youngs_modulus)
    if conf is Configuration.ONE_SIDED:  # §2.2: B and H swapped, then the stacked factor
        w_crit = math.sqrt(2.0) * impact_frequencies(h, b, i.density, i.youngs_modulus)[4]
    else:
        w_crit = max(w_c, w_e, w_r) * (math.sqrt(2.0) if conf is Configuration.STACKED else 1.0)
    zeta = i.damping_ratio
    beta = 2.0 * zeta / w_crit
    alpha_mp = 22.4 * beta + 0.05
    kn = i.youngs_modulus / (big_h / i.blocks)
    ks = kn / (2.0 * (1.0 + i.poisson))
    eta = math.atan2(b, h)
    r_semi = 0.5 * math.hypot(b, h)
    eta_r = math.degrees(eta) / r_semi
    e_eta = 1.0 - 1.5 * math.sin(eta) ** 2
    if e_eta <= 0:
        warn.append(f"e_eta = {e_eta:.3g} <= 0: Housner predicts no rocking after the first impact (eta > 54.7 deg)")
    # timestep: one block of the discretisation (smallest mass, stiffest joints)
    h_blk = big_h / i.blocks
    coupling = 2.0 if i.blocks > 1 else 1.0
    w_max = omega_max_bound(b, i.length, h_blk, i.density, kn, ks, i.points, coupling=coupling)
    dt_mp = SAFETY * 2.0 / w_max
    dt_sp = dt_mp * sp_critical_factor(beta, w_max)
    m_min = i.density * b * i.length * h_blk
    k_max = kn * float(np.max(_base_points(b, i.length, h_blk, i.points)[1]))
    w3 = math.sqrt(k_max / m_min)
    dt3 = 0.2 * math.sqrt(m_min / k_max)
    dt3_sp = dt3 * sp_critical_factor(beta, w3)
    bouncing = eta_r > BOUNCING_LIMIT_DEG_PER_M
    choice = model_beta(i) if (i.target_restitution is not None or i.per_interface) else None
    rec_beta, why = _recommended(i, beta, choice)
    recs = _recommendations(i, rec_beta, alpha_mp, kn, eta_r, bouncing, dt_mp / dt_sp)
    for msg in warn:
        warn_user(msg)
    return Advice(
        inputs=i,
        rocking_height=h,
        mass_per_length=m_b,
        k_j=k_j,
        k_s=k_s,
        omega_c=w_c,
        omega_e=w_e,
        omega_r=w_r,
        omega_crit=w_crit,
        beta_sp=beta,
        rayleigh_alpha=zeta * w_crit,
        rayleigh_beta=zeta / w_crit,
        alpha_mp=alpha_mp,
        kn=kn,
        ks=ks,
        eta=math.degrees(eta),
        semi_diagonal=r_semi,
        eta_over_r=eta_r,
        e_eta=e_eta,
        e_eta_95=0.95 * e_eta,
        omega_max=w_max,
        dt_mp=dt_mp,
        dt_sp=dt_sp,
        cost_ratio=dt_mp / dt_sp,
        dt_3dec_mp=dt3,
        dt_3dec_sp=dt3_sp,
        cost_ratio_3dec=dt3 / dt3_sp,
        bouncing_expected=bouncing,
        recommendations=tuple(recs),
        warnings=tuple(warn),
        beta_choice=choice,
        recommended_beta=rec_beta,
        recommended_why=why,
    )


def model_builder(i: AdviceInput) -> "ModelBuilder":
    """The model the inputs describe, on a fixed foundation (for :func:`model_beta`).

    single: one B x L x H block (with n_b > 1, its kn = E / (H / n_b): a discretised element that
    rocks as a whole); stacked: n_b blocks of H / n_b (:func:`rockdem.specimens.stacked_blocks`);
    one-sided: a façade with return walls 4 mm behind it (:func:`rockdem.specimens.facade`).
    Joints: kn = E / (H / n_b), ks = kn / (2 (1 + nu)), friction :data:`PROBE_FRICTION_DEG`;
    ``points`` x 2 interface points per face.
    """
    from .materials import JointMaterial, ks_from_kn
    from .model import ModelBuilder
    from .specimens import facade, stacked_blocks

    kn = i.youngs_modulus / (i.height / i.blocks)
    mat = JointMaterial(kn=kn, ks=ks_from_kn(kn, i.poisson), friction_angle=PROBE_FRICTION_DEG)
    b = ModelBuilder(points=(i.points, 2))
    b.default_material = mat
    if i.configuration is Configuration.ONE_SIDED:
        facade(b, width=i.width, height=i.height, length=i.length, density=i.density, material=mat)
    else:
        n = i.blocks if i.configuration is Configuration.STACKED else 1
        stacked_blocks(b, width=i.width, length=i.length, heights=[i.height / n] * n, density=i.density, material=mat)
    return b


def model_beta(i: AdviceInput) -> BetaChoice:
    """beta of the model the inputs describe (:func:`model_builder`): targeted to
    ``i.target_restitution`` (``Damping(beta="auto")``) and/or per group pair (``per_interface``)."""
    from .model import Damping

    if i.target_restitution is not None:
        damping = Damping(beta="auto", target_restitution=i.target_restitution, per_interface=i.per_interface,
                          damping_ratio=i.damping_ratio, release_fraction=i.release_fraction)
    else:
        damping = Damping(beta="critical", damping_ratio=i.damping_ratio)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = model_builder(i).finalize(damping=damping)
    assert model.beta_choice is not None
    return model.beta_choice


def _crit_name(i: AdviceInput) -> str:
    """What omega_crit is for ``i``: omega_e, or for a squat rocking body (h/B <= sqrt 2, where the
    paper's ordering of the impact frequencies does not hold) the largest of the three."""
    h = i.height / i.blocks if i.configuration is Configuration.STACKED else i.height  # the rocking body's
    squat = i.configuration is not Configuration.ONE_SIDED and h / i.width <= math.sqrt(2.0)
    return "max(omega_c, omega_e, omega_r) (h/B <= sqrt 2)" if squat else "omega_e"


def _recommended(i: AdviceInput, beta_rule: float, choice: BetaChoice | None) -> tuple[float, str]:
    """The beta the advisor would use [s] and why."""
    if choice is not None and choice.mode == "auto":
        return choice.beta, (
            f"Targeted: with it the model's own free-rocking impacts give a mean apparent restitution "
            f"e_a (Eq. 6) of {choice.achieved:.4f} against the target {choice.target} = {choice.target_value:.4f} "
            f"({choice.iterations} short runs); use damping.beta = \"auto\" with target_restitution = "
            f"\"{choice.target}\" in a case to repeat it on the exact model."
        )
    if choice is not None:
        per = "; ".join(f"{p.label} {p.beta:.4g} s" for p in choice.pairs if p.source == "critical")
        return choice.beta, (
            f"Per interface (damping.beta = \"critical\"): each joint group pair beta = 2 zeta / omega of its own "
            f"critical impact, omega = sqrt(kn A / m) with the model's springs (Eq. 1-4; a face across a gap "
            f"struck by one row of points, A its area, m the block's effective mass there): {per}; the number is the "
            "largest of them."
        )
    rule = "x sqrt 2 (stacked, §2.2)" if i.configuration is Configuration.STACKED else (
        "B and h swapped x sqrt 2 (one-sided, §2.2)" if i.configuration is Configuration.ONE_SIDED else "(§2.2)")
    return beta_rule, (
        f"DeJong's rule as in the paper: beta = 2 zeta / omega_crit, omega_crit = {_crit_name(i)} of Eq. 3 {rule}. It does not "
        "depend on the interface points and over-damped the §4.1 parapet; give --target-restitution (e.g. 0.95eta) "
        "for the beta whose impacts give a chosen restitution, or --per-interface for each pair's own critical beta."
    )


def _recommendations(
    i: AdviceInput, beta: float, alpha_mp: float, kn: float, eta_r: float, bouncing: bool, cost: float
) -> list[str]:
    """Plain-language guidance from the paper's conclusions (§5) for these inputs."""
    recs = [
        f"Use SP damping (alpha = 0, beta = {beta:.3g} s) for collapse and overturning studies and "
        "earthquake rocking: it was consistent with every experiment simulated (§5).",
        f"MP damping (alpha ~ {alpha_mp:.3g} 1/s, §4.3) only as a fast first approximation "
        f"(with rockdem's default implicit dashpots SP takes the MP step; with explicit dashpots, 3DEC's scheme, it needs "
        f"{cost:.2g}x more steps here), to be refined with SP: small changes of alpha changed "
        "the whole history and the overturning (§4.1, §5).",
    ]
    if i.configuration is Configuration.ONE_SIDED:
        recs.append(
            "One-sided rocking: MP damping could not reproduce the tests (§4.2). The one-sided beta damps "
            "the wall impact critically but under-damps base impacts; the two-sided beta over-damps "
            "them; for the paper's façade the best fit (0.00025 s) lay between its one-sided 0.00017 s and "
            "two-sided 0.0047 s values: calibrate on a test when possible."
        )
    if i.configuration is Configuration.SINGLE and i.height / i.width > math.sqrt(2.0):
        recs.append("DeJong's rule (§2.2) over-damped the free-rocking parapet of §4.1: treat beta as an upper value.")
    if bouncing:
        recs.append(
            f"eta/R = {eta_r:.0f} deg/m > 45 deg/m: bouncing is expected when impacts are under-damped "
            "(MP or no viscous damping, §3.1); use SP damping."
        )
    else:
        recs.append(f"eta/R = {eta_r:.0f} deg/m <= 45 deg/m: little bouncing expected (§3.1).")
    if i.blocks > 1:
        recs.append(
            "Discretised model: with no viscous damping the damping comes from joint damage; use cohesive "
            "joints stronger than 0.1 MPa (c and ft) to avoid excessive damage-driven damping (§3.2.2, §5), "
            "and prefer SP damping to control rattling when collapse is expected (§5)."
        )
    if kn < 5e9:
        recs.append(
            f"kn = {kn / 1e6:.0f} MPa/m is low: 1000 MPa/m gave unrealistic motion and false overturning "
            "(§3.2.1, §5)."
        )
    if i.points < 3:
        recs.append(
            "2 points across the thickness give a stiffer, near-rigid rocking onset; 10 to 15 gave smooth "
            "pushover curves at 5 to 9 times the runtime (§3.3, Table 2)."
        )
    recs.append(
        "Housner e_eta is the energy-loss reference; experiments are closer to 0.95 e_eta (§3.2.1): "
        "check e_a of a free-rocking run against both."
    )
    return recs


def _run(args: argparse.Namespace) -> int:
    """``rockdem advise``: print the table or JSON; 0 on success (ValueError -> CLI error)."""
    if args.youngs_modulus is None and args.youngs_modulus_mpa is None:
        raise ValueError("give Young's modulus: --youngs-modulus PA or --youngs-modulus-mpa MPA")
    e = args.youngs_modulus if args.youngs_modulus is not None else args.youngs_modulus_mpa * 1e6
    inputs = AdviceInput(
        width=args.width,
        height=args.height,
        length=1.0 if args.length is None else args.length,
        density=args.density,
        youngs_modulus=e,
        poisson=args.poisson,
        blocks=args.blocks,
        configuration=args.configuration,
        damping_ratio=args.damping_ratio,
        points=args.points,
        target_restitution=args.target_restitution,
        per_interface=args.per_interface,
        release_fraction=args.release_fraction,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # they are printed in the output
        advice = advise(inputs)
    if args.json:
        print(json.dumps(advice.to_dict(), indent=2))
    else:
        print(advice.table())
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``advise`` sub-command."""
    p = subparsers.add_parser(
        "advise",
        help="damping advice for a rocking block (Galvez et al. 2022)",
        description="Damping parameters, stiffnesses, timesteps and recommendations for a rocking block. SI units.",
    )
    p.add_argument("--width", type=float, required=True, help="B, thickness in the rocking direction [m]")
    p.add_argument("--height", type=float, required=True, help="H, total height [m]")
    p.add_argument("--length", type=float, default=None,
                   help="L, length along the rocking axis [m] (default 1, per metre of wall); only the timestep "
                        "estimate (omega_max, dt) depends on it, not beta or alpha")
    p.add_argument("--density", type=float, required=True, help="density [kg/m3]")
    emod = p.add_mutually_exclusive_group()
    emod.add_argument("--youngs-modulus", type=float, help="Young's modulus E [Pa]")
    emod.add_argument("--youngs-modulus-mpa", type=float, help="Young's modulus E [MPa]")
    p.add_argument("--poisson", type=float, default=0.25, help="Poisson's ratio [-] (default 0.25)")
    p.add_argument("--blocks", type=int, default=1, help="number of blocks over the height (default 1)")
    p.add_argument(
        "--configuration", choices=[c.value for c in Configuration], default=None,
        help="default: stacked when --blocks > 1 (each block rocks, paper §2.2, §4.4), else single; give single "
             "with --blocks N for a discretised element that rocks as a whole (joints at H/N set kn only)",
    )
    p.add_argument("--damping-ratio", type=float, default=1.0, help="target zeta at omega_crit (default 1, critical)")
    p.add_argument("--points", type=int, default=2, help="interface points across the thickness (default 2)")
    p.add_argument("--target-restitution", default=None, metavar="E",
                   help="simulate the model (block, stack or façade of these inputs) and find the beta whose impacts "
                        "give this apparent restitution: eta (Housner's e_eta), a multiple such as 0.95eta, or a "
                        "number in (0, 1); a few seconds")
    p.add_argument("--per-interface", action="store_true",
                   help="each joint group pair its own critical beta = 2 zeta / sqrt(kn A / m) of its own impact "
                        "(across a gap: one row of points, the effective mass there) "
                        "(with --target-restitution: the targeted beta on the rocking interface, critical elsewhere)")
    p.add_argument("--release-fraction", type=float, default=None,
                   help="release of the targeted search's free-rocking probe, fraction of eta (default 0.5)")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=_run)
