"""Tests of rockdem.records: readers of ground-motion files, units, and record processing.

Reference values for the shipped records come from rockdem/data/ground-motions/SOURCES.md (computed
there from the file contents, not from the headers). Integration checks compare with closed forms and the trapezoid-rule error bound.
"""

from __future__ import annotations

import argparse
import hashlib
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from rockdem.loading import prepare_record
from rockdem.records import (
    DATA_ENV,
    SHIPPED_RECORDS,
    STANDARD_GRAVITY,
    GroundMotion,
    read_at2,
    read_columns,
    read_record,
    read_single_column,
    record_path,
    records_folder,
    register_cli,
    shipped_record,
)

NGA_HEADER = (
    "PEER NGA STRONG MOTION DATABASE RECORD\n"
    "Test event, 1/1/2000, Test station, 000\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\n"
)


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# ---------------------------------------------------------------------------------------- shipped records

# (file, npts, dt [s], PGA [g] to SOURCES.md's 4 decimals, t(PGA) [s] to its 2 decimals)
SHIPPED = [
    ("RSN6_IMPVALL.I_I-ELC180.AT2", 5372, 0.0100, 0.2808, 2.18),
    ("elCentro.AT2", 1559, 0.0200, 0.3188, 2.02),
    ("RSN77_SFERN_PUL164.AT2", 4172, 0.0100, 1.2190, 7.75),
    ("Nahanni_1985_NS1-280.csv", 4113, 0.005, 1.0957, 9.16),
    ("RSN285_ITALY_A-BAG270.AT2", 12712, 0.0029, 0.1897, 3.90),  # header dt .0029, 4 decimals
    ("RSN289_ITALY_A-CTR270.AT2", 14672, 0.0024, 0.1364, 8.17),  # header dt .0024
    ("RSN292_ITALY_A-STU270.AT2", 16392, 0.0024, 0.3205, 5.24),  # header dt .0024
]


@pytest.mark.parametrize(("name", "npts", "dt", "pga_g", "t_pga"), SHIPPED, ids=[s[0] for s in SHIPPED])
def test_shipped_records_match_sources(name: str, npts: int, dt: float, pga_g: float, t_pga: float) -> None:
    """Each shipped file reads with the npts, dt, PGA and time of PGA listed in SOURCES.md."""
    gm = read_record(record_path(name), units="g" if name.endswith(".csv") else None)
    assert gm.npts == npts
    assert gm.units_in == "g"
    # Header dt is exact; the CSV's dt is the mean step of a printed time column (float noise ~1e-15).
    assert gm.dt == pytest.approx(dt, rel=1e-9)
    assert gm.duration == pytest.approx((npts - 1) * dt, rel=1e-9)
    # SOURCES.md rounds PGA to 4 decimals: half a unit of the last digit.
    assert abs(gm.pga_g - pga_g) <= 0.5e-4
    assert gm.pga == pytest.approx(gm.pga_g * STANDARD_GRAVITY, rel=1e-12)
    # t(PGA) is rounded to 2 decimals; the sample grid itself adds no error (t = i * dt).
    assert abs(gm.pga_time - t_pga) <= 0.005 + 1e-9


def test_header_text_and_units_are_kept() -> None:
    """The AT2 description comes from the header, in the NGA and the Peknold variants."""
    assert "El Centro Array #9" in read_at2(record_path("RSN6_IMPVALL.I_I-ELC180.AT2")).description
    assert "Peknold" in read_at2(record_path("elCentro.AT2")).description


def _sources_sha256() -> dict[str, str]:
    """file name -> SHA-256 as written in the shipped SOURCES.md (its per-file provenance sections)."""
    text = (records_folder() / "SOURCES.md").read_text(encoding="utf-8")
    out: dict[str, str] = {}
    for section in re.split(r"^### ", text, flags=re.M)[1:]:
        files = re.findall(r"[\w.-]+\.(?:AT2|csv)", section.splitlines()[0])
        if len(files) == 1:  # "- SHA-256: `<hex>`"
            out[files[0]] = re.search(r"SHA-256: `([0-9a-f]{64})`", section).group(1)
        else:  # the three Irpinia files share a section: "  - BAG270: `<hex>`"
            for tag, digest in re.findall(r"- (\w+): `([0-9a-f]{64})`", section):
                out[next(f for f in files if f"-{tag}." in f)] = digest
    return out


def test_shipped_files_are_the_sources_byte_for_byte() -> None:
    """Every shipped file's SHA-256 equals the value in SOURCES.md and in the registry; nothing else ships."""
    listed = _sources_sha256()
    assert len(listed) == len(SHIPPED_RECORDS) == len(SHIPPED) == 7
    for rec in SHIPPED_RECORDS:
        digest = hashlib.sha256((records_folder() / rec.file).read_bytes()).hexdigest()
        assert digest == listed[rec.file] == rec.sha256, rec.file
    data = {p.name for p in records_folder().iterdir() if p.suffix in (".AT2", ".csv")}
    assert data == {r.file for r in SHIPPED_RECORDS}


