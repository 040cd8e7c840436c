"""A plain clone needs nothing beside it: records come from the package, examples find them anywhere.

`.ci/run` runs the whole suite from a fresh clone in an empty temporary folder; these tests make the
same promise checkable in any checkout.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from rockdem.case import load_case, parse_case
from rockdem.records import DATA_ENV, SHIPPED_RECORDS, read_record, record_path, records_folder, shipped_record
from rockdem.run_cli import run_case

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))
# a reference to the project's data folder beside the repository (../shared/data/ground-motions)
BESIDE = re.compile(r"\.\./shared|shared/data|shared_record_path")


def _tracked_text_files() -> list[Path]:
    out = []
    for folder in ("rockdem", "tests", "examples", "benchmarks", ".ci"):
        for p in (ROOT / folder).rglob("*"):
            if p.is_file() and p.suffix in (".py", ".toml", ".md", "") and "__pycache__" not in p.parts:
                out.append(p)
    return out + [ROOT / "pyproject.toml", ROOT / "README.md"]


def test_no_file_refers_to_a_folder_beside_the_repository() -> None:
    """No code, test, example or CI script looks for ../shared (the old shared_record_path did)."""
    me = Path(__file__).resolve()
    hits = []
    for p in _tracked_text_files():
        if p.resolve() == me or p.parent == records_folder():
            continue  # this test names the pattern; SOURCES.md describes where the files came from
        text = p.read_text(encoding="utf-8", errors="replace")
        hits += [f"{p.relative_to(ROOT)}:{i}" for i, line in enumerate(text.splitlines(), 1) if BESIDE.search(line)]
    assert hits == []


def test_pyproject_ships_every_record() -> None:
    """pip installs the records: the package-data globs cover every shipped file and SOURCES.md."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    globs = cfg["tool"]["setuptools"]["package-data"]["rockdem"]
    package = ROOT / "rockdem"
    shipped = {p.resolve() for g in globs for p in package.glob(g) if p.is_file()}
    for name in [r.file for r in SHIPPED_RECORDS] + ["SOURCES.md", "README.md"]:
        assert (records_folder() / name).resolve() in shipped, name


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_records_resolve_from_any_folder(path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every example's record (if any) is a shipped record, found with no ROCKDEM_DATA and from an
    unrelated working folder."""
    monkeypatch.delenv(DATA_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    loading = load_case(path).get("loading", {})
    for key in ("record", "vertical"):
        name = loading.get(key)
        if isinstance(name, str):
            assert shipped_record(name) is not None, f"{path.name}: {key} = {name!r} is not a shipped record"
            assert record_path(name).parent == records_folder()
            assert read_record(name).npts > 100


def test_an_earthquake_example_runs_from_an_empty_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The Nahanni two-block wall (a CSV record, units from the registry) runs from an empty folder."""
    monkeypatch.delenv(DATA_ENV, raising=False)
    monkeypatch.chdir(tmp_path)
    data = load_case(ROOT / "examples" / "two_block_wall_nahanni_100.toml")
    data["loading"].pop("units")  # the shipped record knows its units
    ds = run_case(parse_case(data), duration=0.05, progress=False)
    assert ds.attrs["earthquake_record"] == "Nahanni_1985_NS1-280"
    assert ds.sizes["time"] >= 2
