"""Seeded fuzz of bad input: case files, study files, CLI flags and the Python API.

Every generated input is wrong (a wrong type, a negative, zero, NaN, infinite or absurdly large
value, an unknown or missing key, an unreadable file, a bad flag) and must be refused through the
documented path: the CLI returns exit code 2 with a message on stderr naming the key, flag or file
and no traceback; an API call raises ValueError (or FileNotFoundError) naming the field. No case
may hang, and none may be accepted silently; the few merely implausible inputs (``expect="warn"``)
may run but must warn.

The cases run one after another in a spawned worker process so that a hang (a compiled loop
cannot be interrupted from Python) costs only its time limit: the parent kills and restarts the
worker. Run as a script (``python tests/test_fuzz.py``) to print the counts per outcome and class.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import multiprocessing as mp
import os
import re
import sys
import tempfile
import traceback
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

SEED = 20221
MUTATIONS = 260
CASE_TIMEOUT_S = 20.0
WARMUP_TIMEOUT_S = 300.0


@dataclass(frozen=True)
class FuzzCase:
    """One bad input.

    Attributes:
        group: class of input ("case-file", "study", "cli", "api", "file", ...), for the counts.
        name: what was done, e.g. ``specimen.width = nan``.
        argv: command line for ``rockdem.cli.main`` (kind "cli").
        call: key of :data:`API` (kind "api"), with ``args`` and ``kwargs``.
        tokens: the message must contain one of these (case-insensitive): the key, flag or file.
        expect: "refuse", or "warn" (accepted with a warning, or refused).
        timeout: seconds before the case counts as a hang.
    """

    group: str
    name: str
    argv: tuple[str, ...] = ()
    call: str = ""
    args: tuple[Any, ...] = ()
    kwargs: tuple[tuple[str, Any], ...] = ()
    tokens: tuple[str, ...] = ()
    expect: str = "refuse"
    timeout: float = CASE_TIMEOUT_S

    @property
    def kind(self) -> str:
        return "cli" if self.argv else "api"


# --------------------------------------------------------------------------------------------------
# base cases (tiny runs: 5 ms simulated) and a TOML writer
# --------------------------------------------------------------------------------------------------
RUN = {"duration": 0.005, "record_interval": 0.001}
JOINT = {"youngs_modulus": 1.0e9, "poisson": 0.25, "friction_angle_deg": 35.0}
BLOCK = {"type": "block", "width": 0.2, "height": 1.0, "length": 0.5, "density": 1800.0, **JOINT, "points_across": 2}
OUTPUT = {"plot": False, "csv": False}


def bases(record: str) -> dict[str, dict[str, Any]]:
    """Valid case dicts of every specimen and loading type (``record``: a small AT2 file)."""
    return {
        "block": {"description": "fuzz", "run": RUN, "damping": {"beta": 0.001}, "specimen": BLOCK,
                  "loading": {"type": "free-rocking", "tilt_fraction": 0.5}, "output": OUTPUT},
        "stack": {"run": RUN, "damping": {"alpha": 1.0},
                  "specimen": {"type": "stack", "width": 0.2, "length": 0.5, "heights": [0.5, 0.5], **JOINT},
                  "loading": {"type": "gravity"}, "output": OUTPUT},
        "wall": {"run": RUN, "specimen": {"type": "wall", "brick": [0.11, 0.23, 0.076], "courses": 2,
                                          "bricks_per_course": 2, "bond": "stack", "points_along": 3,
                                          "joint": {"youngs_modulus": 1.0e9, "cohesion": 1.0e5, "tension": 5.0e4}},
                 "loading": {"type": "free-rocking", "tilt_fraction": 0.3}, "output": OUTPUT},
        "parapet": {"run": RUN, "specimen": {"type": "parapet", "thickness": 0.23, "height": 0.6, "length": 0.5,
                                             "base_reduction": 0.007, **JOINT},
                    "loading": {"type": "free-rocking", "tilt_fraction": 0.5}, "output": OUTPUT},
        "facade": {"run": RUN, "specimen": {"type": "facade", "width": 0.11, "height": 0.8, "length": 1.5,
                                            "gap": 0.004, "edge_radius": 0.008, "edge_facets": 4, "slope_deg": 0.0,
                                            "rocking_velocity": 0.0, **JOINT},
                   "loading": {"type": "free-rocking", "block": "facade", "tilt_fraction": 0.5,
                               "tilt_direction": [-1.0, 0.0, 0.0]}, "output": OUTPUT},
        "two-block-wall": {"run": RUN, "specimen": {"type": "two-block-wall", "thickness": 0.11, "height": 1.5,
                                                    "length": 0.95, "push_displacement": 0.05, "push_time": 1.0,
                                                    "hold_time": 0.1, "withdraw_speed": 1.0, **JOINT},
                           "loading": {"type": "gravity"}, "output": OUTPUT},
        "pushover": {"run": RUN, "damping": {"local": 0.8}, "specimen": BLOCK,
                     "loading": {"type": "pushover", "rate": 0.02, "max_load_factor": 0.095,
                                 "direction": [1.0, 0.0, 0.0]}, "output": OUTPUT},
        "earthquake": {"run": RUN, "specimen": BLOCK,
                       "loading": {"type": "earthquake", "record": record, "scale": 1.0, "mode": "inertial",
                                   "direction": [1.0, 0.0, 0.0], "tail": 0.0}, "output": OUTPUT},
    }


REQUIRED = {
    "all": [("run",), ("run", "duration"), ("specimen",), ("specimen", "type")],
    "block": [("specimen", "width"), ("specimen", "height"), ("specimen", "youngs_modulus")],
    "stack": [("specimen", "heights"), ("specimen", "width"), ("specimen", "youngs_modulus")],
    "wall": [("specimen", "courses"), ("specimen", "bricks_per_course"), ("specimen", "joint"),
             ("specimen", "joint", "youngs_modulus")],
    "parapet": [("specimen", "height"), ("specimen", "youngs_modulus")],
    "facade": [("specimen", "youngs_modulus")],
    "two-block-wall": [("specimen", "youngs_modulus")],
    "pushover": [("loading", "max_load_factor")],
    "earthquake": [("loading", "record")],
}
POSITIVE = {"duration", "record_interval", "width", "height", "length", "thickness", "density", "youngs_modulus",
            "points_across", "points_along", "courses", "bricks_per_course", "edge_facets", "push_time",
            "withdraw_speed", "rate", "max_load_factor", "brick"}
NON_NEGATIVE = {"alpha", "beta", "local", "cohesion", "tension", "gap", "edge_radius", "base_reduction", "tail",
                "hold_time", "push_displacement", "tilt_fraction", "scale", "friction_angle_deg"}
INTEGERS = {"points_across", "points_along", "courses", "bricks_per_course", "edge_facets"}


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else json.dumps(k)


def toml_value(v: Any) -> str:
    """A TOML literal (NaN and infinities included)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def toml_dump(data: dict[str, Any], prefix: tuple[str, ...] = ()) -> str:
    """A TOML document of nested dicts (tables after the scalars)."""
    lines = [f"{_key(k)} = {toml_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, v in data.items():
        if isinstance(v, dict):
            lines.append(f"[{'.'.join(_key(x) for x in (*prefix, k))}]")
            lines.append(toml_dump(v, (*prefix, k)))
    return "\n".join(lines) + "\n"


def _get(d: dict[str, Any], path: tuple[str, ...]) -> Any:
    for k in path:
        d = d[k]
    return d


def _set(d: dict[str, Any], path: tuple[str, ...], value: Any) -> None:
    for k in path[:-1]:
        d = d[k]
    d[path[-1]] = value


def _leaves(d: dict[str, Any], path: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Any]]:
    out = []
    for k, v in d.items():
        out.append(((*path, k), v))
        if isinstance(v, dict):
            out.extend(_leaves(v, (*path, k)))
    return out


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def mutate(base: dict[str, Any], rng: np.random.Generator) -> tuple[dict[str, Any], str, tuple[str, ...]] | None:
    """A copy of ``base`` with one bad change; returns (case, description, tokens), or None when
    the drawn change does not apply to the drawn key."""
    data = json.loads(json.dumps(base))
    leaves = _leaves(data)
    op = str(rng.choice(["type", "nonfinite", "sign", "huge", "unknown", "delete"], p=[0.3, 0.15, 0.2, 0.15, 0.1, 0.1]))
    path, value = leaves[int(rng.integers(len(leaves)))]
    key = path[-1]
    where = ".".join(path)
    if op == "type":
        if isinstance(value, dict):
            new: Any = [5, "abc"][int(rng.integers(2))]
        elif isinstance(value, str):
            new = [1.5, True, [1, 2], {"x": 1}][int(rng.integers(4))]
        elif isinstance(value, bool):
            new = ["abc", 1, [1]][int(rng.integers(3))]
        elif isinstance(value, list):
            new = ["abc", 1.5, {"x": 1}][int(rng.integers(3))]
        else:
            new = ["abc", True, [1, 2], {"x": 1}][int(rng.integers(4))]
        _set(data, path, new)
        return data, f"{where} = {toml_value(new)}", (key,)
    if op == "nonfinite":
        bad = [math.nan, math.inf, -math.inf][int(rng.integers(3))]
        if _is_number(value):
            _set(data, path, bad)
        elif isinstance(value, list) and value and all(_is_number(v) for v in value):
            value[int(rng.integers(len(value)))] = bad
        else:
            return None
        return data, f"{where} = {toml_value(_get(data, path))}", (key,)
    if op == "sign":
        if key in POSITIVE and _is_number(value):
            new = [0, -abs(value), -1][int(rng.integers(3))]
            new = int(new) if key in INTEGERS else float(new)
        elif key in POSITIVE and isinstance(value, list):
            value[int(rng.integers(len(value)))] = [0.0, -1.0][int(rng.integers(2))]
            return data, f"{where} = {toml_value(value)}", (key,)
        elif key in NON_NEGATIVE and _is_number(value):
            new = -abs(float(value)) - 1.0
        else:
            return None
        _set(data, path, new)
        return data, f"{where} = {toml_value(new)}", (key,)
    if op == "huge":
        if key in INTEGERS and _is_number(value):
            new = 10**12
        elif _is_number(value):
            new = [1e300, 1e25, -1e300][int(rng.integers(3))]
        elif isinstance(value, list) and value and all(_is_number(v) for v in value):
            value[int(rng.integers(len(value)))] = 1e300
            return data, f"{where} = {toml_value(value)}", (key,)
        else:
            return None
        _set(data, path, new)
        return data, f"{where} = {toml_value(new)}", (key,)
    if op == "unknown":
        tables = [p for p, v in leaves if isinstance(v, dict)] + [()]
        t = tables[int(rng.integers(len(tables)))]
        (_get(data, t) if t else data)["colour"] = 1
        return data, f"{'.'.join(t) or 'top level'}: unknown key colour", ("colour",)
    return None  # "delete" is drawn from REQUIRED by the caller


