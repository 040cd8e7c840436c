"""Bad input gives a clear error naming the field and the fix."""

import math
import os
import re
from pathlib import Path
import warnings

import numpy as np

import pytest

from conftest import rocking_block
from rockdem.case import example_case, parse_case
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulation import simulate
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


def test_a_small_overlap_at_start_is_warned_about_for_the_energy_it_releases():
    # 0.3 mm into the ground, within the contact tolerance: the springs start loaded and throw the
    # cube up (it used to go unnoticed: the energy balance counts the start's elastic energy).
    def cube(sink):
        b = ModelBuilder()
        b.default_material = JointMaterial(kn=5e9, friction_angle=30)
        b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
        b.add_box(0.3, 0.3, 0.3, base_center=(0, 0, -sink), name="cube", density=2000)
        return b.finalize(damping=Damping(beta=1e-4))

    with pytest.warns(UserWarning, match=r"'ground' and 'cube' overlap by 0.0003 m at the start: their joint springs start compressed"):
        ds = simulate(cube(3e-4), 0.05, progress=False)
    z = ds.block_position.sel(block="cube").values[:, 2]
    assert z.max() - z[0] > 0.01  # what the warning is about: thrown up by more than 30 times the overlap
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(cube(0.0), 0.01, progress=False)  # touching: no warning


def test_an_undamped_model_is_warned_about_its_ringing_joints():
    # A 0.4 x 0.4 x 0.2 m block on a 20 deg slope at a 30 deg friction angle, undamped: its joint
    # rings for ever (gravity loads the springs from zero) and ratchets it down the slope, about
    # 1 mm/s. The warning's own suggestion (5 % of the critical beta of its impact) holds it.
    c, s = math.cos(math.radians(20)), math.sin(math.radians(20))
    r = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])

    def slid(damping):
        b = ModelBuilder()
        b.default_material = JointMaterial(kn=5e9, friction_angle=30)
        g = b.add_box(4, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
        k = b.add_box(0.4, 0.4, 0.2, density=2000, name="block")
        b.transform_block(g, r)
        b.transform_block(k, r)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            model = b.finalize(damping=damping)
        ds = simulate(model, 1.0, record_interval=1e-2, progress=False)
        down = -(ds.block_displacement.sel(block="block").values @ (r @ np.array([1.0, 0.0, 0.0])))
        return [str(w.message) for w in caught if "no damping" in str(w.message)], abs(float(down[-1]))

    notes, creep = slid(Damping())
    assert len(notes) == 1 and creep > 5e-4  # ~0.95 mm in 1 s
    hint = float(re.search(r"damping\.beta = ([0-9.e-]+) s", notes[0]).group(1))
    notes, held = slid(Damping(beta=hint))
    assert notes == [] and held < 1e-5  # the elastic shear deflection, a few micrometres


@pytest.mark.parametrize("slope", [29.5, 31.0])
def test_the_undamped_warnings_beta_holds_a_cube_below_its_friction_angle_and_slides_it_at_coulombs_rate(slope):
    """A 0.5 m cube with 3 x 3 points on a slope, friction angle 30 deg, with the beta the warning
    suggests: at 29.5 deg it stays (with the 5 % of critical suggested before 2026-11-29 it crept at
    7 mm/s), at 31 deg it slides at g (sin a - tan 30 cos a) within 1 % (it slid 15 % fast)."""
    a = math.radians(slope)
    r = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])

    def build():
        b = ModelBuilder(points=(3, 3))
        b.default_material = JointMaterial.from_modulus(1e9, 0.5, friction_angle=30)
        b.add_box(4, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
        b.add_box(0.5, 0.5, 0.5, density=2000, name="block")
        b.transform_block("ground", r)
        b.transform_block("block", r)
        return b

    with pytest.warns(UserWarning, match="no damping") as caught:
        build().finalize()
    hint = float(re.search(r"damping\.beta = ([0-9.e-]+) s", str(caught[0].message)).group(1))
    ds = simulate(build().finalize(damping=Damping(beta=hint)), 2.0, record_interval=0.01, progress=False)
    s = ds.block_displacement.sel(block="block").values @ (r @ np.array([1.0, 0.0, 0.0]))  # along the slope
    t = ds.time.values
    if slope < 30.0:
        assert abs(s[-1] - s[100]) < 1e-6  # no creep from 1 to 2 s (it crept 7 mm)
    else:
        fit = np.polyfit(t[100:], s[100:], 2)
        expected = 9.81 * (math.sin(a) - math.tan(math.radians(30)) * math.cos(a))
        assert abs(2.0 * fit[0]) == pytest.approx(expected, rel=0.01)  # measured within 2e-9


def test_the_undamped_warning_stays_quiet_for_damped_joints_and_an_undamped_case_by_choice():
    def block(material_beta):
        b = ModelBuilder()
        b.default_material = JointMaterial(kn=2e9, friction_angle=30, beta=material_beta)
        b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
        b.add_box(0.3, 0.3, 0.6, density=2000, name="block")
        return b

    with pytest.warns(UserWarning, match="no damping"):
        block(0.0).finalize()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        block(1e-4).finalize()  # the joints' own SP damping
    data = example_case("free-rocking")
    data["damping"] = {"beta": 0.0}  # stated: the paper's non-damped strategy (§3.2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_case(data)
    del data["damping"]
    with pytest.warns(UserWarning, match="no damping"):
        parse_case(data)


def test_the_undamped_warning_suggests_settling_only_to_a_case_that_does_not_settle():
    data = example_case("free-rocking")
    data.pop("damping", None)
    for settle in (False, True):
        data.setdefault("run", {})["settle"] = settle
        with pytest.warns(UserWarning, match="no damping") as caught:
            parse_case(data)
        text = " ".join(str(w.message) for w in caught if "no damping" in str(w.message))
        assert ("settle = true" in text) is not settle
        assert all(w.filename == __file__ for w in caught)  # the user's line, not the case module's
    with warnings.catch_warnings():  # the caller's filters still apply to the warning issued again
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="no damping"):
            parse_case(data)


