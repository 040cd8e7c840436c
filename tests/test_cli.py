"""The command line as a user runs it: the built-in example end to end, and bad input."""

import re
import sys
import warnings

import numpy as np
import pytest

from rockdem.cli import main
from rockdem.results import load


def test_run_builtin_example_writes_results_plot_and_summary(tmp_path, capsys):
    out = tmp_path / "fr"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "1.5", "--quiet"]) == 0
    text = capsys.readouterr().out
    for key in ("steps", "timestep", "run time", "peak rotation", "energy balance"):
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


def test_version(capsys):
    import rockdem

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"rockdem {rockdem.__version__}"


def test_summary_is_an_aligned_table_with_units(tmp_path, capsys):
    assert main(["run", "--example", "free-rocking", "--out", str(tmp_path), "--duration", "0.3", "--quiet", "--no-plot"]) == 0
    rows = capsys.readouterr().out.splitlines()[1:]
    table = [r for r in rows if not r.strip().startswith(("wrote", "DIVERGED", "INTERRUPTED"))]
    # label (26 columns), value right-aligned in the next 12, unit in the next 5
    ends = {len(r[: 2 + 26 + 1 + 12].rstrip()) for r in table}
    assert ends == {2 + 26 + 1 + 12}, table
    by_label = {r[2:28].strip(): r[29:].split() for r in table}
    assert by_label["peak rotation"][1] == "rad" and "'block'," in by_label["peak rotation"]
    assert by_label["peak |u| at top"][1] == "mm"
    assert by_label["timestep"][1] == "s"
    assert "block block" not in "\n".join(rows)


def test_summary_survives_a_run_stopped_at_zero_or_one_frame():
    from conftest import rocking_block
    from rockdem.run_cli import summary_lines
    from rockdem.simulation import simulate

    ds = simulate(rocking_block(0.2, 1.0, tilt=0.5), 0.02, record_interval=0.01)
    sound = summary_lines(ds)
    for n in (0, 1):  # a run that diverges at t = 0 keeps 0 or 1 frames: IndexError before
        cut = ds.isel(time=slice(0, n))
        cut.attrs.update(diverged=1, diverged_time=0.0)
        lines = summary_lines(cut)
        assert any(line.startswith("DIVERGED at t = 0 s") for line in lines)
        assert any(line.startswith("time simulated") for line in lines)
    # a diverged run's overturning flags are not an outcome, and say so; a sound run's carry no note
    cut = ds.copy()
    cut.attrs = {**ds.attrs, "diverged": 1, "diverged_time": 0.02}
    flags = [line for line in summary_lines(cut) if line.startswith(("overturned", "exceeded eta"))]
    assert len(flags) == 2 and all(line.endswith("the run diverged: not an outcome") for line in flags)
    assert not any("diverged" in line for line in sound if line.startswith(("overturned", "exceeded")))


