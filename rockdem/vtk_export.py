"""Export of a result to ParaView: VTK XML unstructured grids (.vtu) per frame plus .pvd series.

Written into ``DIR``:
  blocks_NNNNNN.vtu   one per exported frame: points = every block vertex (world, global vertex
                      ids as in the result's ``vertex_local``), one polygon cell per face.
                      Cell data (per face, from its block): block_id, group_id, free, velocity
                      [m/s], angular_velocity [rad/s], rotation [rad] (rotation vector since the
                      untilted reference), displacement [m] (centroid, since t = 0).
                      Point data: velocity [m/s] (v + omega x r) and displacement [m] (since t = 0).
  blocks.pvd          the time series of the block files (open this one in ParaView).
  contacts_NNNNNN.vtu one per contact snapshot (results run with ``contact_interval``): one vertex
                      cell per sub-contact (interface point with a partner) with point data
                      normal_force [N], shear_force [N] (magnitudes), the vectors normal (unit,
                      partner face normal into the point's block), normal_force_vector [N] and
                      shear_force_vector [N] (elastic forces on the point's block, world: ParaView's
                      Glyph filter draws them as arrows), state (0 bonded, 1 failed in tension,
                      2 failed in shear, 3 unbonded contact), bonded, failed, block, partner, area [m^2].
  contacts.pvd        their time series.
  groups.txt          group_id -> group name.

Arrays are stored inline as base64 binary (UInt64 headers), little-endian, float64 for reals.
The CLI is ``rockdem export RESULT.nc --vtk DIR`` (``--contacts FILE.csv|.parquet`` writes the contact
snapshots as a table, :func:`rockdem.results.contact_table`). By default at most
:data:`DEFAULT_MAX_FILES` block frames are written, evenly spaced (``--every N`` chooses the stride).
"""

from __future__ import annotations

import argparse
import base64
import math
from pathlib import Path
from typing import Mapping
from xml.sax.saxutils import quoteattr

import numpy as np
import xarray as xr

from .cli import output_folder, positive_int
from .kernels.rotation import quats_to_matrices
from .plots import Result, load_result, read_result_file

__all__ = ["VTK_POLYGON", "VTK_VERTEX", "STATE_CODES", "DEFAULT_MAX_FILES", "default_every", "export_vtk", "block_frame_data", "write_vtu", "register_cli"]

VTK_VERTEX = 1
VTK_POLYGON = 7
STATE_CODES = {0: "bonded", 1: "failed in tension", 2: "failed in shear", 3: "unbonded contact"}
"""Values of the contacts' ``state`` array."""

DEFAULT_MAX_FILES = 501
"""Most block frames ``rockdem export`` writes unless ``--every`` is given (a 10 s run recorded every
2 ms has 5,001 frames: every 10th is written)."""



def _type_name(a: np.ndarray) -> str:
    names = {
        np.dtype(np.float64): "Float64",
        np.dtype(np.float32): "Float32",
        np.dtype(np.int64): "Int64",
        np.dtype(np.int32): "Int32",
        np.dtype(np.int8): "Int8",
        np.dtype(np.uint8): "UInt8",
    }
    if a.dtype not in names:
        raise ValueError(f"VTK array of dtype {a.dtype} not supported")
    return names[a.dtype]


def _data_array(name: str, values: np.ndarray) -> str:
    a = np.ascontiguousarray(values)
    a = a.astype(a.dtype.newbyteorder("<"), copy=False)
    comps = "" if a.ndim == 1 else f' NumberOfComponents="{int(a.shape[1])}"'
    raw = a.tobytes()
    text = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")
    return (
        f'<DataArray type="{_type_name(a)}" Name={quoteattr(name)}{comps} '
        f'format="binary">{text}</DataArray>'
    )


