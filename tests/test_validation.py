"""Bad input gives a clear error naming the field and the fix."""

import math

import numpy as np

import pytest

from conftest import rocking_block
from rockdem.case import example_case, parse_case
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulate import simulate
from rockdem.timestep import stable_timestep


def _builder():
    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    return b


@pytest.mark.parametrize("density", [0.0, -1.0, math.nan])
def test_density_must_be_positive(density):
    with pytest.raises(ValueError, match="density must be positive"):
        _builder().add_box(0.2, 1, 1, density=density)


@pytest.mark.parametrize("field,value", [("kn", 0.0), ("kn", -1e9), ("ks", -1.0), ("friction_angle", 95.0), ("tension", -1.0)])
def test_material_values_are_checked(field, value):
    kwargs = {"kn": 1e9, field: value}
    with pytest.raises(ValueError, match=field):
        _builder().set_material("a", "b", JointMaterial(**kwargs))


def test_overlapping_blocks_at_start_are_refused():
    b = _builder()
    b.add_box(0.2, 1, 1, base_center=(0, 0, -0.01), name="sunk")
    model = b.finalize()
    with pytest.raises(ValueError, match="'ground' and 'sunk' overlap by 0.01"):
        simulate(model, 0.1)


def test_dt_above_the_stable_bound_is_refused_with_the_bound():
    model = rocking_block(damping=Damping(beta=0.00693))
    bound = stable_timestep(model).critical
    with pytest.raises(ValueError, match=f"above the stable bound {bound:.3e} s"):
        simulate(model, 0.1, dt=1.01 * bound)
    simulate(model, 0.01, dt=0.99 * bound)  # just below is accepted


def test_missing_material_and_no_free_block():
    b = ModelBuilder()
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground", group="g")
    with pytest.raises(ValueError, match="no free block"):
        b.finalize()
    b.add_box(0.2, 1, 1, name="wall", group="w")
    with pytest.raises(ValueError, match="no joint material between groups 'g' and 'g'"):
        b.finalize()


@pytest.mark.parametrize(
    "override,message",
    [
        (("run", "durration", 1.0), r"\[run\] unknown key\(s\) \['durration'\]"),
        (("specimen", "width", -0.2), r"\[specimen\] width must be positive"),
        (("specimen", "type", "pyramid"), r"\[specimen\] type must be one of"),
        (("damping", "beta", "big"), r"\[damping\] beta must be a finite number"),
        (("specimen", "points_across", 0), r"\[specimen\] points_across must be >= 1"),
        (("specimen", "kn", 1e9), r"give exactly one of kn"),
    ],
)
def test_case_file_errors_name_the_table_and_key(override, message):
    data = example_case("free-rocking")
    table, key, value = override
    data[table][key] = value
    with pytest.raises(ValueError, match=message):
        parse_case(data)


def test_unknown_top_level_table():
    data = example_case("free-rocking")
    data["dampin"] = {"beta": 0.1}
    with pytest.raises(ValueError, match=r"\[case\] unknown key\(s\) \['dampin'\]"):
        parse_case(data)


def test_divergence_check_cuts_a_blown_up_run_and_passes_a_sound_one():
    # A sound run keeps its energy balance (error ~1e-3 of the energy scale): no divergence. A run
    # whose balance breaks (here injected: 50 J appear from nothing at frame k) or whose state is no
    # longer finite is cut at the first bad frame (the engine then warns and keeps the frames before).
    from rockdem.simulate import first_diverged_frame

    ds = simulate(rocking_block(0.2, 1.0, tilt=0.5), 0.3, record_interval=0.01)
    assert first_diverged_frame(ds) is None and "diverged" not in ds.attrs
    k = 17
    bad = ds.copy(deep=True)
    bad["energy_balance_error"].values[k:] += 50.0
    assert first_diverged_frame(bad) == k
    bad = ds.copy(deep=True)
    bad["block_position"].values[k + 3, 1, 0] = np.nan
    assert first_diverged_frame(bad) == k + 3