def test_the_irpinia_records_are_provisional() -> None:
    """SOURCES.md says to treat the three Irpinia records as provisional: the registry says so too."""
    prov = {r.name for r in SHIPPED_RECORDS if r.provisional}
    assert prov == {"bagnoli", "calitri", "sturno"}
    assert all("Irpinia" in r.event and "PROVISIONAL" in r.licence for r in SHIPPED_RECORDS if r.provisional)
    assert "Treat these three as provisional" in (records_folder() / "SOURCES.md").read_text(encoding="utf-8")
    assert "provisional" in (records_folder() / "README.md").read_text(encoding="utf-8")


def test_shipped_records_need_no_folder_beside_the_package() -> None:
    """The shipped folder lies inside the installed package, not beside a repository."""
    import rockdem

    package = Path(rockdem.__file__).resolve().parent
    assert records_folder().resolve().is_relative_to(package)


@pytest.mark.parametrize("rec", SHIPPED_RECORDS, ids=[r.name for r in SHIPPED_RECORDS])
def test_records_by_short_name_and_file_name(rec, monkeypatch: pytest.MonkeyPatch) -> None:
    """A short name (any case) and the file name read the same record, units from the registry."""
    monkeypatch.delenv(DATA_ENV, raising=False)
    by_name = read_record(rec.name.upper())
    by_file = read_record(rec.file)
    assert shipped_record(rec.name) is shipped_record(rec.file) is rec
    assert by_name.source == by_file.source == records_folder() / rec.file
    np.testing.assert_array_equal(by_name.acceleration, by_file.acceleration)
    assert by_name.units_in == rec.units


def test_record_lookup_order(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Path first, then $ROCKDEM_DATA (the folder or its ground-motions sub-folder), then shipped."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(DATA_ENV, raising=False)
    shipped = records_folder() / "elCentro.AT2"
    assert record_path("elCentro.AT2") == shipped
    own = tmp_path / "data" / "ground-motions"
    own.mkdir(parents=True)
    (own / "elCentro.AT2").write_text("x")
    (own / "mine.AT2").write_text("x")
    monkeypatch.setenv(DATA_ENV, str(tmp_path / "data"))
    assert record_path("elCentro.AT2") == own / "elCentro.AT2"  # the user's folder first
    assert record_path("elcentro-peknold") == shipped  # short names are the shipped records'
    monkeypatch.setenv(DATA_ENV, str(own))
    assert record_path("mine.AT2") == own / "mine.AT2"
    (tmp_path / "elCentro.AT2").write_text("x")
    assert record_path("elCentro.AT2") == Path("elCentro.AT2")  # a file in the working folder first
    with pytest.raises(FileNotFoundError, match=r"elcentro-rsn6.*mine\.AT2"):
        record_path("nope.AT2")  # lists the shipped names and the user's files
    with pytest.raises(FileNotFoundError, match="record file not found"):
        record_path("sub/elCentro.AT2")  # a path with a folder is not looked up elsewhere
    monkeypatch.setenv(DATA_ENV, str(tmp_path / "absent"))
    with pytest.raises(FileNotFoundError, match=DATA_ENV):
        record_path("elcentro-rsn6")  # a mistyped ROCKDEM_DATA is an error, not silently ignored


def _cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="rockdem")
    register_cli(parser.add_subparsers())
    args = parser.parse_args(argv)
    return int(args.func(args))


def test_records_command_lists_values_read_from_the_files(capsys: pytest.CaptureFixture[str]) -> None:
    """`rockdem records`: one row per record, with dt, npts and PGA read from the files (SOURCES.md
    values), and the provisional flag."""
    assert _cli(["records"]) == 0
    out = capsys.readouterr().out
    rows = {line.split()[0]: line for line in out.splitlines() if line.split() and shipped_record(line.split()[0])}
    assert len(rows) == 7
    for name, npts, dt, pga_g, _ in SHIPPED:
        rec = shipped_record(name)
        line = rows[rec.name]
        assert rec.file in line and f" {npts} " in line and f"{pga_g:.4f}" in line and f" {dt:.4g} " in line
        assert line.rstrip().endswith("YES" if rec.provisional else "no")
    assert "Provisional" in out
    assert _cli(["records", "sturno"]) == 0
    detail = capsys.readouterr().out
    assert "PROVISIONAL" in detail and "checksum    matches SOURCES.md" in detail
    with pytest.raises(ValueError, match="short names: elcentro-rsn6"):
        _cli(["records", "nope"])


# ------------------------------------------------------------------------------------------- AT2 parsing