# --------------------------------------------------------------------------------------------------
# API calls (module level: the worker looks them up by name)
# --------------------------------------------------------------------------------------------------
def _builder():
    from rockdem.materials import JointMaterial
    from rockdem.model import ModelBuilder

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.2, 1, 1, name="block")
    return b


def _api_material(**kw):
    from rockdem.materials import JointMaterial

    return JointMaterial(**kw)


def _api_default_material(value):
    from rockdem.model import ModelBuilder

    b = ModelBuilder()
    b.default_material = value if not isinstance(value, dict) or "kn" not in value else _api_material(**value)


def _api_from_modulus(*a, **kw):
    from rockdem.materials import JointMaterial

    return JointMaterial.from_modulus(*a, **kw)


def _api_kn_from_modulus(*a):
    from rockdem.materials import kn_from_modulus

    return kn_from_modulus(*a)


def _api_ks_from_kn(*a, **kw):
    from rockdem.materials import ks_from_kn

    return ks_from_kn(*a, **kw)


def _api_builder_init(**kw):
    from rockdem.model import ModelBuilder

    return ModelBuilder(**kw)


def _api_add_box(*a, **kw):
    return _builder().add_box(*a, **kw)


def _api_add_block(*a, **kw):
    return _builder().add_block(*a, **kw)


def _api_tilt(*a, **kw):
    return _builder().tilt(*a, **kw)


def _api_set_material(*a):
    return _builder().set_material(*a)


def _api_ground_motion(*a):
    return _builder().set_ground_motion(*a)


def _api_body_acceleration(*a):
    return _builder().set_body_acceleration(*a)


def _api_motion(*a):
    from rockdem.model import Motion

    return Motion(*a)


def _api_motion_constant(*a, **kw):
    from rockdem.model import Motion

    return Motion.constant(*a, **kw)


def _api_motion_function(duration, sample_dt):
    from rockdem.model import Motion

    return Motion.from_function(lambda t: (0.0, 0.0, 0.0), duration, sample_dt)


def _api_damping(**kw):
    from rockdem.model import Damping

    return Damping(**kw)


def _api_box(*a, **kw):
    from rockdem.geometry import box

    return box(*a, **kw)


def _api_convex_hull(*a):
    from rockdem.geometry import convex_hull

    return convex_hull(*a)


def _api_face_points(*a):
    from rockdem.geometry import box, face_points

    return face_points(box(1, 1, 1), *a)


def _api_mass_properties(density):
    from rockdem.geometry import box, mass_properties

    return mass_properties(box(1, 1, 1), density)


def _api_specimen(name, **kw):
    from rockdem import specimens
    from rockdem.materials import JointMaterial
    from rockdem.model import ModelBuilder

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=1e9)
    return getattr(specimens, name)(b, **kw)


def _api_push_motion(*a, **kw):
    from rockdem.specimens import push_motion

    return push_motion(*a, **kw)


def _api_rounded_prism(*a, **kw):
    from rockdem.specimens import rounded_prism

    return rounded_prism(*a, **kw)


def _api_parse_case(data):
    from rockdem.case import parse_case

    return parse_case(data)


def _api_load_case(path):
    from rockdem.case import load_case

    return load_case(path)


