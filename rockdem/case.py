"""TOML case files: validated one-to-one onto the builders and ``simulate()`` options.

A case has the tables ``[run]``, ``[damping]``, ``[specimen]`` (with ``type``), ``[loading]`` and
``[output]``. Every key is checked: an unknown key or a wrong type is an error naming the table,
the key and the accepted keys. Specimen types register themselves in :data:`SPECIMENS`; loadings
in :data:`LOADINGS`. Units: SI, angles in degrees where the key says ``_deg``.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import difflib
import json
import math
import os
import threading
import tomllib
import warnings
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping

import numpy as np

from ._warn import warn_user
from .beta_choice import BETA_AUTO, BETA_MODES, BetaChoice
from .geometry import MAX_FACE_POINTS, MAX_LENGTH
from .materials import JointMaterial, check_material, ks_from_kn
from .model import SETTLING, Damping, Model, ModelBuilder
from .records import STANDARD_GRAVITY
from .results import _has_pyarrow
from .simulation import Monitor
from .stopping import REST_WINDOW, STOP_MODES
from .timestep import DASHPOT_SCHEMES, IMPACT_REFINEMENT

__all__ = [
    "Table",
    "RunOptions",
    "Case",
    "SPECIMENS",
    "LOADINGS",
    "load_case",
    "parse_case",
    "CaseTemplate",
    "template_key",
    "SWAPPABLE_LOADINGS",
    "example_names",
    "example_case",
    "apply_overrides",
    "parse_assignment",
    "read_toml",
    "parse_toml_value",
    "check_plausible",
    "MAX_MAGNITUDE",
    "MAX_FILE_BYTES",
    "MAX_DEPTH",
]

MAX_MAGNITUDE = 1e15
"""Largest magnitude of any number in a case file (SI units): stiffnesses per area reach ~1e14 Pa/m."""

MAX_FILE_BYTES = 8 * 1024**2
"""Largest case or study file read [bytes]."""

MAX_DEPTH = 16
"""Deepest nesting of tables and arrays in a case or study file (a case needs 3)."""

PLAUSIBLE: dict[str, tuple[float, float, str]] = {
    "pga_g": (5.0, 50.0, "the largest peak ground acceleration ever recorded is about 4 g"),
    "gravity": (30.0, 5000.0, "gravity is in m/s^2, 9.81 on the Earth (tens of g only on a centrifuge; 9810 is mm/s^2)"),
}
"""Keys with a plausible range: (warn above, refuse above, why)."""
BINARY_KINDS: tuple[tuple[bytes, str], ...] = (
    (b"\x89HDF\r\n\x1a\n", "a NetCDF-4 file (a result, result.nc)"),
    (b"CDF\x01", "a NetCDF file (a result, result.nc)"),
    (b"CDF\x02", "a NetCDF file (a result, result.nc)"),
    (b"PK\x03\x04", "a zip archive (a checkpoint, checkpoint.npz)"),
    (b"PAR1", "a Parquet table (a contact or study table)"),
    (b"\x89PNG", "a PNG image"),
    (b"%PDF", "a PDF document"),
    (b"GIF8", "a GIF animation"),
    (b"ftyp", "an MP4 video"),  # (at offset 4)
)
"""Leading bytes of the files rockdem writes (and of images) that a user may give where a case or
study file is read: named, not reported as text that is not UTF-8 (before 2026-12-01)."""
BINARY_HINT = ("give the TOML file (to continue a run: rockdem run CASE.toml --from OUT/checkpoint.npz; a result "
               "is read by rockdem plot and rockdem export)")
GRAVITY_LOW = 1.62
"""[specimen] gravity [m/s^2] below which (but above 0) a case is warned about: the Moon's."""