def test_dt_above_the_stable_bound_is_refused_with_the_bound():
    model = rocking_block(damping=Damping(beta=0.00693))
    bound = stable_timestep(model).critical
    with pytest.raises(ValueError, match=f"above the stable bound {bound:.3e} s"):
        simulate(model, 0.1, dt=1.01 * bound)
    simulate(model, 0.01, dt=0.99 * bound)  # just below is accepted
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stable_timestep(model, dt=0.1 * bound)  # a convergence check's tenth: no warning
    with pytest.warns(UserWarning, match=r"dt = 1.000e-09 s is [\d.e+]+ times below the stable bound .* leave dt unset"):
        stable_timestep(model, dt=1e-9)  # (1e8 steps for 0.1 s, without a word before 2026-12-08)


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
        (("specimen", "points_across", 0), r"\[specimen\] points_across must be 2 or more .* got 0"),
        (("specimen", "points_along", -3), r"\[specimen\] points_along must be 2 or more .* got -3"),
        (("specimen", "points_across", 1), r"\[specimen\] points_across = 1 .* knife edge"),
        (("specimen", "points_along", 1), r"\[specimen\] points_along = 1 .* give 2 or more"),
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
    # that creates energy (here injected: 50 J of kinetic energy appear from nothing at frame k) or
    # whose state is no longer finite is cut at the first bad frame (the engine then warns and keeps
    # the frames before). A dissipation booked in excess creates no energy: not a divergence.
    from rockdem.simulation import first_diverged_frame

    ds = simulate(rocking_block(0.2, 1.0, tilt=0.5), 0.3, record_interval=0.01)
    assert first_diverged_frame(ds) is None and "diverged" not in ds.attrs
    k = 17
    bad = ds.copy(deep=True)
    bad["energy_kinetic"].values[k:] += 50.0
    assert first_diverged_frame(bad) == k
    lossy = ds.copy(deep=True)
    lossy["energy_friction"].values[k:] += 50.0
    assert first_diverged_frame(lossy) is None
    bad = ds.copy(deep=True)
    bad["block_position"].values[k + 3, 1, 0] = np.nan
    assert first_diverged_frame(bad) == k + 3


# -- materials, damping and builder arguments check themselves (every path: API, case files, defaults)
@pytest.mark.parametrize(
    "kwargs,field",
    [
        ({"kn": math.nan}, "kn"),  # ran forever at t = 0 before
        ({"kn": 0.0}, "kn"),
        ({"kn": math.inf}, "kn"),
        ({"kn": "1e9"}, "kn"),
        ({"kn": None}, "kn"),
        ({"kn": 1e9, "ks": -1.0}, "ks"),
        ({"kn": 1e9, "cohesion": -1.0}, "cohesion"),
        ({"kn": 1e9, "tension": math.nan}, "tension"),
        ({"kn": 1e9, "friction_angle": "30"}, "friction_angle"),
    ],
)
def test_joint_material_is_checked_on_construction(kwargs, field):
    with pytest.raises(ValueError, match=rf"JointMaterial: {field} must be"):
        JointMaterial(**kwargs)


def test_default_material_must_be_a_material():
    b = ModelBuilder()
    with pytest.raises(ValueError, match="default_material must be a JointMaterial"):
        b.default_material = {"kn": 1e9}
    b.default_material = JointMaterial(kn=1e9)
    assert b.default_material.kn == 1e9


@pytest.mark.parametrize("kwargs,field", [({"alpha": -1.0}, "alpha"), ({"beta": math.nan}, "beta"), ({"alpha": "x"}, "alpha"),
                                          ({"alpha_relative": "yes"}, "alpha_relative")])
