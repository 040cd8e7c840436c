"""Published values of Galvez et al. (2022) used beside ours in the reproductions.

Only numbers printed in the paper's text and tables are here; values read off its figures are not
(the figures' data are not published). Section, table or figure of each value in its comment.
"""

from __future__ import annotations

# §3.1: free-rocking blocks (Fig. 2A) with SP and MP damping, 2 interface points, released from
# 90 % of the instability displacement; density 1800 kg/m^3 (§3.2), L = 1 m (assumed, not given).
BLOCK_WIDTHS = (0.19, 0.35)  # B [m]
BLOCK_HEIGHTS = (0.5, 0.9, 1.5, 2.0)  # H [m]
YOUNGS_MODULI = (1000e6, 1800e6, 3600e6)  # E [Pa], kn = E / H (§3)
DENSITY = 1800.0  # kg/m^3
TILT_FRACTION = 0.9
SP_MP_RUNTIME_RATIO = (50.0, 350.0)  # §3.1: "varied from approximately 50 to 350" (3DEC)
EXCLUDED_BLOCK = (0.35, 0.5)  # §3.1: eta = 35 deg, bounced away on the first impact (not in Fig. 4)
BOUNCING_CRITICAL_ETA_OVER_R = 45.0  # deg/m, §3.1 / Fig. 5B: bouncing critical above about this
BOUNCING_LARGEST = (0.35, 0.5, 115.0)  # B, H, eta/R [deg/m]: largest bouncing (Fig. 5B)

# Fig. 16: pragmatic alpha-beta relation (alpha [1/s], beta [s]) fitted to Fig. 4A and §4 matches.
ALPHA_BETA_SLOPE = 22.4  # 1/s^2
ALPHA_BETA_INTERCEPT = 0.05  # 1/s
# §4.1: best single-block fits of the Giaretton et al. parapet free rocking test.
PARAPET_ALPHA = 0.0753  # 1/s (MP)
PARAPET_BETA = 0.00068  # s (SP); the §2.2 formula gave beta = 0.00305 s (overdamped)
PARAPET_BETA_FORMULA = 0.00305  # s
FACADE_BETA = 0.00025  # s, §4.3: free rocking of the non-deteriorated one-sided wall
# §4.2: the §2 formula's beta for the façade (B = 0.11, H = 0.8, L = 1.5 m, 1750 kg/m^3, E = 1800 MPa)
FACADE_BETA_ONE_SIDED = 0.00017  # s, one-sided (return-wall impact, B and H swapped, x sqrt 2)
FACADE_BETA_TWO_SIDED = 0.00470  # s, two-sided rocking block
FACADE_BETAS_UNDERDAMPED_TAIL = (0.000125, 0.00025, 0.0005, 0.001)  # s: late motion left undamped
FACADE_BETAS_OVERDAMPED = (0.002, 0.004, 0.0058)  # s: over-damped after the first impact

# §3.2.1 / Table 1: discretised blocks, no viscous damping, joints that do not fail, base friction
# angle 31 deg; e_eta = 1 - 1.5 sin^2(eta) and 95 % of it.
TABLE1_BLOCKS = ((0.19, 0.5), (0.35, 1.5), (0.19, 2.0))  # (B, H) [m]: eta = 20.8, 13.1, 5.4 deg
TABLE1_KN = (1000e6, 5000e6, 10000e6, 20000e6)  # Pa/m
TABLE1_E_ETA = {(0.19, 0.5): (0.811, 0.770), (0.35, 1.5): (0.922, 0.876), (0.19, 2.0): (0.986, 0.937)}
# mean e_a, WME(e_eta), WME(95 % e_eta) by (B, H) and kn [Pa/m]
TABLE1 = {
    (0.19, 0.5): {1000e6: (0.629, 0.846, 0.841), 5000e6: (0.589, 0.892, 0.886), 10000e6: (0.639, 0.883, 0.878), 20000e6: (0.636, 0.844, 0.836)},
    (0.35, 1.5): {1000e6: (0.938, 0.657, 0.684), 5000e6: (0.918, 0.031, 0.091), 10000e6: (0.919, 0.032, 0.092), 20000e6: (0.915, 0.027, 0.086)},
    (0.19, 2.0): {1000e6: (0.959, 0.618, 0.644), 5000e6: (0.963, 0.008, 0.058), 10000e6: (0.966, 0.006, 0.062), 20000e6: (0.969, 0.002, 0.065)},
}
TABLE1_FRICTION_ANGLE = 31.0  # deg, base joint
# Fig. 7B: runtime of SP-damped single blocks over that of the discretised models
DISCRETISED_SPEEDUP = (2.0, 5.0)  # "approximately two to five times more efficient"
DISCRETISED_SPEEDUP_SQUAT = (30.0, 50.0)  # eta = 20.8 deg block

# §3.2.2 / Fig. 8: the eta = 5.4 deg block (0.19 x 2 m), kn = 10000 MPa/m
FIG8_KN = 10000e6  # Pa/m
FIG8_COHESION = (0.1e6, 0.5e6)  # Pa
FIG8_TENSION = (0.1e6, 0.3e6, 0.5e6)  # Pa
FIG8_FRICTION = (0.30, 0.50, 0.75)  # mu
FIG8_A_TENSION = 0.3e6  # Pa: Fig. 8A/C pairs ft = 0.3 MPa with c and mu
FIG8_B_FRICTION = 0.7  # mu: Fig. 8B/D pairs mu = 0.7 with c and ft

# §3.3 / Table 2 / Fig. 9: B = 0.2, H = 2, L = 1 m, 1800 kg/m^3, E = 1800 MPa, mu > 5,
# SP damping beta = 0.00693 s (free rocking); 3DEC runtime [h] on a Xeon E5-2698 v3.
TABLE2_BLOCK = (0.2, 2.0, 1.0)
TABLE2_E = 1800e6
TABLE2_BETA = 0.00693
TABLE2_POINTS = (2, 3, 4, 5, 10, 15)
TABLE2_HOURS = (6.0, 13.0, 16.0, 20.0, 34.0, 54.0)