def _api_overrides(data, overrides):
    from rockdem.case import apply_overrides, parse_case

    return parse_case(apply_overrides(data, overrides))


def _api_parse_study(data):
    from rockdem.studies import parse_study

    return parse_study(data)


def _api_expand_random(ranges, n, seed):
    from rockdem.studies import expand_random

    return expand_random(ranges, n, seed)


def _api_expand_grid(params):
    from rockdem.studies import expand_grid

    return expand_grid(params)


def _api_execute(overrides, **kw):
    from rockdem.case import example_case
    from rockdem.studies import RunSpec, execute

    return execute([RunSpec.make(example_case("free-rocking"), overrides, duration=0.005)], None, progress=False, **kw)


def _api_runspec(**kw):
    from rockdem.case import example_case
    from rockdem.studies import RunSpec

    return RunSpec.make(example_case("free-rocking"), {}, **kw)


API: dict[str, Callable[..., Any]] = {name[5:]: f for name, f in globals().items() if name.startswith("_api_")}


# --------------------------------------------------------------------------------------------------
# the generator
# --------------------------------------------------------------------------------------------------
AT2 = ("PEER NGA STRONG MOTION DATABASE RECORD\nFuzz 2022, synthetic\nACCELERATION TIME SERIES IN UNITS OF G\n"
       "NPTS=   40, DT=   .0050 SEC\n" + "\n".join(
           " ".join(f"{0.05 * math.sin(0.3 * (5 * i + j)):.6f}" for j in range(5)) for i in range(8)) + "\n")


def _api(group: str, call: str, /, *args: Any, tokens: tuple[str, ...], expect: str = "refuse", **kwargs: Any) -> FuzzCase:
    desc = ", ".join([*(repr(a)[:40] for a in args), *(f"{k}={v!r}"[:40] for k, v in kwargs.items())])
    return FuzzCase(group, f"{call}({desc})", call=call, args=args, kwargs=tuple(kwargs.items()), tokens=tokens, expect=expect)


