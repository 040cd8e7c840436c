"""Checkpoints: save a run and continue it later, bit for bit, or start new loadings from its state.

A :class:`Checkpoint` holds everything :func:`rockdem.simulation.simulate` keeps between its
compiled chunks: the engine's :class:`~rockdem.kernels.layout.State` (poses, velocities, the
per-point contact history: partners, shear springs, bonds, failure modes; the timestep) and
:class:`~rockdem.kernels.layout.Scratch` (detection buffers and the values carried from one step
to the next), the frames recorded so far (:class:`~rockdem.kernels.layout.Records`), the contact
snapshots taken, the frame and snapshot counters, the record and contact intervals and the
initial timestep figures. State, Scratch and Records are stored field by field over their
``_fields``, so checkpoints follow the engine's layout without code here naming its fields.

File format (``.npz``, NumPy's zip of arrays, read without pickle): ``meta`` is a JSON string
(``format`` = :data:`FORMAT`, ``version`` = :data:`FORMAT_VERSION`, the model hashes, counters and
intervals); ``state/NAME``, ``scratch/NAME``, ``records/NAME`` and ``snapshots/NAME`` hold the
arrays. A checkpoint is bound to its model by :func:`model_hash` (every model array, the block
names and the initial configuration): continuing a run needs the very same model. A checkpoint
whose clock is reset (:meth:`Checkpoint.reset_clock`) starts a new run at t = 0 from the saved
state, e.g. a model settled under gravity, and only needs the same blocks, geometry and joints
(:func:`structure_hash`): its loading (ground motion, body forces, prescribed motions) and damping
may differ.

Usage::

    ds = simulate(model, 5.0, checkpoint="run.npz")           # written at the end (or on Ctrl-C)
    ds = simulate(model, 10.0, initial="run.npz")             # continues to t = 10 s: frames 0..10 s
    settled = Checkpoint.load("settled.npz").reset_clock()    # settled under gravity alone
    for model_eq in models_with_records:                     # same blocks, other loadings
        ds = simulate(model_eq, 20.0, initial=settled)
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import zipfile
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping, NamedTuple

import numpy as np

from .kernels.layout import ModelArrays, Records, Scratch, State
from .model import Model
from .timestep import TimestepInfo

__all__ = ["Checkpoint", "FORMAT", "FORMAT_VERSION", "LOADING_FIELDS", "model_hash", "structure_hash", "field_hashes",
           "model_differences", "load_checkpoint"]

FORMAT = "rockdem-checkpoint"
FORMAT_VERSION = 11
"""Version of the checkpoint file layout; a file of another version is refused. (2: the model
hash covers ``ModelArrays.face_corner_uw``, so a version-1 file's hash would not match. 3: the
state holds ``slot_stiffening`` and ``slot_updates``, the model ``point_corner``. 5: the state
holds ``slot_cover``, the scratch ``pair_handover``. 6: the state holds ``velocity_lag``. 10: the
state holds ``slot_anchor`` and ``slot_deepest``, the scratch ``driven_force_last`` and ``driven_dashpot``. 11: the
scratch holds ``prev_pair_weight``.)"""

LOADING_FIELDS = frozenset(
    {"block_motion", "motion_start", "motion_time", "motion_velocity", "ground_motion", "body_time",
     "body_acceleration", "alpha", "alpha_relative", "local_damping", "mat_beta"}
)
"""ModelArrays fields that describe the loading and damping, not the blocks: a checkpoint with its
clock reset may start a model that differs in these (every other field must match)."""

PathLike = str | os.PathLike[str]


def _digest(h: Any, value: Any) -> None:
    """Feed one value (array, scalar, string or sequence of them) to a hash, with its type and shape."""
    if isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    elif isinstance(value, (tuple, list)):
        h.update(f"seq{len(value)}".encode())
        for v in value:
            _digest(h, v)
    else:
        h.update(repr(value).encode())


def _hash_model(model: Model, fields: tuple[str, ...], extra: tuple[str, ...]) -> str:
    h = hashlib.sha256()
    for name in fields:
        h.update(name.encode())
        _digest(h, getattr(model.arrays, name))
    for name in extra:
        h.update(name.encode())
        _digest(h, getattr(model, name))
    return h.hexdigest()


MODEL_EXTRAS = ("block_names", "group_names", "position0", "quaternion0", "quaternion_ref", "position_ref",
                "velocity0", "omega0", "rocking_axis")
"""Model attributes beside its arrays that :func:`model_hash` covers."""

STRUCTURE_FIELDS = tuple(f for f in ModelArrays._fields if f not in LOADING_FIELDS)
STRUCTURE_EXTRAS = ("block_names", "group_names", "position0", "quaternion0")
"""The model arrays and attributes that :func:`structure_hash` covers."""


def model_hash(model: Model) -> str:
    """SHA-256 of every model array, the block and group names and the initial configuration:
    equal hashes mean the same model (and a continued run then equals an uninterrupted one)."""
    return _hash_model(model, ModelArrays._fields, MODEL_EXTRAS)


def structure_hash(model: Model) -> str:
    """SHA-256 of the blocks, geometry, interface points and joint materials: the model arrays less
    :data:`LOADING_FIELDS`, with the block names and reference configuration."""
    return _hash_model(model, STRUCTURE_FIELDS, STRUCTURE_EXTRAS)




def field_hashes(model: Model) -> dict[str, str]:
    """A short hash per model array and per :data:`MODEL_EXTRAS` attribute, kept in a checkpoint so
    that a model that differs can be told what differs (:func:`model_differences`)."""
    out = {}
    for name in ModelArrays._fields + MODEL_EXTRAS:
        h = hashlib.sha256()
        _digest(h, getattr(model.arrays, name) if name in ModelArrays._fields else getattr(model, name))
        out[name] = h.hexdigest()[:16]
    return out


def _what(name: str) -> str:
    """What a model array or attribute describes, in a case's words."""
    if name in ("alpha", "alpha_relative", "local_damping", "mat_beta"):
        return "the damping"
    if name in LOADING_FIELDS or name == "rocking_axis":
        return "the loading (driven motions, ground or body accelerations, its direction)"
    if name == "block_free":
        return "which blocks are driven"
    if name.startswith("mat_"):
        return "the joint materials"
    if name in ("position0", "quaternion0", "quaternion_ref", "position_ref"):
        return "the blocks' starting poses (a tilt is one)"
    if name in ("velocity0", "omega0"):
        return "the initial velocities"
    if name in ("gravity", "contact_tol", "touch_tol", "block_names", "group_names", "block_group"):
        return {"gravity": "gravity", "block_names": "the block names", "contact_tol": "the contact tolerance",
                "touch_tol": "the contact tolerance"}.get(name, "the joint groups")
    if name.startswith(("point_", "cell_")):
        return "the interface points"
    return "the blocks' geometry, size or density"