def test_stuck_negative_values_are_split(tmp_path: Path) -> None:
    """A sign not preceded by E/e/D starts a new number: '1.234-5.678', '.1E-02-.2E-03', D exponents."""
    body = "1.234-5.678  .1E-02-.2E-03\n-1.0D-01 2.5d+00-3\n"
    path = _write(tmp_path, "stuck.AT2", NGA_HEADER + "NPTS=  7, DT=   .0100 SEC,\n" + body)
    gm = read_at2(path)
    expected = np.array([1.234, -5.678, 0.1e-2, -0.2e-3, -0.1, 2.5, -3.0]) * STANDARD_GRAVITY
    np.testing.assert_allclose(gm.acceleration, expected, rtol=1e-15)


@pytest.mark.parametrize(
    "npts_line",
    [
        "NPTS=  3, DT=   .0100 SEC,",  # NGA-West2
        "NPTS=  3, DT= .01000 SEC",  # Peknold
        "NPTS= 3 DT= 0.01",  # no comma, no SEC
        "npts=3, dt=1.0e-2 sec",  # lowercase, E-format dt
        "     3    0.01000   NPTS, DT",  # older PEER header
    ],
)
def test_at2_header_variants(tmp_path: Path, npts_line: str) -> None:
    """All tolerated NPTS/DT spellings give NPTS=3 and dt=0.01 s."""
    path = _write(tmp_path, "h.AT2", NGA_HEADER + npts_line + "\n  .1  -.2\n .3\n")
    gm = read_at2(path)
    assert gm.npts == 3 and gm.dt == pytest.approx(0.01, rel=1e-15)


def test_at2_header_units_and_conflict(tmp_path: Path) -> None:
    """Header units are honoured (cm/s/s -> x0.01); an explicit contradicting unit is refused."""
    text = NGA_HEADER.replace("UNITS OF G", "UNITS OF CM/S/S") + "NPTS= 2, DT= .01 SEC\n 100. -50.\n"
    path = _write(tmp_path, "cm.AT2", text)
    np.testing.assert_allclose(read_at2(path).acceleration, [1.0, -0.5], rtol=1e-15)
    assert read_at2(path).units_in == "cm/s2"
    with pytest.raises(ValueError, match="contradicts the header"):
        read_at2(path, units="g")


