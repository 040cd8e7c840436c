"""The command line as a user runs it: the built-in example end to end, and bad input."""

import numpy as np
import pytest

from rockdem.cli import main
from rockdem.results import load


def test_run_builtin_example_writes_results_plot_and_summary(tmp_path, capsys):
    out = tmp_path / "fr"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "1.5", "--quiet"]) == 0
    text = capsys.readouterr().out
    for key in ("steps", "dt", "runtime", "peak rotation", "energy balance"):
        assert key in text
    ds = load(out / "result.nc")
    # Released from 0.9 eta of the 0.2 x 2 m block, the angle after 1.5 s has crossed zero once
    # (Housner quarter period 1.11 s) and never exceeded the initial one.
    theta = ds.rocking_angle.values[:, 1]
    assert theta[0] == pytest.approx(0.9 * np.arctan(0.1), rel=1e-9)
    assert np.max(np.abs(theta)) <= theta[0] + 1e-9
    assert np.count_nonzero(np.diff(np.sign(theta))) == 1
    assert (out / "rocking.png").stat().st_size > 10_000
    header = (out / "histories.csv").read_text().splitlines()[0]
    assert "block.rocking_angle [rad]" in header and "top.ux [m]" in header


def test_case_file_with_overrides(tmp_path, capsys):
    case = tmp_path / "c.toml"
    case.write_text(
        '[run]\nduration = 0.2\n[specimen]\ntype = "block"\nwidth = 0.3\nheight = 1.2\n'
        'youngs_modulus = 1e9\n[loading]\ntype = "free-rocking"\ntilt_fraction = 0.5\n'
    )
    code = main(["run", str(case), "--out", str(tmp_path / "o"), "--set", "damping.alpha=1.5", "--no-plot", "--quiet"])
    assert code == 0
    ds = load(tmp_path / "o" / "result.nc")
    assert ds.attrs["alpha"] == 1.5
    assert not (tmp_path / "o" / "rocking.png").exists()


def test_cli_reports_bad_case_without_traceback(tmp_path, capsys):
    case = tmp_path / "bad.toml"
    case.write_text('[run]\nduration = 1\n[specimen]\ntype = "block"\nwidth = 0.2\nheigth = 2\n')
    assert main(["run", str(case)]) == 2
    err = capsys.readouterr().err
    assert "[specimen]" in err and "height is required" in err
    assert "Traceback" not in err
    assert main(["run", str(tmp_path / "missing.toml")]) == 2


def test_package_root_exports_the_api():
    import rockdem

    for name in rockdem.__all__:
        assert getattr(rockdem, name) is not None
    assert rockdem.ModelBuilder is __import__("rockdem.model", fromlist=["ModelBuilder"]).ModelBuilder
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        rockdem.nope  # noqa: B018