def test_damping_is_checked_on_construction(kwargs, field):
    with pytest.raises(ValueError, match=f"damping.{field}"):
        Damping(**kwargs)


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda b: b.add_box("0.2", 1, 1), r"b \(width, x\) must be a positive length"),
        (lambda b: b.add_box(0.2, 1, 1, density="heavy"), "density must be positive"),
        (lambda b: b.add_box(0.2, 1, 1, base_center=(0, 0)), "base_center"),
        (lambda b: b.add_box(0.2, 1, 1, velocity=(1, 2)), "velocity"),
        (lambda b: b.add_box(0.2, 1, 1, points=(10**12, 2)), "points per face exceed the limit of 10000"),
        (lambda b: b.add_block("box"), "poly must be a Polyhedron"),
        (lambda b: b.tilt("nope", 0.5), "tilt: give a block name or id"),
        (lambda b: b.tilt("ground", 0.5), "driven"),
        (lambda b: b.set_material("a", "b", None), "material must be a JointMaterial"),
        (lambda b: b.set_ground_motion("quake"), "give a Motion"),
        (lambda b: b.set_body_acceleration([0, 1], [[1, 0]]), r"acceleration \(n, 3\) must match"),
        (lambda b: b.transform_block("block", 2.0 * np.eye(3)), "rotation must be a 3 x 3 rotation matrix"),
        (lambda b: b.transform_block("block", [[1, 0.3, 0], [0, 1, 0], [0, 0, 1]]), "orthonormal"),
        (lambda b: b.transform_block("block", np.diag([1.0, 1.0, -1.0])), "mirror"),
        (lambda b: b.transform_block("block", np.eye(2)), "3 x 3"),
        (lambda b: b.transform_block("block", np.eye(3), translation=(0, 0, math.nan)), "translation"),
    ],
)
def test_builder_arguments_are_checked(call, message):
    b = _builder()
    b.add_box(0.2, 1, 1, name="block")
    with pytest.raises(ValueError, match=message):
        call(b)


def test_tilt_fraction_is_bounded_by_lying_flat():
    b = _builder()
    b.add_box(0.2, 1, 1, name="block")
    with pytest.raises(ValueError, match="tilts the blocks by 90 deg or more"):
        b.tilt("block", 1e300)


# -- case files: what is read, and numbers beyond reason
def _case_text() -> str:
    return '[run]\nduration = 0.01\n[specimen]\ntype = "block"\nwidth = 0.2\nheight = 1.0\nyoungs_modulus = 1e9\n'


def test_case_file_that_is_not_a_regular_file_is_refused_without_reading(tmp_path):
    from rockdem.case import load_case

    fifo = tmp_path / "case.fifo"
    os.mkfifo(fifo)  # opening it for reading would block forever
    for path, message in ((tmp_path, "is a folder"), (fifo, "not a regular file"), ("/dev/zero", "not a regular file")):
        with pytest.raises(ValueError, match=message):
            load_case(path)
    with pytest.raises(ValueError, match="give a file path"):
        load_case(None)


def test_case_file_encoding_size_and_nesting(tmp_path):
    from rockdem.case import load_case

    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + _case_text().encode())  # written by Windows Notepad: accepted
    assert load_case(bom)["specimen"]["width"] == 0.2
    latin = tmp_path / "latin.toml"
    latin.write_bytes(b"# caf\xe9\n" + _case_text().encode())
    with pytest.raises(ValueError, match=r"not UTF-8 text \(byte 0xe9 at offset 5\)"):
        load_case(latin)
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (9 * 1024**2))
    with pytest.raises(ValueError, match="larger than 8 MiB"):
        load_case(big)
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "{b = " * 500 + "1" + "}" * 500 + "\n")  # RecursionError before
    with pytest.raises(ValueError, match="nested too deeply"):
        load_case(deep)


@pytest.mark.parametrize(
    "table,key,value,message",
    [
        ("specimen", "height", 1e300, r"height = 1e\+300 is beyond any plausible value"),
        ("specimen", "points_across", 10**12, "exceeds the limit of 10000"),  # MemoryError before
        ("loading", "tilt_direction", ["1", "0", "0"], "tilt_direction must be a list of 3 numbers"),
        ("run", "record_interval", 5.0, r"record_interval \(5 s\) exceeds the simulated time"),
    ],
)
def test_absurd_case_values_are_refused_before_the_run(table, key, value, message):
    from rockdem.run_cli import run_case

    data = example_case("free-rocking")
    data["run"]["duration"] = 0.01
    data[table][key] = value
    with pytest.raises(ValueError, match=message):
        run_case(parse_case(data))


def test_peak_ground_acceleration_is_checked_for_plausibility(tmp_path):
    rec = tmp_path / "r.at2"
    rec.write_text("PEER NGA STRONG MOTION DATABASE RECORD\nsynthetic\nACCELERATION TIME SERIES IN UNITS OF G\n"
                   "NPTS=   5, DT=   .0100 SEC\n 0.0 0.1 -0.1 0.05 0.0\n")
    data = example_case("free-rocking")
    data["loading"] = {"type": "earthquake", "record": str(rec), "mode": "inertial", "pga_g": 1e6}
    with pytest.raises(ValueError, match=r"pga_g = 1000000.0 is not plausible"):
        parse_case(data)
    data["loading"]["pga_g"] = 20.0
    with pytest.warns(UserWarning, match=r"pga_g = 20.0 is above 5"):
        parse_case(data)
    data["loading"]["pga_g"] = 0.5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_case(data)
    del data["loading"]["pga_g"]
    data["loading"]["scale"] = 1e4  # the record's 0.1 g peak becomes ~1000 g (after baseline correction)
    with pytest.raises(ValueError, match=r"scaled record's peak ground acceleration \[g\] \(see scale\) = \d+\.?\d* is not plausible"):
        parse_case(data)