def model_differences(model: Model, saved: Mapping[str, str], structure: bool = False) -> list[str]:
    """What differs between ``model`` and the model whose :func:`field_hashes` are ``saved``, in a
    case's words (each once, in the order of the arrays), with the arrays that differ; with
    ``structure`` only what :func:`structure_hash` covers (the loading and damping may differ)."""
    now = field_hashes(model)
    covered = set(STRUCTURE_FIELDS + STRUCTURE_EXTRAS) if structure else set(now)
    groups: dict[str, list[str]] = {}
    for name, h in now.items():
        if name in covered and name in saved and saved[name] != h:
            groups.setdefault(_what(name), []).append(name)
    return [f"{what} ({', '.join(names[:4])}{', ...' if len(names) > 4 else ''})" for what, names in groups.items()]


def _copy(nt: NamedTuple) -> Any:
    """A deep copy of a NamedTuple of arrays (every field, whatever the fields are)."""
    return type(nt)(*(np.array(v, copy=True) for v in nt))


@dataclass(frozen=True)
class Checkpoint:
    """A saved run (see the module notes). Build one with :func:`rockdem.simulation.simulate`'s
    ``checkpoint=`` option or :meth:`load`; pass it (or its path) as ``simulate(..., initial=)``.

    Attributes:
        state, scratch: the engine's arrays after the last completed chunk.
        records: the frames recorded so far (R frames).
        frame: index of the next frame to record (= R).
        record_interval: time between frames [s]; contact_interval: between contact snapshots [s] or None.
        snapshot_count: index of the next contact snapshot; snapshots: the snapshots taken, name ->
            (S, ...) array (see :mod:`rockdem.snapshots`).
        timestep: the run's initial timestep figures.
        model_hash, structure_hash: the model's :func:`model_hash` and :func:`structure_hash`.
        runtime_s: wall time spent on the run so far [s].
        fresh: True after :meth:`reset_clock`: a new run starts at t = 0 from this state.
        check_target: for a run with a stop rule (:mod:`rockdem.stopping`) whose end cut its last
            chunk short, the time [s] that chunk was to end at: a continuation ends its first chunk
            there, so that its stop checks fall where an uninterrupted run's do; else None.
        field_hashes: the model's :func:`field_hashes` (None in files written before 2026-12-08), to
            say what differs in a model it is refused for.
    """

    state: State
    scratch: Scratch
    records: Records
    frame: int
    record_interval: float
    contact_interval: float | None
    snapshot_count: int
    snapshots: dict[str, np.ndarray]
    timestep: TimestepInfo
    model_hash: str
    structure_hash: str
    runtime_s: float = 0.0
    fresh: bool = False
    block_names: tuple[str, ...] = field(default_factory=tuple)
    check_target: float | None = None
    field_hashes: dict[str, str] | None = None

    @property
    def time(self) -> float:
        """Engine time of the saved state [s] (just past the last recorded frame)."""
        return float(self.state.time[0])

    def __repr__(self) -> str:
        kind = "fresh start from" if self.fresh else "run at"
        return (f"<Checkpoint: {kind} t = {self.time:.6g} s, {self.frame} frames every {self.record_interval:g} s, "
                f"{len(self.block_names)} blocks, model {self.model_hash[:12]}>")

    def reset_clock(self) -> "Checkpoint":
        """This state as the start of a new run: time, step count and accumulated energies
        (dissipation, work) set to zero, no frames or snapshots; the poses, velocities and contact
        history (partners, shear springs, bonds, failures) are kept. The new run may use another
        loading and damping on the same blocks (:func:`structure_hash`)."""
        state, scratch = _copy(self.state), _copy(self.scratch)
        state.time[:] = 0.0
        state.step[:] = 0
        state.energy[:] = 0.0
        empty = Records(*(a[:0] for a in self.records))
        return replace(self, state=state, scratch=scratch, records=empty, frame=0, snapshot_count=0,
                       snapshots={}, runtime_s=0.0, fresh=True, check_target=None)

    def check_model(self, model: Model) -> None:
        """Raise ValueError unless ``model`` is the one this checkpoint was saved from (the same
        blocks, geometry and joints only, when the clock was reset)."""
        if self.fresh:
            if structure_hash(model) != self.structure_hash:
                raise ValueError(
                    "the checkpoint's blocks, geometry, joint materials or starting poses differ from this model's: a "
                    "checkpoint with its clock reset starts only a model built as the one it was saved from, with the "
                    "same blocks and joints standing in the same poses (its loading and damping may differ; a tilt, "
                    "as a free-rocking release has, is a pose: tilt the blocks in the settling case too); checkpoint "
                    f"blocks: {_names(self.block_names)}, model blocks: {_names(model.block_names)}{self._differing(model, structure=True)}")
            return
        if model_hash(model) != self.model_hash:
            same = structure_hash(model) == self.structure_hash
            hint = ("the blocks match but the loading or damping differs: to run another loading from this state "
                    "use Checkpoint.reset_clock() (rockdem run --settled)" if same else
                    f"checkpoint blocks: {_names(self.block_names)}, model blocks: {_names(model.block_names)}")
            raise ValueError(f"the checkpoint was saved from another model (model hash {self.model_hash[:12]} vs "
                             f"{model_hash(model)[:12]}); continue it with the same case and options; {hint}"
                             f"{self._differing(model)}")

    def _differing(self, model: Model, structure: bool = False) -> str:
        """'; what differs: ...' for a refused model (:func:`model_differences`), or '' without the
        saved hashes."""
        what = model_differences(model, self.field_hashes, structure) if self.field_hashes else []
        return f"; what differs: {'; '.join(what)}" if what else ""

    def save(self, path: PathLike) -> Path:
        """Write the checkpoint (atomically: a partial file never replaces a good one)."""
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        meta = {
            "format": FORMAT, "version": FORMAT_VERSION, "model_hash": self.model_hash,
            "structure_hash": self.structure_hash, "frame": self.frame, "record_interval": self.record_interval,
            "contact_interval": self.contact_interval, "snapshot_count": self.snapshot_count,
            "timestep": self.timestep.__dict__, "runtime_s": self.runtime_s, "fresh": self.fresh,
            "block_names": list(self.block_names), "time": self.time, "check_target": self.check_target,
            "field_hashes": self.field_hashes,
        }
        arrays: dict[str, np.ndarray] = {"meta": np.array(json.dumps(meta))}
        for prefix, nt in (("state", self.state), ("scratch", self.scratch), ("records", self.records)):
            arrays.update({f"{prefix}/{k}": np.asarray(v) for k, v in zip(nt._fields, nt)})
        arrays.update({f"snapshots/{k}": v for k, v in self.snapshots.items()})
        fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=p.name, suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                np.savez(fh, **arrays)
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # as an ordinary new file (mkstemp makes it private)
            os.replace(tmp, p)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return p

    @classmethod
    def load(cls, path: PathLike) -> "Checkpoint":
        """Read a checkpoint file.

        Raises:
            FileNotFoundError: no such file.
            ValueError: not a rockdem checkpoint, another format version, or written by a rockdem
                whose engine state has other fields.
        """
        p = Path(path)
        if p.is_dir():
            raise ValueError(f"checkpoint {p} is a folder; give the checkpoint.npz that rockdem run writes in its output folder")
        if not p.is_file():
            raise FileNotFoundError(f"checkpoint {p} does not exist (rockdem run writes OUT/checkpoint.npz)")
        try:
            with np.load(p, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}
            meta = json.loads(str(data.pop("meta")))
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:  # truncated or empty files too
            # (NumPy reads a file that is no .npz as a pickle, which it refuses with advice to load it unsafely)
            why = "not an .npz archive" if "pickle" in str(exc) else str(exc)
            raise ValueError(f"{p} is not a rockdem checkpoint (.npz written by rockdem run or simulate): {why}") from None
        if meta.get("format") != FORMAT:
            raise ValueError(f"{p} is not a rockdem checkpoint (format {meta.get('format')!r})")
        if meta.get("version") != FORMAT_VERSION:
            raise ValueError(f"checkpoint {p} has format version {meta.get('version')}; this rockdem reads version "
                             f"{FORMAT_VERSION}: rerun the case to write a new one")
        parts = {}
        for prefix, kind in (("state", State), ("scratch", Scratch), ("records", Records)):
            have = {k.split("/", 1)[1]: v for k, v in data.items() if k.startswith(prefix + "/")}
            missing, extra = set(kind._fields) - set(have), set(have) - set(kind._fields)
            if missing or extra:
                raise ValueError(
                    f"checkpoint {p} was written by a rockdem whose engine {kind.__name__} differs from this one's "
                    f"(missing {sorted(missing)}, unknown {sorted(extra)}): rerun the case to write a new checkpoint")
            parts[prefix] = kind(**have)
        snaps = {k.split("/", 1)[1]: v for k, v in data.items() if k.startswith("snapshots/")}
        return cls(
            state=parts["state"], scratch=parts["scratch"], records=parts["records"], frame=int(meta["frame"]),
            record_interval=float(meta["record_interval"]), contact_interval=meta["contact_interval"],
            snapshot_count=int(meta["snapshot_count"]), snapshots=snaps, timestep=TimestepInfo(**meta["timestep"]),
            model_hash=meta["model_hash"], structure_hash=meta["structure_hash"], runtime_s=float(meta["runtime_s"]),
            fresh=bool(meta["fresh"]), block_names=tuple(meta["block_names"]),
            check_target=meta.get("check_target"),  # absent in files written before stop rules
            field_hashes=meta.get("field_hashes"),  # absent in files written before 2026-12-08
        )

    def engine_arrays(self, model: Model) -> tuple[State, Scratch]:
        """Copies of the saved State and Scratch, checked against a fresh allocation for ``model``
        (same dtypes and shapes; buffers that grow during a run may be longer)."""
        from .state import initial_state

        fresh_s, fresh_sc = initial_state(model, check_overlap=False)
        for saved, ref in ((self.state, fresh_s), (self.scratch, fresh_sc)):
            for name, a, b in zip(ref._fields, saved, ref):
                ok = a.dtype == b.dtype and a.ndim == b.ndim and a.shape[1:] == b.shape[1:] and (
                    a.shape[:1] == b.shape[:1] or (a.ndim and a.shape[0] >= b.shape[0]))
                if not ok:
                    raise ValueError(f"checkpoint {type(ref).__name__}.{name} has dtype {a.dtype} shape {a.shape}, "
                                     f"this model needs {b.dtype} {b.shape}: the checkpoint belongs to another model")
        return _copy(self.state), _copy(self.scratch)


def _names(names: tuple[str, ...], n: int = 6) -> str:
    return f"{len(names)} ({', '.join(names[:n])}{', ...' if len(names) > n else ''})"


def load_checkpoint(initial: Checkpoint | PathLike) -> Checkpoint:
    """A checkpoint, read from its file when given a path."""
    if isinstance(initial, Checkpoint):
        return initial
    if isinstance(initial, (str, os.PathLike)):
        return Checkpoint.load(initial)
    raise TypeError(f"initial must be a Checkpoint or a checkpoint file path, got {type(initial).__name__}")