def test_bad_output_folder_is_refused_before_the_run(tmp_path, capsys, monkeypatch):
    import rockdem.run_cli

    def no_run(*args, **kwargs):
        raise AssertionError("the run started")

    monkeypatch.setattr(rockdem.run_cli, "run_case", no_run)
    afile = tmp_path / "notes.txt"
    afile.write_text("x")
    assert main(["run", "--example", "free-rocking", "--out", str(afile), "--quiet"]) == 2
    assert f"--out {afile} is an existing file; give a folder" in capsys.readouterr().err
    assert main(["run", "--example", "free-rocking", "--out", str(afile / "sub"), "--quiet"]) == 2
    assert "cannot write there" in capsys.readouterr().err
    (tmp_path / "o" / "result.nc").mkdir(parents=True)
    assert main(["run", "--example", "free-rocking", "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "result.nc is a folder" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_stop_signals_save_the_frames_computed_so_far(tmp_path, capsys, monkeypatch, name):
    """SIGTERM and SIGHUP (as Ctrl-C) stop a run inside the time loop; the partial result is saved
    and the exit status is 128 + the signal number (nothing was written for SIGTERM/SIGHUP before)."""
    import os
    import signal

    import rockdem.simulation

    sig = getattr(signal, name, None)
    if sig is None:
        pytest.skip(f"no {name} on this platform")
    real, calls = rockdem.simulation.advance, []

    def advance(*args):
        frame, status = real(*args)
        calls.append(frame)
        if len(calls) == 2:
            os.kill(os.getpid(), sig)  # delivered in the loop, between two compiled chunks
        return frame, status

    monkeypatch.setattr(rockdem.simulation, "advance", advance)
    code = main(["run", "--example", "free-rocking", "--out", str(tmp_path), "--duration", "60", "--quiet", "--no-plot"])
    assert code == 128 + sig
    assert "INTERRUPTED" in capsys.readouterr().out
    ds = load(tmp_path / "result.nc")
    assert ds.attrs["interrupted"] == 1
    assert 0 < float(ds.time[-1]) < 60.0 and ds.sizes["time"] in calls  # the frames of finished chunks
    assert signal.getsignal(sig) is not None  # handlers restored after the run


def test_an_interrupt_while_saving_is_held_and_a_second_abandons_the_save(tmp_path, capsys, monkeypatch):
    """One interrupt while the complete result is saved is held: the save goes on and the run's own
    exit status is kept (0: the result is whole). A second one abandons the save (130)."""
    import os
    import signal

    import rockdem.run_cli

    real = rockdem.run_cli.save
    for count, code, saved in ((1, 0, True), (2, 130, False)):
        out = tmp_path / str(count)

        def save(ds, path, count=count):
            for _ in range(count):
                os.kill(os.getpid(), signal.SIGINT)
            return real(ds, path)

        monkeypatch.setattr(rockdem.run_cli, "save", save)
        assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.05", "--quiet", "--no-plot"]) == code
        err = capsys.readouterr().err
        assert "saving the results computed so far; interrupt again to abandon" in err
        assert (out / "result.nc").exists() == saved
        if not saved:
            assert "stopped by SIGINT" in err
            assert "the save was abandoned; written: checkpoint.npz" in err  # (written by the run itself)
        else:
            assert "SIGINT came after the run had ended; the result is complete" in err


@pytest.mark.parametrize("where", ["_Saver.save", "build_dataset"])
def test_a_stop_signal_after_the_last_frame_keeps_the_whole_result(tmp_path, capsys, monkeypatch, where):
    """A SIGTERM that comes once every frame is computed, while the result is put together (in
    run_model past its loop: the final checkpoint; in simulate: the dataset) is held: the complete
    result is saved and the run's status returned. It used to escape as 'stopped by SIGTERM', exit
    143, with nothing but the checkpoint written."""
    import os
    import signal

    import rockdem.simulation

    owner = {"_Saver.save": rockdem.simulation._Saver, "build_dataset": rockdem.simulation}[where]
    name = where.rsplit(".", 1)[-1]
    real = getattr(owner, name)

    def late(*args, **kwargs):
        out = real(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGTERM)
        return out

    monkeypatch.setattr(owner, name, late)
    args = ["run", "--example", "free-rocking", "--out", str(tmp_path), "--duration", "0.2", "--quiet", "--no-plot"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "SIGTERM came after the run had ended; the result is complete" in err
    ds = load(tmp_path / "result.nc")
    assert ds.attrs["interrupted"] == 0 and float(ds.time[-1]) == pytest.approx(0.2)
    assert (tmp_path / "histories.csv").exists()


def test_only_the_program_pauses_and_freezes_the_garbage_collector(monkeypatch):
    # main() as the program (argv None) imports the command's modules with the collector paused,
    # freezes their objects before the command runs (collector on again) and what is left after it
    # (a fast interpreter exit); with an argument list (from Python, as here) it leaves it alone
    import gc

    import rockdem.run_cli

    seen, made = [], []

    def command(args):
        seen.append(gc.get_freeze_count())
        made.append([])  # an object of the command, alive at the end
        return 0

    def frozen(obj):  # the permanent generation is not among gc.get_objects()
        return not any(o is obj for o in gc.get_objects())

    collecting = []  # whether the collector runs while the command's modules are imported
    add_commands = rockdem.cli._add_commands
    monkeypatch.setattr(rockdem.cli, "_add_commands", lambda *a: collecting.append(gc.isenabled()) or add_commands(*a))
    monkeypatch.setattr(rockdem.run_cli, "_run", command)
    monkeypatch.setattr(sys, "argv", ["rockdem", "run", "--list-examples"])
    assert main(["run", "--list-examples"]) == 0
    assert seen == [0] and gc.get_freeze_count() == 0 and not frozen(made[0]) and collecting == [True]
    try:
        assert main() == 0
        assert seen[1] > 0 and frozen(made[1]) and collecting == [True, False] and gc.isenabled()
    finally:
        gc.unfreeze()


def test_command_modules_without_a_command_are_skipped(monkeypatch):
    import rockdem.cli

    assert "rockdem.records" in rockdem.cli._COMMAND_MODULES
    monkeypatch.setattr(rockdem.cli, "_COMMAND_MODULES", (*rockdem.cli._COMMAND_MODULES, "rockdem.geometry", "rockdem.nope"))
    parser = rockdem.cli.build_parser()
    assert "run" in parser._subparsers._group_actions[0].choices


def test_each_command_comes_from_the_module_named_for_it():
    # ``rockdem CMD`` imports only CMD's module: the table must name every command and its module
    import rockdem.cli

    every = set(rockdem.cli.build_parser()._subparsers._group_actions[0].choices)
    assert every == set(rockdem.cli._COMMANDS)
    for command in every:
        assert command in rockdem.cli.build_parser(command)._subparsers._group_actions[0].choices


def test_citation_file_matches_the_package_and_cites_the_paper():
    from pathlib import Path

    import rockdem

    text = (Path(__file__).parents[1] / "CITATION.cff").read_text()
    assert "cff-version: 1.2.0" in text
    assert f"\nversion: {rockdem.__version__}\n" in text
    assert "doi: 10.1002/eqe.3598" in text and "Damping considerations for rocking block dynamics" in text


def test_threads_option(tmp_path, capsys):
    """--threads N runs the joint law on N threads (the result says so); a bad count is refused
    with the option named, without a traceback."""
    import numba

    out = tmp_path / "t"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.2", "--quiet", "--no-plot",
                 "--threads", "1"]) == 0
    assert load(out / "result.nc").attrs["threads"] == 1
    capsys.readouterr()
    assert main(["run", "--example", "free-rocking", "--threads", "0"]) == 2
    assert "--threads" in capsys.readouterr().err
    too_many = str(numba.config.NUMBA_NUM_THREADS + 1)
    assert main(["run", "--example", "free-rocking", "--out", str(tmp_path / "u"), "--threads", too_many, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "NUMBA_NUM_THREADS" in err and "Traceback" not in err


def test_a_sinking_block_is_found_when_it_sinks():
    # A block on joints far too soft (kn = 3e4 Pa/m, a timestep of several hundredths of a second)
    # sinks by 25 % of its thickness at 0.10 s (0.05 m = (g / w^2)(1 - cos w t), w = 4.08 1/s). The
    # check runs at fixed times, every SINK_CHECK_TIME here (it ran once per compiled chunk, which
    # could span the whole run, then at least every 5 % of the run, so that the stop moved with the
    # duration asked for, until 2026-11-30) and reads the overlaps of the last force pass, a step
    # behind the positions, whose last step may pass the check time by a step: it finds the
    # sinking within 0.1 s + SINK_CHECK_TIME + two steps (0.058 s each), at the same time for any
    # duration. A bad step found past the end is said to be "at the end of the run".
    import warnings

    from rockdem.materials import JointMaterial
    from rockdem.model import ModelBuilder
    from rockdem.run_cli import summary_lines
    from rockdem.simulation import SINK_CHECK_TIME, simulate

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=3e4, friction_angle=30.0)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.2, 1, 1, density=1800, name="block")
    model = b.finalize()
    found = []
    for duration in (0.4, 2.0):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = simulate(model, duration, progress=False)
        t_bad = ds.attrs["diverged_time"]
        found.append(t_bad)
        assert ds.attrs["diverged_reason"] == "sank" and t_bad < 0.1 + SINK_CHECK_TIME + 2.0 * ds.attrs["dt"]
        lines = "\n".join(summary_lines(ds))
        assert f"DIVERGED at t = {t_bad:.4g} s: the result holds the frames up to it, the last ones already sinking" in lines
    assert found[0] == found[1]  # the same stop for any duration asked for
    ds.attrs.update(duration=0.1, diverged_reason="energy")
    assert f"DIVERGED at the end of the run (its last step reached t = {t_bad:.4g} s): the result holds the sound frames" in "\n".join(summary_lines(ds))


def test_the_progress_bar_writes_seldom_into_a_log(monkeypatch):
    """Into a log file or a batch job's output (stderr no terminal) the bar updates every
    PROGRESS_LOG_INTERVAL s, not ten times a second; on a terminal it stays live."""
    import io
    import sys

    from rockdem.simulation import PROGRESS_LOG_INTERVAL, _progress_bar

    log = io.StringIO()
    monkeypatch.setattr(sys, "stderr", log)
    bar = _progress_bar(5.0)
    assert bar.mininterval == PROGRESS_LOG_INTERVAL >= 10.0
    bar.close()

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    monkeypatch.setattr(sys, "stderr", Terminal())
    bar = _progress_bar(5.0)
    assert bar.mininterval <= 0.1
    bar.close()


def test_every_command_checks_its_output_path_and_input_files(tmp_path, capsys):
    """Each command refuses an output path it cannot write and an input file that is not what it
    reads with a message naming the path and exit 2, never a traceback (before 2026-11-29 plot,
    show, animate, records --plot and export raised OSError tracebacks for a file given as a
    folder, a truncated or empty checkpoint BadZipFile or EOFError, plot a NetCDF file that is not
    a result KeyError)."""
    import xarray as xr

    out = tmp_path / "fr"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.2", "--quiet", "--no-plot"]) == 0
    capsys.readouterr()
    afile = tmp_path / "afile"
    afile.write_text("x")
    result = str(out / "result.nc")
    for argv in (["plot", result, "-o", str(afile / "x.png")],
                 ["show", "--example", "free-rocking", "-o", str(afile / "x.png")],
                 ["animate", result, "-o", str(afile / "x.gif")],
                 ["records", "--plot", "elcentro-rsn6", "-o", str(afile / "x.png")],
                 ["export", result, "--vtk", str(afile / "sub")]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert str(afile) in err and "Traceback" not in err, argv
    saved = (out / "checkpoint.npz").read_bytes()
    (tmp_path / "trunc.npz").write_bytes(saved[:3000])
    (tmp_path / "empty.npz").write_bytes(b"")
    for bad in ("trunc.npz", "empty.npz"):
        for flag in ("--from", "--settled"):
            assert main(["run", "--example", "free-rocking", flag, str(tmp_path / bad), "--out", str(tmp_path / "o2"), "--quiet"]) == 2
            assert "is not a rockdem checkpoint" in capsys.readouterr().err
    (tmp_path / "case.toml").write_text("[run]\nduration = 1.0\n")  # a case file given as a checkpoint
    assert main(["run", "--example", "free-rocking", "--from", str(tmp_path / "case.toml"), "--out", str(tmp_path / "o3"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "is not a rockdem checkpoint" in err and "not an .npz archive" in err and "pickle" not in err
    xr.Dataset({"a": ("t", np.arange(3.0))}).to_netcdf(tmp_path / "other.nc")
    assert main(["plot", str(tmp_path / "other.nc")]) == 2
    assert "other.nc is not a rockdem result" in capsys.readouterr().err
    assert main(["calibrate", str(tmp_path / "other.nc"), "--base", "free-rocking", "--parameter", "damping.beta",
                 "--bounds", "0.001", "0.01"]) == 2
    assert "reference" in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["advise", "--width", "0.2", "--height", "1", "--density", "1800", "--youngs-modulus-mpa", "1.8e9"], "stiffer than any material"),
    (["advise", "--width", "0.2", "--height", "1", "--density", "1.8", "--youngs-modulus-mpa", "1800"], "density = 1.8 kg/m^3"),
    (["animate", "r.nc", "--size", "100000", "480"], "at most 4096 pixels"),
    (["animate", "r.nc", "--view", "nan,nan"], "--view"),
    (["run"], "give a case file (rockdem run CASE.toml) or --example NAME (rockdem run --list-examples)"),
    (["plot", "r.nc", "--dpi", "100000"], "--dpi: must be a resolution in (0, 1200] dots per inch"),  # a MemoryError before
    (["plot", "r.nc", "--dpi", "0"], "--dpi: must be a resolution in (0, 1200] dots per inch"),  # the default before
    (["animate", "r.nc", "--dpi", "1e5"], "--dpi: must be a resolution in (0, 1200] dots per inch"),
    (["plot", "r.nc", "--length", "-1"], "--length: must be a positive number"),  # u/B with B = -1 m before
    (["run", "--example", "free-rocking", "--set", "specimen.gravity=9810"], "gravity = 9810 is not plausible"),
])
def test_implausible_command_line_values_are_refused(argv, message, capsys):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_the_continue_command_of_an_interrupted_run_keeps_its_options(tmp_path):
    """The printed command that continues an interrupted run carries its overrides, duration,
    output folder and stop rule (before 2026-11-29 it printed "--set ..." and dropped --duration
    and --out: the continued run ended at the case file's duration, in another folder)."""
    import shlex

    from rockdem.cli import build_parser
    from rockdem.run_cli import continue_command

    argv = ["run", "my case.toml", "--duration", "12.5", "-o", str(tmp_path / "out dir"), "--set", "damping.beta=0.005",
            "--set", 'loading.record="nahanni"', "--stop", "rest", "--quiet"]
    args = build_parser("run").parse_args(argv)
    words = shlex.split(continue_command(args, tmp_path / "out dir" / "checkpoint.npz"))
    assert words[:2] == ["rockdem", "run"]
    again = build_parser("run").parse_args(words[1:])
    assert again.from_ == str(tmp_path / "out dir" / "checkpoint.npz") and again.settled is None
    for name in ("case", "duration", "out", "set", "stop", "quiet", "example", "threads", "no_plot"):
        assert getattr(again, name) == getattr(args, name), name


def _plot_bytes_here(result_path, path):
    from rockdem.rocking_plot import draw_rocking, rocking_series

    return draw_rocking(rocking_series(load(result_path)), path).read_bytes()


@pytest.mark.parametrize("loading", ["free-rocking", "earthquake"])
def test_run_plot_is_drawn_by_a_second_process_as_here(tmp_path, capsys, monkeypatch, loading):
    """`rockdem run` draws its plot in a second process (it imports Matplotlib while the run goes
    on): the image is the one drawn in this process, byte for byte, for the two-panel plot and the
    five-panel one of an earthquake run. Drawing here is forbidden, so the process drew it."""
    import rockdem.rocking_plot

    here = rockdem.rocking_plot.draw_rocking
    monkeypatch.setattr(rockdem.rocking_plot, "draw_rocking", lambda *a: pytest.fail("drawn in this process"))
    out = tmp_path / "o"
    source = ["--example", "free-rocking"]
    if loading == "earthquake":
        source = [str(tmp_path / "quake.toml")]
        (tmp_path / "quake.toml").write_text(
            '[run]\nduration = 0.6\n[specimen]\ntype = "block"\nwidth = 0.3\nheight = 1.5\nyoungs_modulus = 1e9\n'
            '[loading]\ntype = "earthquake"\nrecord = "elcentro-peknold"\nscale = 0.5\nmode = "inertial"\n')
    assert main(["run", *source, "--out", str(out), "--duration", "0.6", "--quiet"]) == 0
    monkeypatch.setattr(rockdem.rocking_plot, "draw_rocking", here)
    assert ("ground_acceleration" in load(out / "result.nc")) == (loading == "earthquake")
    assert (out / "rocking.png").read_bytes() == _plot_bytes_here(out / "result.nc", tmp_path / "here.png")


@pytest.mark.parametrize("failure", ["no interpreter", "process fails"])
def test_run_plot_is_drawn_here_where_the_plot_process_fails(tmp_path, capsys, monkeypatch, failure):
    """Where the plotting process cannot start or exits with an error, the run draws the plot itself
    (the same image) and says nothing of it."""
    import rockdem.rocking_plot

    if failure == "no interpreter":
        monkeypatch.setattr(sys, "executable", str(tmp_path / "no-python"))
    else:
        monkeypatch.setattr(rockdem.rocking_plot, "_SERVE_CODE", "import sys; sys.stdin.read(1); sys.exit(3)  # {root}")
    out = tmp_path / "o"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.3", "--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert (out / "rocking.png").read_bytes() == _plot_bytes_here(out / "result.nc", tmp_path / "here.png")


def test_a_plot_process_given_nothing_to_draw_ends_at_once():
    """A run that ends before its plot (an error) ends its plotting process: killed, not left to
    finish importing Matplotlib, and reaped (no process left behind)."""
    import signal

    from rockdem.rocking_plot import PlotProcess

    with PlotProcess() as plotter:
        proc = plotter._process
    assert proc is not None and proc.returncode is not None  # reaped
    assert proc.returncode == (-signal.SIGKILL if hasattr(signal, "SIGKILL") else 1)  # killed, not finished


def test_the_plot_process_passes_its_warnings_on(tmp_path, monkeypatch):
    """A warning raised while the second process draws (here Matplotlib's, for a legend whose only
    label starts with an underscore) is raised again in the run's process, with its category."""
    import rockdem.rocking_plot
    from rockdem.rocking_plot import PlotProcess, RockingSeries

    monkeypatch.setattr(rockdem.rocking_plot, "draw_rocking", lambda *a: pytest.fail("drawn in this process"))
    t = np.linspace(0.0, 1.0, 50)
    series = RockingSeries(time=t, blocks=("_hidden",), angle=np.sin(t)[:, None], displacement=np.cos(t)[:, None],
                           monitors=(), quake=None)
    with PlotProcess() as plotter:
        plotter.submit(series, tmp_path / "p.png")
        with pytest.warns(UserWarning, match="No artists with labels found to put in legend"):
            assert plotter.draw(series, tmp_path / "p.png") == tmp_path / "p.png"
    assert (tmp_path / "p.png").stat().st_size > 1000


def test_records_plot_reads_a_file_with_the_options_its_advice_names(tmp_path, capsys):
    """A two-column file without units: the error names --units (it advised a keyword argument the
    command did not have), and with --units g the record is plotted."""
    rec = tmp_path / "rec.txt"
    rec.write_text("".join(f"{0.01 * k:.2f} {0.1 * np.sin(k):.5f}\n" for k in range(200)))
    assert main(["records", "--plot", str(rec), "-o", str(tmp_path / "r.png")]) == 2
    assert "--units" in capsys.readouterr().err
    assert main(["records", "--plot", str(rec), "--units", "g", "-o", str(tmp_path / "r.png")]) == 0
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"


def test_a_run_stopped_at_collapse_does_not_read_as_no_collapse():
    """A column stopped when its top block fell: the analysed block, which did not pass its own
    eta, reports "overturned no" with a note that the run stopped at collapse (it read as a plain
    "no" beside the STOPPED line)."""
    import xarray as xr

    from rockdem.run_cli import _analysis_lines

    t = np.linspace(0.0, 1.0, 101)
    theta = np.stack([0.3 * t, 0.1 * t], axis=1)  # both below their eta of 0.5 rad
    ds = xr.Dataset({"rocking_angle": (("time", "block"), theta), "block_free": ("block", [True, True]),
                     "block_eta": ("block", [0.5, 0.5]), "block_name": ("block", ["b1", "b2"])}, coords={"time": t})
    rows = {line.split()[0]: line for line in _analysis_lines(ds, 0)}
    assert rows["overturned"].split()[1] == "no" and "collapse" not in rows["overturned"]
    ds.attrs.update(stop_reason="fell", stop_block="b2", stop_time=1.0)
    rows = {line.split()[0]: line for line in _analysis_lines(ds, 0)}
    assert "no" in rows["overturned"] and "the run stopped at collapse (block 'b2' fell)" in rows["overturned"]


def test_a_closed_standard_output_ends_the_command_quietly(monkeypatch, capsys):
    """``rockdem records | head -0``: the pipe's reader left; the command says so in one line and
    exits 141 (128 + SIGPIPE, as a shell reports it), not 2 with "check the path and its
    permissions"."""
    class Closed:
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            pass

    monkeypatch.setattr(sys, "stdout", Closed())
    assert main(["records"]) == 141
    assert "standard output closed by its reader" in capsys.readouterr().err


def test_a_reused_output_folder_names_what_an_earlier_run_left_there(tmp_path, capsys):
    """A run into a folder of an earlier one that wrote more (a plot, a contact table, a
    checkpoint) names those files (before 2026-12-01 they stayed beside the new result without a
    word); files the new run rewrites are not named."""
    out = tmp_path / "o"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.05", "--quiet", "--no-plot",
                 "--set", "run.contact_interval=0.01"]) == 0
    capsys.readouterr()
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.02", "--quiet", "--no-plot",
                 "--no-checkpoint"]) == 0
    err = capsys.readouterr().err
    assert f"{out} also holds checkpoint.npz, contacts.csv of an earlier run, not written by this one" in err
    assert main(["run", "--example", "free-rocking", "--out", str(tmp_path / "new"), "--duration", "0.02", "--quiet",
                 "--no-plot"]) == 0
    assert "of an earlier run" not in capsys.readouterr().err