def test_simulate_from_the_package_root_is_the_function():
    # The package docstring advertises ``from rockdem import simulate``: it must be the function,
    # also after the module that defines it has been imported.
    import rockdem.simulation
    from rockdem import simulate

    assert callable(simulate) and simulate is rockdem.simulation.simulate
    with pytest.raises(TypeError, match="Model"):
        simulate(None, 1.0)


def _soft_block():
    """A 0.2 x 1 x 1 m block on joints of kn = 1e5 Pa/m: far too soft for its weight."""
    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e5, friction_angle=35)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.2, 1, 1, density=1800, name="block")
    return b.finalize()


def test_a_block_sinking_into_far_too_soft_joints_stops_the_run():
    # kn = 1e5 Pa/m under a 1 m tall block: the static overlap rho g h / kn = 0.18 m is most of
    # its 0.2 m thickness. The run stops once an overlap passes a quarter of the thinner block.
    from rockdem.simulation import SINK_FRACTION, simulate

    with pytest.warns(RuntimeWarning, match="sank"):
        ds = simulate(_soft_block(), 20.0, progress=False)
    assert ds.attrs["diverged"] == 1 and ds.attrs["diverged_reason"] == "sank" and ds.attrs["diverged_blocks"] == "block"
    assert ds.attrs["diverged_time"] < 20.0 and float(ds.time[-1]) < 20.0  # stopped, keeping the frames computed
    sink = -float(ds.block_position.values[-1, 1, 2] - 0.5)
    assert sink > SINK_FRACTION * 0.2 * 0.5  # it had sunk well into the ground when it stopped


def test_a_block_falling_off_the_edge_of_its_foundation_falls_on_and_the_run_completes():
    # A tall block tilted past its slenderness angle near the edge of a small foundation topples
    # over the edge. The run goes on to its end (it is not a divergence), names the block and the
    # time it left, and the block falls freely: g t^2 / 2 below the foundation, energy conserved.
    from rockdem.simulation import simulate

    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e9, friction_angle=35)
    b.add_box(1.0, 1.0, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.2, 0.2, 1.0, base_center=(0.35, 0, 0), density=2000, name="block")
    b.add_box(0.2, 0.2, 0.2, base_center=(-0.3, 0, 0), density=2000, name="stays")
    b.tilt("block", 1.3)  # past its slenderness 0.2 / 1 -> topples towards +x
    with pytest.warns(RuntimeWarning, match="fell off the edge"):
        ds = simulate(b.finalize(damping=Damping(beta=1e-4)), 3.0, progress=False)
    assert ds.attrs.get("diverged", 0) == 0 and float(ds.time[-1]) == pytest.approx(3.0, abs=1e-3)  # the frame nearest the end
    assert ds.attrs["fell_off_blocks"] == "block"
    t_off = float(np.atleast_1d(ds.attrs["fell_off_times"])[0])
    assert 0.3 < t_off < 3.0
    z = ds.block_position.sel(block_id=1).values[:, 2]
    vz = ds.block_velocity.sel(block_id=1).values[:, 2]
    late = ds.time.values > t_off
    # free fall after it left: constant acceleration -g
    acc = np.gradient(vz[late], ds.time.values[late])
    assert np.allclose(acc[2:-2], -9.81, rtol=1e-3)
    assert z[-1] < -2.0
    # the small block stays where it was, resting on the foundation
    assert abs(float(ds.block_position.sel(block_id=2).values[-1, 0]) + 0.3) < 1e-3
    # no energy created: kinetic + potential + elastic never exceed the initial energy
    mech = (ds.energy_kinetic + ds.energy_potential + ds.energy_elastic).values
    assert np.max(mech - mech[0]) <= 1e-3 * float(ds.block_mass[1]) * 9.81


def _run_until_the_cube_falls_off(m, duration: float):
    """Run ``m`` for ``duration`` [s]: it must reach its end, the block "cube" named (and warned
    about) as having left the supports. Returns (result, the time it left [s], that frame)."""
    with pytest.warns(RuntimeWarning, match="fell off the edge"):
        ds = simulate(m, duration, progress=False)
    assert ds.attrs.get("diverged", 0) == 0 and float(ds.time[-1]) == pytest.approx(duration, abs=1e-3)
    assert ds.attrs["fell_off_blocks"] == "cube"
    t_off = float(np.atleast_1d(ds.attrs["fell_off_times"])[0])
    return ds, t_off, int(np.searchsorted(ds.time.values, t_off))


