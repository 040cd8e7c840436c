"""Verification of the damping advisor against the paper's own numbers and its equations.

References: Galvez et al. 2022 (Eq. 1-5, §2.2, §3.1, §3.2.1 Table 1, §4.2, §4.4).
Tolerances: the paper quotes 2-3 significant figures, so a value is accepted within one unit of
its last quoted digit; identities between our own outputs are checked to round-off (rel 1e-12).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rockdem.advisor import AdviceInput, Configuration, advise, omega_max_bound
from rockdem.cli import main

FACADE = dict(width=0.11, height=0.8, length=1.5, density=1750.0, youngs_modulus=1.8e9)


def test_beta_two_sided_and_one_sided_match_paper_section_4_2() -> None:
    # §4.2: beta = 0.00470 (two-sided) and 0.00017 (one-sided), beta = 2 zeta / omega_crit with
    # zeta = 1 (§2.2). Quoted to 2 significant figures: accept one unit of the last digit.
    two = advise(**FACADE)
    one = advise(**FACADE, configuration="one-sided")
    assert abs(two.beta_sp - 0.0047) < 1e-4
    assert abs(one.beta_sp - 0.00017) < 1e-5


@pytest.mark.parametrize(
    ("b", "h", "e_eta", "e_95"),
    [(0.19, 0.5, 0.811, 0.770), (0.35, 1.5, 0.922, 0.876), (0.19, 2.0, 0.986, 0.937)],
)
def test_housner_restitution_matches_table_1(b: float, h: float, e_eta: float, e_95: float) -> None:
    # Table 1: e_eta = 1 - 1.5 sin^2(eta) and 0.95 e_eta, printed with 3 decimals (truncated or
    # rounded): accept |difference| < 1e-3.
    adv = advise(width=b, height=h, length=1.0, density=1800.0, youngs_modulus=1.8e9)
    assert abs(adv.e_eta - e_eta) < 1e-3
    assert abs(adv.e_eta_95 - e_95) < 1e-3


def test_eta_over_r_of_squat_block_section_3_1() -> None:
    # §3.1: the 0.35 x 0.5 m block has eta/R ~ 115 deg/m ("approximately"): accept +-1 deg/m;
    # it is above the 45 deg/m bouncing limit, the 0.19 x 2 m block is below it.
    adv = advise(width=0.35, height=0.5, length=1.0, density=1800.0, youngs_modulus=1.8e9)
    assert abs(adv.eta_over_r - 115.0) < 1.0
    assert adv.bouncing_expected
    assert not advise(width=0.19, height=2.0, length=1.0, density=1800.0, youngs_modulus=1.8e9).bouncing_expected


def test_impact_frequencies_and_configuration_rules() -> None:
    # Eq. 1-3 and §2.2: omega_e = sqrt 2 omega_c; stacked = sqrt 2 x single for the same block;
    # one-sided = sqrt 2 x omega_e with B and H swapped. Identities: rel 1e-12.
    single = advise(**FACADE)
    assert single.omega_e == pytest.approx(math.sqrt(2) * single.omega_c, rel=1e-12)
    assert single.omega_crit == pytest.approx(single.omega_e, rel=1e-12)
    e, rho, b, h = 1.8e9, 1750.0, 0.11, 0.8
    assert single.omega_e == pytest.approx(math.sqrt(e * b * b / (rho * b * h * h)), rel=1e-12)  # Eq. 3
    # omega_r from Eq. 1 with Eq. 2: 3 E B^4 / (2 H m_b (B^2 + H^2)). The paper's Eq. 3 prints B^3,
    # which is not a frequency squared (units 1/(m s^2)): a typo; rockdem follows Eq. 1 + Eq. 2.
    assert single.omega_r == pytest.approx(math.sqrt(3 * e * b**4 / (2 * h * rho * b * h * (b * b + h * h))), rel=1e-12)
    stacked = advise(**{**FACADE, "height": 1.6}, blocks=2, configuration="stacked")  # blocks of 0.8 m
    assert stacked.rocking_height == pytest.approx(0.8)
    assert stacked.omega_crit == pytest.approx(math.sqrt(2) * single.omega_crit, rel=1e-12)
    one = advise(**FACADE, configuration=Configuration.ONE_SIDED)
    assert one.omega_crit == pytest.approx(math.sqrt(2) * math.sqrt(e * h * h / (rho * b * h * b)), rel=1e-12)


def test_damping_parameters_follow_eq_4_and_5() -> None:
    # Eq. 4: zeta(omega) = alpha / (2 omega) + beta omega / 2.
    adv = advise(**FACADE, damping_ratio=0.3)
    w = adv.omega_crit

    def zeta(a: float, bt: float, om: float) -> float:
        return a / (2 * om) + bt * om / 2

    assert zeta(0.0, adv.beta_sp, w) == pytest.approx(0.3, rel=1e-12)  # SP only reaches zeta at omega_crit
    assert zeta(adv.rayleigh_alpha, adv.rayleigh_beta, w) == pytest.approx(0.3, rel=1e-12)  # Eq. 5 minimum value
    for f in (0.9, 1.1):  # ... and it is the minimum
        assert zeta(adv.rayleigh_alpha, adv.rayleigh_beta, f * w) > 0.3
    assert adv.alpha_mp == pytest.approx(22.4 * adv.beta_sp + 0.05, rel=1e-12)  # §4.3


def test_joint_stiffness_section_3() -> None:
    # §3: kn = E / l with l = H / n_b; ks = kn / (2 (1 + nu)) = 0.4 kn for nu = 0.25. A discretised
    # block rocking as a whole (§3.2.2): configuration single, given explicitly with blocks > 1.
    adv = advise(**FACADE, blocks=10, configuration="single")
    assert adv.kn == pytest.approx(1.8e9 / 0.08, rel=1e-12)
    assert adv.ks == pytest.approx(0.4 * adv.kn, rel=1e-12)


@pytest.mark.parametrize("points", [1, 2, 5])
def test_omega_max_bound_is_an_upper_bound_of_the_spring_block_system(points: int) -> None:
    # DESIGN §2: the Gershgorin-type sum equals trace(M^-1 K) of the 6-dof block on its sub-contact
    # springs, hence >= the largest eigenvalue and <= 6 x it (K is positive semi-definite, rank 6).
    b, length, h, rho, kn = 0.2, 1.0, 2.0, 1800.0, 1e9
    ks = 0.4 * kn
    m = rho * b * length * h
    inertia = m / 12 * np.array([length**2 + h**2, b**2 + h**2, b**2 + length**2])
    xs = np.linspace(-b / 2, b / 2, points) if points > 1 else np.array([0.0])
    wx = np.full(points, b / max(points - 1, 1)) if points > 1 else np.array([b])
    if points > 1:
        wx[[0, -1]] /= 2
    k = np.zeros((6, 6))
    for x, ax in zip(xs, wx):
        for y in (-length / 2, length / 2):
            r = np.array([x, y, -h / 2])
            for d, kk in ((np.array([0, 0, 1.0]), kn), (np.array([1.0, 0, 0]), ks), (np.array([0, 1.0, 0]), ks)):
                j = np.concatenate((d, np.cross(r, d)))
                k += kk * ax * length / 2 * np.outer(j, j)
    minv = np.diag(1 / np.concatenate(([m, m, m], inertia)))
    lam = np.max(np.linalg.eigvals(minv @ k).real)
    bound = omega_max_bound(b, length, h, rho, kn, ks, points) ** 2
    assert bound >= lam * (1 - 1e-12)
    assert bound <= 6 * lam


def test_timesteps_and_cost_ratio() -> None:
    # DESIGN §2: dt_SP = dt_MP (sqrt(1 + xi^2) - xi), xi = beta omega_max / 2; 3DEC: 0.2 sqrt(m/k).
    adv = advise(**FACADE)
    xi = adv.beta_sp * adv.omega_max / 2
    assert adv.dt_mp == pytest.approx(0.9 * 2 / adv.omega_max, rel=1e-12)
    assert adv.dt_sp == pytest.approx(adv.dt_mp * (math.sqrt(1 + xi * xi) - xi), rel=1e-12)
    assert adv.cost_ratio == pytest.approx(adv.dt_mp / adv.dt_sp, rel=1e-12)
    m, k = 1750 * 0.11 * 1.5 * 0.8, 1.8e9 / 0.8 * 0.11 * 1.5 / 4  # corner point area B L / 4
    assert adv.dt_3dec_mp == pytest.approx(0.2 * math.sqrt(m / k), rel=1e-12)
    assert adv.cost_ratio > 1 and adv.cost_ratio_3dec > 1


def test_rows_carry_unit_and_source() -> None:
    adv = advise(**FACADE)
    rows = list(adv.rows())
    assert len(rows) >= 25
    assert all(unit and source and math.isfinite(value) for _, value, unit, source in rows)
    assert any("Eq. 5" in source for *_, source in rows)
    assert adv.recommendations and any("SP damping" in r for r in adv.recommendations)


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ({"width": -0.1}, "width"),
        ({"height": 0.0}, "height"),
        ({"density": float("nan")}, "density"),
        ({"youngs_modulus": 1800.0}, "youngs_modulus"),  # MPa typed as Pa
        ({"poisson": 0.6}, "poisson"),
        ({"blocks": 0}, "blocks"),
        ({"points": 2.5}, "points"),
        ({"configuration": "sideways"}, "configuration"),
        ({"configuration": "stacked"}, "stacked"),  # needs blocks >= 2
    ],
)
def test_bad_input_raises_naming_the_field(override: dict, field: str) -> None:
    with pytest.raises(ValueError, match=field):
        AdviceInput(**{**FACADE, **override})


def test_squat_block_warns() -> None:
    with pytest.warns(UserWarning, match="H/B"):
        adv = advise(width=0.6, height=0.5, length=1.0, density=1800.0, youngs_modulus=1e9)
    assert adv.warnings


def test_cli_table_json_and_errors(capsys: pytest.CaptureFixture[str]) -> None:
    base = ["advise", "--width", "0.11", "--height", "0.8", "--length", "1.5", "--density", "1750"]
    assert main(base + ["--youngs-modulus", "1.8e9", "--configuration", "one-sided"]) == 0
    assert "beta (SP only)" in capsys.readouterr().out
    assert main(base + ["--youngs-modulus-mpa", "1800", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert abs(data["outputs"]["beta_sp"]["value"] - 0.0047) < 1e-4
    assert data["outputs"]["beta_sp"]["unit"] == "s"
    assert main(base + ["--youngs-modulus", "-5"]) == 2
    assert "youngs_modulus" in capsys.readouterr().err


def test_several_blocks_imply_stacked_and_length_only_changes_the_timestep(capsys: pytest.CaptureFixture[str]) -> None:
    # A two-block wall (paper §4.4, B = 0.11 m, H = 1.5 m): each block rocks (stacked, §2.2:
    # omega_crit = sqrt 2 omega_e of an H/2 block). --blocks 2 without --configuration used to give
    # the single-block beta, sqrt(2) x 2 = 2.8 times too large.
    wall = dict(width=0.11, height=1.5, density=1800.0, youngs_modulus=4.8e7)
    implied = advise(**wall, blocks=2)
    stacked = advise(**wall, blocks=2, configuration="stacked")
    single = advise(**wall, blocks=2, configuration="single")  # explicit: a discretised element rocking as a whole
    assert implied.inputs.configuration is Configuration.STACKED and implied.inputs.configuration_implied
    assert implied.beta_sp == stacked.beta_sp
    assert single.beta_sp / stacked.beta_sp == pytest.approx(2.0 * math.sqrt(2.0), rel=1e-12)
    assert advise(**wall).inputs.configuration is Configuration.SINGLE  # one block: single
    # beta, alpha and eta do not depend on the length; only the timestep estimate does
    short, long_ = advise(**wall, blocks=2, length=0.5), advise(**wall, blocks=2, length=3.0)
    assert (short.beta_sp, short.alpha_mp, short.eta) == (long_.beta_sp, long_.alpha_mp, long_.eta)
    assert implied.inputs.length == 1.0
    # the command line: --length optional, the implied configuration said in the header
    assert main(["advise", "--width", "0.11", "--height", "1.5", "--density", "1800", "--youngs-modulus-mpa", "48",
                 "--blocks", "2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["inputs"]["configuration"] == "stacked" and data["inputs"]["length"] == 1.0
    assert data["outputs"]["beta_sp"]["value"] == pytest.approx(stacked.beta_sp, rel=1e-12)
    assert main(["advise", "--width", "0.11", "--height", "1.5", "--density", "1800", "--youngs-modulus-mpa", "48",
                 "--blocks", "2"]) == 0
    assert "stacked (implied by 2 blocks" in capsys.readouterr().out


def test_advisor_texts_cite_the_paper_not_internal_documents() -> None:
    adv = advise(**FACADE)
    texts = [src for *_, src in adv.rows()] + list(adv.recommendations) + [adv.table()]
    assert not any("DESIGN" in t or "issue" in t.lower() for t in texts)


def test_advisor_targets_the_restitution_and_says_which_beta_and_why(capsys: pytest.CaptureFixture[str]) -> None:
    # --target-restitution: the advisor simulates the block the inputs describe and recommends the
    # beta whose free-rocking impacts give that mean e_a (Eq. 6), with the target, what was
    # achieved and the equations; without it, DeJong's rule (Eq. 3) and why.
    block = ["advise", "--width", "0.2", "--height", "2", "--density", "1800", "--youngs-modulus-mpa", "1800"]
    assert main(block + ["--target-restitution", "eta", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    mb = data["model_beta"]
    e_eta = 1 - 1.5 * math.sin(math.atan(0.1)) ** 2
    assert mb["mode"] == "auto" and mb["target"] == "eta" and mb["target_value"] == pytest.approx(e_eta)
    assert abs(mb["achieved_e_a"] / e_eta - 1) < 0.01 and mb["probe_runs"] >= 2
    assert data["recommended_beta"]["value"] == mb["beta_s"] and data["recommended_beta"]["unit"] == "s"
    assert "Eq. 6" in data["recommended_beta"]["why"]
    plain = advise(width=0.2, height=2.0, density=1800.0, youngs_modulus=1.8e9)
    assert plain.recommended_beta == plain.beta_sp and "Eq. 3" in plain.recommended_why
    assert main(block + ["--target-restitution", "fast"]) == 2
    assert "target_restitution" in capsys.readouterr().err


def test_advisor_per_interface_betas_of_a_one_sided_facade(capsys: pytest.CaptureFixture[str]) -> None:
    # each pair beta = 2 zeta / omega with kn = E / H (paper Eq. 1-4, §2.2): the base landing flat,
    # omega = sqrt(kn A / m) (B x L); the return walls (end faces 2 x 0.11 m x H) struck across the gap
    # by their top row of points (A / 2) on the free façade, 1 / m_eff = (1 + 3 H^2 / (B^2 + H^2)) / m
    adv = advise(**FACADE, configuration="one-sided", per_interface=True)
    c = adv.beta_choice
    m, kn = 1750 * 0.11 * 0.8 * 1.5, 1.8e9 / 0.8
    base, ret = c.pair("facade", "foundation"), c.pair("facade", "return")
    assert base.beta == pytest.approx(2 / math.sqrt(kn * 0.11 * 1.5 / m), rel=1e-9)
    assert ret.beta == pytest.approx(2 / math.sqrt(kn * 0.11 * 0.8 * (1 + 3 * 0.64 / (0.0121 + 0.64)) / m), rel=1e-9)
    assert adv.recommended_beta == max(base.beta, ret.beta)
    assert "sqrt(kn A / m)" in base.how and "per interface" in adv.recommended_why.lower()
    text = adv.table()
    assert "Recommended beta" in text and "facade-return: beta" in text


@pytest.mark.parametrize("kwargs, message", [
    ({"points": 1}, r"points = 1 .* knife edge .* give 2 or more"),
    ({"width": 200.0, "height": 2000.0}, r"width = 200 m is larger than any masonry block .* not mm"),
    ({"release_fraction": 0.5}, r"release_fraction is the release of the target_restitution probe"),
])
def test_advice_inputs_a_run_would_refuse_or_ignore_are_refused(kwargs, message):
    """Before 2026-11-30 these were accepted: one point gave a full table (the engine refuses it),
    mm typed as m a beta of 0.28 s, and a release fraction without a target was ignored."""
    inputs = {"width": 0.2, "height": 2.0, "density": 1800.0, "youngs_modulus": 1.8e9, **kwargs}
    with pytest.raises(ValueError, match=message):
        AdviceInput(**inputs)
