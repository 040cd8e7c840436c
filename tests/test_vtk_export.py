"""Tests of rockdem.vtk_export and of the contact snapshots it needs (simulate's contact_interval).

The exported files are read back with meshio (an independent VTK XML reader) and compared with
the simulated poses applied to the *model's* geometry, with quaternions converted by SciPy.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rockdem.cli import main
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.results import load, save
from rockdem.simulation import simulate
from rockdem.snapshots import BYTES_PER_POINT
from rockdem.vtk_export import STATE_CODES, export_vtk
from viz_cases import wall_model, wall_result


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("vtk")
    path = save(wall_result(), out / "wall.nc")
    assert main(["export", str(path), "--vtk", str(out / "vtk"), "--every", "10"]) == 0
    return out / "vtk"


def _world(model, quats: np.ndarray, pos: np.ndarray) -> np.ndarray:
    """R(q) v_local + x for every model vertex; q scalar-first (w, x, y, z)."""
    a = model.arrays
    out = np.empty_like(a.vertex_local)
    for b in range(model.block_count):
        s = slice(a.block_vertex_start[b], a.block_vertex_start[b + 1])
        r = Rotation.from_quat(quats[b][[1, 2, 3, 0]]).as_matrix()
        out[s] = a.vertex_local[s] @ r.T + pos[b]
    return out


def test_block_vertices_equal_the_simulated_poses_applied_to_the_model(exported):
    ds, model = wall_result(), wall_model()
    for frame in (0, 40, 10 * ((ds.sizes["time"] - 1) // 10)):
        mesh = meshio.read(exported / f"blocks_{frame:06d}.vtu")
        expect = _world(model, ds.block_quaternion.values[frame], ds.block_position.values[frame])
        np.testing.assert_allclose(mesh.points, expect, rtol=0, atol=1e-12)
        faces = np.concatenate([c.data for c in mesh.cells])
        np.testing.assert_array_equal(faces, np.array([f for fs in model.faces for f in fs]))
        blk = np.concatenate(mesh.cell_data["block_id"])
        np.testing.assert_array_equal(blk, np.repeat(np.arange(model.block_count), 6))
        np.testing.assert_allclose(np.concatenate(mesh.cell_data["velocity"]), ds.block_velocity.values[frame][blk])
        np.testing.assert_allclose(np.concatenate(mesh.cell_data["rotation"]), ds.block_rotation.values[frame][blk])


def test_vertex_velocity_is_rigid_body_velocity(exported):
    ds, model = wall_result(), wall_model()
    mesh = meshio.read(exported / "blocks_000040.vtu")
    owner = np.repeat(np.arange(model.block_count), np.diff(model.arrays.block_vertex_start))
    v, w = ds.block_velocity.values[40][owner], ds.block_angular_velocity.values[40][owner]
    arm = mesh.points - ds.block_position.values[40][owner]
    np.testing.assert_allclose(mesh.point_data["velocity"], v + np.cross(w, arm), atol=1e-12)


def test_pvd_series_lists_every_exported_frame_with_its_time(exported):
    ds = wall_result()
    rows = ET.parse(exported / "blocks.pvd").getroot().findall("./Collection/DataSet")
    frames = range(0, ds.sizes["time"], 10)
    assert [r.get("file") for r in rows] == [f"blocks_{f:06d}.vtu" for f in frames]
    np.testing.assert_allclose([float(r.get("timestep")) for r in rows], ds.time.values[list(frames)])
    crows = ET.parse(exported / "contacts.pvd").getroot().findall("./Collection/DataSet")
    assert len(crows) == ds.sizes["contact_time"]


def test_contact_points_carry_forces_and_states(exported):
    ds = wall_result()
    k = ds.sizes["contact_time"] - 1
    mesh = meshio.read(exported / f"contacts_{k:06d}.vtu")
    has = ds.point_partner.values[k] >= 0
    assert len(mesh.points) == np.count_nonzero(has)
    np.testing.assert_allclose(mesh.points, ds.point_position.values[k][has])
    np.testing.assert_allclose(mesh.point_data["normal_force"], ds.point_normal_force.values[k][has])
    state = mesh.point_data["state"]
    assert set(np.unique(state)) <= set(STATE_CODES)
    assert np.any(state == 1)  # the weak wall cracked in tension
    np.testing.assert_array_equal(state == 1, ds.point_failed.values[k][has] == 1)


def test_snapshots_of_a_block_at_rest_balance_its_weight():
    # Static equilibrium: the normal forces of the base sub-contacts sum to m g, and the points lie
    # at the base corners R(q) p_local + x.
    bld = ModelBuilder()
    bld.default_material = JointMaterial(kn=1e9, friction_angle=40)
    bld.add_box(1, 1, 0.2, base_center=(0, 0, -0.2), driven=True, name="ground", group="ground")
    bld.add_box(0.3, 0.4, 0.5, density=2000, name="block")
    model = bld.finalize(damping=Damping(beta=2e-3))
    ds = simulate(model, 0.3, record_interval=0.05, contact_interval=0.1, progress=False)
    assert ds.sizes["contact_time"] == 4
    np.testing.assert_allclose(ds.contact_time.values, [0.0, 0.1, 0.2, 0.3], atol=2 * ds.attrs["dt"])
    fn = np.nansum(ds.point_normal_force.values[-1])
    weight = 2000 * 0.3 * 0.4 * 0.5 * 9.81
    assert fn == pytest.approx(weight, rel=1e-3)
    base = ds.point_block.values == 1
    assert np.count_nonzero(ds.point_partner.values[-1][base] == 0) == 4
    z = ds.point_position.values[-1][ds.point_partner.values[-1] >= 0][:, 2]
    np.testing.assert_allclose(z, -weight / (1e9 * 0.3 * 0.4), atol=1e-9)  # uniform overlap W/(kn A)


def test_snapshot_size_matches_the_documented_bytes_per_point(tmp_path):
    ds = wall_result()
    names = [n for n in ds.data_vars if ds[n].dims[:2] == ("contact_time", "point")]  # every snapshot variable
    assert {"point_position", "point_normal_force", "point_normal", "point_shear_force_vector"} <= set(names)
    per_point = sum(ds[n].dtype.itemsize * (3 if "xyz" in ds[n].dims else 1) for n in names)
    assert per_point == BYTES_PER_POINT
    poses = ["block_position", "block_quaternion", "block_velocity", "block_angular_velocity"]
    assert sum(ds[n].dtype.itemsize * ds.sizes[ds[n].dims[-1]] for n in poses) == 104
    back = load(save(ds, tmp_path / "w.nc"))  # snapshots survive NetCDF
    np.testing.assert_array_equal(back.point_failed.values, ds.point_failed.values)


def test_no_snapshot_variables_without_contact_interval():
    ds = simulate(wall_model(), 0.02, record_interval=0.01, progress=False)
    assert "contact_time" not in ds.coords and "point_position" not in ds


def test_export_errors(tmp_path):
    path = save(wall_result(), tmp_path / "w.nc")
    assert main(["export", str(path)]) == 2  # --vtk missing
    with pytest.raises(ValueError, match="every"):
        export_vtk(path, tmp_path / "v", every=0)
    with pytest.raises(ValueError, match="contact_interval"):
        simulate(wall_model(), 0.01, contact_interval=-1.0)