def test_a_block_thrown_clear_of_a_small_foundation_falls_on_and_the_run_completes():
    # A cube sliding off a 0.6 m foundation at 6 m/s flies clear of it and leaves the model's
    # extent (1 m beyond the blocks) through its side, not its bottom, while falling. It has left
    # the supports, as one falling over their edge: the run goes on to its end (before 2026-11-28
    # it stopped as "lost", a divergence), names it, and the cube is in free flight after it left.
    from rockdem.specimens import add_foundation

    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e9 / 0.3, friction_angle=30)
    add_foundation(b, 0.6)
    b.add_box(0.3, 0.3, 0.3, base_center=(0, 0, 0), density=2000, name="cube", velocity=(6.0, 0, 0))
    m = b.finalize(damping=Damping(beta=1e-4))
    ds, t_off, i_off = _run_until_the_cube_falls_off(m, 0.6)
    x, z = ds.block_position.sel(block_id=1).values[:, 0], ds.block_position.sel(block_id=1).values[:, 2]
    assert x[i_off] > m.arrays.extent_high[0] and z[i_off] > m.arrays.extent_low[2]  # it left through the side
    late = ds.time.values > t_off
    v = ds.block_velocity.sel(block_id=1).values[late]
    assert np.allclose(np.gradient(v[:, 2], ds.time.values[late])[2:-2], -9.81, rtol=1e-3)  # free fall
    assert np.allclose(v[:, 0], v[0, 0], rtol=1e-9) and 4.0 < v[0, 0] < 6.0  # flying on at the speed it left with
    mech = (ds.energy_kinetic + ds.energy_potential + ds.energy_elastic).values
    assert np.max(mech - mech[0]) <= 1e-3 * float(ds.block_mass[1]) * 9.81  # no energy created


