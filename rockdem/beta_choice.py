"""How a model's SP damping beta was chosen: the target restitution and the record of the choice.

``Damping(beta="auto")`` finds the beta for which the model's own impacts give a target apparent
restitution (:mod:`rockdem.targeting`); ``Damping(beta="critical")`` gives every joint group pair
its own beta from its own critical impact (:mod:`rockdem.interfaces`). Both leave a
:class:`BetaChoice` on the model (``Model.beta_choice``), written into the result's attributes.
References: Galvez et al. 2022 (Eq. 1-6, §2.2, §3.2.1).
"""

from __future__ import annotations

import math
import numbers
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["BETA_AUTO", "BETA_CRITICAL", "BETA_MODES", "RestitutionTarget", "PairBeta", "BetaChoice", "housner_e_eta"]

BETA_AUTO = "auto"
"""beta targeted to a restitution by a root-find over short free-rocking runs of the model."""
BETA_CRITICAL = "critical"
"""beta = 2 zeta / omega of each group pair's own critical impact (paper Eq. 1-4, §2.2)."""
BETA_MODES = (BETA_AUTO, BETA_CRITICAL)

_ETA = re.compile(r"^\s*(?:(\d+(?:\.\d*)?|\.\d+)\s*\*?\s*)?e?_?eta\s*$", re.IGNORECASE)


def housner_e_eta(eta: float) -> float:
    """Housner's coefficient of restitution e_eta = 1 - 1.5 sin^2(eta) of a rectangular block of
    slenderness angle eta [rad] (paper §3.2.1)."""
    return 1.0 - 1.5 * math.sin(eta) ** 2


@dataclass(frozen=True)
class RestitutionTarget:
    """A target apparent restitution: a multiple of Housner's e_eta, or a value.

    Attributes:
        factor: the target is ``factor`` x e_eta of the released body (``"eta"`` is 1, Sorrentino
            et al.'s ``"0.95eta"`` 0.95); None when ``value`` is given.
        value: the target e itself (e.g. measured on a test) [-], in (0, 1); None with ``factor``.
    """

    factor: float | None = None
    value: float | None = None

    def __post_init__(self) -> None:
        if (self.factor is None) == (self.value is None):
            raise ValueError("RestitutionTarget: give exactly one of factor (x e_eta) or value")
        if self.factor is not None and not (0.0 < self.factor <= 1.2):
            raise ValueError(f"damping.target_restitution: the multiple of e_eta must lie in (0, 1.2], got {self.factor!r}")
        if self.value is not None and not (0.0 < self.value < 1.0):
            raise ValueError(f"damping.target_restitution must lie in (0, 1) (a coefficient of restitution), got {self.value!r}")

    @classmethod
    def parse(cls, spec: Any) -> "RestitutionTarget":
        """``"eta"``, ``"0.95eta"`` (also ``"0.95 eta"``, ``"0.95*e_eta"``), a number in (0, 1), or a
        RestitutionTarget; ValueError naming ``damping.target_restitution`` otherwise."""
        if isinstance(spec, RestitutionTarget):
            return spec
        if isinstance(spec, numbers.Real) and not isinstance(spec, bool):
            if not math.isfinite(spec):
                raise ValueError(f"damping.target_restitution must be finite, got {spec!r}")
            return cls(value=float(spec))
        if isinstance(spec, str):
            m = _ETA.match(spec)
            if m:
                return cls(factor=float(m.group(1)) if m.group(1) else 1.0)
            try:
                return cls(value=float(spec))
            except ValueError:
                pass
        raise ValueError(
            f"damping.target_restitution must be 'eta' (Housner's e_eta), a multiple such as '0.95eta', or a "
            f"restitution in (0, 1), got {spec!r}"
        )

    def resolve(self, eta: float) -> float:
        """The target e [-] for a released body of slenderness angle ``eta`` [rad]."""
        if self.value is not None:
            return self.value
        e = self.factor * housner_e_eta(eta)  # type: ignore[operator]
        if not 0.0 < e < 1.0:
            raise ValueError(
                f"damping.target_restitution = {self} gives e = {e:.4g} for eta = {math.degrees(eta):.3g} deg "
                "(e_eta = 1 - 1.5 sin^2 eta): outside (0, 1); give the target as a number"
            )
        return e

    def __str__(self) -> str:
        if self.value is not None:
            return f"{self.value:g}"
        return "eta" if self.factor == 1.0 else f"{self.factor:g}eta"