class Table:
    """A TOML table read key by key with type checks; :meth:`finish` rejects unused keys."""

    def __init__(self, data: Mapping[str, Any] | None, where: str) -> None:
        if data is not None and not isinstance(data, Mapping):
            raise ValueError(f"[{where}] must be a table, got {type(data).__name__}")
        self.data = dict(data or {})
        self.where = where
        self.used: set[str] = set()

    def _get(self, key: str, default: Any) -> Any:
        self.used.add(key)
        return self.data.get(key, default)

    def _required(self, key: str, what: str) -> ValueError:
        """The error for a required ``key`` that is absent, naming a key of the table that looks
        like a misspelling of it (``widht`` for ``width``)."""
        near = difflib.get_close_matches(key, [k for k in self.data if k not in self.used], n=1, cutoff=0.7)
        hint = f"; the table has {near[0]!r}: a misspelling of {key!r}?" if near else ""
        return ValueError(f"[{self.where}] {key} is required ({what}){hint}")

    def number(self, key: str, default: float | None = None, *, positive: bool = False, min_: float | None = None) -> float:
        """A real number; ``default=None`` makes it required."""
        v = self._get(key, default)
        if v is None:
            raise self._required(key, "a number")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"[{self.where}] {key} must be a finite number, got {v!r}")
        check_plausible(v, f"[{self.where}] {key}", key)
        if positive and not v > 0:
            raise ValueError(f"[{self.where}] {key} must be positive, got {v!r}")
        if min_ is not None and v < min_:
            raise ValueError(f"[{self.where}] {key} must be >= {min_}, got {v!r}")
        return float(v)

    def optional_number(self, key: str, *, positive: bool = False) -> float | None:
        """A number or None when absent."""
        if key not in self.data:
            self.used.add(key)
            return None
        return self.number(key, positive=positive)

    def integer(self, key: str, default: int | None = None, *, min_: int = 0, max_: int | None = None) -> int:
        """An integer in [min_, max_]; ``default=None`` makes it required."""
        v = self._get(key, default)
        if v is None:
            raise self._required(key, "an integer")
        if isinstance(v, bool) or not isinstance(v, int):
            raise ValueError(f"[{self.where}] {key} must be an integer, got {v!r}")
        if v < min_:
            raise ValueError(f"[{self.where}] {key} must be >= {min_}, got {v!r}")
        if max_ is not None and v > max_:
            raise ValueError(f"[{self.where}] {key} = {v} exceeds the limit of {max_}")
        return v

    def points(self, across: int = 2, along: int = 2) -> tuple[int, int]:
        """Interface points per face from ``points_across`` and ``points_along`` (at most
        :data:`~rockdem.geometry.MAX_FACE_POINTS` per face)."""
        a = self.integer("points_across", across, min_=-MAX_FACE_POINTS, max_=MAX_FACE_POINTS)
        b = self.integer("points_along", along, min_=-MAX_FACE_POINTS, max_=MAX_FACE_POINTS)
        for key, n in (("points_across", a), ("points_along", b)):
            if n == 1:
                raise ValueError(
                    f"[{self.where}] {key} = 1 puts a face's only point at its middle: a block on it balances on a "
                    "knife edge and cannot rock about its edges; give 2 or more (the paper uses 2 to 15)")
            if n < 2:
                raise ValueError(f"[{self.where}] {key} must be 2 or more (points across a face, with its edges; "
                                 f"the paper uses 2 to 15), got {n}")
        if a * b > MAX_FACE_POINTS:
            raise ValueError(
                f"[{self.where}] points_across x points_along = {a} x {b} exceeds the limit of {MAX_FACE_POINTS} "
                "points per face (the paper uses 2 to 15 across)"
            )
        return a, b

    def boolean(self, key: str, default: bool) -> bool:
        v = self._get(key, default)
        if not isinstance(v, bool):
            raise ValueError(f"[{self.where}] {key} must be true or false, got {v!r}")
        return v

    def string(self, key: str, default: str | None = None, *, choices: tuple[str, ...] | None = None) -> str:
        v = self._get(key, default)
        if v is None:
            raise self._required(key, "a string")
        if not isinstance(v, str):
            raise ValueError(f"[{self.where}] {key} must be a string, got {v!r}")
        if choices is not None and v not in choices:
            raise ValueError(f"[{self.where}] {key} must be one of {list(choices)}, got {v!r}")
        return v

    def vector(self, key: str, default: tuple[float, ...] | None = None, *, size: int = 3) -> np.ndarray:
        v = self._get(key, default)
        if v is None:
            raise self._required(key, f"a list of {size} numbers")
        arr = self._numbers(key, v, f"a list of {size} numbers")
        if arr.shape != (size,):
            raise ValueError(f"[{self.where}] {key} must be a list of {size} numbers, got {v!r}")
        return arr

    def numbers(self, key: str, *, positive: bool = False) -> np.ndarray:
        """A required non-empty list of finite numbers (e.g. block heights)."""
        v = self._get(key, None)
        what = "a non-empty list of " + ("positive " if positive else "") + "numbers"
        if v is None:
            raise self._required(key, what)
        arr = self._numbers(key, v, what)
        if arr.size == 0:
            raise ValueError(f"[{self.where}] {key} must be {what}, got {v!r}")
        if positive and not np.all(arr > 0):
            k = int(np.argmin(arr > 0))
            raise ValueError(f"[{self.where}] {key} must be {what}; {key}[{k}] = {float(arr[k])!r}")
        return arr

    def _numbers(self, key: str, v: Any, what: str) -> np.ndarray:
        if not isinstance(v, (list, tuple)) or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in v):
            raise ValueError(f"[{self.where}] {key} must be {what}, got {_short(v)}")
        arr = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"[{self.where}] {key} must be finite, got {_short(v)}")
        for x in arr:
            check_plausible(float(x), f"[{self.where}] {key}", key)
        return arr

    def sub(self, key: str) -> "Table":
        """A nested table (empty when absent)."""
        return Table(self._get(key, {}), key if self.where == "case" else f"{self.where}.{key}")

    def raw(self, key: str, default: Any = None) -> Any:
        """The value as read (the caller checks it)."""
        return self._get(key, default)

    def finish(self) -> None:
        """Raise for any key that was not read."""
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise ValueError(
                f"[{self.where}] unknown key(s) {unknown}; accepted keys are {sorted(self.used)}"
            )