def test_alpha_that_overdamps_an_assembly_is_warned_about():
    # The discretised 0.19 x 2.0 m wall rocks as one body (2 p = 5.4 1/s); its bricks alone
    # would allow 16 1/s. alpha = 10 over-damps the wall's rocking: warned, naming the body.
    from rockdem.case import apply_overrides, load_case, parse_case

    data = load_case(Path(__file__).resolve().parent.parent / "examples" / "discretised_block_0.19x2.0.toml")
    with pytest.warns(UserWarning, match=r"alpha = 10 1/s over-damps the rocking of the free blocks rocking as one body: .*2 p = 5.3"):
        parse_case(apply_overrides(data, ["damping.alpha=10"]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_case(apply_overrides(data, ["damping.alpha=1"]))


def test_a_block_falling_past_the_trailing_edge_of_a_displaced_foundation_falls_on():
    """A frictionless 0.2 m cube on a 1 m foundation that slides away under it at 1 m/s along -x:
    the cube tips over the foundation's trailing edge and falls past it. It left the supports:
    below the extent it is not under the foundation where that is now. Before 2026-11-28 the
    footprint at the start widened by the displacement still covered the cube's plan, and the run
    stopped as "fell through its support" (El Centro's parapet variants: a brick off the trailing
    edge, 17 m below)."""
    from rockdem.model import Motion

    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e9, friction_angle=0.0)
    b.add_box(1.0, 1.0, 0.25, base_center=(0, 0, -0.25), driven=Motion.constant((-1.0, 0.0, 0.0)), name="foundation")
    b.add_box(0.2, 0.2, 0.2, base_center=(0.3, 0, 0), density=2000, name="cube")
    m = b.finalize(damping=Damping(beta=1e-4))
    ds, _, k = _run_until_the_cube_falls_off(m, 1.2)
    x = float(ds.block_position.sel(block="cube").values[k, 0])
    trailing_edge = float(ds.block_position.sel(block="foundation").values[k, 0]) + 0.5
    # Where it left the extent: within the foundation's plan at the start, past it where it is now.
    assert m.arrays.support_low[0] <= x <= m.arrays.support_high[0] and trailing_edge < x


def test_a_block_beside_a_foundation_that_moves_back_under_it_has_fallen_off_not_through():
    """A cube set beside a 4 m foundation falls past its edge; the foundation then moves 0.5 m
    towards it (1 m/s from 0.5 to 1 s) and covers the cube's plan by the time the cube leaves the
    model's extent, 4.5 m below. The cube left the supports when its centroid passed below them
    beside their plan (0.15 + 0.5 m = g t^2 / 2 at 0.364 s): the run completes and names it.
    Before 2026-11-29 it stopped as "lost" (fell through its support) at 1.016 s."""
    from rockdem.model import Motion

    b = ModelBuilder(points=(2, 2))
    b.default_material = JointMaterial(kn=1e10, friction_angle=35)
    b.add_box(4, 4, 0.5, base_center=(0, 0, -0.5), driven=Motion.constant((1.0, 0, 0), start=0.5, stop=1.0), name="ground")
    b.add_box(0.2, 0.2, 0.2, base_center=(2.3, 0, 0.05), density=2000, name="cube")
    m = b.finalize(damping=Damping(beta=1e-4))
    ds, t_off, _ = _run_until_the_cube_falls_off(m, 1.5)
    assert t_off == pytest.approx(math.sqrt(2 * 0.65 / 9.81), abs=0.003)  # the first frame below the foundation
    x, z = ds.block_position.sel(block="cube").values[-1, [0, 2]]
    edge = float(ds.block_position.sel(block="ground").values[-1, 0]) + 2.0
    assert x < edge and z < m.arrays.extent_low[2]  # under the foundation's plan now, below the extent


def test_a_free_block_with_one_point_across_its_faces_is_warned_about():
    """One point across a face sits at its middle: the block cannot rock about its edges. A driven
    rod (one point across its thin face) is left alone."""
    b = _builder()
    with pytest.warns(UserWarning, match="balances on it"):
        b.add_box(0.2, 1, 1, name="block", points=(1, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        b.add_box(0.02, 0.5, 0.02, base_center=(1, 0, 1), driven=True, name="rod", points=(1, 2))


@pytest.mark.parametrize("point", [(0.0, 0.0, math.nan), (0.0, math.inf, 0.5)])
def test_a_monitor_point_must_be_finite(point):
    b = _builder()
    b.add_box(0.2, 0.5, 1.0, density=2000, name="block")
    with pytest.raises(ValueError, match="monitor 'top': the point .* must be finite"):
        simulate(b.finalize(), 0.01, monitors={"top": ("block", point)}, progress=False)


@pytest.mark.parametrize(("block", "match"), [("nope", r"monitor 'top': no block named 'nope'; blocks are \['ground', 'block'\]"),
                                              (1.5, "monitor 'top': give its block by name or id, got 1.5"),
                                              (7, "monitor 'top': block id 7 out of range")])
def test_a_monitor_on_a_block_that_is_not_there_is_refused_by_name(block, match):
    b = _builder()
    b.add_box(0.2, 0.5, 1.0, density=2000, name="block")
    with pytest.raises(ValueError, match=match):
        simulate(b.finalize(), 0.01, monitors={"top": (block, (0.0, 0.0, 1.0))}, progress=False)


def test_doubtful_values_are_warned_about():
    """A residual friction angle above the peak one, a contact tolerance of the blocks' size and
    free rocking without gravity run, with a warning that says why they are doubtful."""
    with pytest.warns(UserWarning, match="residual_friction_angle = 50 deg exceeds friction_angle = 35"):
        JointMaterial(kn=1e9, friction_angle=35, residual_friction_angle=50)
    b = _builder()
    b.add_box(0.2, 0.5, 1.0, density=2000, name="block")
    with pytest.warns(UserWarning, match="contact_tolerance = 0.5 m exceeds half the smallest block dimension"):
        b.finalize(contact_tolerance=0.5)
    data = example_case("free-rocking")
    data["specimen"]["gravity"] = 0.0
    with pytest.warns(UserWarning, match="gravity = 0: nothing brings the tilted blocks back"):
        parse_case(data)


def test_an_empty_override_removes_a_key_and_only_an_existing_one():
    """``--set loading.scale=`` removes the case's scale, so that pga_g can replace it (the two are
    exclusive and there was no way to drop one from the command line)."""
    from rockdem.case import apply_overrides

    data = {"loading": {"type": "earthquake", "record": "elcentro-rsn6", "scale": 2.0}}
    out = apply_overrides(data, ["loading.pga_g=0.3", "loading.scale="])
    assert out["loading"] == {"type": "earthquake", "record": "elcentro-rsn6", "pga_g": 0.3}
    assert data["loading"]["scale"] == 2.0  # the case itself is left alone
    with pytest.raises(ValueError, match="an empty value removes a key, and the case has no loading.tail"):
        apply_overrides(data, ["loading.tail="])


# -- what a new user's hostile cases found (2026-11-30)
def test_a_misspelt_required_key_is_named_with_the_required_one():
    data = example_case("free-rocking")
    data["specimen"]["widht"] = data["specimen"].pop("width")
    with pytest.raises(ValueError, match=r"\[specimen\] width is required \(a number\); the table has 'widht': a misspelling"):
        parse_case(data)
    del data["specimen"]["widht"]  # nothing like it: the plain message
    with pytest.raises(ValueError, match=r"\[specimen\] width is required \(a number\)$"):
        parse_case(data)


@pytest.mark.parametrize("name", ["../../escape", "/tmp/absolute", "", "  ", "..", "a\\b"])
def test_a_case_name_that_is_not_a_plain_folder_name_is_refused(name):
    data = example_case("free-rocking")
    data["name"] = name
    with pytest.raises(ValueError, match=r"\[case\] name = .* names its output folder"):
        parse_case(data)


@pytest.mark.parametrize("specimen, brick, message", [
    ({"type": "wall", "courses": 2, "bricks_per_course": 2, "joint": {"youngs_modulus": 1e9}},
     [0.1, 0.2, -0.076], r"brick\[2\] \(height, z\) must be a positive length"),
    ({"type": "wall", "courses": 2, "bricks_per_course": 2, "joint": {"youngs_modulus": 1e9}},
     [0.1, 0.0, 0.076], r"brick\[1\] \(length, y\) must be a positive length"),
    ({"type": "parapet", "height": 0.6, "youngs_modulus": 1e9}, [0.23, 0.0], r"brick\[1\] \(height, z\) must be a positive"),
    ({"type": "facade", "youngs_modulus": 1e9}, [0.0, 0.08], r"brick\[0\] \(length, y\) must be a positive"),
])
def test_a_bad_brick_size_is_blamed_on_the_brick_not_the_joint(specimen, brick, message):
    data = example_case("free-rocking")
    data["specimen"] = dict(specimen, brick=brick)
    with pytest.raises(ValueError, match=message):
        parse_case(data)


def test_an_earthquake_that_moves_nothing_is_refused(tmp_path):
    data = example_case("free-rocking")
    data["loading"] = {"type": "earthquake", "record": "elcentro-rsn6", "scale": 0.0}
    with pytest.raises(ValueError, match=r"scale = 0 applies no ground motion"):
        parse_case(data)
    zero = tmp_path / "zero.txt"
    zero.write_text("\n".join("0.0" for _ in range(50)))
    data["loading"] = {"type": "earthquake", "record": str(zero), "units": "g", "dt": 0.01}
    with pytest.raises(ValueError, match=r"its acceleration is zero at every sample"):
        parse_case(data)


def test_parquet_contacts_without_pyarrow_are_refused_before_the_run(monkeypatch):
    import importlib.util

    find = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pyarrow" else find(name, *a))
    data = example_case("free-rocking")
    data["output"] = {"contacts": "parquet"}
    with pytest.raises(ValueError, match=r'contacts = "parquet" needs pyarrow .* contacts = "csv"'):
        parse_case(data)


def test_frames_far_closer_than_a_step_are_refused():
    from rockdem.run_cli import run_case

    data = example_case("free-rocking")
    data["run"].update(duration=0.05, record_interval=1e-7)
    with pytest.raises(ValueError, match=r"record_interval = 1e-07 s puts [\d.e+]+ frames in each time step .* give record_interval >="):
        run_case(parse_case(data))


def test_contact_snapshots_closer_than_a_step_are_refused():
    # one snapshot per step at best; at 1e-12 s the clock stopped while snapshots piled up in memory
    from rockdem.run_cli import run_case

    data = example_case("free-rocking")
    data["run"].update(duration=0.05, contact_interval=1e-12)
    with pytest.raises(ValueError, match=r"contact_interval = 1e-12 s is less than half the time step .* give contact_interval >="):
        run_case(parse_case(data))


def _slider_model(speed: float, seconds: float):
    """A cube resting on the ground and, beside it, a driven block moving at ``speed`` [m/s] along x
    for ``seconds`` [s]."""
    from rockdem.model import Motion

    b = _builder()
    b.add_box(0.2, 0.2, 0.2, density=2000, name="cube")
    b.add_box(0.1, 0.1, 0.1, base_center=(0.7, 0.7, 0.3), driven=Motion.constant([speed, 0.0, 0.0], stop=seconds), name="slider")
    return b.finalize(damping=Damping(beta=1e-4))


def test_a_prescribed_motion_faster_than_the_step_is_refused_and_a_resolved_one_followed():
    with pytest.raises(ValueError, match=r"driven block\(s\) \['slider'\]: the time step .* misses 100% of their prescribed motion"):
        simulate(_slider_model(1e4, 1e-5), 0.05, progress=False)  # 0.1 m in a tenth of a step: it stayed where it was
    ds = simulate(_slider_model(0.5, 0.2), 0.3, record_interval=0.01, progress=False)
    moved = float(ds.block_position.sel(block="slider").isel(time=-1)[0] - ds.block_position.sel(block="slider").isel(time=0)[0])
    assert moved == pytest.approx(0.1, rel=0.01)


def test_a_rod_pushover_that_would_strike_the_specimen_is_refused_and_a_fast_one_warned_about():
    from rockdem.loading import apply_rod_pushover

    for speed, raises in ((10.0, True), (0.5, False)):
        b = _builder()
        b.add_box(0.2, 1.0, 1.0, density=1800, name="block")
        if raises:  # sqrt(g H) = 3.1 m/s for the 1 m block
            with pytest.raises(ValueError, match=r"pushover velocity = 10 m/s: the rod would strike the specimen"):
                apply_rod_pushover(b, displacement=0.1, velocity=speed)
        else:
            with pytest.warns(UserWarning, match=r"pushover velocity = 0.5 m/s is above 0.05 sqrt\(g H\)"):
                apply_rod_pushover(b, displacement=0.1, velocity=speed)


def test_implausible_rocking_speed_and_joint_stiffness_and_no_support():
    data = example_case("free-rocking")
    data["specimen"] = {"type": "facade", "youngs_modulus": 1e9, "rocking_velocity": 1e6}
    data["loading"] = {"type": "gravity"}
    with pytest.raises(ValueError, match=r"rocking_velocity = 1e\+06 rad/s moves the façade's top at .* \(rad/s, not deg/s\)"):
        parse_case(data)
    data["specimen"]["rocking_velocity"] = 2.0  # a strong rocking: accepted
    parse_case(data)
    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e15)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.2, 0.5, 1.0, density=2000, name="block")
    with pytest.warns(UserWarning, match=r"kn = 1e\+15 .* stiffer than any material"):
        b.finalize(damping=Damping(beta=1e-6))
    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9)
    b.add_box(0.2, 0.5, 1.0, density=2000, base_center=(0, 0, 1.0), name="block")
    with pytest.warns(UserWarning, match=r"no driven block: nothing supports its free blocks"):
        b.finalize(damping=Damping(beta=1e-4))