def test_at2_dt_override(tmp_path: Path) -> None:
    """dt= overrides a header dt rounded to 4 decimals (the Italian records' case) silently; a dt
    beyond the header's rounding (half a unit in its last digit) is used with a warning that
    gives the stretched duration."""
    path = _write(tmp_path, "d.AT2", NGA_HEADER + "NPTS= 2, DT= .0029 SEC\n .1 .2\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_at2(path, dt=0.00293).dt == 0.00293
        assert read_at2(path, dt=0.00285).dt == 0.00285  # .0029 is 0.00285 .. 0.00295 rounded
    with pytest.warns(UserWarning, match=r"overrides the header's DT = 0.0029 s .*0.0058 s become 0.0116 s"):
        assert read_at2(path, dt=0.0058).dt == 0.0058
    path = _write(tmp_path, "e.AT2", NGA_HEADER + "NPTS= 2, DT= 1.0E-02 SEC\n .1 .2\n")  # rounding 5e-4, 2 %: 2e-4
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_at2(path, dt=0.0101)
    with pytest.warns(UserWarning, match=r"by more than its rounding \(0.0002 s\)"):
        read_at2(path, dt=0.0104)


def test_columns_chosen_in_a_wider_file(tmp_path: Path) -> None:
    """A time/velocity/acceleration file: its width alone is refused with the keys to give, and
    time_column / acc_column choose the columns (read_record, and the case file's [loading])."""
    path = _write(tmp_path, "three.csv", "# t, v, a\n0.00, 9, 0.0\n0.01, 9, 0.1\n0.02, 9, -0.2\n0.03, 9, 0.0\n")
    with pytest.raises(ValueError, match="time_column = 0, acc_column = 2"):
        read_record(path, units="g")
    gm = read_record(path, units="g", acc_column=2)
    np.testing.assert_allclose(gm.acceleration / STANDARD_GRAVITY, [0.0, 0.1, -0.2, 0.0], rtol=1e-15)
    assert gm.dt == pytest.approx(0.01, rel=1e-12)
    with pytest.raises(ValueError, match="both 1"):
        read_record(path, units="g", time_column=1)
    with pytest.raises(ValueError, match="zero-based column index"):
        read_record(path, units="g", acc_column=-1)
    with pytest.raises(ValueError, match="do not apply to the at2 format"):
        read_record(_write(tmp_path, "f.AT2", NGA_HEADER + "NPTS= 2, DT= .01 SEC\n .1 .2\n"), acc_column=2)
    from rockdem.case import parse_case
    from rockdem.run_cli import run_case

    case = {"run": {"duration": 0.05, "record_interval": 0.01},
            "specimen": {"type": "block", "width": 0.2, "height": 1.0, "length": 0.5, "youngs_modulus": 1.8e9},
            "loading": {"type": "earthquake", "record": str(path), "units": "g", "acc_column": 2, "baseline": False}}
    ds = run_case(parse_case(case), progress=False)
    t = ds.time.values
    np.testing.assert_allclose(ds.ground_acceleration.values[:, 0], np.interp(t, [0, 0.01, 0.02, 0.03], [0, 0.1 * STANDARD_GRAVITY, -0.2 * STANDARD_GRAVITY, 0]), atol=1e-9)
    one = _write(tmp_path, "steps.txt", "0.1\n0.2\n-0.3\n0.0\n")
    for dt in (1e-9, 5.0):  # a dt off by orders of magnitude is named (before 2026-12-08: an error about the foundation's path)
        bad = {**case, "loading": {"type": "earthquake", "record": str(one), "units": "g", "dt": dt, "baseline": False}}
        with pytest.warns(UserWarning, match=rf"record .*steps.txt': dt = {dt:g} s lies far outside .* check its dt"):
            parse_case(bad)
    with pytest.raises(ValueError, match="do not apply to the single format"):  # not "both 0"
        read_record(_write(tmp_path, "one.txt", "0.1\n0.2\n0.3\n"), units="g", dt=0.01, acc_column=0)
    for bad in ("0.01", True, -0.01, float("nan")):
        with pytest.raises(ValueError, match="dt must be a positive time step"):
            read_record(path, units="g", dt=bad, acc_column=2)
    indexed = _write(tmp_path, "idx.csv", "idx,t,a\n0,0.00,0.1\n1,0.01,0.2\n2,0.02,0.3\n")
    with pytest.raises(ValueError, match="column 0 holds whole numbers .*milliseconds.*give time_column"):
        read_record(indexed, units="g", acc_column=2)
    millis = _write(tmp_path, "ms.txt", "".join(f"{k} {0.1 * np.sin(k / 50.0):.6f}\n" for k in range(200)))
    with pytest.raises(ValueError, match="times in milliseconds"):  # 1 ms samples read as 1 s: 1000 times too slow
        read_record(millis, units="g")
    millis5 = _write(tmp_path, "ms5.txt", "".join(f"{5 * k} {0.1 * np.sin(k / 10.0):.6f}\n" for k in range(40)))
    with pytest.raises(ValueError, match="a time step of 5 s"):
        read_record(millis5, units="g")
    assert read_record(_write(tmp_path, "ramp.txt", "0 0.1\n10 0.1\n"), units="g").dt == 10.0  # two samples: a ramp
    assert read_record(indexed, units="g", time_column=1, acc_column=2).dt == pytest.approx(0.01)
    case["loading"]["acc_column"] = "2"
    with pytest.raises(ValueError, match=r"\[loading\] acc_column must be an integer"):
        parse_case(case)


def test_malformed_token_names_line(tmp_path: Path) -> None:
    """An unparsable token on file line 7 is reported with the file, 'line 7' and the text."""
    lines = ["  .1  .2  .3  .4  .5"] * 3
    lines[2] = "  .1  .2  x.3  .4  .5"  # header is 4 lines, so this is line 7
    path = _write(tmp_path, "bad.AT2", NGA_HEADER + "NPTS= 15, DT= .01\n" + "\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"bad\.AT2, line 7: cannot read 'x\.3'"):
        read_at2(path)


def test_nan_in_file_is_rejected(tmp_path: Path) -> None:
    """NaN is not a number a record may contain: the line is named."""
    path = _write(tmp_path, "nan.AT2", NGA_HEADER + "NPTS= 3, DT= .01\n .1 NaN .3\n")
    with pytest.raises(ValueError, match="line 5: cannot read 'NaN'"):
        read_at2(path)


def test_npts_mismatch(tmp_path: Path) -> None:
    """A value count different from NPTS is an error stating both numbers."""
    path = _write(tmp_path, "short.AT2", NGA_HEADER + "NPTS= 6, DT= .01\n .1 .2 .3\n .4 .5\n")
    with pytest.raises(ValueError, match=r"short\.AT2.*NPTS=6 but 5 values"):
        read_at2(path)


def test_missing_empty_and_headerless(tmp_path: Path) -> None:
    """File not found, empty file and a .AT2 without NPTS line give clear errors."""
    with pytest.raises(FileNotFoundError, match="not found"):
        read_record(tmp_path / "absent.AT2")
    with pytest.raises(ValueError, match="empty"):
        read_record(_write(tmp_path, "empty.AT2", "\n  \n"))
    with pytest.raises(ValueError, match="NPTS"):
        read_at2(_write(tmp_path, "nohead.AT2", ".1 .2\n"))


# --------------------------------------------------------------------------------------- column formats

def test_columns_non_uniform_step_names_line(tmp_path: Path) -> None:
    """A time column whose spacing breaks (a missing sample) is refused, naming the line."""
    rows = [f"{0.01 * i!r},{0.1 * i!r}" for i in range(10) if i != 6]  # sample 6 missing
    path = _write(tmp_path, "gap.csv", "# comment\ntime,accel\n" + "\n".join(rows) + "\n")
    # line 1 comment, line 2 titles, data from line 3: sample 7 sits on line 3 + 6 = 9.
    with pytest.raises(ValueError, match=r"gap\.csv, line 9: time step"):
        read_columns(path, units="g")


def test_columns_titles_comments_and_float_noise(tmp_path: Path) -> None:
    """Titles at the top and '#' lines anywhere are skipped; times with float noise are uniform."""
    times = np.cumsum(np.full(50, 0.005)) - 0.005  # accumulated sum: noise ~1e-17 relative
    rows = [f"{t:.17g} {a:.17g}" for t, a in zip(times, np.sin(times))]
    rows.insert(20, "# a comment in the middle")
    path = _write(tmp_path, "cols.txt", "Time  Accel\n" + "\n".join(rows) + "\n")
    gm = read_columns(path, units="m/s2")
    assert gm.npts == 50 and gm.dt == pytest.approx(0.005, rel=1e-12)
    np.testing.assert_allclose(gm.acceleration, np.sin(times), rtol=1e-15)
    bad = _write(tmp_path, "late.txt", "0 1\n0.1 2\nTime Accel\n0.2 3\n")
    with pytest.raises(ValueError, match="line 3"):  # titles are only allowed above the data
        read_columns(bad, units="g")


def test_single_column_and_autodetect(tmp_path: Path) -> None:
    """One value per line needs dt (the message says so); with dt it reads; bad dt is refused."""
    path = _write(tmp_path, "one.txt", "0.1\n-0.2\n0.3\n")
    with pytest.raises(ValueError, match="pass dt="):
        read_record(path, units="g")
    gm = read_record(path, units="g", dt=0.02)
    assert gm.npts == 3 and gm.dt == 0.02
    assert read_single_column(path, dt=0.02, units="g").pga_g == pytest.approx(0.3, rel=1e-15)
    for dt in (0.0, -0.01, float("nan")):
        with pytest.raises(ValueError, match="dt must be a positive"):
            read_single_column(path, dt=dt, units="g")
    with pytest.raises(ValueError, match="units"):
        read_record(path, dt=0.02)


def test_units_give_same_si_values(tmp_path: Path) -> None:
    """The same record written in g and in cm/s^2 gives the same m/s^2 samples (1 g = 980.665 cm/s^2)."""
    rng = np.random.default_rng(1)
    a_g = rng.normal(0.0, 0.2, 200)
    t = 0.01 * np.arange(200)
    p_g = _write(tmp_path, "g.csv", "\n".join(f"{ti:.17g},{a:.17g}" for ti, a in zip(t, a_g)))
    p_cm = _write(tmp_path, "cm.csv", "\n".join(f"{ti:.17g},{a * 980.665:.17g}" for ti, a in zip(t, a_g)))
    gm_g, gm_cm = read_record(p_g, units="g"), read_record(p_cm, units="cm/s2")
    # Only rounding of the printed and converted floats differs: a few ulps.
    np.testing.assert_allclose(gm_cm.acceleration, gm_g.acceleration, rtol=1e-13)
    assert gm_g.pga == pytest.approx(np.max(np.abs(a_g)) * STANDARD_GRAVITY, rel=1e-15)


# ------------------------------------------------------------------------------------------- processing

def test_scaling_and_tail() -> None:
    """A factor 2 doubles the PGA; scaled_to_pga hits its target; a tail appends zeros at the same dt."""
    gm = GroundMotion(np.array([0.0, 1.0, -3.0, 2.0]), 0.01, vertical=np.array([0.0, 0.5, 0.0, 0.0]))
    assert gm.scaled(2.0).pga == pytest.approx(2.0 * gm.pga, rel=1e-15)
    target = gm.scaled_to_pga(9.0)
    assert target.pga == pytest.approx(9.0, rel=1e-15)
    assert target.vertical is not None and target.vertical[1] == pytest.approx(1.5)  # V/H ratio kept
    tail = gm.with_tail(0.05)
    assert tail.npts == 9 and tail.dt == gm.dt and np.all(tail.acceleration[4:] == 0.0)
    with pytest.raises(ValueError, match="a tail of 1e\\+06 s at dt = 0.01 s is 1e\\+08 samples .* shorten the tail"):
        gm.with_tail(1e6)  # 0.8 GB of zeros, refused before any is allocated


def test_constant_acceleration_integrates_exactly() -> None:
    """Constant a over T: v(T) = a T and d(T) = a T^2 / 2 (Newton). The trapezoid rule is exact for
    constant and linear integrands, so only roundoff remains (rtol 1e-12)."""
    a, dt, n = 0.7, 0.01, 1001
    gm = GroundMotion(np.full(n, a), dt)
    big_t = gm.duration
    assert gm.velocity()[-1] == pytest.approx(a * big_t, rel=1e-12)
    assert gm.displacement()[-1] == pytest.approx(0.5 * a * big_t**2, rel=1e-12)
    assert gm.velocity()[0] == 0.0 and gm.displacement()[0] == 0.0


def test_velocity_of_cosine_within_trapezoid_bound() -> None:
    """a = cos(w t) gives v = sin(w t)/w. Trapezoid error bound: T dt^2 max|a''| / 12 = T dt^2 w^2 / 12."""
    w, dt, n = 2.0 * np.pi * 1.5, 0.005, 2001
    gm = GroundMotion(np.cos(w * dt * np.arange(n)), dt)
    bound = gm.duration * dt**2 * w**2 / 12.0
    assert np.max(np.abs(gm.velocity() - np.sin(w * gm.time) / w)) <= bound


def test_baseline_correction_removes_offset() -> None:
    """A sine over whole periods plus a constant offset a0 ends with v = a0 T; after the order-1
    correction the end velocity is within the trapezoid error bound T dt^2 A w^2 / 12 of zero."""
    amp, w, a0, dt = 1.0, 2.0 * np.pi, 0.05, 0.01
    t = dt * np.arange(2001)  # 20 s = 20 whole periods
    gm = GroundMotion(amp * np.sin(w * t) + a0, dt)
    assert gm.velocity()[-1] == pytest.approx(a0 * 20.0, rel=1e-9)
    corrected = gm.baseline_corrected(order=1)
    assert abs(corrected.velocity()[-1]) <= 20.0 * dt**2 * amp * w**2 / 12.0
    # A pure constant offset is removed exactly (a linear velocity is fitted exactly): roundoff only.
    flat = GroundMotion(np.full(500, a0), dt).baseline_corrected(order=2)
    assert np.max(np.abs(flat.acceleration)) <= 1e-12


@pytest.mark.parametrize("window", [(0.0, 20.0), (3.0, 7.31), (10.0, 40.0)])
def test_windowed_record_ends_at_rest(window) -> None:
    """A shipped record cut inside its strong motion (El Centro at 20 s moves at 0.068 m/s) is
    brought to rest over the last tenth of the window and stays at rest through the tail; before
    that tenth the correction is the linear trend removal alone (a constant), and over a long
    window the deceleration is small against the record. (Before 2026-11-27 the ground kept the velocity left at the cut: El Centro
    cut at 20 s drifted at 0.061 m/s through the whole tail, 3 m in 50 s.)"""
    gm = read_record("elcentro-rsn6")
    raw = prepare_record(gm, window=window, baseline=False)  # with one zero sample appended
    applied = prepare_record(gm, window=window, tail=50.0)
    n = raw.npts - 1
    t, duration = raw.time[:n], raw.duration - raw.dt
    speed = np.max(np.abs(applied.velocity()))
    assert np.max(np.abs(applied.velocity()[n:])) <= 1e-12 * speed
    shift = np.ptp(applied.displacement()[n:])
    assert shift <= 1e-10 * np.max(np.abs(applied.displacement()))
    head = t < t[-1] - 0.1 * duration
    change = applied.acceleration[:n] - raw.acceleration[:n]
    assert np.all(np.diff(change[head]) == pytest.approx(0.0, abs=1e-12))  # a constant offset there
    if duration >= 20.0:  # a long window: the deceleration is small against the record
        assert np.max(np.abs(change)) <= 0.03 * gm.pga


def test_direction_vertical_and_resampling() -> None:
    """vector_acceleration = a * unit(direction) + vertical on z; horizontal-only directions;
    linear resampling reproduces a linear record exactly."""
    acc = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    gm = GroundMotion(acc, 0.1, direction=(3.0, 4.0, 0.0), vertical=-0.5 * acc)
    expected = np.column_stack([0.6 * acc, 0.8 * acc, -0.5 * acc])
    np.testing.assert_allclose(gm.vector_acceleration(), expected, rtol=1e-15)
    np.testing.assert_allclose(gm.vector_velocity()[:, 2], -0.5 * gm.velocity(), rtol=1e-15)
    with pytest.raises(ValueError, match="horizontal"):
        gm.with_direction((0.0, 0.0, 1.0))
    fine = gm.resampled(0.025)
    assert fine.npts == 17
    np.testing.assert_allclose(fine.acceleration, fine.time / 0.1, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="non-finite"):
        GroundMotion(np.array([0.0, np.nan]), 0.01)
    with warnings.catch_warnings():  # an absurd sample is named before the unit conversion overflows
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"big: acceleration has 1 value\(s\) beyond any plausible .* first 1e\+300 at sample 1"):
            GroundMotion.from_samples([0.0, 1e300, 0.0], dt=0.01, units="g", name="big")
    with pytest.raises(ValueError, match="dt must be a positive"):
        GroundMotion(acc, 0.0)


def test_window_and_time_errors_print_plain_numbers(tmp_path: Path) -> None:
    """Errors give the numbers as written, not NumPy reprs (``np.float64(5.0)``)."""
    gm = read_record("elcentro-rsn6")
    with pytest.raises(ValueError, match=r"got \(5, 2\)$"):
        prepare_record(gm, window=(np.float64(5.0), np.float64(2.0)))
    with pytest.raises(ValueError, match=r"window \(100, 101\) holds fewer"):
        prepare_record(gm, window=(100.0, 101.0))
    bad = _write(tmp_path, "back.csv", "0.0,0.1\n0.01,0.2\n0.005,0.3\n0.02,0.1\n")
    with pytest.raises(ValueError, match=r"line 3: time 0.005 does not increase \(previous 0.01 on line 2\)"):
        read_record(bad, units="g")


def test_a_vertical_component_from_the_records_own_file_needs_its_column(tmp_path: Path) -> None:
    """time, NS, EW, UD columns: the vertical record read from the same file must name its column
    (it used to take the horizontal's, silently); vertical_column picks it."""
    from rockdem.case import parse_case
    from rockdem.run_cli import run_case

    rows = "\n".join(f"{0.01 * k:.2f}, {0.1 * k:.2f}, 0.0, {-0.05 * k:.3f}" for k in range(5))
    path = _write(tmp_path, "nsewud.csv", "t, ns, ew, ud\n" + rows + "\n")
    case = {"run": {"duration": 0.03, "record_interval": 0.01},
            "specimen": {"type": "block", "width": 0.2, "height": 1.0, "length": 0.5, "youngs_modulus": 1.8e9},
            "loading": {"type": "earthquake", "record": str(path), "units": "g", "acc_column": 1, "vertical": str(path),
                        "baseline": False}}
    with pytest.raises(ValueError, match="vertical is the record's own file: give vertical_column"):
        parse_case(case)
    case["loading"]["vertical_column"] = 1
    with pytest.raises(ValueError, match="vertical_column = 1 is the horizontal record's column"):
        parse_case(case)
    case["loading"]["vertical_column"] = 3
    ds = run_case(parse_case(case), progress=False)
    t = ds.time.values
    np.testing.assert_allclose(ds.ground_acceleration.values[:, 0], 10.0 * t * STANDARD_GRAVITY, atol=1e-9)
    np.testing.assert_allclose(ds.ground_acceleration.values[:, 2], -5.0 * t * STANDARD_GRAVITY, atol=1e-9)


def test_a_vertical_file_of_another_layout(tmp_path: Path) -> None:
    """A three-column horizontal file (acc_column = 2) with a vertical of two columns: the vertical
    is read by its own layout; one of three columns needs vertical_column, named in the error."""
    from rockdem.case import parse_case

    rows = "\n".join(f"{0.01 * k:.2f}, 9, {0.1 * k:.2f}" for k in range(5))
    h = _write(tmp_path, "h.csv", rows + "\n")
    v2 = _write(tmp_path, "v2.csv", "\n".join(f"{0.01 * k:.2f}, {-0.05 * k:.3f}" for k in range(5)) + "\n")
    v3 = _write(tmp_path, "v3.csv", "\n".join(f"{0.01 * k:.2f}, 9, {-0.05 * k:.3f}" for k in range(5)) + "\n")
    case = {"run": {"duration": 0.03, "record_interval": 0.01},
            "specimen": {"type": "block", "width": 0.2, "height": 1.0, "length": 0.5, "youngs_modulus": 1.8e9},
            "loading": {"type": "earthquake", "record": str(h), "units": "g", "acc_column": 2, "vertical": str(v2), "baseline": False}}
    gm = parse_case(case).model  # builds: the two-column vertical read as such
    assert gm.block_count == 2
    case["loading"]["vertical"] = str(v3)
    with pytest.raises(ValueError, match=r"vertical record .*v3.csv.*acceleration column is vertical_column"):
        parse_case(case)
    case["loading"]["vertical_column"] = 2
    parse_case(case)
    with pytest.raises(ValueError, match="holds whole numbers .*give time_column"):
        read_record(_write(tmp_path, "i.csv", "0, 0.0, 0.1\n1, 0.01, 0.2\n2, 0.02, 0.3\n"), units="g", acc_column=2, dt=0.01)


def test_a_window_reaching_beyond_the_record_is_warned_about() -> None:
    """A window past the end of a record (El Centro is 53.7 s long) is used as far as the record
    goes, and says so (before 2026-11-29 it was clipped silently)."""
    gm = read_record("elcentro-rsn6")
    with pytest.warns(UserWarning, match=r"window \(50, 60\) s reaches beyond the record \(0\.\.53\.7"):
        cut = prepare_record(gm, window=(50.0, 60.0), baseline=False)
    assert cut.duration == pytest.approx(gm.time[-1] - 50.0 + cut.dt, abs=2 * gm.dt)  # one zero sample appended
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        prepare_record(gm, window=(10.0, 40.0), baseline=False)  # inside: no warning


def test_misread_files_say_how_to_read_them(tmp_path: Path) -> None:
    """A spreadsheet export with ';' and decimal commas, swapped columns and a step that drifts are
    refused with what to do, the numbers as a user writes them (no NumPy reprs)."""
    euro = _write(tmp_path, "euro.csv", "t;a\n0,00;0,10\n0,01;0,20\n0,02;0,30\n")
    with pytest.raises(ValueError, match="decimal commas"):
        read_record(euro, units="g")
    swapped = _write(tmp_path, "swapped.csv", "a,t\n0.3,0.00\n0.1,0.01\n0.2,0.02\n")
    with pytest.raises(ValueError, match="does not increase .*give time_column and acc_column"):
        read_record(swapped, units="g")
    drift = _write(tmp_path, "drift.txt", "0.0 0.1\n0.01 0.2\n0.02 0.3\n0.035 0.1\n")
    with pytest.raises(ValueError, match=r"time step 0\.015 s differs from the record's 0\.01 s") as err:
        read_record(drift, units="g")
    assert "np.float64" not in str(err.value)
    tabs = _write(tmp_path, "tabs.txt", "0,00\t0,10\n0,01\t0,20\n0,02\t0,30\n")
    with pytest.raises(ValueError, match="decimal commas"):
        read_record(tabs, units="g")
    dots = _write(tmp_path, "dots.csv", "t;a\n0.00;0.10\n0.01;0.20\n0.02;0.30\n")  # what the message advises
    assert read_record(dots, units="g").dt == pytest.approx(0.01)
    half = _write(tmp_path, "half_ms.txt", "".join(f"{2.5 * k} 0.1\n" for k in range(20)))  # 2.5 ms steps, in ms
    with pytest.warns(UserWarning, match="a time step of 2.5 s.*milliseconds"):
        read_record(half, units="g")


@pytest.mark.parametrize("line, units", [
    ("Units: cm/s^2", "cm/s2"), ("acceleration (gal)", "cm/s2"), ("UNITS: CM/S**2", "cm/s2"),
    ("ACCELERATION IN CM/SEC**2", "cm/s2"), ("UNITS OF CM/S/S", "cm/s2"), ("Units: m/s2", "m/s2"), ("M/S/S", "m/s2"),
    ("ACCELERATION TIME SERIES IN UNITS OF G", "g"), ("The units are (g)", "g"), ("synthetic record", "g"),
])
def test_at2_header_units_are_read_as_written(tmp_path, line, units):
    """Before 2026-11-30 a header that wrote its units otherwise than 'UNITS OF ...' was read as g:
    "Units: cm/s^2" gave a record of 196 g. A header without units is g (the NGA convention)."""
    from rockdem.records import read_at2

    f = tmp_path / "r.AT2"
    f.write_text(f"PEER NGA STRONG MOTION DATABASE RECORD\nsynthetic, station Galway\n{line}\nNPTS=   3, DT=   .0100 SEC,\n 100.0 -50.0 0.0\n")
    g = read_at2(f)
    assert g.units_in == units
    assert g.pga == pytest.approx({"g": 100.0 * 9.80665, "m/s2": 100.0, "cm/s2": 1.0}[units])


@pytest.mark.parametrize("line, message", [
    ("Units: furlongs per fortnight", "speaks of units rockdem cannot read"),
    ("UNITS OF G (peak 200 CM/S2)", "names several units"),
])
def test_at2_header_units_that_cannot_be_read_ask_for_units(tmp_path, line, message):
    from rockdem.records import read_at2

    f = tmp_path / "r.AT2"
    f.write_text(f"PEER NGA STRONG MOTION DATABASE RECORD\nsynthetic\n{line}\nNPTS=   3, DT=   .0100 SEC,\n 1.0 -0.5 0.0\n")
    with pytest.raises(ValueError, match=rf"{message} .*give units"):
        read_at2(f)
    assert read_at2(f, units="cm/s2").pga == pytest.approx(0.01)  # given: taken
