"""Contact output: the case/CLI option, force vectors checked by statics, the per-contact table,
ParaView glyph arrays, export defaults, and the documented rule for the recorded frame times."""

from __future__ import annotations

import meshio
import numpy as np
import pandas as pd
import pytest

from rockdem.case import apply_overrides, example_case, parse_case
from rockdem.cli import main
from rockdem.materials import JointMaterial
from rockdem.geometry import box
from rockdem.model import Damping, ModelBuilder
from rockdem.results import contact_table, load, save, write_contact_table
from rockdem.simulation import simulate
from rockdem.vtk_export import DEFAULT_MAX_FILES, default_every, export_vtk
from viz_cases import example_result

MASS = 2000 * 0.3 * 0.4 * 0.5  # [kg]
PUSH = 2.0  # horizontal body acceleration [m/s^2], below friction (tan 40 deg g = 8.2 m/s^2)


@pytest.fixture(scope="module")
def pushed():
    """A block at rest on a fixed base under gravity and a steady horizontal body acceleration."""
    bld = ModelBuilder()
    bld.default_material = JointMaterial(kn=1e9, friction_angle=40)
    bld.add_box(1, 1, 0.2, base_center=(0, 0, -0.2), driven=True, name="ground", group="ground")
    bld.add_box(0.3, 0.4, 0.5, density=2000, name="block")
    bld.set_body_acceleration([0.0, 10.0], [[PUSH, 0, 0], [PUSH, 0, 0]])
    model = bld.finalize(damping=Damping(beta=2e-3))
    return simulate(model, 0.4, record_interval=0.05, contact_interval=0.1, progress=False)


def test_contact_force_vectors_balance_the_loads_on_a_block_at_rest(pushed):
    # Statics: the contact forces on the block balance its weight m g (normal) and the body load
    # m a (shear): sum F_n = (0, 0, m g), sum F_s = (-m a, 0, 0); the base normal is +z.
    tab = contact_table(pushed)
    last = tab[tab.time == tab.time.max()]
    assert set(last.block) == {"block"} and set(last.partner) == {"ground"} and len(last) == 4
    np.testing.assert_allclose(last[["nx", "ny", "nz"]].to_numpy(), np.tile([0, 0, 1.0], (4, 1)), atol=1e-9)
    fn = last[["fnx", "fny", "fnz"]].to_numpy().sum(axis=0)
    fs = last[["fsx", "fsy", "fsz"]].to_numpy().sum(axis=0)
    np.testing.assert_allclose(fn, [0, 0, MASS * 9.81], rtol=1e-3, atol=1e-6 * MASS * 9.81)
    np.testing.assert_allclose(fs, [-MASS * PUSH, 0, 0], rtol=2e-3, atol=1e-3 * MASS * PUSH)
    np.testing.assert_allclose(np.linalg.norm(last[["fsx", "fsy", "fsz"]], axis=1), last.shear_force, rtol=1e-12)


def test_vtk_contacts_carry_glyph_vectors(pushed, tmp_path):
    export_vtk(pushed, tmp_path)
    k = pushed.sizes["contact_time"] - 1
    mesh = meshio.read(tmp_path / f"contacts_{k:06d}.vtu")
    has = pushed.point_partner.values[k] >= 0
    n, fn = pushed.point_normal.values[k][has], pushed.point_normal_force.values[k][has]
    np.testing.assert_allclose(mesh.point_data["normal"], n)
    np.testing.assert_allclose(mesh.point_data["normal_force_vector"], fn[:, None] * n)
    np.testing.assert_allclose(mesh.point_data["shear_force_vector"], pushed.point_shear_force_vector.values[k][has])


def test_contact_table_formats_and_its_error(pushed, tmp_path):
    p = write_contact_table(pushed, tmp_path / "c.csv")
    back = pd.read_csv(p)
    np.testing.assert_allclose(back.normal_force, contact_table(pushed).normal_force)
    auto = write_contact_table(pushed, tmp_path / "contacts")
    assert auto.suffix in (".csv", ".parquet")
    with pytest.raises(ValueError, match="contact_interval"):
        contact_table(simulate_no_contacts())


def simulate_no_contacts():
    case = parse_case(apply_overrides(example_case("free-rocking"), ["run.duration=0.02"]))
    return simulate(case.model, 0.02, progress=False)