def test_a_file_that_is_not_a_result_is_refused_without_netcdf_advice(tmp_path):
    from rockdem.plots import read_result_file

    npz = tmp_path / "checkpoint.npz"
    np.savez(npz, a=np.zeros(3))
    with pytest.raises(ValueError, match=r"not a rockdem result: not a NetCDF file \(a checkpoint") as err:
        read_result_file(npz)
    assert "engine" not in str(err.value)
    text = tmp_path / "case.toml"
    text.write_text(_case_text())
    with pytest.raises(ValueError, match=r"not a rockdem result: not a NetCDF file; give the result.nc"):
        read_result_file(text)


def test_a_load_along_y_is_measured_about_its_own_axis_in_the_python_api():
    """apply_earthquake, apply_pushover and apply_rod_pushover set the default rocking axis to up x d,
    so that rocking_angle tips blocks along the load (before 2026-11-30 an earthquake along y was
    measured about y: an overturned block read 0 rad, "not overturned")."""
    from rockdem.analysis import summarize_result
    from rockdem.loading import apply_earthquake, apply_pushover
    from rockdem.records import GroundMotion

    b = _builder()
    b.add_box(0.6, 0.2, 1.2, density=2000, name="block")  # slender along y
    apply_earthquake(b, GroundMotion(np.full(50, 2.0), 0.01), direction=(0, 1, 0), mode="inertial")
    assert np.allclose(b.finalize(damping=Damping(beta=1e-4)).rocking_axis, [-1.0, 0.0, 0.0])
    b = _builder()
    b.add_box(0.6, 0.2, 1.2, density=2000, name="block")
    apply_pushover(b, rate=20.0, max_load_factor=1.0, direction=(0, 1, 0))  # 1 g sideways: far above B / H = 1/6
    ds = simulate(b.finalize(damping=Damping(beta=1e-4)), 0.4, record_interval=0.01, progress=False)
    turned = np.linalg.norm(ds.block_rotation.sel(block="block").values[-1])
    assert turned > 0.05
    assert float(ds.rocking_angle.sel(block="block")[-1]) == pytest.approx(turned, rel=1e-6)  # towards +y
    assert summarize_result(ds, block="block")["max_rotation_rad"] == pytest.approx(turned, rel=1e-6)
    with pytest.raises(ValueError, match=r"block 'nope' not in the result; give one of \['ground', 'block'\]"):
        summarize_result(ds, block="nope")