def _short(v: Any, n: int = 60) -> str:
    text = repr(v)
    return text if len(text) <= n else text[: n - 5] + " ...]"


def check_plausible(value: float, what: str, key: str = "") -> None:
    """Refuse a number beyond :data:`MAX_MAGNITUDE`, and a value of a :data:`PLAUSIBLE` ``key``
    above its range (a warning above its plausible limit). ``what`` names the value in messages."""
    if abs(value) > MAX_MAGNITUDE:
        raise ValueError(
            f"{what} = {value!r} is beyond any plausible value (|value| > {MAX_MAGNITUDE:g} in SI units); "
            "check the value and its units"
        )
    if key in PLAUSIBLE:
        warn, refuse, why = PLAUSIBLE[key]
        if value > refuse:
            raise ValueError(f"{what} = {value!r} is not plausible (above {refuse:g}; {why}); check the value and its units")
        if value > warn:
            warn_user(f"{what} = {value!r} is above {warn:g}: {why}; check the value and its units")


@dataclass(frozen=True)
class RunOptions:
    """``simulate()`` options from ``[run]`` (see :func:`rockdem.simulation.simulate`)."""

    duration: float
    dt: float | None = None
    timestep_rule: str = "bound"
    safety: float = 0.9
    resolution: float = 0.3
    impact_refinement: float = IMPACT_REFINEMENT
    dashpots: str = "auto"
    record_interval: float = 0.002
    contact_tolerance: float | None = None
    contact_interval: float | None = None
    stop: str = "off"
    settle: float = 0.0


SETTLE_LONGEST = 2.0
"""[s] the longest settling of ``[run] settle = true`` (it ends earlier once the blocks are at rest)."""

SETTLE_SHORTEST = 1.0
"""[s] the shortest ``[run] settle`` accepted: rest is judged over :data:`rockdem.stopping.REST_WINDOW` of stillness."""

SETTLE_LONGEST_ACCEPTED = 60.0
"""[s] the longest ``[run] settle`` accepted (blocks that do not settle in a minute do not stand)."""


@dataclass(frozen=True, repr=False)
class Case:
    """A built case: the model, run options, monitors and output settings, plus what the loading
    adds to the result: ``attrs`` (scalars, e.g. the pushover ramp, the record and its PGA, the tilt
    angle) and ``series`` (name -> (times (n,), values (n, 3)), e.g. the ground acceleration)."""

    name: str
    model: Model
    run: RunOptions
    monitors: dict[str, Monitor]
    output: dict[str, Any]
    data: dict[str, Any]
    attrs: dict[str, Any] = field(default_factory=dict)
    series: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)

    def __repr__(self) -> str:
        run = f"duration {self.run.duration:g} s, frames every {self.run.record_interval:g} s"
        model = repr(self.model).split("\n", 1)[1]
        return f"rockdem Case {self.name!r}: {run}, monitors {sorted(self.monitors)}\n{model}"

    def _repr_html_(self) -> str:
        from html import escape

        run = f"duration {self.run.duration:g} s, frames every {self.run.record_interval:g} s"
        return f"<b>rockdem Case {escape(self.name)}</b>: {escape(run)}<br>{self.model._repr_html_()}"


SpecimenBuilder = Callable[[Table, ModelBuilder], dict[str, Monitor]]
LoadingBuilder = Callable[[Table, ModelBuilder, dict[str, Monitor], dict[str, Any]], None]

SPECIMENS: dict[str, SpecimenBuilder] = {}
"""Specimen types: ``[specimen] type = NAME`` -> builder(table, model builder) -> monitors."""

LOADINGS: dict[str, LoadingBuilder] = {}
"""Loading types: ``[loading] type = NAME`` -> builder(table, model builder, monitors, context)."""


def specimen(name: str) -> Callable[[SpecimenBuilder], SpecimenBuilder]:
    """Register a specimen builder under ``name``."""

    def deco(func: SpecimenBuilder) -> SpecimenBuilder:
        SPECIMENS[name] = func
        return func

    return deco


def loading(name: str) -> Callable[[LoadingBuilder], LoadingBuilder]:
    """Register a loading builder under ``name``."""

    def deco(func: LoadingBuilder) -> LoadingBuilder:
        LOADINGS[name] = func
        return func

    return deco