def test_case_and_cli_option_contact_interval(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["run", "--example", "free-rocking", "--duration", "0.3", "--quiet", "--no-plot", "--no-checkpoint",
            "--out", str(out), "--set", "run.contact_interval=0.1"]
    assert main(args) == 0
    ds = load(out / "result.nc")
    assert ds.sizes["contact_time"] == 4
    table = list(out.glob("contacts.*"))
    assert len(table) == 1
    assert main(["export", str(out / "result.nc"), "--vtk", str(tmp_path / "vtk")]) == 0
    assert len(list((tmp_path / "vtk").glob("contacts_*.vtu"))) == 4
    assert main(["export", str(out / "result.nc"), "--contacts", str(tmp_path / "t.csv")]) == 0
    assert len(pd.read_csv(tmp_path / "t.csv")) == int((ds.point_partner.values >= 0).sum())
    with pytest.raises(ValueError, match=r"\[run\] contact_interval must be positive"):
        parse_case(apply_overrides(example_case("free-rocking"), ["run.contact_interval=0"]))


def test_export_writes_at_most_the_default_number_of_frames(tmp_path, capsys):
    assert default_every(5001) == 10 and default_every(501) == 1 and default_every(502) == 2
    assert len(range(0, 5001, default_every(5001))) <= DEFAULT_MAX_FILES
    ds = example_result()  # 201 frames: all written
    path = save(ds, tmp_path / "r.nc")
    assert main(["export", str(path), "--vtk", str(tmp_path / "v")]) == 0
    assert len(list((tmp_path / "v").glob("blocks_*.vtu"))) == ds.sizes["time"]
    assert main(["export", str(path), "--vtk", str(tmp_path / "w"), "--every", "50"]) == 0
    assert len(list((tmp_path / "w").glob("blocks_*.vtu"))) == 5
    assert "one in 50," in capsys.readouterr().out


def test_frames_are_recorded_at_exact_multiples_of_the_interval():
    # Poses and velocities are taken on the leapfrog trajectory at k dt_rec (kernels.step._record_pose).
    ds = example_result()
    t = ds.time.values
    k = np.arange(t.size)
    assert np.max(np.abs(t - k * 0.01)) <= 1e-12


def test_frames_between_steps_follow_free_flight_exactly():
    """A block thrown upward and spinning, no contact (closed forms): the spin angle is omega t and
    the height the parabola z0 + v t - g t^2 / 2 at each frame time, although the frames (every
    7 ms) fall between steps. The leapfrog path is off its parabola by at most g dt^2 / 8 between
    steps; a frame taken at the nearest step instead would be off by up to |v| dt / 2 in height
    and omega dt / 2 in angle. The parabola's v(0) is the given 3 m/s: the first velocity update
    spans half a step (until 2026-11-29 it took the initial velocity as that of the half step
    before t = 0, and the parabola's v(0) was v0 - g dt / 2)."""
    b = ModelBuilder()
    b.default_material = JointMaterial.from_modulus(1.8e9, 0.4)
    b.add_box(1.0, 1.0, 0.1, base_center=(0, 0, -5.0), driven=True, name="far ground")
    b.add_block(box(0.2, 0.3, 0.4, center=(0.0, 0.0, 1.0)), name="thrown", velocity=(0.0, 0.0, 3.0),
                angular_velocity=(0.0, 5.0, 0.0))
    model = b.finalize()
    ds = simulate(model, 0.5, record_interval=0.007, progress=False)
    t = ds.time.values
    dt = ds.attrs["dt"]
    assert 0.007 / dt % 1.0 > 0.05  # the frames do fall between steps
    k = int(np.flatnonzero(ds.block_free.values)[0])
    z = ds.block_position.values[:, k, 2]
    v_start = 3.0
    exact = 1.0 + v_start * t - 0.5 * 9.81 * t * t
    assert np.max(np.abs(z - exact)) <= 9.81 * dt * dt / 8 + 1e-12
    assert np.max(np.abs(z - exact)) < 0.01 * 3.0 * 0.5 * dt  # far below the nearest-step error
    vz = ds.block_velocity.values[:, k, 2]
    assert np.max(np.abs(vz - (v_start - 9.81 * t))) <= 1e-9
    angle = np.abs(ds.block_rotation.values[:, k, 1])
    assert np.max(np.abs(angle - 5.0 * t)[5.0 * t < np.pi]) <= 1e-9