def test_duration_on_the_command_line_stands_for_a_missing_one(tmp_path, capsys):
    """--duration overrides [run] duration, and stands for it where the case leaves it out (such a
    case was refused, "[run] duration is required", before 2026-12-01); rockdem show runs nothing
    and needs none."""
    case = tmp_path / "c.toml"
    case.write_text('[specimen]\ntype = "block"\nwidth = 0.3\nheight = 1.2\nyoungs_modulus = 1e9\n'
                    '[damping]\nbeta = 0.001\n[loading]\ntype = "free-rocking"\ntilt_fraction = 0.5\n')
    assert main(["run", str(case), "--out", str(tmp_path / "o"), "--duration", "0.1", "--no-plot", "--quiet"]) == 0
    assert float(load(tmp_path / "o" / "result.nc").time.values[-1]) == pytest.approx(0.1)
    assert main(["run", str(case), "--out", str(tmp_path / "o2"), "--quiet"]) == 2
    assert "[run] duration is required" in capsys.readouterr().err
    assert main(["show", str(case), "-o", str(tmp_path / "p.png")]) == 0
    assert (tmp_path / "p.png").exists()
    case.write_text("run = 5\n" + case.read_text())  # a [run] that is no table is refused as without --duration
    assert main(["run", str(case), "--out", str(tmp_path / "o3"), "--duration", "0.1", "--quiet"]) == 2
    assert "[run] must be a table" in capsys.readouterr().err


