"""A preview of a model's geometry before running it: a 3D view and a side view of the blocks at
their initial poses (tilts included), with the monitor points.

The CLI is ``rockdem show CASE.toml [-o PREVIEW.png]`` (also ``--example NAME`` and ``--set``).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Mapping

import numpy as np
import xarray as xr
from matplotlib import rc_context

from .kernels.layout import new_records
from .model import Model
from .plots import STYLE, InlineFigure, save_figure

__all__ = ["initial_frame", "preview", "register_cli"]


def initial_frame(model: Model, monitors: Mapping[str, tuple] | None = None) -> xr.Dataset:
    """A one-frame result of ``model`` at t = 0 (initial poses, at rest), without running it."""
    from .results import build_dataset
    from .simulation import _check_monitors

    driven = int(np.count_nonzero(~model.arrays.block_free.astype(bool)))
    rec = new_records(1, model.block_count, driven)
    rec.position[0] = model.position0
    rec.quaternion[0] = model.quaternion0
    return build_dataset(model, rec, monitors=_check_monitors(model, monitors or {}), attrs={})


def preview(model: Model, monitors: Mapping[str, tuple] | None = None, *, title: str = "") -> InlineFigure:
    """The blocks at their initial poses: an isometric 3D view and a side view (projection on the
    plane normal to the rocking axis), driven blocks grey, monitor points marked (side view)."""
    from .animate import VIEWS, _block_colors, _bounds, _draw_3d, _draw_side, _faces
    from .plots import rocking_direction

    ds = initial_frame(model, monitors)
    frames = np.array([0])
    lo, hi = _bounds(ds, frames, 1.0)
    faces, owner = _faces(ds)
    colors = _block_colors(ds)
    free = int(model.arrays.block_free.sum())
    with rc_context(STYLE):
        fig = InlineFigure(figsize=(9.0, 4.6), layout="constrained")
        ax3 = fig.add_subplot(1, 2, 1, projection="3d")
        _draw_3d(ax3, ds, 0, 1.0, VIEWS["iso"], lo, hi, faces, owner, colors)
        ax3.set_title("3D view (foundation cut to the view)")
        ax2 = fig.add_subplot(1, 2, 2)
        _draw_side(ax2, ds, 0, 1.0, lo, hi, colors)
        d = rocking_direction(ds)
        up = np.cross(d, model.rocking_axis)
        mon = ds.monitor_displacement_absolute.values[0]  # from the reference (untilted) point
        for k, name in enumerate(ds.monitor.values):
            p_now = np.asarray((monitors or {})[str(name)][1], dtype=float) + mon[k]
            ax2.plot(p_now @ d, p_now @ up, "x", color="C3", ms=7)
            ax2.annotate(str(name), (p_now @ d, p_now @ up), xytext=(4, 4), textcoords="offset points", fontsize=8, color="C3")
        ax2.set_title("side view, rocking direction to the right")
        head = title or "model"
        fig.suptitle(f"{head}: {model.block_count} blocks ({free} free), {model.point_count} interface points, "
                     f"free mass {float(model.arrays.block_mass[model.arrays.block_free].sum()):.4g} kg")
    return fig


def _show(args: argparse.Namespace) -> int:
    from .case import apply_overrides, example_case, load_case, parse_case, with_duration
    from .cli import output_file

    if (args.case is None) == (args.example is None):
        raise ValueError("give a case file (rockdem show CASE.toml) or --example NAME")
    data = apply_overrides(example_case(args.example) if args.example else load_case(args.case), args.set or [])
    case = parse_case(with_duration(data, 1.0))  # a preview runs nothing: a case without a duration is shown
    out = output_file(args.output if args.output else f"{case.name}_preview.png", "-o")
    p = save_figure(preview(case.model, case.monitors, title=case.name), out)
    print(repr(case.model))
    print(f"rockdem show: wrote {p}")
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``show`` sub-command."""
    p = subparsers.add_parser("show", help="preview a case's model (3D and side view PNG) without running it")
    p.add_argument("case", nargs="?", help="TOML case file")
    p.add_argument("--example", help="a built-in example instead of a case file")
    p.add_argument("--set", action="append", metavar="TABLE.KEY=VALUE", help="override a case value")
    p.add_argument("-o", "--output", help="output .png or .pdf (default CASENAME_preview.png)")
    p.set_defaults(func=_show)
