"""Results: displacements relative to the ground (absolute kept, both labelled) and safe saving."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
import xarray as xr

from rockdem.loading import apply_earthquake
from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.records import read_record
from rockdem.results import export_csv, load, save
from rockdem.simulation import simulate

B, H, RHO, E = 0.2, 1.0, 1800.0, 1.8e9


def _earthquake_run(mode: str) -> xr.Dataset:
    """A 0.2 x 1 m block under 1.5 s of El Centro (record 1.0-2.5 s, around its 2.18 s peak)."""
    bld = ModelBuilder(points=(2, 2))
    bld.default_material = JointMaterial(kn=E / H, friction_angle=80.0)
    bld.add_box(2.0, 2.0, 0.5, base_center=(0, 0, -0.5), driven="ground", name="foundation", points=(2, 2))
    bld.add_box(B, 0.5, H, density=RHO, name="block")
    apply_earthquake(bld, read_record("elcentro-rsn6"), mode=mode, window=(1.0, 2.5))
    beta = 2.0 / math.sqrt(E * B / (RHO * H * H))
    model = bld.finalize(damping=Damping(beta=beta))
    return simulate(model, 1.5, monitors={"top": ("block", (B / 2, 0.0, H))}, record_interval=0.005, progress=False)


@pytest.fixture(scope="module")
def runs() -> dict[str, xr.Dataset]:
    return {mode: _earthquake_run(mode) for mode in ("foundation", "inertial")}


def test_displacements_are_relative_to_the_ground_by_default(runs):
    # Foundation mode moves the ground-driven foundation with the record's displacement (here tens
    # of mm); the response relative to the ground is frame invariant: it equals the inertial-mode
    # response (fixed foundation). The difference of the two frames is O(substep) (see
    # tests/test_loading.py); tolerance 2 % of the peak relative displacement.
    fnd, ine = runs["foundation"], runs["inertial"]
    ug = fnd.ground_displacement.values
    assert np.abs(ug[:, 0]).max() > 0.01  # the ground really moved
    rel = fnd.monitor_displacement.values[:, 0, 0]
    ref = ine.monitor_displacement.values[:, 0, 0]
    peak = np.abs(ref).max()
    assert peak > 1e-4  # the block responded
    assert np.abs(rel - ref).max() < 0.02 * peak
    # absolute = relative + ground, for monitors and centroids; labels say which is which
    np.testing.assert_allclose(fnd.monitor_displacement_absolute.values, fnd.monitor_displacement.values + ug[:, None], atol=1e-12)
    np.testing.assert_allclose(fnd.block_displacement_absolute.values, fnd.block_displacement.values + ug[:, None], atol=1e-12)
    assert np.abs(fnd.block_displacement.values[:, 0]).max() == 0.0  # the foundation itself is the ground
    assert fnd.monitor_displacement.attrs["reference"] == fnd.attrs["displacement_reference"] == "ground"
    assert fnd.monitor_displacement_absolute.attrs["reference"] == "fixed frame"
    # inertial mode: no moving ground, relative = absolute, labelled so
    assert ine.attrs["displacement_reference"] == "fixed frame"
    np.testing.assert_array_equal(ine.monitor_displacement.values, ine.monitor_displacement_absolute.values)
    # rotations do not see a translating ground
    th_f, th_i = fnd.rocking_angle.values[:, 1], ine.rocking_angle.values[:, 1]
    assert np.abs(th_f - th_i).max() < 0.02 * np.abs(th_i).max()


def test_ground_displacement_is_the_records_double_integral(runs):
    # The driven foundation follows v_g(t) (trapezoid integral of the baseline-corrected record):
    # its displacement is the integral of v_g, to the engine's step (dt ~ 1e-5 s) accuracy.
    fnd = runs["foundation"]
    gm = read_record("elcentro-rsn6")
    from rockdem.loading import prepare_record

    used = prepare_record(gm, window=(1.0, 2.5))
    t = fnd.time.values
    expect = np.interp(t, used.time - used.time[0], used.displacement())
    ug = fnd.ground_displacement.values[:, 0]
    assert np.abs(ug - expect).max() < 0.01 * np.abs(expect).max()


def test_csv_labels_relative_columns_and_adds_the_ground(runs, tmp_path):
    path = export_csv(runs["foundation"], tmp_path / "h.csv")
    header = path.read_text().splitlines()[0].split(",")
    assert "top.ux rel. ground [m]" in header and "ground.ux [m]" in header and "top.ux [m]" not in header


def test_csv_is_the_file_pandas_writes(runs, tmp_path):
    # export_csv formats the numbers itself: the bytes of pandas' to_csv for the histories of a run,
    # and for random columns: every float64 magnitude, random bit patterns, NaN (an empty field),
    # infinities, -0.0, integers, float32 and booleans; header names that need quoting
    import pandas as pd

    from rockdem.results import _write_csv

    path = export_csv(runs["foundation"], tmp_path / "h.csv")
    table = pd.read_csv(path)
    pd.DataFrame({c: table[c].to_numpy() for c in table.columns}).to_csv(tmp_path / "pandas.csv", index=False)
    assert path.read_bytes() == (tmp_path / "pandas.csv").read_bytes()
    rng = np.random.default_rng(7)
    n = 5000
    bits = rng.integers(0, 2**64, size=n, dtype=np.uint64).view(np.float64)
    special = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 1e16, 1e-5, 1e-4, 0.1, 123456789.0])
    cols = {
        "time [s]": np.linspace(0.0, 10.0, n),
        "scaled": rng.normal(size=n) * 10.0 ** rng.integers(-30, 30, size=n),
        'bits, "raw"': bits,
        "special": rng.choice(special, size=n),
        "count [-]": rng.integers(-(2**40), 2**40, size=n),
        "single": rng.normal(size=n).astype(np.float32),
        "flag": rng.uniform(size=n) < 0.5,
    }
    _write_csv(tmp_path / "mine.csv", cols)
    pd.DataFrame(cols).to_csv(tmp_path / "theirs.csv", index=False)
    assert (tmp_path / "mine.csv").read_bytes() == (tmp_path / "theirs.csv").read_bytes()


def _small_result() -> xr.Dataset:
    bld = ModelBuilder(points=(2, 2))
    bld.default_material = JointMaterial(kn=E / H, friction_angle=80.0)
    bld.add_box(2.0, 2.0, 0.5, base_center=(0, 0, -0.5), driven=True, name="foundation")
    bld.add_box(B, 0.5, H, density=RHO, name="block")
    return simulate(bld.finalize(), 0.01, record_interval=0.005, progress=False)


def test_interrupted_save_leaves_no_truncated_file(tmp_path, monkeypatch):
    # A second Ctrl-C during the write: the destination must keep its previous content (or not
    # exist), never hold a partial file that still opens; no temporary file is left behind.
    ds = _small_result()
    dest = tmp_path / "result.nc"
    real = xr.Dataset.dump_to_store

    def interrupted(self, store, **kwargs):
        real(self.isel(time=[0]), store)  # a valid but incomplete file on disk...
        raise KeyboardInterrupt  # ...then the interruption

    monkeypatch.setattr(xr.Dataset, "dump_to_store", interrupted)
    with pytest.raises(KeyboardInterrupt):
        save(ds, dest)
    assert not dest.exists()
    dest.write_bytes(b"previous result")
    with pytest.raises(KeyboardInterrupt):
        save(ds, dest)
    assert dest.read_bytes() == b"previous result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.nc"]
    monkeypatch.setattr(xr.Dataset, "dump_to_store", real)
    save(ds, dest)
    assert load(dest).sizes["time"] == ds.sizes["time"]


def test_save_writes_the_bytes_of_xarrays_to_netcdf_without_importing_distributed(tmp_path, monkeypatch):
    # save() writes through the NetCDF4 store directly: the file must be the one Dataset.to_netcdf
    # writes, byte for byte; and a process that saves does not import dask.distributed (0.2 s)
    import subprocess
    import sys

    import rockdem.results

    ds = _small_result()
    save(ds, tmp_path / "direct.nc")
    monkeypatch.setattr(rockdem.results, "_write_netcdf", lambda d, path, encoding: d.to_netcdf(path, encoding=encoding))
    save(ds, tmp_path / "xarray.nc")
    assert (tmp_path / "direct.nc").read_bytes() == (tmp_path / "xarray.nc").read_bytes()
    pytest.importorskip("distributed")
    code = ("import sys; from rockdem.results import load, save; "
            f"save(load({str(tmp_path / 'direct.nc')!r}), {str(tmp_path / 'again.nc')!r}); "
            "print('distributed' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.strip() == "False"
    xr.testing.assert_identical(load(tmp_path / "again.nc"), load(tmp_path / "direct.nc"))


def test_save_computes_a_result_held_as_dask_arrays(tmp_path):
    pytest.importorskip("dask")
    ds = _small_result()
    save(ds.chunk({"time": 1}), tmp_path / "chunked.nc")
    save(ds, tmp_path / "plain.nc")
    xr.testing.assert_identical(load(tmp_path / "chunked.nc"), load(tmp_path / "plain.nc"))


def test_building_a_result_does_not_import_dask_array_and_dask_arrays_still_work(tmp_path):
    # xarray imports dask.array (0.2 to 0.7 s) at its first Variable wherever dask is installed, and
    # dask (0.07 s) to ask whether an array is a dask collection; rockdem's record of dask resolves
    # its array type only once dask.array is imported, and the question is answered no without dask
    # for an object without __dask_graph__.
    pytest.importorskip("dask")
    import subprocess
    import sys

    code = ("import sys; import xarray as xr; from rockdem.results import save, load; "
            "from rockdem.model import ModelBuilder; from rockdem.materials import JointMaterial; "
            "from rockdem.simulation import simulate; "
            "b = ModelBuilder(); b.default_material = JointMaterial.from_modulus(1.8e9, 2.0); "
            "b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True); b.add_box(0.2, 1, 2); "
            "ds = simulate(b.finalize(), 0.01, progress=False); "
            f"save(ds, {str(tmp_path / 'a.nc')!r}); r = load({str(tmp_path / 'a.nc')!r}); "
            "print('dask' in sys.modules, int((r.contacts_active * 0 + 2).sum()) == 2 * r.sizes['time']); "
            "import dask.array as da; from xarray.namedarray.pycompat import array_type; "
            "from xarray.namedarray.utils import is_duck_dask_array; import numpy as np; "
            "c = xr.Dataset({'x': ('time', da.arange(4.0, chunks=2))}); "
            "print(array_type('dask') == (da.Array,), isinstance(c.x.data, da.Array), c.x.chunks, float(c.x.sum()), "
            "is_duck_dask_array(c.x.data), is_duck_dask_array(np.arange(3.0)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    first, second = out.stdout.strip().splitlines()[-2:]
    assert first == "False True"  # neither dask nor dask.array imported
    assert second == "True True ((2, 2),) 6.0 True False"


def test_save_replaces_a_symlink_instead_of_writing_through_it(tmp_path):
    ds = _small_result()
    target = tmp_path / "elsewhere.txt"
    target.write_text("not yours to overwrite")
    link = tmp_path / "result.nc"
    os.symlink(target, link)
    save(ds, link)
    assert target.read_text() == "not yours to overwrite"
    assert link.is_file() and not link.is_symlink()
    assert load(link).sizes["time"] == ds.sizes["time"]
    with pytest.raises(ValueError, match="is a folder"):
        save(ds, tmp_path)


def test_energy_check_closed_forms():
    """energy_check on synthetic energies: an exchange between kinetic and potential energy creates
    nothing; a dissipated joule booked as friction keeps the balance; a bump of 5 J is 5 J created."""
    from rockdem.kernels.layout import E_ELASTIC, E_FRICTION, E_KINETIC, E_POTENTIAL, ENERGY_NAMES, W_DRIVEN
    from rockdem.results import energy_check

    n = 200
    t = np.linspace(0.0, 1.0, n)
    e = np.zeros((n, len(ENERGY_NAMES)))
    e[:, E_KINETIC] = 10.0 * np.sin(2 * np.pi * t) ** 2
    e[:, E_POTENTIAL] = -10.0 * np.sin(2 * np.pi * t) ** 2 - 1.0 * t  # 1 J lost over the run ...
    e[:, E_FRICTION] = 1.0 * t  # ... to friction
    chk = energy_check(e)
    assert chk.created == pytest.approx(0.0, abs=1e-12)
    assert chk.balance_error == pytest.approx(0.0, abs=1e-12)
    assert chk.scale == pytest.approx(np.max(20.0 * np.sin(2 * np.pi * t) ** 2 + 2.0 * t), rel=1e-12)  # kinetic + |potential| + lost
    e[n // 2 :, E_ELASTIC] += 5.0  # energy from nowhere
    chk = energy_check(e)
    assert chk.created == pytest.approx(5.0 - 1.0 / (n - 1), rel=1e-9)  # the rise less one sample's friction loss
    assert chk.balance_error == pytest.approx(5.0, rel=1e-9)
    e[n // 2 :, W_DRIVEN] += 5.0  # ... unless a driven block did that work
    assert energy_check(e).created == pytest.approx(0.0, abs=1e-9)


def test_summary_rows_carry_the_energy_check():
    """A damped free-rocking block creates no energy: the row's check is near zero, its balance
    error small against its energy scale."""
    from rockdem.case import example_case
    from rockdem.studies import RunSpec, run_spec

    row = run_spec(RunSpec.make(example_case("free-rocking"), duration=1.5))
    assert row["energy_scale_J"] > 0.0
    assert 0.0 <= row["energy_created_J"] < 1e-3 * row["energy_scale_J"]
    assert abs(row["energy_error_J"]) < 0.01 * row["energy_scale_J"]
