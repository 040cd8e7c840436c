"""Tests of rockdem.plots: every plot kind on the built-in example and on a discretised wall,
the kinematics behind the plotted quantities, WME in the comparison legend, and an image
regression of two figures against stored baselines.

Baselines: tests/baseline/*.png, drawn from an engine-independent synthetic result with the fixed
style of rockdem.plots.STYLE; regenerate with ``ROCKDEM_UPDATE_BASELINES=1 pytest tests/test_plots.py``.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from matplotlib.testing.compare import compare_images
from PIL import Image

from rockdem.cli import main
from rockdem.plots import (
    PLOTS,
    block_dimensions,
    plot_comparison,
    plot_history,
    plot_restitution,
    save_figure,
    top_displacement,
)
from rockdem.results import load, save
from viz_cases import example_result, synthetic_result, wall_result

BASELINE = Path(__file__).parent / "baseline"


@pytest.fixture(scope="module")
def result_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("results")
    return {"example": save(example_result(), d / "example.nc"), "wall": save(wall_result(), d / "wall.nc"),
            "pushover": save(_rod_pushover(0.3, 1.2, 0.9, 8.0), d / "pushover.nc")}


def _nonempty_image(path: Path) -> None:
    assert path.stat().st_size > 1000
    with Image.open(path) as im:
        pixels = np.asarray(im.convert("L"), dtype=float)
    assert pixels.std() > 5.0  # something is drawn, not a blank canvas


@pytest.mark.parametrize("which", ["example", "wall", "pushover"])
@pytest.mark.parametrize("kind", sorted(PLOTS))
def test_every_plot_command_writes_an_image(result_files, tmp_path, kind, which, capsys):
    out = tmp_path / f"{which}_{kind}.png"
    code = main(["plot", str(result_files[which]), "--kind", kind, "-o", str(out), "--dpi", "50"])
    if kind == "capacity" and which != "pushover":  # a capacity curve of a free-rocking run is meaningless
        assert code == 2 and "not a pushover" in capsys.readouterr().err
        assert not out.exists()
        return
    if kind == "comparison":  # one result alone (drawn as its own reference before 2026-12-08) ...
        assert code == 2 and "nothing to compare; give two or more RESULTs, or --measured" in capsys.readouterr().err
        assert not out.exists()
        # ... and with itself, or a measured history
        code = main(["plot", str(result_files[which]), str(result_files[which]), "--kind", kind, "-o", str(out), "--dpi", "50"])
    assert code == 0
    _nonempty_image(out)


def test_plot_all_writes_the_plots_that_apply_and_says_which_it_skipped(result_files, capsys):
    # free rocking: no capacity curve, and nothing to compare one result with
    assert main(["plot", str(result_files["example"]), "--kind", "all", "--format", "pdf"]) == 0
    out = capsys.readouterr().out
    for kind in PLOTS:
        p = result_files["example"].with_name(f"example_{kind}.pdf")
        if kind in ("capacity", "comparison"):
            assert not p.exists() and f"skipped {kind}: " in out
        else:
            assert p.read_bytes()[:5] == b"%PDF-"
    # a pushover: capacity yes, restitution and bouncing (free-rocking and impact measures) no
    assert main(["plot", str(result_files["pushover"]), "--kind", "all"]) == 0
    out = capsys.readouterr().out
    assert result_files["pushover"].with_name("pushover_capacity.png").exists()
    assert "skipped restitution: " in out and "skipped bouncing: " in out
    # -o without a suffix names the files with the format's (it made "plots_history" and refused it)
    stem = result_files["pushover"].with_name("named")
    assert main(["plot", str(result_files["pushover"]), "--kind", "all", "-o", str(stem)]) == 0
    assert stem.with_name("named_capacity.png").read_bytes()[:4] == b"\x89PNG"


def _rod_pushover(b: float, h: float, z: float, duration: float):
    """A rod pushing a b x h block at height z (displacement control) to half its instability angle."""
    from rockdem.case import parse_case
    from rockdem.run_cli import run_case

    eta = np.arctan(b / h)
    disp = z * np.sin(0.5 * eta) + b * (1 - np.cos(0.5 * eta))
    case = {
        "run": {"duration": duration, "record_interval": 0.02},
        "damping": {"local": 0.8},
        "specimen": {"type": "block", "width": b, "height": h, "length": 0.8, "kn": 2 * 1.8e9 / h, "friction_angle_deg": 80.0},
        "loading": {"type": "pushover", "mode": "displacement", "displacement": float(disp),
                    "velocity": float(disp) / (duration - 1.0), "rod_height": z},
    }
    return run_case(parse_case(case), progress=False)


def test_rod_pushover_capacity_plot_draws_the_rod_force(result_files):
    # The rod's force is in driven_reaction (per driven block); base_reaction sums the rod and the
    # foundation, which balance in a quasi-static push (~0). The plotted curve must be the rod's:
    # its peak is near the rigid capacity b / (2 z) (0.167; 8 s push, measured 0.186).
    from rockdem.loading import capacity_curve
    from rockdem.plots import plot_capacity

    ds = load(result_files["pushover"])
    lam, _ = capacity_curve(ds)
    y = plot_capacity(ds).axes[0].lines[0].get_ydata()
    np.testing.assert_array_equal(y, lam)
    assert y.max() > 0.8 * 0.3 / (2 * 0.9)
    assert np.abs(ds.base_reaction.values[:, 0]).max() / ds.attrs["pushover_weight"] < 0.5 * y.max()


def _texts(fig) -> list[str]:
    out = []
    for ax in fig.axes:
        out += [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        if ax.get_legend():
            out += [t.get_text() for t in ax.get_legend().get_texts()]
    return [t for t in out if t]


def test_titles_do_not_repeat_words_and_angles_are_in_rad(result_files):
    # The example's block is named "block": titles said "block block". Rotations and eta are in
    # rad in every plot (rockdem's unit for rocking_angle), never in degrees.
    from rockdem.plots import plot_bouncing

    ds = load(result_files["example"])
    for func in (plot_history, plot_restitution, plot_bouncing):
        for text in _texts(func(ds)):
            words = text.lower().replace(",", " ").replace(":", " ").split()
            assert all(a != b for a, b in zip(words, words[1:])), text
            assert "°" not in text and "deg" not in text, text
            if "θ [" in text:  # an angle axis (not the ratio |θ|/η [-])
                assert "θ [rad]" in text, text
    assert "rad" in plot_restitution(ds).axes[0].get_title()


def test_block_dimensions_are_the_untilted_width_and_height():
    # The example block is 0.2 m wide and 2 m high, tilted to 0.9 eta: B and H must not see the tilt.
    b, h = block_dimensions(example_result(), "block")
    assert b == pytest.approx(0.2, abs=1e-9)
    assert h == pytest.approx(2.0, abs=1e-9)


def test_top_displacement_at_release_is_h_sin_theta0():
    # Rigid rotation by theta0 about the base corner moves the top of the pivot side by H sin(theta0).
    ds = example_result()
    u, _ = top_displacement(ds)
    theta0 = float(ds.rocking_angle.values[0, 1])
    assert theta0 == pytest.approx(0.9 * np.arctan(0.2 / 2.0), rel=1e-9)
    assert u[0] == pytest.approx(2.0 * np.sin(theta0), rel=1e-6)


def test_comparison_legend_gives_wme_against_the_measured_history(tmp_path):
    ds = example_result()
    u, _ = top_displacement(ds)
    csv = tmp_path / "measured.csv"
    np.savetxt(csv, np.column_stack([ds.time.values, u / 0.2]), delimiter=",", header="time [s],u/B [-]")
    fig = plot_comparison([ds, ds], labels=["same", "same again"], measured=csv)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts[0].startswith("measured")
    assert "WME = 0.000" in texts[1]
    # Half the amplitude: sum|x - x/2||x| / sum x^2 = 0.5 exactly.
    half = (ds.time.values, 2.0 * u / 0.2)
    fig = plot_comparison(ds, labels=["sim"], measured=half)
    assert "WME = 0.500" in fig.axes[0].get_legend().get_texts()[1].get_text()


def test_errors_name_the_field_and_the_fix(tmp_path):
    ds = example_result()
    with pytest.raises(ValueError, match="block 'nope'.*give one of"):
        plot_history(ds, block="nope")
    with pytest.raises(ValueError, match="monitor 'nope'"):
        plot_history(ds, monitor="nope")
    bad = tmp_path / "one_column.csv"
    bad.write_text("1\n2\n3\n")
    with pytest.raises(ValueError, match="two numeric columns"):
        plot_comparison(ds, measured=bad)
    with pytest.raises(ValueError, match=r"\.png or \.pdf"):
        save_figure(plot_history(ds), tmp_path / "x.jpg")


@pytest.mark.parametrize("name, func", [("history", plot_history), ("restitution", plot_restitution)])
def test_image_matches_baseline(tmp_path, name, func):
    actual = save_figure(func(synthetic_result()), tmp_path / f"{name}.png", dpi=60)
    expected = BASELINE / f"{name}.png"
    if os.environ.get("ROCKDEM_UPDATE_BASELINES"):
        BASELINE.mkdir(exist_ok=True)
        expected.write_bytes(actual.read_bytes())
    assert expected.exists(), f"missing baseline {expected}; run with ROCKDEM_UPDATE_BASELINES=1"
    # RMS tolerance on 0-255 pixel values: absorbs anti-aliasing and FreeType differences only.
    assert compare_images(str(expected), str(actual), tol=3.0) is None