def write_vtu(
    path: str | Path,
    points: np.ndarray,
    connectivity: np.ndarray,
    offsets: np.ndarray,
    types: np.ndarray,
    *,
    point_data: Mapping[str, np.ndarray] | None = None,
    cell_data: Mapping[str, np.ndarray] | None = None,
    time: float | None = None,
) -> Path:
    """Write one VTK XML UnstructuredGrid file.

    Args:
        path: output .vtu.
        points: (n, 3) [m].
        connectivity: point ids of all cells, concatenated; offsets: (cells,) end of each cell in it.
        types: (cells,) VTK cell types (e.g. :data:`VTK_POLYGON`).
        point_data, cell_data: arrays (n,) / (n, k) and (cells,) / (cells, k).
        time: written as field data ``TimeValue`` [s].
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    ncell = int(len(types))
    lines = [
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">',
        "<UnstructuredGrid>",
    ]
    if time is not None:
        lines += ["<FieldData>", _data_array("TimeValue", np.array([time], dtype=np.float64)), "</FieldData>"]
    lines += [f'<Piece NumberOfPoints="{len(pts)}" NumberOfCells="{ncell}">', "<Points>"]
    lines += [_data_array("Points", pts), "</Points>", "<Cells>"]
    lines += [
        _data_array("connectivity", np.asarray(connectivity, dtype=np.int64)),
        _data_array("offsets", np.asarray(offsets, dtype=np.int64)),
        _data_array("types", np.asarray(types, dtype=np.uint8)),
        "</Cells>",
    ]
    for tag, data in (("PointData", point_data), ("CellData", cell_data)):
        if data:
            lines.append(f"<{tag}>")
            lines += [_data_array(k, np.asarray(v)) for k, v in data.items()]
            lines.append(f"</{tag}>")
    lines += ["</Piece>", "</UnstructuredGrid>", "</VTKFile>", ""]
    p = Path(path)
    p.write_text("\n".join(lines), encoding="ascii")
    return p


def _write_pvd(path: Path, entries: list[tuple[float, str]]) -> Path:
    rows = "\n".join(f'<DataSet timestep="{t!r}" part="0" file={quoteattr(f)}/>' for t, f in entries)
    path.write_text(
        '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
        f"<Collection>\n{rows}\n</Collection>\n</VTKFile>\n",
        encoding="ascii",
    )
    return path


def block_frame_data(ds: xr.Dataset, frame: int) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """World vertices (nv, 3) [m] at a recorded frame with the point and per-face cell data."""
    start = ds.block_vertex_start.values
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    vl = ds.vertex_local.values
    x, r = ds.block_position.values[frame], quats_to_matrices(ds.block_quaternion.values[frame])
    x0, r0 = ds.block_position.values[0], quats_to_matrices(ds.block_quaternion.values[0])
    arm = np.einsum("vij,vj->vi", r[owner], vl)
    pts = arm + x[owner]
    pts0 = np.einsum("vij,vj->vi", r0[owner], vl) + x0[owner]
    v, w = ds.block_velocity.values[frame], ds.block_angular_velocity.values[frame]
    point_data = {"velocity": v[owner] + np.cross(w[owner], arm), "displacement": pts - pts0}
    face_block = np.repeat(np.arange(len(start) - 1), np.diff(ds.block_face_start.values))
    groups = _group_ids(ds)
    cell_data = {
        "block_id": face_block.astype(np.int32),
        "group_id": groups[face_block].astype(np.int32),
        "free": ds.block_free.values[face_block].astype(np.int8),
        "velocity": v[face_block],
        "angular_velocity": w[face_block],
        "rotation": ds.block_rotation.values[frame][face_block],
        "displacement": ds.block_displacement.values[frame][face_block],
    }
    return pts, point_data, cell_data


def _group_names(ds: xr.Dataset) -> list[str]:
    return sorted({str(g) for g in ds.block_group.values})


def _group_ids(ds: xr.Dataset) -> np.ndarray:
    names = _group_names(ds)
    return np.array([names.index(str(g)) for g in ds.block_group.values], dtype=np.int64)


def _contact_data(ds: xr.Dataset, k: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    partner = ds.point_partner.values[k]
    sel = np.flatnonzero(partner >= 0)
    failed = ds.point_failed.values[k, sel].astype(np.int8)
    bonded = ds.point_bonded.values[k, sel].astype(np.int8)
    state = np.where(failed > 0, failed, np.where(bonded > 0, 0, 3)).astype(np.int8)
    fn = ds.point_normal_force.values[k, sel].astype(np.float64)
    vectors = {}
    if "point_normal" in ds:  # results written before the vectors were recorded lack them
        normal = ds.point_normal.values[k, sel].astype(np.float64)
        vectors = {
            "normal": normal,
            "normal_force_vector": fn[:, None] * normal,
            "shear_force_vector": ds.point_shear_force_vector.values[k, sel].astype(np.float64),
        }
    data = {
        "normal_force": fn,
        "shear_force": ds.point_shear_force.values[k, sel].astype(np.float64),
        "state": state,
        "bonded": bonded,
        "failed": failed,
        "block": ds.point_block.values[sel].astype(np.int32),
        "partner": partner[sel].astype(np.int32),
        "area": ds.point_area.values[sel].astype(np.float64),
        **vectors,
    }
    return ds.point_position.values[k, sel], data


def default_every(frames: int, max_files: int = DEFAULT_MAX_FILES) -> int:
    """Smallest stride that writes at most ``max_files`` of ``frames`` recorded frames."""
    return max(1, math.ceil((frames - 1) / max(max_files - 1, 1))) if frames > max_files else 1


def export_vtk(result: Result, directory: str | Path, *, every: int = 1, contacts: bool = True) -> Path:
    """Write the block geometry per recorded frame (and contact snapshots) for ParaView.

    Args:
        result: a result or its NetCDF path.
        directory: output folder (created).
        every: export every n-th recorded frame.
        contacts: also export the contact snapshots when the result has them.

    Returns:
        The path of ``blocks.pvd``.
    """
    ds = load_result(result)
    if every < 1:
        raise ValueError(f"every must be a positive number of frames, got {every!r}")
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    fs = ds.face_corner_start.values
    conn, offsets = ds.face_vertex.values, fs[1:]
    types = np.full(len(fs) - 1, VTK_POLYGON, dtype=np.uint8)
    entries = []
    for frame in range(0, ds.sizes["time"], every):
        pts, pdata, cdata = block_frame_data(ds, frame)
        t = float(ds.time.values[frame])
        name = f"blocks_{frame:06d}.vtu"
        write_vtu(out / name, pts, conn, offsets, types, point_data=pdata, cell_data=cdata, time=t)
        entries.append((t, name))
    pvd = _write_pvd(out / "blocks.pvd", entries)
    (out / "groups.txt").write_text("".join(f"{i} {g}\n" for i, g in enumerate(_group_names(ds))))
    if contacts and "contact_time" in ds.coords:
        centries = []
        for k, t in enumerate(ds.contact_time.values):
            pts, data = _contact_data(ds, k)
            n = len(pts)
            name = f"contacts_{k:06d}.vtu"
            cells = np.arange(n, dtype=np.int64)
            write_vtu(out / name, pts, cells, cells + 1, np.full(n, VTK_VERTEX, np.uint8), point_data=data, time=float(t))
            centries.append((float(t), name))
        _write_pvd(out / "contacts.pvd", centries)
    return pvd


def _export(args: argparse.Namespace) -> int:
    if not args.vtk and not args.contacts:
        raise ValueError("export: give --vtk DIR (the .vtu files and .pvd series for ParaView) and/or "
                         "--contacts FILE.csv|.parquet (the contact snapshots as a table)")
    ds = read_result_file(args.result)
    if args.contacts:
        from .results import write_contact_table

        print(f"rockdem export: wrote {write_contact_table(ds, args.contacts)}")
    if args.vtk:
        out = output_folder(args.vtk, "--vtk")
        n = ds.sizes["time"]
        every = args.every or default_every(n)
        p = export_vtk(ds, out, every=every, contacts=not args.no_contacts)
        shown = len(range(0, n, every))
        dt = float(np.median(np.diff(ds.time.values))) * every if n > 1 else 0.0
        note = "" if every == 1 else f" (one in {every}, {dt:.3g} s apart; --every 1 for all)"
        print(f"rockdem export: wrote {shown} of {n} frames{note} to {p} (open it in ParaView)")
        if "contact_time" not in ds.coords and not args.no_contacts:
            print("rockdem export: no contact snapshots in this result: run the case with [run] contact_interval "
                  "(or --set run.contact_interval=0.05) to export contacts")
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``export`` sub-command."""
    p = subparsers.add_parser("export", help="export a result for ParaView (VTK files and a .pvd series) or a contact table")
    p.add_argument("result", metavar="RESULT.nc", help="a result written by rockdem run")
    p.add_argument("--vtk", metavar="DIR", help="folder for blocks_*.vtu, contacts_*.vtu and the .pvd files")
    p.add_argument("--every", type=positive_int, default=None,
                   help=f"export every n-th recorded frame (default: at most {DEFAULT_MAX_FILES} frames, evenly spaced)")
    p.add_argument("--no-contacts", action="store_true", help="skip the contact snapshots")
    p.add_argument("--contacts", metavar="FILE", help="write the contact snapshots as a table (.csv, or .parquet with pyarrow)")
    p.set_defaults(func=_export)
