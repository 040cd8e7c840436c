"""Small results shared by the visualisation tests (plots, animation, VTK export), computed once.

- ``example_result``: the built-in ``free-rocking`` example (0.2 x 2 m block released from 90 %
  of its instability angle, SP damping), shortened to 2 s and recorded coarsely;
- ``wall_result``: a discretised wall of 4 courses x 2 bricks with weak bonded joints on a
  foundation given a short velocity pulse: joints fail in tension and shear while it rocks;
- ``synthetic_result``: a hand-made, engine-independent result (deterministic) for image baselines.
"""

from __future__ import annotations

import functools

import numpy as np
import xarray as xr

from rockdem.case import apply_overrides, example_case, parse_case
from rockdem.materials import JointMaterial
from rockdem.model import Damping, Model, ModelBuilder, Motion
from rockdem.simulation import simulate

WALL_BRICK = (0.2, 0.4, 0.25)  # b (rocking direction), l, h [m]


@functools.lru_cache(maxsize=None)
def example_case_model() -> tuple[Model, dict]:
    data = apply_overrides(example_case("free-rocking"), ["run.duration=2.0", "run.record_interval=0.01"])
    case = parse_case(data)
    return case.model, dict(case.monitors)


@functools.lru_cache(maxsize=None)
def example_result() -> xr.Dataset:
    model, monitors = example_case_model()
    return simulate(model, 2.0, record_interval=0.01, monitors=monitors, contact_interval=0.1, progress=False)


@functools.lru_cache(maxsize=None)
def wall_model() -> Model:
    b, l, h = WALL_BRICK
    bld = ModelBuilder()
    bld.default_material = JointMaterial.from_modulus(200e6, h, friction_angle=35)
    bld.add_box(2, 2, 0.3, base_center=(0, 0, -0.3), driven="ground", group="ground", name="ground")
    for i in range(4):
        for j in range(2):
            bld.add_box(b, l, h, base_center=(0, -0.5 * l + l * j, h * i), density=1800, group="brick", name=f"b{i}{j}")
    weak = JointMaterial(kn=200e6 / h, cohesion=100e3, tension=10e3, friction_angle=35)
    bld.set_material("brick", "brick", weak)
    bld.set_material("brick", "ground", weak)
    bld.set_ground_motion(Motion.constant((0.15, 0.0, 0.0), start=0.0, stop=0.05))
    return bld.finalize(damping=Damping(beta=0.0005))


@functools.lru_cache(maxsize=None)
def wall_result() -> xr.Dataset:
    b, l, h = WALL_BRICK
    top = ("b31", (0.5 * b, 0.5 * l, 4 * h))
    return simulate(wall_model(), 0.8, record_interval=0.01, monitors={"top": top}, contact_interval=0.05, progress=False)


def synthetic_result() -> xr.Dataset:
    """A decaying rocking history of a 0.2 x 2 m block, built by hand (no engine involved)."""
    b, h, theta0 = 0.2, 2.0, 0.09
    t = np.linspace(0.0, 4.0, 401)
    theta = theta0 * np.exp(-0.25 * t) * np.cos(2.0 * np.pi * t / 2.4)
    nt = t.size
    quat = np.zeros((nt, 2, 4))
    quat[:, :, 0] = 1.0
    quat[:, 1, 0], quat[:, 1, 2] = np.cos(0.5 * theta), np.sin(0.5 * theta)
    rot = np.zeros((nt, 2, 3))
    rot[:, 1, 1] = theta
    pos = np.zeros((nt, 2, 3))
    pos[:, 0, 2] = -0.25
    pos[:, 1, 2] = 0.5 * h * np.cos(theta)
    box = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    verts = np.concatenate([box * (1.5, 1.5, 0.25), box * (0.5 * b, 0.5, 0.5 * h)])
    mon = np.zeros((nt, 1, 3))
    mon[:, 0, 0] = h * np.sin(theta)
    energy = {
        "energy_kinetic": 30.0 * np.sin(2.0 * np.pi * t / 2.4) ** 2 * np.exp(-0.5 * t),
        "energy_potential": -30.0 * (1.0 - np.exp(-0.5 * t) * np.cos(2.0 * np.pi * t / 2.4) ** 2),
        "energy_damping_stiffness": 30.0 * (1.0 - np.exp(-0.5 * t)),
    }
    ds = xr.Dataset(
        {
            "block_position": (("time", "block", "xyz"), pos),
            "block_quaternion": (("time", "block", "quat"), quat),
            "block_rotation": (("time", "block", "xyz"), rot),
            "block_displacement": (("time", "block", "xyz"), pos - pos[0]),
            "rocking_angle": (("time", "block"), rot[:, :, 1]),
            "monitor_displacement": (("time", "monitor", "xyz"), mon),
            "block_free": ("block", np.array([False, True])),
            "block_name": ("block", np.array(["ground", "block"], dtype=object)),
            "block_group": ("block", np.array(["ground", "block"], dtype=object)),
            "block_mass": ("block", np.array([0.0, 720.0])),
            "vertex_local": (("vertex", "xyz"), verts),
            "block_vertex_start": ("block_p1", np.array([0, 8, 16])),
            **{k: ("time", v) for k, v in energy.items()},
            "energy_balance_error_relative": ("time", 1e-4 * np.sin(3.0 * t)),
        },
        coords={"time": t, "block": [0, 1], "monitor": np.array(["top"], dtype=object)},
        attrs={"rocking_axis": [0.0, 1.0, 0.0], "gravity": [0.0, 0.0, -9.81], "name": "synthetic"},
    )
    return ds