def generate(tmp: Path, seed: int = SEED, mutations: int = MUTATIONS) -> tuple[list[FuzzCase], FuzzCase]:
    """The bad inputs (files written under ``tmp``) and a valid warm-up case."""
    tmp.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    rec = tmp / "quake.at2"
    rec.write_text(AT2)
    all_bases = bases(str(rec))
    cases: list[FuzzCase] = []
    counter = iter(range(10**9))

    def run_file(group: str, name: str, text: str | bytes | None, tokens: tuple[str, ...], *, path: Path | None = None,
                 extra: tuple[str, ...] = (), expect: str = "refuse") -> None:
        k = next(counter)
        if path is None:
            path = tmp / f"case{k}.toml"
            path.write_bytes(text if isinstance(text, bytes) else str(text).encode())
        argv = ("run", str(path), "--out", str(tmp / "out" / f"r{k}"), "--quiet", "--no-plot", *extra)
        cases.append(FuzzCase(group, name, argv, tokens=tokens, expect=expect))

    def run_data(group: str, name: str, data: dict[str, Any], tokens: tuple[str, ...], **kw: Any) -> None:
        run_file(group, name, toml_dump(data), tokens, **kw)

    # -- random mutations of valid case files
    names = sorted(all_bases)
    made = 0
    while made < mutations:
        bname = names[int(rng.integers(len(names)))]
        base = all_bases[bname]
        if rng.random() < 0.1:
            req = REQUIRED["all"] + REQUIRED[bname]
            path = req[int(rng.integers(len(req)))]
            data = json.loads(json.dumps(base))
            del _get(data, path[:-1])[path[-1]]
            tokens = (path[-1],) if path[-1] != "specimen" else ("specimen", "type")
            run_data("case-file mutation", f"{bname}: {'.'.join(path)} removed", data, tokens)
        else:
            got = mutate(base, rng)
            if got is None:
                continue
            data, desc, tokens = got
            run_data("case-file mutation", f"{bname}: {desc}", data, tokens)
        made += 1

    # -- bad record files (earthquake loading)
    eq = all_bases["earthquake"]

    def with_record(path: Path | str, content: str | bytes | None, name: str) -> None:
        p = Path(path)
        if content is not None:
            p.write_bytes(content if isinstance(content, bytes) else content.encode())
        data = json.loads(json.dumps(eq))
        data["loading"]["record"] = str(p)
        run_data("record file", name, data, (p.name,))

    with_record(tmp / "missing.at2", None, "record file missing")
    with_record(tmp / "empty.at2", "", "record file empty")
    with_record(tmp / "truncated.at2", AT2[: AT2.rfind("\n", 0, len(AT2) - 2)] + "\n 0.12E-", "record truncated mid-number (0.12E-)")
    with_record(tmp / "nanrec.at2", AT2.replace("0.0", "nan", 1), "record holding NaN")
    with_record(tmp / "garbage.at2", bytes(range(256)) * 4, "record of binary garbage")
    with_record(tmp / "fewer.at2", AT2.replace("NPTS=   40", "NPTS=   45"), "record with fewer values than NPTS")
    with_record(tmp / "zerodt.at2", AT2.replace(".0050", ".0000"), "record with DT = 0")
    rdir = tmp / "recdir"
    rdir.mkdir(exist_ok=True)
    with_record(rdir, None, "record is a directory")
    data = json.loads(json.dumps(eq))
    data["loading"]["pga_g"] = 1e6
    del data["loading"]["scale"]
    run_data("fixed", "pga_g = 1e6", data, ("pga_g",))
    data["loading"]["pga_g"] = 20.0
    run_data("fixed", "pga_g = 20 (implausible)", data, ("pga_g",), expect="warn")

    # -- the case file itself
    block = all_bases["block"]
    run_file("case file", "a directory", None, ("casedir",), path=_mkdir(tmp / "casedir"))
    fifo = tmp / "case.fifo"
    if hasattr(os, "mkfifo") and not fifo.exists():
        os.mkfifo(fifo)
    run_file("case file", "a FIFO", None, ("case.fifo",), path=fifo)
    run_file("case file", "/dev/zero", None, ("/dev/zero",), path=Path("/dev/zero"))
    run_file("case file", "missing", None, ("nope.toml",), path=tmp / "nope.toml")
    run_file("case file", "empty", "", ("duration",))
    run_file("case file", "not TOML", "[run\nduration = 1\n", ("not valid TOML",))
    run_file("case file", "duplicate key", "[run]\nduration = 1\nduration = 2\n", ("not valid TOML",))
    run_file("case file", "non-UTF-8 (Latin-1 comment)", b"# caf\xe9\n" + toml_dump(block).encode(), ("UTF-8",))
    run_file("case file", "UTF-16", toml_dump(block).encode("utf-16"), ("UTF-8",))
    run_file("case file", "binary garbage", bytes(range(256)) * 8, ("UTF-8", "not valid TOML"))
    run_file("case file", "11 MiB of comments", (b"#" + b"x" * 1023 + b"\n") * 11 * 1024, ("MiB",))
    run_file("case file", "inline tables nested 500 deep", "a = " + "{b = " * 500 + "1" + "}" * 500 + "\n", ("nested",))
    run_file("case file", "arrays nested 500 deep", "a = " + "[" * 500 + "]" * 500 + "\n", ("nested",))
    run_file("case file", "tables nested 300 deep", "[" + ".".join(["t"] * 300) + "]\nx = 1\n", ("nested", "unknown key"))
    run_file("case file", "a top-level array", toml_dump(block) + "specimen_list = [1, 2]\n", ("specimen_list",))
    run_file("case file", "[run] is a number", "run = 5\n" + toml_dump({k: v for k, v in block.items() if k != "run"}), ("[run]",))

    # -- the part-5 classes on case files
    def variant(bname: str, path: tuple[str, ...], value: Any, tokens: tuple[str, ...], name: str | None = None) -> None:
        data = json.loads(json.dumps(all_bases[bname]))
        _set(data, path, value)
        run_data("fixed", name or f"{bname}: {'.'.join(path)} = {toml_value(value)[:30]}", data, tokens)

    variant("block", ("specimen", "points_across"), 10**12, ("points_across",))
    variant("block", ("specimen", "points_across"), 100_000, ("points_across",))
    variant("wall", ("specimen", "points_along"), 10**12 + 1, ("points_along",))
    variant("wall", ("specimen", "courses"), 10**9, ("courses",))
    variant("wall", ("specimen", "bricks_per_course"), 10**9, ("bricks_per_course",))
    variant("parapet", ("specimen", "brick"), [1e-6, 1e-6], ("brick",))
    variant("facade", ("specimen", "edge_facets"), 10**9, ("edge_facets",))
    variant("stack", ("specimen", "heights"), [-1.0, 1.0], ("heights",))
    variant("stack", ("specimen", "heights"), [1.0, -1.0], ("heights",))
    variant("stack", ("specimen", "heights"), [0.0, 0.0], ("heights",))
    variant("stack", ("specimen", "heights"), [], ("heights",))
    variant("stack", ("specimen", "heights"), [0.001] * 100_000, ("heights",), "stack of 100000 blocks")
    variant("block", ("specimen", "kn"), 0.0, ("kn",))
    variant("block", ("specimen", "ks"), -1.0e9, ("ks",))
    variant("block", ("specimen", "cohesion"), -5.0, ("cohesion",))
    variant("block", ("specimen", "tension"), math.nan, ("tension",))
    variant("block", ("specimen", "poisson"), 0.5, ("poisson",))
    variant("block", ("specimen", "friction_angle_deg"), 90.0, ("friction_angle",))
    variant("block", ("specimen", "gravity"), -9.81, ("gravity",))
    variant("block", ("run", "safety"), 0.0, ("safety",))
    variant("block", ("run", "timestep_rule"), "fast", ("timestep_rule",))
    variant("block", ("damping", "local"), 1.5, ("local",))
    variant("block", ("loading", "tilt_direction"), [0.0, 0.0, 1.0], ("direction",))
    variant("block", ("loading", "block"), "nope", ("nope",))
    variant("block", ("output", "directory"), 5, ("directory",))
    data = json.loads(json.dumps(block))
    data["specimen"]["kn"] = 1e9
    run_data("fixed", "block: both kn and youngs_modulus", data, ("kn",))

    # -- command-line flags of run
    good = tmp / "good.toml"
    good.write_text(toml_dump(block))
    afile = tmp / "a_file.txt"
    afile.write_text("not a folder\n")

    def run_flags(name: str, *flags: str, tokens: tuple[str, ...], case: Path | None = good) -> None:
        k = next(counter)
        argv = ("run", *([str(case)] if case else []), "--quiet", "--no-plot", *flags)
        if "--out" not in flags:
            argv += ("--out", str(tmp / "out" / f"f{k}"))
        cases.append(FuzzCase("cli flag", name, argv, tokens=tokens))

    for v in ("-1", "0", "nan", "inf", "abc", "1e300"):
        run_flags(f"run --duration {v}", "--duration", v, tokens=("--duration",))
    for s, tok in (("nokey", ("--set",)), ("=5", ("--set",)), ("run.duration=abc", ("duration",)),
                   ("run=5", ("[run]", "run")), ("specimen.width=nan", ("width",)), ("specimen.width=-1", ("width",)),
                   ("nosuch.key=1", ("nosuch",)), ("run.duration.x=1", ("duration",)),
                   ("specimen.width=" + "{a=" * 500 + "1" + "}" * 500, ("nested",)),
                   ("specimen.points_across=1000000000000", ("points_across",))):
        run_flags(f"run --set {s[:40]}", "--set", s, tokens=tok)
    run_flags("run --out naming an existing file", "--out", str(afile), tokens=("a_file.txt",))
    run_flags("run --out below a file", "--out", str(afile / "sub"), tokens=("a_file.txt",))
    run_flags("run --example nope", "--example", "nope", tokens=("nope",), case=None)
    run_flags("run with a case file and --example", "--example", "free-rocking", tokens=("--example",))
    run_flags("run with no case", tokens=("case",), case=None)
    run_flags("run --bogus", "--bogus", tokens=("--bogus",))
    run_flags("run --duration without value", "--duration", tokens=("--duration",))

    # -- study files and sweep flags
    study_base = {"base": str(good), "duration": 0.005, "executor": "serial"}

    def sweep(name: str, study: Any, tokens: tuple[str, ...], *flags: str, raw: str | bytes | None = None) -> None:
        k = next(counter)
        p = tmp / f"study{k}.toml"
        text = raw if raw is not None else toml_dump({"study": study} if isinstance(study, dict) else study)
        p.write_bytes(text if isinstance(text, bytes) else text.encode())
        cases.append(FuzzCase("study", name, ("sweep", str(p), "--out", str(tmp / "out" / f"s{k}"), "--no-progress", *flags),
                              tokens=tokens))

    for key, value, tok in (
        ("set", 5, ("set",)), ("set", {"specimen.width": -1.0}, ("width",)), ("set", {"nosuch.key": 1}, ("nosuch",)),
        ("workers", 0, ("workers",)), ("workers", -1, ("workers",)), ("workers", "x", ("workers",)),
        ("workers", 2.5, ("workers",)), ("history_interval", -1.0, ("history_interval",)),
        ("history_interval", math.nan, ("history_interval",)), ("history", "yes", ("history",)),
        ("duration", -1.0, ("duration",)), ("duration", "x", ("duration",)), ("duration", math.inf, ("duration",)),
        ("grid", 5, ("grid",)), ("grid", {"damping.alpha": 5}, ("damping.alpha",)),
        ("grid", {"damping.alpha": []}, ("damping.alpha",)), ("list", 5, ("list",)), ("list", [5], ("list",)),
        ("random", {"n": 0, "damping.alpha": [1.0, 2.0]}, ("n",)), ("random", {"n": "x"}, ("n",)),
        ("random", {"n": 2, "damping.alpha": [1.0]}, ("damping.alpha",)),
        ("random", {"n": 2, "damping.alpha": [2.0, 1.0]}, ("damping.alpha",)),
        ("random", {"n": 10**9, "damping.alpha": [1.0, 2.0]}, ("n",)),
        ("random", 5, ("random",)), ("executor", "gpu", ("executor",)), ("executor", "dask", ("scheduler",)),
        ("base", 5, ("base",)), ("base", str(tmp / "nope.toml"), ("nope.toml",)), ("base", "nope-example", ("nope-example",)),
        ("colour", 1, ("colour",)), ("name", 5, ("name",)), ("scheduler", 5, ("scheduler",)),
    ):
        sweep(f"study {key} = {toml_value(value)[:30]}", {**study_base, key: value}, tok)
    sweep("study without base", {"duration": 0.005}, ("base",))
    sweep("study without [study]", None, ("[study]",), raw="[other]\nx = 1\n")
    sweep("study [study] is a number", None, ("[study]",), raw="study = 5\n")
    sweep("study non-UTF-8", None, ("UTF-8",), raw=b"[study]\n# caf\xe9\nbase = \"free-rocking\"\n")
    sweep("study nested 500 deep", None, ("nested",), raw="[study]\nset = " + "{a = " * 500 + "1" + "}" * 500 + "\n")
    for flag, value in (("--workers", "0"), ("--workers", "-2"), ("--workers", "x")):
        sweep(f"sweep {flag} {value}", study_base, (flag,), flag, value)
    k = next(counter)
    for path, tok in ((tmp / "nostudy.toml", "nostudy.toml"), (_mkdir(tmp / "studydir"), "studydir"),
                      (Path("/dev/zero"), "/dev/zero"), (fifo, "case.fifo")):
        cases.append(FuzzCase("study", f"sweep of {tok}", ("sweep", str(path), "--out", str(tmp / "out" / f"s{k}"), "--no-progress"),
                              tokens=(tok,)))

    # -- calibrate and fragility flags (validated by the shared study options)
    ref = tmp / "ref.csv"
    ref.write_text("time,rotation\n" + "\n".join(f"{0.001 * i},{0.01 * math.cos(0.5 * i)}" for i in range(6)) + "\n")
    cal = ("calibrate", str(ref), "--base", str(good), "--bounds", "0.001", "0.01", "--duration", "0.005",
           "--executor", "serial", "--no-progress")
    frag = ("fragility", str(rec), "--base", str(good), "--pga", "0.1", "0.2", "2", "--duration", "0.005",
            "--executor", "serial", "--no-progress")
    for flag, value in (("--scan", "0"), ("--scan", "-3"), ("--workers", "0"), ("--duration", "-1"), ("--duration", "nan")):
        k = next(counter)
        argv = [*cal, "--out", str(tmp / "out" / f"c{k}")]
        if flag == "--duration":
            argv[argv.index("--duration") + 1] = value
            cases.append(FuzzCase("cli flag", f"calibrate {flag} {value}", tuple(argv), tokens=(flag,)))
        else:
            cases.append(FuzzCase("cli flag", f"calibrate {flag} {value}", (*argv, flag, value), tokens=(flag,)))
    for flag, value in (("--drift-limit", "-1"), ("--drift-limit", "0"), ("--drift-limit", "nan"), ("--workers", "0"),
                        ("--duration", "-1")):
        k = next(counter)
        argv = [*frag, "--out", str(tmp / "out" / f"g{k}")]
        if flag == "--duration":
            argv[argv.index("--duration") + 1] = value
            cases.append(FuzzCase("cli flag", f"fragility {flag} {value}", tuple(argv), tokens=(flag,)))
        else:
            cases.append(FuzzCase("cli flag", f"fragility {flag} {value}", (*argv, flag, value), tokens=(flag,)))

    # -- export and animate of a result (the warm-up run writes it)
    result = tmp / "warm" / "result.nc"
    notnc = tmp / "not_a_result.nc"
    notnc.write_text("hello\n")
    for cmd, extra in (("export", ("--vtk", str(tmp / "out" / "vtk"))), ("animate", ("-o", str(tmp / "out" / "a.gif")))):
        cases.append(FuzzCase("cli flag", f"{cmd} of a missing result", (cmd, str(tmp / "none.nc"), *extra), tokens=("none.nc",)))
        cases.append(FuzzCase("cli flag", f"{cmd} of a text file", (cmd, str(notnc), *extra), tokens=("not_a_result.nc",)))
        cases.append(FuzzCase("cli flag", f"{cmd} of a directory", (cmd, str(tmp / "casedir"), *extra), tokens=("casedir",)))
    for flag, value in (("--every", "0"), ("--every", "-2")):
        cases.append(FuzzCase("cli flag", f"export {flag} {value}", ("export", str(result), "--vtk", str(tmp / "out" / "v2"), flag, value),
                              tokens=(flag,)))
    for flag, value in (("--fps", "0"), ("--fps", "nan"), ("--magnify", "nan"), ("--speed", "-1"), ("--max-frames", "0"),
                        ("--dpi", "0"), ("--size", "0")):
        argv = ("animate", str(result), "-o", str(tmp / "out" / "b.gif"), flag, value) + (("0",) if flag == "--size" else ())
        cases.append(FuzzCase("cli flag", f"animate {flag} {value}", argv, tokens=(flag,)))
    cases.append(FuzzCase("cli flag", "animate -o naming a folder", ("animate", str(result), "-o", str(tmp / "casedir")),
                          tokens=("casedir",)))

    # -- the Python API
    nan, inf = math.nan, math.inf
    for kw, tok in (({"kn": nan}, "kn"), ({"kn": 0.0}, "kn"), ({"kn": -1e9}, "kn"), ({"kn": "1e9"}, "kn"), ({"kn": None}, "kn"),
                    ({"kn": inf}, "kn"), ({"kn": True}, "kn"), ({"kn": 1e9, "ks": -1.0}, "ks"), ({"kn": 1e9, "ks": nan}, "ks"),
                    ({"kn": 1e9, "ks": 0.0}, "ks"), ({"kn": 1e9, "cohesion": -1.0}, "cohesion"),
                    ({"kn": 1e9, "tension": -1.0}, "tension"), ({"kn": 1e9, "tension": nan}, "tension"),
                    ({"kn": 1e9, "friction_angle": 90.0}, "friction_angle"),
                    ({"kn": 1e9, "friction_angle": "30"}, "friction_angle"), ({"kn": 1e9, "beta": -1.0}, "beta"),
                    ({"kn": 1e9, "residual_cohesion": inf}, "residual_cohesion"),
                    ({"kn": 1e9, "residual_friction_angle": nan}, "residual_friction_angle"),
                    ({"kn": [1e9]}, "kn")):
        cases.append(_api("api", "material", tokens=(tok,), **kw))
    cases.append(_api("api", "from_modulus", nan, 1.0, tokens=("youngs_modulus",)))
    cases.append(_api("api", "from_modulus", 1e9, 1.0, poisson="x", tokens=("poisson",)))
    cases.append(_api("api", "kn_from_modulus", "1e9", 1.0, tokens=("youngs_modulus",)))
    cases.append(_api("api", "kn_from_modulus", 1e9, nan, tokens=("joint_spacing",)))
    cases.append(_api("api", "ks_from_kn", nan, tokens=("kn",)))
    cases.append(_api("api", "ks_from_kn", 1e9, poisson="x", tokens=("poisson",)))
    for v, tok in (({"kn": 0.0}, "kn"), ({"kn": 1e9, "ks": -1.0}, "ks"), ({"kn": 1e9, "cohesion": -1.0}, "cohesion"),
                   ({"kn": 1e9, "tension": -1.0}, "tension"), ({"kn_": 1e9}, "default_material"), ("granite", "default_material"),
                   (5, "default_material")):
        cases.append(_api("api", "default_material", v, tokens=(tok,)))
    for kw, tok in (({"gravity": "down"}, "gravity"), ({"gravity": (0, 0, nan)}, "gravity"), ({"gravity": (0, 0)}, "gravity"),
                    ({"points": (0, 2)}, "points"), ({"points": (2.5, 2)}, "points"), ({"points": (10**12, 2)}, "points"),
                    ({"points": "22"}, "points"), ({"points": None}, "points")):
        cases.append(_api("api", "builder_init", tokens=(tok,), **kw))
    for a, kw, tok in (
        (("0.2", 1, 1), {}, "width"), ((None, 1, 1), {}, "width"), ((-1, 1, 1), {}, "width"), ((nan, 1, 1), {}, "width"),
        ((0.2, 1, 1e300), {}, "height"), ((0.2, 1, 1), {"density": "heavy"}, "density"), ((0.2, 1, 1), {"density": None}, "density"),
        ((0.2, 1, 1), {"density": inf}, "density"), ((0.2, 1, 1), {"base_center": (0, 0)}, "base_center"),
        ((0.2, 1, 1), {"base_center": "x"}, "base_center"), ((0.2, 1, 1), {"base_center": (nan, 0, 0)}, "base_center"),
        ((0.2, 1, 1), {"velocity": (1, 2)}, "velocity"), ((0.2, 1, 1), {"velocity": (nan, 0, 0)}, "velocity"),
        ((0.2, 1, 1), {"angular_velocity": "fast"}, "angular_velocity"), ((0.2, 1, 1), {"driven": "sky"}, "driven"),
        ((0.2, 1, 1), {"points": (10**12, 2)}, "points"), ((0.2, 1, 1), {"points": (2, 0)}, "points"),
        ((0.2, 1, 1), {"name": "block"}, "block"), ((0.2, 1, 1), {"group": None}, "group"),
    ):
        cases.append(_api("api", "add_box", *a, tokens=(tok,), **kw))
    for a, kw, tok in ((("box",), {}, "poly"), ((None,), {}, "poly"), ((5,), {}, "poly")):
        cases.append(_api("api", "add_block", *a, tokens=(tok,), **kw))
    for a, kw, tok in ((("block", "0.9"), {}, "fraction"), (("block", nan), {}, "fraction"), (("block", -1), {}, "fraction"),
                       (("block", 1e300), {}, "fraction"), (("nope", 0.5), {}, "nope"), ((7, 0.5), {}, "7"),
                       (("block", 0.5), {"direction": (0, 0, 1)}, "direction"), (("block", 0.5), {"direction": "x"}, "direction"),
                       (("block", 0.5), {"direction": (nan, 0, 0)}, "direction"), ((None, 0.5), {}, "block"),
                       (("ground", 0.5), {}, "driven")):
        cases.append(_api("api", "tilt", *a, tokens=(tok,), **kw))
    for a, tok in ((("a", "b", None), "material"), (("a", "b", {"kn": 1e9}), "material"), ((1, 2, "x"), "material"),
                   ((None, "b", 5), "material")):
        cases.append(_api("api", "set_material", *a, tokens=(tok,)))
    for a in (("quake",), (5,), ([0, 1],)):
        cases.append(_api("api", "ground_motion", *a, tokens=("motion",)))
    for a, tok in ((([0, 1], [[1, 0]]), "acceleration"), (("t", "a"), "time"), (([0, 1], [[0, 0, nan], [0, 0, 0]]), "acceleration"),
                   (([1, 0], [[0, 0, 0], [0, 0, 0]]), "time"), ((None, None), "time"), (([0, 1, 2], [[0, 0, 0]] * 2), "acceleration")):
        cases.append(_api("api", "body_acceleration", *a, tokens=(tok,)))
    for a, tok in ((([0, 1], [[1, 0]]), "velocity"), (("t", "v"), "time"), (([0, nan], [[0, 0, 0]] * 2), "time"),
                   (([1, 0], [[0, 0, 0]] * 2), "time"), ((None, None), "time")):
        cases.append(_api("api", "motion", *a, tokens=(tok,)))
    for a, kw, tok in ((("fast",), {}, "velocity"), (((1, 0, 0),), {"start": nan}, "start"), (((1, 0, 0),), {"start": -1.0}, "start"),
                       (((1, 0, 0),), {"start": 2.0, "stop": 1.0}, "stop")):
        cases.append(_api("api", "motion_constant", *a, tokens=(tok,), **kw))
    for a, tok in (((-1.0, 1e-3), "duration"), ((nan, 1e-3), "duration"), ((1.0, 0.0), "sample_dt"), ((1.0, -1e-3), "sample_dt"),
                   ((1e9, 1e-9), "sample")):
        cases.append(_api("api", "motion_function", *a, tokens=(tok,)))
    for kw, tok in (({"alpha": -1.0}, "alpha"), ({"alpha": "x"}, "alpha"), ({"beta": nan}, "beta"), ({"beta": inf}, "beta"),
                    ({"local": 1.0}, "local"), ({"alpha_relative": "yes"}, "alpha_relative")):
        cases.append(_api("api", "damping", tokens=(tok,), **kw))
    for a, kw, tok in ((("1", 1, 1), {}, "b (width"), ((None, 1, 1), {}, "b (width"), ((1, 1, 1), {"center": "x"}, "center"),
                       ((1, 1, 1), {"center": (0, 0)}, "center"), ((1, 1, 1), {"center": (0, 0, inf)}, "center")):
        cases.append(_api("api", "box", *a, tokens=(tok,), **kw))
    for a, tok in (((None,), "vertices"), (("abc",), "vertices"), (([["a", "b", "c"]] * 4,), "vertices"), (([[0, 0, 0]] * 4,), "coincide"),
                   (([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],), "flat"), (([[0, 0]] * 4,), "vertices")):
        cases.append(_api("api", "convex_hull", *a, tokens=(tok,)))
    for a, tok in (((0, 10**12, 2), "points"), ((0, 2, 10**12), "points"), ((99, 2, 2), "face"), ((0, 0, 2), "points"),
                   ((0, 2.5, 2), "points"), ((0, "2", 2), "points")):
        cases.append(_api("api", "face_points", *a, tokens=(tok,)))
    for d, tok in (("x", "density"), (nan, "density"), (-1.0, "density")):
        cases.append(_api("api", "mass_properties", d, tokens=(tok,)))
    spec_calls: list[tuple[str, dict[str, Any], str]] = [
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": [-1, 1]}, "heights"),
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": "abc"}, "heights"),
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": None}, "heights"),
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": [nan]}, "heights"),
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": 5.0}, "heights"),
        ("stacked_blocks", {"width": "0.2", "length": 1.0, "heights": [1.0]}, "width"),
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": [1.0], "points": (10**12, 2)}, "points"),
        ("stacked_blocks", {"width": 0.2, "length": 1.0, "heights": [1.0], "material": "mortar"}, "material"),
        ("brick_wall", {"courses": 2.5, "bricks_per_course": 2}, "courses"),
        ("brick_wall", {"courses": 10**9, "bricks_per_course": 2}, "courses"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 10**9}, "bricks_per_course"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "brick": (0.1, 0.2)}, "brick"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "brick": "abc"}, "brick"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "points": (2,)}, "points"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "points": (2, 10**12 + 1)}, "points"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "points": "23"}, "points"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "bond": "english"}, "bond"),
        ("brick_wall", {"courses": 2, "bricks_per_course": 2, "joint": 5}, "joint"),
        ("parapet", {"height": None, "length": 1.0}, "height"),
        ("parapet", {"height": 1.0, "length": 1.0, "brick": (1e-6, 1e-6)}, "brick"),
        ("parapet", {"height": 1.0, "length": 1.0, "base_reduction": 1.0}, "base_reduction"),
        ("parapet", {"height": 1.0, "length": 1.0, "bond": 5}, "bond"),
        ("facade", {"width": "x"}, "width"),
        ("facade", {"edge_radius": 0.01, "edge_facets": 10**9}, "edge_facets"),
        ("facade", {"slope_deg": nan}, "slope_deg"),
        ("facade", {"rocking_velocity": "fast"}, "rocking_velocity"),
        ("facade", {"return_height": -1.0}, "return_height"),
        ("two_block_wall", {"push_time": nan, "push_displacement": 0.05}, "push_time"),
        ("two_block_wall", {"push_displacement": -1.0}, "push_displacement"),
        ("two_block_wall", {"crack_height": 5.0}, "crack_height"),
        ("add_foundation", {"extent": "x"}, "extent"),
    ]
    for fn, kw, tok in spec_calls:
        cases.append(_api("api", "specimen", fn, tokens=(tok,), **kw))
    for a, kw, tok in (((nan, 1.0), {}, "displacement"), ((0.05, 0.0), {}, "push_time"), ((0.05, 1.0), {"hold_time": -1.0}, "hold_time")):
        cases.append(_api("api", "push_motion", *a, tokens=(tok,), **kw))
    for a, kw, tok in (((1.0, 1.0, 1.0), {"radius": "a"}, "radius"), ((1.0, 1.0, 1.0), {"radius": -0.1}, "radius"),
                       ((1.0, 1.0, 1.0), {"chamfer": nan}, "chamfer"), (("1", 1.0, 1.0), {}, "width"),
                       ((1.0, 1.0, 1.0), {"radius": 0.1, "facets": 10**9}, "facets")):
        cases.append(_api("api", "rounded_prism", *a, tokens=(tok,), **kw))
    for d, tok in ((None, "duration"), ("abc", "[case]"), (5, "[case]"), ({"run": {"duration": 0.01}, "specimen": 5}, "[specimen]")):
        cases.append(_api("api", "parse_case", d, tokens=(tok,)))
    for p, tok in ((None, "path"), (5, "path"), (str(tmp / "casedir"), "casedir"), ("/dev/zero", "/dev/zero")):
        cases.append(_api("api", "load_case", p, tokens=(tok,)))
    for o, tok in (("run.duration=1", "overrides"), ([5], "overrides"), (["run.duration"], "--set")):
        cases.append(_api("api", "overrides", dict(block), o, tokens=(tok,)))
    for d, tok in (({"study": 5}, "[study]"), ({"study": {"base": "free-rocking", "set": 5}}, "set"),
                   ({"study": {"base": "free-rocking", "workers": 0}}, "workers"),
                   ({"study": {"base": "free-rocking", "history_interval": -1.0}}, "history_interval"),
                   ({"study": {"base": "free-rocking", "grid": 5}}, "grid"), (None, "study")):
        cases.append(_api("api", "parse_study", d, tokens=(tok,)))
    for a, tok in ((({"a": [1.0]}, 3, 0), "'a'"), (({"a": "xy"}, 3, 0), "'a'"), (({"a": {"choices": []}}, 3, 0), "'a'"),
                   (({"a": [1.0, 2.0]}, "3", 0), "n"), (({"a": [1.0, 2.0]}, 3, "s"), "seed")):
        cases.append(_api("api", "expand_random", *a, tokens=(tok,)))
    cases.append(_api("api", "expand_grid", 5, tokens=("grid",)))
    cases.append(_api("api", "expand_grid", {"a": "abc"}, tokens=("'a'",)))
    for o, kw, tok in (({}, {"workers": 0}, "workers"), ({}, {"workers": -1}, "workers"), ({}, {"executor": "gpu"}, "executor")):
        cases.append(_api("api", "execute", o, tokens=(tok,), **kw))
    for kw, tok in (({"duration": -1.0}, "duration"), ({"duration": "x"}, "duration"), ({"pga_g": 1e6}, "pga_g"),
                    ({"history_interval": -1.0}, "history_interval"), ({"history_interval": nan}, "history_interval")):
        cases.append(_api("api", "runspec", tokens=(tok,), **kw))

    warm = FuzzCase("warm-up", "valid block case", ("run", str(good), "--out", str(tmp / "warm"), "--quiet", "--no-plot"))
    return cases, warm


