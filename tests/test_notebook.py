"""Notebook use: short reprs and HTML summaries, figures that display inline without pyplot,
blocks selected by name, and the model preview (rockdem show)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rockdem.case import example_case, parse_case
from rockdem.cli import main
from rockdem.preview import preview
from rockdem.results import load, save
from viz_cases import example_result, wall_model

PNG = b"\x89PNG\r\n\x1a\n"


def test_model_and_case_reprs_are_short_summaries():
    case = parse_case(example_case("free-rocking"))
    text = repr(case.model)
    assert len(text) < 1000 and "2 (1 free, 1 driven: foundation)" in text and "beta 0.00693 s" in text
    assert "1 block(s) tilted" in text and "720 kg" in text
    html = case.model._repr_html_()
    assert html.startswith("<b>rockdem Model</b><table>") and "interface points" in html
    assert len(repr(case)) < 1200 and "free-rocking" in repr(case)
    wall = repr(wall_model())
    assert "9 (8 free, 1 driven: ground)" in wall and "... (2 more)" in wall and "ground motion" in wall


def test_result_summary_accessor():
    ds = example_result()
    text = repr(ds.rockdem)
    assert "peak rotation" in text and "energy balance error" in text and len(text) < 3000
    assert ds.rockdem._repr_html_().startswith("<b>rockdem result</b><pre>")
    assert len(ds.rockdem.plot("energy").axes) == 2
    with pytest.raises(ValueError, match="plot kind"):
        ds.rockdem.plot("spaghetti")


def test_figures_display_inline_without_importing_pyplot():
    # A fresh interpreter, as a notebook kernel: the figure's PNG comes from _repr_png_ (what
    # IPython calls for a cell's value) and pyplot is never imported.
    code = (
        "import sys; sys.path.insert(0, %r)\n"
        "from viz_cases import example_result\n"
        "from rockdem.plots import plot_history\n"
        "png = plot_history(example_result())._repr_png_()\n"
        "assert png[:8] == %r, png[:8]\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
        "print(len(png))\n"
    ) % (str(Path(__file__).parent), PNG)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert int(out.stdout.split()[-1]) > 10_000


def test_blocks_are_selected_by_name_or_id(tmp_path):
    ds = example_result()
    assert list(ds.block.values) == ["foundation", "block"]
    by_name = ds.rocking_angle.sel(block="block").values
    np.testing.assert_array_equal(by_name, ds.rocking_angle.values[:, 1])
    np.testing.assert_array_equal(ds.rocking_angle.sel(block_id=1).values, by_name)
    np.testing.assert_array_equal(ds.rocking_angle.isel(block=1).values, by_name)
    back = load(save(ds, tmp_path / "r.nc"))  # names and the id index survive NetCDF
    np.testing.assert_array_equal(back.rocking_angle.sel(block="block").values, by_name)
    np.testing.assert_array_equal(back.rocking_angle.sel(block_id=1).values, by_name)
    assert str(back.block_name.sel(block_id=0).values) == "foundation"


def test_show_previews_the_model_before_running(tmp_path, capsys):
    out = tmp_path / "p.png"
    assert main(["show", "--example", "free-rocking", "-o", str(out)]) == 0
    assert out.read_bytes()[:8] == PNG
    assert "rockdem Model" in capsys.readouterr().out
    case = parse_case(example_case("free-rocking"))
    fig = preview(case.model, case.monitors)
    side = fig.axes[1]
    # the side view draws the tilted block: its projected outline spans the tilted width, and the
    # monitor sits at the block's top corner, moved by the tilt
    x, z = side.lines[0].get_xdata()[0], side.lines[0].get_ydata()[0]
    assert z == pytest.approx(2.0, abs=0.02) and x > 0.1 + 0.15  # 0.1 m half width + tilt of ~0.18 m
    assert main(["show"]) == 2