def joint_material(t: Table, *, spacing: float) -> JointMaterial:
    """A joint material from keys ``kn`` [Pa/m] or ``youngs_modulus`` [Pa] (kn = E / spacing),
    ``ks`` or ``poisson``, ``friction_angle_deg``, ``cohesion`` [Pa], ``tension`` [Pa],
    ``residual_friction_angle_deg``, ``residual_cohesion`` [Pa], ``beta`` [s]."""
    kn = t.optional_number("kn", positive=True)
    e = t.optional_number("youngs_modulus", positive=True)
    if (kn is None) == (e is None):
        raise ValueError(f"[{t.where}] give exactly one of kn [Pa/m] or youngs_modulus [Pa] (kn = E / l)")
    if not (math.isfinite(spacing) and spacing > 0):
        raise ValueError(f"[{t.where}] the joint spacing l of kn = E / l must be positive [m], got {spacing!r}")
    nu = t.number("poisson", 0.25)
    if not -1.0 < nu < 0.5:
        raise ValueError(f"[{t.where}] poisson must lie in (-1, 0.5), got {nu!r}")
    kn = e / spacing if kn is None else kn
    ks = t.optional_number("ks", positive=True)
    values = check_material(
        {
            "kn": kn,
            "ks": ks_from_kn(kn, nu) if ks is None else ks,
            "friction_angle": t.number("friction_angle_deg", 30.0),
            "cohesion": t.number("cohesion", 0.0, min_=0.0),
            "tension": t.number("tension", 0.0, min_=0.0),
            "residual_friction_angle": t.optional_number("residual_friction_angle_deg"),
            "residual_cohesion": t.number("residual_cohesion", 0.0, min_=0.0),
            "beta": t.optional_number("beta"),
        },
        f"[{t.where}]",
        {"friction_angle": "friction_angle_deg", "residual_friction_angle": "residual_friction_angle_deg",
         "kn": "kn (or youngs_modulus / l)"},
    )
    return JointMaterial(**values)  # type: ignore[arg-type]


@specimen("block")
def _block(t: Table, b: ModelBuilder) -> dict[str, Monitor]:
    """A single rectangular block (width along x, the rocking direction) on a fixed foundation.

    Keys: width, height, length [m], density [kg/m^3], points_across, points_along,
    foundation_extent [m] (plan size of the foundation; default twice the block's largest
    dimension), and the joint keys of :func:`joint_material` (with youngs_modulus, kn = E / height).
    """
    width = t.number("width", positive=True)
    height = t.number("height", positive=True)
    length = t.number("length", 1.0, positive=True)
    density = t.number("density", 1800.0, positive=True)
    pts = t.points()
    mat = joint_material(t, spacing=height)
    b.default_material = mat
    extent = t.optional_number("foundation_extent", positive=True)
    if extent is not None and extent < max(width, length):
        raise ValueError(f"[{t.where}] foundation_extent = {extent:g} m is smaller than the block's footprint "
                         f"({width:g} x {length:g} m); give at least {max(width, length):g} m")
    for key, v in (("width", width), ("height", height), ("length", length), ("foundation_extent", extent)):
        if v is not None and v > MAX_LENGTH:
            raise ValueError(f"[{t.where}] {key} = {v:g} m is beyond any structure (at most {MAX_LENGTH:g} m); lengths are in metres")
    size = 2.0 * max(width, length, height) if extent is None else extent
    if size > MAX_LENGTH:
        raise ValueError(f"[{t.where}] the foundation, twice the block's largest dimension ({size:g} m), exceeds {MAX_LENGTH:g} m: "
                         "check the block's dimensions (in metres) or give foundation_extent")
    b.add_box(size, size, 0.25 * size, base_center=(0.0, 0.0, -0.25 * size), driven="ground", group="foundation", name="foundation", points=(2, 2))
    b.add_box(width, length, height, density=density, name="block", points=pts)
    return {"top": ("block", (0.5 * width, 0.0, height))}


@loading("free-rocking")
def _free_rocking(t: Table, b: ModelBuilder, monitors: dict[str, Monitor], ctx: dict[str, Any]) -> None:
    """Tilt the free blocks, as one rigid assembly, about their base edge to ``tilt_fraction`` of
    the assembly's instability angle and release them (paper §3.1, §3.2, §4.1).

    Keys: block (a block name or a list of names; default every free block, e.g. all the bricks
    of a discretised wall), tilt_fraction (default 0.9), tilt_direction (default +x).
    """
    raw = t.raw("block", None)
    free = b.block_names(driven=False)
    if raw is None:
        names: list[str] = free
    elif isinstance(raw, str):
        names = [raw]
    elif isinstance(raw, list) and raw and all(isinstance(v, str) for v in raw):
        names = list(raw)
    else:
        raise ValueError(f"[{t.where}] block must be a block name or a list of names, got {raw!r}")
    unknown = [n for n in names if n not in b.block_names()]
    if unknown:
        raise ValueError(f"[{t.where}] block: no block named {unknown}; the free blocks are {free[:10]}{' ...' if len(free) > 10 else ''}")
    if not names:
        raise ValueError(f"[{t.where}] the specimen has no free block to tilt")
    frac = t.number("tilt_fraction", 0.9, min_=0.0)
    d = t.vector("tilt_direction", (1.0, 0.0, 0.0))
    if not np.any(b.gravity):
        warn_user(f"[{t.where}] free rocking with [specimen] gravity = 0: nothing brings the tilted blocks back, "
                  "they stay where they are released")
    try:
        angle = b.tilt(names, frac, direction=d)
    except ValueError as exc:
        raise ValueError(f"[{t.where}] {exc}") from None
    ctx["attrs"].update(tilt_angle_rad=angle, tilt_fraction=frac, tilted_blocks=len(names))


