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

# §2.1 / Fig. 1: rattling. Free vibration under gravity of blocks L 370 x W 250 x H 120 mm on a fixed
# block, E = 1800 MPa, joints c = 1.4 MPa, ft = 0.84 MPa, mu = 0.7. Amplitudes as printed [m].
RATTLING_BLOCK = (0.37, 0.25, 0.12)  # (L along the wall, W thickness, H) [m]
RATTLING_E = 1800e6  # Pa, kn = E / block height
RATTLING_DENSITY = 1800.0  # kg/m^3 (not stated in §2.1; the paper's value elsewhere)
RATTLING_COHESION = 1.4e6  # Pa
RATTLING_TENSION = 0.84e6  # Pa
RATTLING_FRICTION = 0.7  # mu
RATTLING_FREQUENCY_RANGE = (300.0, 1600.0)  # Hz, columns of two and seven blocks
RATTLING_VERTICAL = {2: 2e-7, 7: 22e-7}  # m: vertical amplitude of the two- and seven-block columns
RATTLING_HORIZONTAL_COLUMN = 1e-20  # m (1e-17 mm): horizontal rattling of the columns (Fig. 1A-C)
RATTLING_WALL_OUT_OF_PLANE = 4e-6  # m (4e-3 mm): seven-course wall with head joints, paper's y (out of plane)
RATTLING_WALL_VERTICAL = 1e-6  # m (1e-3 mm): the same wall, z
RATTLING_WALL_HEIGHTS = (0.84, 3.00)  # m
RATTLING_BASE_FAILURE_DRIFT = 14e-6  # m (14e-3 mm): drift after the base joint failed in tension
RATTLING_COHESIONLESS_BASE = 3e-7  # m (3e-4 mm): seven-block wall, cohesionless base, vertical
RATTLING_COHESIVE_BASE = 4e-6  # m (4e-3 mm): the same wall with the cohesive base, as quoted beside it

# §4.1 / Figs. 10-11: Giaretton et al. parapet, 230 mm thick with 7 mm removed at the base, E = 1800 MPa,
# 1800 kg/m^3; discretised joints c, ft [Pa] with mu = 0.6 and the failed sub-contact shares [%].
PARAPET_THICKNESS = 0.23  # m
PARAPET_BASE_REDUCTION = 0.007  # m
PARAPET_E = 1800e6  # Pa
PARAPET_FRICTION = 0.6
PARAPET_DISCRETISED = {(0.5e6, 0.1e6): (35.0, 55.0), (0.6e6, 0.5e6): (18.0, 19.0)}  # (c, ft): (shear %, tension %)
PARAPET_BASE_TENSION = (0.06e6, 0.07e6, 0.10e6)  # Pa: SP best fit, mortar tests, MP best fit
PARAPET_BASE_TENSION_MORTAR = 0.07e6  # Pa (Giaretton et al. mortar samples)
PARAPET_BASE_TENSION_BEST = {"MP": 0.10e6, "SP": 0.06e6}  # Pa

# §4.2 / Figs. 12-15: one-sided façade of Sorrentino et al. / Shawa et al.
FACADE_BLOCK = (0.11, 0.8, 1.5)  # B, H, L [m]
FACADE_DENSITY = 1750.0  # kg/m^3
FACADE_E = 1800e6  # Pa
FACADE_FRICTION = 0.6
FACADE_GAP = 0.004  # m
FACADE_EDGE_RADIUS = 0.008  # m
FACADE_BETAS = (0.000125, 0.00025, 0.0005, 0.001, 0.002, 0.004, 0.0058)  # s, free rocking (§4.2)
FACADE_BETAS_UNDERDAMPED = (0.000125, 0.00025, 0.0005, 0.001)  # late motion left undamped
FACADE_BETAS_OVERDAMPED = (0.002, 0.004, 0.0058)  # "overdamped after the first impact"
FACADE_BETA_FORMULA = {"one-sided": 0.00017, "two-sided": 0.00470}  # s (§4.2)
FACADE_E_FACTOR_DISCRETISED = 1e-2  # E x 1e-2 brought the discretised model closer to the test
FACADE_DISCRETISED_TOP_DRIFT = 0.004  # m: residual rotational displacement at the top (Fig. 12B)
FACADE_RECORDS = {"bagnoli": 0.191, "sturno": 0.210, "calitri": 0.348}  # shipped record: slope phi [deg]
FACADE_MISSING_RECORD = ("R1168EW", 0.272)  # record name and slope [deg] of Fig. 14C/15C: not available

# §4.4 / Figs. 17-18: Griffith et al. two-block wall
TWO_BLOCK_WALL = (0.11, 1.5, 0.95)  # B, H, L [m]
TWO_BLOCK_DENSITY = 1800.0  # kg/m^3
TWO_BLOCK_E = 48e6  # Pa (Godio and Beyer)
TWO_BLOCK_FRICTION = 0.7
TWO_BLOCK_ALPHA = 0.7539  # 1/s, MP (minimum WME)
TWO_BLOCK_BETA = 0.0032  # s, SP: the §2.2 formula (with E = 1800 MPa, see the study)
TWO_BLOCK_BETA_GODIO = 0.0038  # s, Godio and Beyer
TWO_BLOCK_RECORDS = (("elcentro-rsn6", 0.66), ("pacoima", 0.80), ("nahanni", 1.00))  # record, scale