def _mkdir(p: Path) -> Path:
    p.mkdir(parents=True, exist_ok=True)
    return p


# --------------------------------------------------------------------------------------------------
# the worker and the classification
# --------------------------------------------------------------------------------------------------
def run_one(case: FuzzCase) -> dict[str, Any]:
    """Run one case in this process; returns its outcome (exit code, messages, warnings)."""
    out, err = io.StringIO(), io.StringIO()
    res: dict[str, Any] = {"code": None, "message": "", "exception": "", "warnings": []}
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if case.kind == "cli":
                from rockdem.cli import main

                try:
                    res["code"] = main(list(case.argv))
                except SystemExit as exc:
                    res["code"] = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            else:
                try:
                    API[case.call](*case.args, **dict(case.kwargs))
                    res["code"] = 0
                except (ValueError, TypeError, FileNotFoundError) as exc:
                    res["code"] = 2
                    res["message"] = f"{type(exc).__name__}: {exc}"
        except BaseException:  # noqa: BLE001 - any other exception is what the fuzz looks for
            res["exception"] = traceback.format_exc(limit=-3)
    res["stderr"] = err.getvalue()
    res["warnings"] = [f"{w.category.__name__}: {w.message}" for w in caught]
    if case.kind == "cli":
        res["message"] = res["stderr"]
    return res