@loading("gravity")
def _gravity_only(t: Table, b: ModelBuilder, monitors: dict[str, Monitor], ctx: dict[str, Any]) -> None:
    """Gravity alone (settlement, static checks)."""


def read_toml(path: str | os.PathLike[str], what: str = "case file") -> dict[str, Any]:
    """Read a TOML file safely: a regular file (not a folder, FIFO or device) of at most
    :data:`MAX_FILE_BYTES`, UTF-8 (a byte-order mark is accepted), nested at most :data:`MAX_DEPTH`
    levels. Errors name ``what`` and the path."""
    if not isinstance(path, (str, os.PathLike)):
        raise ValueError(f"{what}: give a file path, got {path!r}")
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"{what} {p} does not exist")
    if not p.is_file():
        kind = "a folder" if p.is_dir() else "not a regular file (a FIFO, socket or device)"
        raise ValueError(f"{what} {p} is {kind}; give a TOML file")
    with p.open("rb") as fh:
        raw = fh.read(MAX_FILE_BYTES + 1)
    for magic, kind in BINARY_KINDS:
        if raw.startswith(magic) or (magic == b"ftyp" and raw[4:8] == magic):
            raise ValueError(f"{what} {p} is {kind}, not a TOML case or study file; {BINARY_HINT}")
    if len(raw) > MAX_FILE_BYTES:
        raise ValueError(f"{what} {p} is larger than {MAX_FILE_BYTES // 1024**2} MiB; a TOML case or study file is a few kB")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ValueError(
            f"{what} {p} is not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start}); save it as UTF-8"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{what} {p}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ValueError(f"{what} {p}: tables or arrays nested too deeply (more than {MAX_DEPTH} levels)") from None
    _check_depth(data, f"{what} {p}")
    return data


def parse_toml_value(text: str, what: str) -> Any:
    """A TOML value (``5``, ``"name"``, ``[1, 2]``, ``{a = 1}``), or ``text`` itself when it is not one."""
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text
    except RecursionError:
        raise ValueError(f"{what}: value nested too deeply (more than {MAX_DEPTH} levels)") from None
    _check_depth(value, what)
    return value


def _check_depth(data: Any, what: str) -> None:
    """Refuse tables or arrays nested deeper than :data:`MAX_DEPTH`."""
    stack = [(data, 0)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ValueError(f"{what}: tables or arrays nested more than {MAX_DEPTH} levels deep; a case needs 3")
        children = node.values() if isinstance(node, dict) else node if isinstance(node, list) else ()
        stack.extend((c, depth + 1) for c in children)


def load_case(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a TOML case file into a dict (no validation yet; see :func:`read_toml` for the checks)."""
    data = read_toml(path, "case file")
    data.setdefault("name", Path(path).stem)
    return data


def example_names() -> list[str]:
    """Names of the built-in example cases."""
    return sorted(f.name[:-5] for f in resources.files("rockdem.cases").iterdir() if f.name.endswith(".toml"))


def example_case(name: str) -> dict[str, Any]:
    """A built-in example case as a dict."""
    if name not in example_names():
        raise ValueError(f"unknown example {name!r}; built-in examples are {example_names()}")
    data = tomllib.loads(resources.files("rockdem.cases").joinpath(f"{name}.toml").read_text())
    data.setdefault("name", name)
    return data


def parse_assignment(item: str) -> tuple[str, Any]:
    """One ``table.key=value`` override (``--set``): the dotted key and the value, parsed as TOML,
    else kept as a string. A missing ``=`` or an empty key is refused with the form to use."""
    if not isinstance(item, str) or "=" not in item:
        raise ValueError(f"--set {item!r}: use table.key=value, e.g. damping.beta=0.005")
    path, value = item.split("=", 1)
    parsed = parse_toml_value(value, f"--set {path.strip()}")
    if not all(k.strip() for k in path.strip().split(".")):
        raise ValueError(f"--set {item[:60]!r}: use table.key=value, e.g. damping.beta=0.005")
    return path.strip(), parsed


def apply_overrides(data: Mapping[str, Any], overrides: list[str]) -> dict[str, Any]:
    """Apply ``table.key=value`` overrides (value parsed as TOML, else kept as a string); an empty
    value (``table.key=``) removes the key, e.g. a record's ``scale`` to give ``pga_g`` instead."""
    if not isinstance(data, Mapping):
        raise ValueError(f"overrides apply to a case (a dict), got {_short(data)}")
    if isinstance(overrides, (str, bytes)) or not all(isinstance(o, str) for o in overrides):
        raise ValueError(f"overrides must be a list of 'table.key=value' strings, got {_short(overrides)}")
    out = copy.deepcopy(dict(data))
    for item in overrides:
        path, parsed = parse_assignment(item)
        keys = path.split(".")
        if item.split("=", 1)[1].strip() == "":
            parent = out
            for k in keys[:-1]:
                parent = parent.get(k) if isinstance(parent, dict) else None
            if not isinstance(parent, dict) or keys[-1] not in parent:
                raise ValueError(f"--set {item!r}: an empty value removes a key, and the case has no {path}")
            del parent[keys[-1]]
            continue
        node = out
        for k in keys[:-1]:
            node = node.setdefault(k, {})
            if not isinstance(node, dict):
                raise ValueError(f"--set {item!r}: {k} is not a table")
        node[keys[-1]] = parsed
    return out


def with_duration(data: dict[str, Any], seconds: float) -> dict[str, Any]:
    """``data`` with [run] duration = ``seconds`` [s] where the case leaves it out (a [run] that is
    no table is left to :func:`parse_case` to refuse): the command line's ``--duration`` stands for
    it, and a preview (``rockdem show``) needs none."""
    run = data.get("run", {})
    if not isinstance(run, dict) or "duration" in run:
        return data
    return {**data, "run": {**run, "duration": float(seconds)}}


def _run_options(top: Table) -> RunOptions:
    run_t = top.sub("run")
    run = RunOptions(
        duration=run_t.number("duration", positive=True),
        dt=run_t.optional_number("dt", positive=True),
        timestep_rule=run_t.string("timestep_rule", "bound", choices=("bound", "3dec")),
        safety=run_t.number("safety", 0.9, positive=True),
        resolution=run_t.number("resolution", 0.3, positive=True),
        impact_refinement=run_t.number("impact_refinement", IMPACT_REFINEMENT, positive=True),
        dashpots=run_t.string("dashpots", "auto", choices=DASHPOT_SCHEMES),
        record_interval=run_t.number("record_interval", 0.002, positive=True),
        contact_tolerance=run_t.optional_number("contact_tolerance", positive=True),
        contact_interval=run_t.optional_number("contact_interval", positive=True),
        stop=run_t.string("stop", "off", choices=STOP_MODES),
        settle=_settle_time(run_t),
    )
    run_t.finish()
    return run


def _settle_time(run_t: Table) -> float:
    """``[run] settle``: false (0), true (:data:`SETTLE_LONGEST`) or the longest settling [s]."""
    v = run_t.raw("settle", False)
    if isinstance(v, bool):
        return SETTLE_LONGEST if v else 0.0
    if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
        raise ValueError(f"[{run_t.where}] settle must be true, false or the longest settling time [s], got {v!r}")
    if v > 0 and not SETTLE_SHORTEST <= v <= SETTLE_LONGEST_ACCEPTED:
        raise ValueError(f"[{run_t.where}] settle = {v!r} s: give from {SETTLE_SHORTEST:g} s (rest is judged over "
                         f"{REST_WINDOW:g} s of stillness) to {SETTLE_LONGEST_ACCEPTED:g} s, or true ({SETTLE_LONGEST:g} s at most)")
    return float(v)


def _specimen(top: Table) -> tuple[ModelBuilder, dict[str, Monitor]]:
    spec_t = top.sub("specimen")
    kind = spec_t.string("type", choices=tuple(sorted(SPECIMENS)))
    grav = spec_t.number("gravity", 9.81, min_=0.0)
    if 0.0 < grav < GRAVITY_LOW:
        warn_user(f"[specimen] gravity = {grav:g} m/s^2 is below the Moon's {GRAVITY_LOW} m/s^2: gravity is in m/s^2 "
                  "(9.81 on the Earth, not 1 for 1 g); check the value and its units")
    builder = ModelBuilder(gravity=(0.0, 0.0, -grav))
    monitors = SPECIMENS[kind](spec_t, builder)
    spec_t.finish()
    return builder, monitors


def _loading(top: Table, builder: ModelBuilder, monitors: dict[str, Monitor], run: RunOptions) -> dict[str, Any]:
    """Apply ``[loading]`` to the builder; returns the context (attrs, series, rocking_axis)."""
    load_t = top.sub("loading")
    lkind = load_t.string("type", "gravity", choices=tuple(sorted(LOADINGS)))
    ctx: dict[str, Any] = {"run": run, "attrs": {"loading": lkind}, "series": {}}
    LOADINGS[lkind](load_t, builder, monitors, ctx)
    load_t.finish()
    pga = ctx["attrs"].get("earthquake_pga_m_s2")
    if isinstance(pga, float) and "pga_g" not in load_t.data:  # a record scaled by ``scale``
        check_plausible(float(f"{pga / STANDARD_GRAVITY:.4g}"), "[loading] the scaled record's peak ground acceleration [g] (see scale)", "pga_g")
    return ctx


def _output(top: Table) -> dict[str, Any]:
    out_t = top.sub("output")
    output = {
        "directory": out_t.string("directory", ""),
        "plot": out_t.boolean("plot", True),
        "csv": out_t.boolean("csv", True),
        "checkpoint": out_t.boolean("checkpoint", True),
        "checkpoint_every": out_t.optional_number("checkpoint_every", positive=True),
        "contacts": out_t.string("contacts", "auto", choices=("auto", "csv", "parquet", "none")),
    }
    out_t.finish()
    if output["contacts"] == "parquet" and not _has_pyarrow():
        raise ValueError('[output] contacts = "parquet" needs pyarrow (pip install pyarrow); or give contacts = "csv" '
                         '("auto" writes Parquet when pyarrow is installed, else CSV)')
    return output


def _case_name(top: Table) -> str:
    """``name``: the case's title, and the name of its output folder (``results/<name>``) when no
    folder is given, so a plain name (no path)."""
    name = top.string("name", "case")
    if not name.strip() or name.strip() in (".", "..") or any(c in name for c in "/\\\0"):
        raise ValueError(f"[case] name = {name!r}: the name titles the run and names its output folder (results/<name>); "
                         "give a plain, non-empty name without '/', '\\' or '..' (choose another folder with "
                         "--out or [output] directory)")
    return name


def parse_case(data: Mapping[str, Any]) -> Case:
    """Validate a case dict and build its model."""
    return CaseTemplate(data).case


SWAPPABLE_LOADINGS = ("earthquake",)
"""Loading types that only set a model's prescribed kinematics (ground motion, body acceleration),
so that a :class:`CaseTemplate` swaps them without rebuilding the geometry."""


def template_key(data: Mapping[str, Any]) -> str:
    """Cases with equal keys have the same model geometry, materials and initial pose: the
    ``[specimen]`` table, ``run.contact_tolerance`` and, unless its type is one of
    :data:`SWAPPABLE_LOADINGS`, the ``[loading]`` table (damping and run options are swapped)."""
    data = Table(data, "case").data  # a mapping, or the error a case file gets
    load = data.get("loading", {})
    swap = isinstance(load, Mapping) and load.get("type") in SWAPPABLE_LOADINGS
    run = data.get("run", {})
    key = {
        "specimen": data.get("specimen"),
        "contact_tolerance": run.get("contact_tolerance") if isinstance(run, Mapping) else None,
        "loading": {"type": load.get("type")} if swap else load,
    }
    return json.dumps(key, sort_keys=True, separators=(",", ":"), default=str)


class CaseTemplate:
    """A parsed case whose model is reused by cases that differ only in damping, run options,
    output and, for a swappable loading (:data:`SWAPPABLE_LOADINGS`), the loading itself (another
    record, scale or PGA): :meth:`derive` validates such a case as :func:`parse_case` does and
    swaps the new damping and input arrays into the model (:meth:`rockdem.model.Model.with_inputs`)
    without rebuilding blocks, interface points or the contact geometry. The models are the ones
    :func:`parse_case` builds, array for array. An automatic beta (``beta = "auto"`` or
    ``"critical"``, :mod:`rockdem.targeting`) is resolved once per distinct ``[damping]`` table and
    kept: it depends on the specimen and the damping options, not on the record or its scale.

    Attributes:
        key: :func:`template_key` of the cases it serves.
        case: the parsed case of ``data``.
    """

    def __init__(self, data: Mapping[str, Any]) -> None:
        top = Table(data, "case")
        self.key = template_key(data)
        name = _case_name(top)
        top.string("description", "")
        run = _run_options(top)
        damping = _damping(top.sub("damping"))
        builder, monitors = _specimen(top)
        load = top.data.get("loading", {})
        self._swap = isinstance(load, Mapping) and load.get("type") in SWAPPABLE_LOADINGS
        self._bare = copy.copy(builder) if self._swap else None  # before the loading
        self._monitors = dict(monitors)
        ctx = _loading(top, builder, monitors, run)
        output = _output(top)
        top.finish()
        with _chosen_damping(data, run.settle > 0.0):
            model = builder.finalize(damping=damping, rocking_axis=ctx.get("rocking_axis"),
                                     contact_tolerance=run.contact_tolerance)
        self._ctx = ctx
        self._builder = builder  # what an automatic beta is resolved on
        self._choices: dict[Damping, BetaChoice] = {damping: model.beta_choice} if model.beta_choice is not None else {}
        self._lock = threading.Lock()  # Dask workers may derive in threads: one search per damping
        self.case = Case(name, model, run, dict(monitors), output, dict(data), dict(ctx["attrs"]), dict(ctx["series"]))

    def beta_choice(self, damping: Damping) -> BetaChoice | None:
        """The resolution of ``damping``'s automatic beta on this template's model (the search runs
        once per distinct damping; :func:`rockdem.targeting.choose_beta`), None for a numeric beta."""
        if damping.beta_mode is None:
            return None
        with self._lock:
            choice = self._choices.get(damping)
            if choice is None:
                from .targeting import choose_beta  # runs simulations (imports simulate)

                choice = self._choices[damping] = choose_beta(self._builder, self.case.model, damping)
        return choice

    def derive(self, data: Mapping[str, Any]) -> Case:
        """The case of ``data`` (same :func:`template_key`), built on this template's model."""
        top = Table(data, "case")
        if template_key(data) != self.key:
            raise ValueError("CaseTemplate.derive: the case's specimen or loading differs from the template's")
        name = _case_name(top)
        top.string("description", "")
        run = _run_options(top)
        damping = _damping(top.sub("damping"))
        top.used.add("specimen")  # equal to the template's (the key)
        model = self.case.model
        if self._swap:
            builder, monitors = copy.copy(self._bare), dict(self._monitors)
            ctx = _loading(top, builder, monitors, run)
            with _chosen_damping(data, run.settle > 0.0):
                model = model.with_inputs(damping=damping, builder=builder, beta_choice=self.beta_choice(damping))
            axis = np.asarray(ctx.get("rocking_axis", builder.default_rocking_axis()), dtype=float)  # the load's own direction
            model = dataclasses.replace(model, rocking_axis=axis / np.linalg.norm(axis))
        else:
            top.used.add("loading")
            ctx, monitors = self._ctx, dict(self.case.monitors)
            with _chosen_damping(data, run.settle > 0.0):
                model = model.with_inputs(damping=damping, beta_choice=self.beta_choice(damping))
        output = _output(top)
        top.finish()
        return Case(name, model, run, monitors, output, dict(data), dict(ctx["attrs"]), dict(ctx["series"]))


@contextlib.contextmanager
def _chosen_damping(data: Mapping[str, Any], settled: bool = False) -> Iterator[None]:
    """Within the block, no warning about an undamped model when the case's ``[damping]`` states
    alpha or beta itself (``beta = 0.0``: an undamped model by choice, e.g. the paper's
    discretised non-damped strategy, §3.2); without them it warns (model._warn_implausible_damping),
    and for a case that settles its blocks (``settled``: ``[run] settle``) without suggesting
    settling (:data:`rockdem.model.SETTLING`)."""
    table = data.get("damping")
    token = SETTLING.set(settled)
    try:
        with warnings.catch_warnings():
            if isinstance(table, Mapping) and ("beta" in table or "alpha" in table):
                warnings.filterwarnings("ignore", message="no damping", category=UserWarning)
            yield
    finally:
        SETTLING.reset(token)


_AUTO_KEYS = ("target_restitution", "per_interface", "release_fraction", "probe_impacts")


def _damping(t: Table) -> Damping:
    """``[damping]``: alpha, beta (a number [s], ``"auto"`` or ``"critical"``), alpha_relative, local,
    and for an automatic beta target_restitution, per_interface, release_fraction, probe_impacts
    (``"auto"``) and damping_ratio (``"critical"``, and the other pairs of ``per_interface``)."""
    raw = t.raw("beta", 0.0)
    if isinstance(raw, str):
        if raw not in BETA_MODES:
            raise ValueError(
                f"[{t.where}] beta must be a finite number [s], 'auto' (targeted to target_restitution) or 'critical' "
                f"(each group pair 2 zeta / omega of its own impact), got {raw!r}"
            )
        beta: float | str = raw
    else:
        beta = t.number("beta", 0.0, min_=0.0)
    given = [k for k in _AUTO_KEYS if k in t.data]
    if given and beta != BETA_AUTO:
        raise ValueError(f"[{t.where}] {', '.join(given)} only apply to beta = \"auto\" (beta is {beta!r}); set beta = \"auto\"")
    if "damping_ratio" in t.data and not isinstance(beta, str):
        raise ValueError(f"[{t.where}] damping_ratio only applies to beta = \"critical\" or \"auto\" (beta is {beta!r})")
    target = t.raw("target_restitution", "0.95eta")
    if isinstance(target, bool) or not isinstance(target, (str, int, float)):
        raise ValueError(f"[{t.where}] target_restitution must be 'eta', a multiple such as '0.95eta', or a number in (0, 1), got {target!r}")
    out = Damping(
        alpha=t.number("alpha", 0.0, min_=0.0),
        beta=beta,
        alpha_relative=t.boolean("alpha_relative", False),
        local=t.number("local", 0.0, min_=0.0),
        target_restitution=target,
        damping_ratio=t.number("damping_ratio", 1.0, positive=True),
        per_interface=t.boolean("per_interface", False),
        release_fraction=t.optional_number("release_fraction", positive=True),
        probe_impacts=t.integer("probe_impacts", 0, min_=0),
    )
    t.finish()
    return out


def _register_builtin_types() -> None:
    """Import the modules that register more specimen and loading types (if present)."""
    import importlib

    for name in ("rockdem.specimens", "rockdem.loading"):
        try:
            importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name != name:
                raise


_register_builtin_types()