@dataclass(frozen=True)
class PairBeta:
    """The beta of one joint group pair and where it came from.

    Attributes:
        groups: the two group names (sorted).
        beta: SP damping coefficient [s].
        source: ``"targeted"`` (the restitution search), ``"critical"`` (2 zeta / omega of the pair's
            own impact), ``"material"`` (the joint material's own beta), ``"no free block"`` (both
            groups driven: the pair never acts).
        omega: circular frequency of the pair's critical impact [rad/s] (nan when not computed).
        area: contact area A of that impact [m^2]; mass: its effective mass m [kg]; kn [Pa/m].
        blocks: the two blocks of the critical impact ("" when none).
        how: one line: the equation and numbers.
    """

    groups: tuple[str, str]
    beta: float
    source: str
    omega: float = math.nan
    area: float = math.nan
    mass: float = math.nan
    kn: float = math.nan
    blocks: tuple[str, str] = ("", "")
    how: str = ""

    @property
    def zeta(self) -> float:
        """Damping ratio at the pair's critical impact, beta omega / 2 (paper Eq. 4, alpha = 0) [-]."""
        return 0.5 * self.beta * self.omega

    @property
    def label(self) -> str:
        return f"{self.groups[0]}-{self.groups[1]}"


@dataclass(frozen=True)
class BetaChoice:
    """The record of an automatic beta (``Model.beta_choice``).

    Attributes:
        mode: ``"auto"`` (targeted) or ``"critical"``.
        beta: the model's beta [s]: the targeted value (``auto``), else the largest pair beta.
        pairs: one :class:`PairBeta` per group pair.
        per_interface: whether only the rocking interface(s) carry the targeted beta.
        target: the target as given (``"0.95eta"``); target_value: the target e [-].
        achieved: mean e_a of the probe at ``beta`` (paper Eq. 6) [-].
        evaluations: (k, 2) the (beta [s], mean e_a [-]) pairs simulated, in order.
        search_time: wall time of the search [s].
        release_fraction: release of the probe as a fraction of eta; eta: the released body's
            instability angle [rad]; impacts: impacts measured by the probe at ``beta``;
            whole_decay: the probe measured its whole free-rocking decay (else the first
            ``impacts``); probe_duration: the longest probe run [s].
        released: names of the released blocks; rocking_pairs: labels of the searched pairs.
    """

    mode: str
    beta: float
    pairs: tuple[PairBeta, ...]
    per_interface: bool = False
    target: str = ""
    target_value: float = math.nan
    achieved: float = math.nan
    evaluations: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    search_time: float = 0.0
    release_fraction: float = math.nan
    eta: float = math.nan
    impacts: int = 0
    whole_decay: bool = True
    probe_duration: float = math.nan
    released: tuple[str, ...] = ()
    rocking_pairs: tuple[str, ...] = ()

    @property
    def iterations(self) -> int:
        """Number of probe simulations run by the search."""
        return int(len(self.evaluations))

    def pair(self, group_a: str, group_b: str) -> PairBeta:
        """The :class:`PairBeta` of a group pair (either order)."""
        key = tuple(sorted((group_a, group_b)))
        for p in self.pairs:
            if p.groups == key:
                return p
        raise KeyError(f"no group pair {group_a!r}-{group_b!r}; pairs are {[p.label for p in self.pairs]}")

    def attrs(self) -> dict[str, Any]:
        """Flat attributes for a result (NetCDF-safe: numbers, strings, 1-D arrays)."""
        out: dict[str, Any] = {
            "beta_mode": self.mode,
            "beta_per_interface": int(self.per_interface or self.mode == BETA_CRITICAL),
            "beta_pairs": "; ".join(f"{p.label}: {p.beta:.5g} s ({p.source})" for p in self.pairs),
            "beta_pair_values": np.array([p.beta for p in self.pairs]),
            "beta_how": " | ".join(self.lines()),
        }
        if self.mode == BETA_AUTO:
            out.update(
                beta_target_restitution=self.target,
                beta_target_value=self.target_value,
                beta_achieved_e_a=self.achieved,
                beta_iterations=self.iterations,
                beta_search_beta=self.evaluations[:, 0].copy(),
                beta_search_e_a=self.evaluations[:, 1].copy(),
                beta_search_time_s=self.search_time,
                beta_release_fraction=self.release_fraction,
                beta_probe_duration_s=self.probe_duration,
                beta_impacts=self.impacts,
            )
        return out

    def lines(self) -> list[str]:
        """Plain-language explanation of every pair's beta, with the equations and units."""
        out = []
        if self.mode == BETA_AUTO:
            out.append(
                f"beta = {self.beta:.5g} s targeted: mean apparent restitution e_a (Eq. 6) of "
                + (f"the free-rocking decay ({self.impacts} impacts, peaks down to 2 % of the release)" if self.whole_decay
                   else f"the first {self.impacts} impact(s)")
                + f" after a release of {', '.join(self.released[:4])}{' ...' if len(self.released) > 4 else ''} "
                f"from {self.release_fraction:g} eta (eta = {math.degrees(self.eta):.4g} deg) = target {self.target} = "
                f"{self.target_value:.4f}; achieved {self.achieved:.4f} after {self.iterations} probe runs "
                f"({self.search_time:.2g} s, brentq on log beta)"
            )
        for p in self.pairs:
            out.append(f"{p.label}: beta = {p.beta:.5g} s ({p.source}){': ' + p.how if p.how else ''}")
        return out