def _serve(conn: Any, warm: FuzzCase) -> None:
    """Worker: run the warm-up case (loads the compiled kernels), then every case sent. Its address
    space is capped (6 GiB) so that an input read without limit fails fast instead of filling memory."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    with contextlib.suppress(ImportError, ValueError, OSError):
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (6 * 1024**3, resource.RLIM_INFINITY))
    conn.send(run_one(warm))
    while True:
        case = conn.recv()
        if case is None:
            return
        conn.send(run_one(case))


def classify(case: FuzzCase, res: dict[str, Any]) -> str:
    """clear | warned (implausible input run with a warning) | unclear (refused without naming the
    key) | traceback | hang | accepted (an absurd input taken silently)."""
    if res.get("hang"):
        return "hang"
    if res.get("crash") or res["exception"] or "Traceback" in res.get("stderr", ""):
        return "traceback"
    if res["code"] == 2:
        msg = res["message"].lower()
        return "clear" if any(t.lower() in msg for t in case.tokens) else "unclear"
    shown = res["warnings"] + [ln for ln in res.get("stderr", "").splitlines() if "warning:" in ln]
    if case.expect == "warn" and any(any(t.lower() in w.lower() for t in case.tokens) for w in shown):
        return "warned"
    return "accepted"


def run_fuzz(cases: list[FuzzCase], warm: FuzzCase) -> list[tuple[FuzzCase, dict[str, Any]]]:
    """Run the cases in a spawned worker, restarting it after a hang or a crash."""
    ctx = mp.get_context("spawn")
    results: list[tuple[FuzzCase, dict[str, Any]]] = []
    i = 0
    while i < len(cases):
        parent, child = ctx.Pipe()
        proc = ctx.Process(target=_serve, args=(child, warm))  # not daemonic: a sweep may start a pool
        proc.start()
        try:
            if not parent.poll(WARMUP_TIMEOUT_S):
                raise RuntimeError("fuzz worker: the warm-up run did not finish")
            w = parent.recv()
            if w["code"] != 0:
                raise RuntimeError(f"fuzz worker: the warm-up run failed: {w}")
            while i < len(cases):
                case = cases[i]
                parent.send(case)
                i += 1
                if not parent.poll(case.timeout):
                    results.append((case, {"hang": True, "code": None, "message": "", "exception": "", "warnings": []}))
                    break
                try:
                    results.append((case, parent.recv()))
                except EOFError:
                    results.append((case, {"crash": True, "code": None, "message": "", "exception": "worker died", "warnings": []}))
                    break
            else:
                parent.send(None)
        finally:
            proc.join(timeout=5)
            if proc.is_alive():
                proc.kill()
                proc.join()
    return results


def report(results: list[tuple[FuzzCase, dict[str, Any]]]) -> tuple[Counter, list[str]]:
    """Counts per outcome and one line per case that is not clear (or warned)."""
    counts: Counter = Counter()
    lines = []
    for case, res in results:
        outcome = classify(case, res)
        counts[outcome] += 1
        counts[(case.group, outcome)] += 1
        if outcome not in ("clear", "warned"):
            detail = (res["exception"].strip().splitlines() or [""])[-1] if outcome == "traceback" else res["message"].strip()[-200:]
            lines.append(f"{outcome:9s} [{case.group}] {case.name}: {detail}")
    return counts, lines


def _summary(counts: Counter) -> str:
    order = ("clear", "warned", "unclear", "traceback", "hang", "accepted")
    total = sum(counts[k] for k in order)
    head = f"{total} inputs: " + ", ".join(f"{counts[k]} {k}" for k in order)
    groups = sorted({g for g in counts if isinstance(g, tuple)})
    by = {}
    for g, o in groups:
        by.setdefault(g, []).append(f"{counts[(g, o)]} {o}")
    return head + "\n" + "\n".join(f"  {g}: {', '.join(v)}" for g, v in by.items())


# --------------------------------------------------------------------------------------------------
# tests
# --------------------------------------------------------------------------------------------------
def test_fuzz_bad_inputs_get_clear_errors(tmp_path):
    cases, warm = generate(tmp_path)
    assert len(cases) >= 300
    results = run_fuzz(cases, warm)
    counts, lines = report(results)
    print(_summary(counts))
    assert not lines, f"{len(lines)} of {len(cases)} bad inputs not refused clearly:\n" + "\n".join(lines)


def _engine_cases(tmp: Path) -> list[FuzzCase]:
    """Inputs whose refusal belongs to the engine (time loop, timestep, finalize)."""
    return [
        _api("engine", "simulate_block", tokens=("timestep", "duration"), density=1e30),
        _api("engine", "simulate_block", tokens=("timestep", "duration"), kn=1e-300),
        _api("engine", "simulate_block", tokens=("timestep", "duration"), youngs_modulus=2.0),
        _api("engine", "simulate_block", tokens=("steps",), youngs_modulus=1e30),
        _api("engine", "simulate_block", tokens=("steps",), beta=1e300),
        _api("engine", "simulate_block", tokens=("steps",), dt=1e-9, duration=1000.0),
        _api("engine", "simulate_block", tokens=("youngs_modulus", "sank", "stopped"), expect="warn", youngs_modulus=3e4, duration=2.0),
        _api("engine", "simulate_block", tokens=("mpa", "youngs_modulus", "kn"), expect="warn", youngs_modulus=1800.0),
        _api("engine", "simulate_block", tokens=("density", "t/m3"), expect="warn", density=1.8),
        _api("engine", "simulate_block", tokens=("density", "heavier"), expect="warn", density=1e6),
        _api("engine", "simulate_block", tokens=("friction", "atan"), expect="warn", friction_angle=0.7),
        _api("engine", "simulate_block", tokens=("alpha", "over-damps"), expect="warn", alpha=1e12),
        _api("engine", "simulate_block", tokens=("beta", "critical"), expect="warn", beta=10.0),
        _api("engine", "simulate_arg", None, tokens=("model",)),
        _api("engine", "simulate_arg", "builder", tokens=("finalize",)),
    ]


def _api_simulate_block(*, density=1800.0, kn=None, youngs_modulus=1.8e9, alpha=0.0, beta=0.0, dt=None, duration=0.01,
                        friction_angle=30.0):
    from rockdem.materials import JointMaterial
    from rockdem.model import Damping, ModelBuilder
    from rockdem.simulation import simulate

    b = ModelBuilder()
    b.default_material = JointMaterial(kn=youngs_modulus / 1.0 if kn is None else kn, friction_angle=friction_angle)
    b.add_box(2, 2, 0.5, base_center=(0, 0, -0.5), driven=True, name="ground")
    b.add_box(0.2, 1, 1, density=density, name="block")
    b.tilt("block", 0.5)
    return simulate(b.finalize(damping=Damping(alpha=alpha, beta=beta)), duration, dt=dt, progress=False)


def _api_simulate_arg(what):
    from rockdem.simulation import simulate

    return simulate(_builder() if what == "builder" else what, 0.01)


API.update(simulate_block=_api_simulate_block, simulate_arg=_api_simulate_arg)


def test_fuzz_engine_inputs(tmp_path):
    cases = _engine_cases(tmp_path)
    _, warm = generate(tmp_path)
    counts, lines = report(run_fuzz(cases, warm))
    assert not lines, "\n".join(lines)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as d:
        which = sys.argv[1] if len(sys.argv) > 1 else "inputs"
        cs, wm = generate(Path(d))
        if which == "engine":
            cs = _engine_cases(Path(d))
        res = run_fuzz(cs, wm)
        cnt, bad = report(res)
        print("\n".join(bad))
        print(_summary(cnt))