def test_a_sinking_block_stops_the_run_at_the_same_step_on_a_slow_machine(monkeypatch):
    """The sinking check runs at fixed simulated times, not after calls whose length follows the
    machine's speed: the same inputs stop at the same step with the clock running 100 times slower
    (before 2026-11-30 a block that sank 52 % stopped a run on a slow machine only)."""
    import rockdem.simulation as sim

    def run():
        with pytest.warns(RuntimeWarning, match="sank"):
            ds = simulate(_soft_block(), 20.0, progress=False)
        return ds.attrs["diverged_time"], ds.sizes["time"], float(ds.block_position.values[-1, 1, 2])

    fast = run()
    assert fast[0] < 2.0  # found within the first checks (every 0.5 s here), not at the end
    clock = sim._time.perf_counter
    monkeypatch.setattr(sim._time, "perf_counter", lambda: 100.0 * clock())
    assert run() == fast


def test_energy_created_after_dissipation_is_warned_about():
    """The divergence check compares the mechanical energy with the initial one plus the work, so
    energy created after friction had taken some passed it without a word; the balance over the
    recorded frames is now checked (ENERGY_DRIFT_SHARE of the run's scale)."""
    from rockdem.kernels.layout import E_FRICTION, E_KINETIC, ENERGY_NAMES
    from rockdem.simulation import _warn_energy_drift

    t = np.linspace(0.0, 1.0, 5)
    e = np.zeros((5, len(ENERGY_NAMES)))
    e[:, E_KINETIC] = [100.0, 50.0, 10.0, 40.0, 40.0]  # 90 J to friction, then 30 J from nowhere
    e[:, E_FRICTION] = [0.0, 50.0, 90.0, 90.0, 90.0]
    with pytest.warns(RuntimeWarning, match=r"the energy balance is off by \+23.1% of the run.s energy scale \(130 J\) "
                                            r"at t = 0.75 s: the contacts created 30 J"):
        _warn_energy_drift(t, e, 9.81e-3 * 1000.0)  # a tonne lifted by 1 mm: 9.8 J
    assert e[3, E_KINETIC] < e[0, E_KINETIC]  # (never above the initial energy: the divergence check's blind spot)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # the same history in a run whose energies are noise (below 1e-3 of lifting its blocks by
        # 1 mm: a model without gravity or load) is not warned about, as its summary calls it noise
        _warn_energy_drift(t, e * 1e-20, 9.81e-3 * 1000.0)
        e[3:, E_KINETIC] = 12.0  # 2 J created: within 5 %
        _warn_energy_drift(t, e, 9.81e-3 * 1000.0)


def test_a_rod_pushover_with_its_own_material_needs_no_default():
    from rockdem.loading import apply_rod_pushover

    b = ModelBuilder()
    joint = JointMaterial(kn=1e9, friction_angle=35)
    b.set_material("ground", "ground", joint)
    b.set_material("ground", "block", joint)
    b.set_material("block", "block", joint)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground", group="ground")
    b.add_box(0.2, 1.0, 1.0, density=1800, name="block", group="block")
    apply_rod_pushover(b, displacement=0.01, velocity=0.01, material=JointMaterial(kn=1e9, friction_angle=0.0))
    m = b.finalize(damping=Damping(local=0.8))  # refused before 2026-11-30: no material for 'ground'-'pushover_rod'
    assert "rod_pushover" in m.block_names