def test_a_result_checkpoint_or_image_given_as_a_case_is_named(tmp_path, capsys):
    """A result, a checkpoint or a plot given where a case file is read is named for what it is,
    with the command that reads it (it was "not UTF-8 text" before 2026-12-01)."""
    out = tmp_path / "o"
    assert main(["run", "--example", "free-rocking", "--out", str(out), "--duration", "0.02", "--quiet"]) == 0
    capsys.readouterr()
    for name, kind in (("result.nc", "a NetCDF-4 file (a result, result.nc)"),
                       ("checkpoint.npz", "a zip archive (a checkpoint, checkpoint.npz)"), ("rocking.png", "a PNG image")):
        for argv in (["run", str(out / name), "--quiet"], ["show", str(out / name)]):
            assert main(argv) == 2
            err = capsys.readouterr().err
            assert f"{out / name} is {kind}, not a TOML case or study file" in err and "--from OUT/checkpoint.npz" in err


def test_gravity_in_other_units_is_warned_about(tmp_path):
    """[specimen] gravity is in m/s^2: 9810 (mm/s^2) is refused (above), 50 (a centrifuge's 5 g, or
    a mistake) and 1 (meant as 1 g) are warned about; 9.81 and 0 (a model without weight) are not."""
    from rockdem.case import example_case, parse_case

    data = example_case("free-rocking")
    for g, message in ((50.0, "gravity = 50.0 is above 30"), (1.0, "gravity = 1 m/s^2 is below the Moon's 1.62 m/s^2")):
        with pytest.warns(UserWarning, match=re.escape(message)):
            parse_case({**data, "specimen": {**data["specimen"], "gravity": g}})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_case({**data, "specimen": {**data["specimen"], "gravity": 9.81}})
