"""Model building: blocks, groups, joint materials, damping and prescribed motions -> frozen Model.

A :class:`ModelBuilder` collects blocks with friendly calls and :meth:`ModelBuilder.finalize`
validates everything once and freezes it into a :class:`Model` of flat arrays
(:class:`~rockdem.kernels.layout.ModelArrays`) that the kernels use. Units: SI.
"""

from __future__ import annotations

import contextvars
import math
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._warn import warn_user
from .beta_choice import BETA_MODES, BetaChoice, RestitutionTarget
from .flatten import BlockFrame, flatten_geometry
from .geometry import MAX_FACE_POINTS, Polyhedron, box, mass_properties
from .kernels.layout import ModelArrays
from .kernels.rotation import axis_angle_matrix, matrix_to_quat
from .materials import (HEAVIEST_DENSITY, PLAUSIBLE_DENSITY, PLAUSIBLE_FRICTION_ANGLE, PLAUSIBLE_MODULUS, STIFFEST_MODULUS, JointMaterial,
                        real_number)

__all__ = ["Motion", "Damping", "ModelBuilder", "Model", "GROUND"]

GROUND = "ground"
"""Value of ``driven`` for blocks attached to the ground: they follow the model's ground motion."""


@dataclass(frozen=True)
class Motion:
    """A prescribed velocity history v(t) of a driven block (linear between samples, end value held).

    Attributes:
        time: (n,) increasing sample times [s].
        velocity: (n, 3) velocity [m/s].
    """

    time: NDArray[np.float64]
    velocity: NDArray[np.float64]

    def __post_init__(self) -> None:
        t = _float_array(self.time, "Motion: time [s]").reshape(-1)
        v = _float_array(self.velocity, "Motion: velocity [m/s]")
        if v.ndim == 1:
            v = v.reshape(-1, 1) * np.array([[1.0, 0.0, 0.0]]) if v.shape[0] == t.shape[0] else v.reshape(1, 3)
        if t.shape[0] < 1 or v.shape != (t.shape[0], 3):
            raise ValueError(f"Motion: time (n,) and velocity (n, 3) must match, got {t.shape} and {v.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise ValueError("Motion: time and velocity must be finite")
        if np.any(np.diff(t) <= 0):
            raise ValueError("Motion: time samples must be strictly increasing")
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "velocity", v)

    @classmethod
    def constant(cls, velocity: ArrayLike, *, start: float = 0.0, stop: float | None = None) -> "Motion":
        """Constant velocity [m/s] from ``start`` to ``stop`` [s] (at rest outside)."""
        v = _vector3(velocity, "Motion.constant: velocity [m/s]")
        if not real_number(start, "Motion.constant: start [s]") >= 0.0:
            raise ValueError(f"Motion.constant: start must be a time >= 0 [s], got {start!r}")
        if stop is not None and not real_number(stop, "Motion.constant: stop [s]") > start:
            raise ValueError(f"Motion.constant: stop must come after start ({start} s), got {stop!r}")
        eps = 1e-9
        if stop is None:
            t = [0.0, start, start + eps] if start > 0 else [0.0]
            vel = [np.zeros(3), np.zeros(3), v] if start > 0 else [v]
        else:
            t = [0.0, start, start + eps, stop, stop + eps]
            vel = [np.zeros(3), np.zeros(3), v, v, np.zeros(3)]
            if start <= 0:
                t, vel = [0.0, stop, stop + eps], [v, v, np.zeros(3)]
        return cls(np.array(t), np.array(vel))

    @classmethod
    def from_function(cls, func: Callable[[float], ArrayLike], duration: float, sample_dt: float = 1e-4) -> "Motion":
        """Sample a velocity function v(t) -> (3,) [m/s] every ``sample_dt`` over [0, duration] [s]."""
        if not real_number(duration, "Motion.from_function: duration [s]") > 0:
            raise ValueError(f"Motion.from_function: duration must be positive [s], got {duration!r}")
        if not real_number(sample_dt, "Motion.from_function: sample_dt [s]") > 0:
            raise ValueError(f"Motion.from_function: sample_dt must be positive [s], got {sample_dt!r}")
        if duration / sample_dt > MAX_MOTION_SAMPLES:
            raise ValueError(
                f"Motion.from_function: {duration / sample_dt:.3g} samples (duration / sample_dt) exceed "
                f"{MAX_MOTION_SAMPLES}; raise sample_dt"
            )
        t = np.arange(0.0, duration + sample_dt, sample_dt)
        return cls(t, np.array([np.asarray(func(ti), dtype=float).reshape(3) for ti in t]))


@dataclass(frozen=True)
class Damping:
    """Rayleigh damping (paper §3, Eq. 4) and Cundall's local damping (quasi-static runs only).

    Attributes:
        alpha: mass-proportional coefficient [1/s]: force -alpha m v, moment -alpha I omega.
        beta: stiffness-proportional coefficient [s]: dashpots beta kn A and beta ks A at every
            active sub-contact (a joint material's own ``beta`` overrides it). Or chosen by
            :meth:`ModelBuilder.finalize` (``docs/damping.md``): ``"auto"``, the beta for which the
            model's own impacts give the apparent restitution ``target_restitution``
            (:mod:`rockdem.targeting`); ``"critical"``, every joint group pair its own
            2 ``damping_ratio`` / omega of its own critical impact (:mod:`rockdem.interfaces`).
        alpha_relative: MP damping on velocities relative to the ground motion instead of absolute
            ones (3DEC uses absolute velocities).
        local: Cundall's local (non-viscous) damping coefficient for quasi-static runs only [-].
        target_restitution: target of ``beta = "auto"``: ``"eta"`` (Housner's e_eta = 1 - 1.5
            sin^2 eta of the released body), a multiple (``"0.95eta"``, Sorrentino et al.'s, the
            default), or a restitution in (0, 1) (e.g. measured) [-].
        damping_ratio: zeta of ``beta = "critical"`` and of the non-rocking pairs with
            ``per_interface`` [-] (1 = critical).
        per_interface: with ``beta = "auto"``, only the rocking interface(s) (the released body on
            its supports) get the targeted beta, every other group pair its own critical beta;
            without it every pair gets the targeted beta (one value, as in 3DEC).
        release_fraction: release of the ``"auto"`` probe as a fraction of the instability angle
            eta [-]; default the model's own free-rocking release (:meth:`ModelBuilder.tilt`),
            else :data:`rockdem.targeting.DEFAULT_RELEASE_FRACTION`.
        probe_impacts: impacts whose e_a the ``"auto"`` search matches to the target: 0 (default)
            every half cycle of the probe's free-rocking decay down to 2 % of the release (the
            mean e_a a free-rocking run reports), or the first N only (the large-amplitude
            impacts; shorter probes).
    """

    alpha: float = 0.0
    beta: float | str = 0.0
    alpha_relative: bool = False
    local: float = 0.0
    target_restitution: float | str = "0.95eta"
    damping_ratio: float = 1.0
    per_interface: bool = False
    release_fraction: float | None = None
    probe_impacts: int = 0

    def __post_init__(self) -> None:
        self.validate()

    @property
    def beta_mode(self) -> str | None:
        """``"auto"`` or ``"critical"`` when beta is chosen at :meth:`ModelBuilder.finalize`, else None."""
        return self.beta if isinstance(self.beta, str) else None

    def validate(self) -> None:
        """Raise ValueError naming the field for a negative, non-finite or non-numeric value."""
        names = ("alpha", "local") if isinstance(self.beta, str) else ("alpha", "beta", "local")
        if isinstance(self.beta, str) and self.beta not in BETA_MODES:
            raise ValueError(
                f"damping.beta must be a non-negative number [s], 'auto' (targeted to damping.target_restitution) "
                f"or 'critical' (per group pair, 2 zeta / omega), got {self.beta!r}"
            )
        for name in names:
            v = getattr(self, name)
            if not real_number(v, f"damping.{name}") >= 0.0:
                raise ValueError(f"damping.{name} must be a finite non-negative number, got {v!r}")
        if not isinstance(self.alpha_relative, (bool, np.bool_)):
            raise ValueError(f"damping.alpha_relative must be True or False, got {self.alpha_relative!r}")
        if self.local >= 1.0:
            raise ValueError(f"damping.local must be below 1 (0.8 is usual for quasi-static runs), got {self.local!r}")
        RestitutionTarget.parse(self.target_restitution)
        if not real_number(self.damping_ratio, "damping.damping_ratio") > 0.0:
            raise ValueError(f"damping.damping_ratio must be positive (1 = critical), got {self.damping_ratio!r}")
        if not isinstance(self.per_interface, (bool, np.bool_)):
            raise ValueError(f"damping.per_interface must be True or False, got {self.per_interface!r}")
        if self.release_fraction is not None and not 0.0 < real_number(self.release_fraction, "damping.release_fraction") < 1.0:
            raise ValueError(f"damping.release_fraction must lie in (0, 1) (a fraction of eta), got {self.release_fraction!r}")
        if isinstance(self.probe_impacts, bool) or not isinstance(self.probe_impacts, (int, np.integer)) or self.probe_impacts < 0:
            raise ValueError(f"damping.probe_impacts must be an integer >= 0 (0: the whole decay), got {self.probe_impacts!r}")


@dataclass(frozen=True)
class Release:
    """A free-rocking release recorded by :meth:`ModelBuilder.tilt`.

    Attributes:
        blocks: names of the blocks tilted as one rigid assembly.
        fraction: tilt as a fraction of the assembly's instability angle [-].
        direction: (3,) horizontal unit direction towards which the top moved.
    """

    blocks: tuple[str, ...]
    fraction: float
    direction: NDArray[np.float64]


@dataclass(frozen=True)
class ReleaseGeometry:
    """Where and how far an assembly was tilted (:meth:`ModelBuilder.released_copy`).

    Attributes:
        angle: tilt angle theta_0 [rad]. eta: the assembly's instability angle about the pivot [rad].
        pivot: (3,) a point of the pivot edge [m]. axis: (3,) unit rotation axis of the tilt.
    """

    angle: float
    eta: float
    pivot: NDArray[np.float64]
    axis: NDArray[np.float64]


@dataclass
class _Block:
    name: str
    poly: Polyhedron
    density: float
    group: str
    driven: bool | str | Motion
    points: tuple[int, int]
    velocity: NDArray[np.float64]
    angular_velocity: NDArray[np.float64]
    tilt: NDArray[np.float64] = field(default_factory=lambda: np.eye(3))
    reference: Polyhedron | None = None


@dataclass(frozen=True, repr=False)
class Model:
    """A frozen model: the kernel arrays plus the names and initial state (printed as a short
    summary; a notebook shows it as a table).

    Attributes:
        arrays: flat arrays used by the kernels.
        block_names: one name per block.
        group_names: joint-material groups, index = ``arrays.block_group`` value.
        faces: per block, the face vertex-index lists (global vertex ids into ``arrays.vertex_local``).
        position0: (nb, 3) initial centroids [m].
        quaternion0: (nb, 4) initial orientations (body principal frame -> world).
        quaternion_ref: (nb, 4) reference orientations from which rotations are measured: the
            initial ones before any :meth:`ModelBuilder.tilt`.
        position_ref: (nb, 3) reference centroids (before any tilt) [m]; monitor points are
            given, and their displacements measured, in this reference configuration.
        velocity0: (nb, 3) initial velocities [m/s].
        omega0: (nb, 3) initial angular velocities, body frame [rad/s].
        damping: the damping options.
        rocking_axis: (3,) world axis about which ``rocking_angle`` is measured.
        materials: the material table by group-name pair.
        beta_choice: how beta was chosen when ``damping.beta`` was ``"auto"`` or ``"critical"``
            (``damping.beta`` then holds the chosen value), else None.
    """

    arrays: ModelArrays
    block_names: tuple[str, ...]
    group_names: tuple[str, ...]
    faces: tuple[tuple[NDArray[np.int64], ...], ...]
    position0: NDArray[np.float64]
    quaternion0: NDArray[np.float64]
    quaternion_ref: NDArray[np.float64]
    position_ref: NDArray[np.float64]
    velocity0: NDArray[np.float64]
    omega0: NDArray[np.float64]
    damping: Damping
    rocking_axis: NDArray[np.float64]
    materials: dict[tuple[str, str], JointMaterial] = field(default_factory=dict)
    beta_choice: BetaChoice | None = None

    @property
    def block_count(self) -> int:
        return len(self.block_names)

    @property
    def point_count(self) -> int:
        return int(self.arrays.point_area.shape[0])

    def with_inputs(
        self, *, damping: Damping | None = None, builder: ModelBuilder | None = None, beta_choice: BetaChoice | None = None
    ) -> Model:
        """This model with another damping and/or the prescribed kinematics (ground motion, body
        acceleration, driven motions) of ``builder``, whose blocks must be this model's: the
        geometry is not rebuilt. The arrays are those :meth:`ModelBuilder.finalize` would give.

        A damping whose beta is ``"auto"`` or ``"critical"`` needs ``beta_choice``, its resolution on
        this model's builder (:func:`rockdem.targeting.choose_beta`; :class:`rockdem.case.CaseTemplate`
        keeps one per damping); the model then carries the chosen betas as ``finalize`` leaves them.
        """
        fields: dict[str, Any] = {}
        new_damping, choice = self.damping, self.beta_choice
        if damping is not None:
            damping.validate()
            if beta_choice is not None and beta_choice.mode != damping.beta_mode:
                raise ValueError(f"with_inputs: beta_choice is the resolution of beta = {beta_choice.mode!r}, "
                                 f"but damping.beta is {damping.beta!r}")
            if damping.beta_mode is not None and beta_choice is None:
                raise ValueError(
                    f"with_inputs: damping.beta = {damping.beta!r} is chosen from the model's builder; pass "
                    "beta_choice=rockdem.targeting.choose_beta(builder, model, damping) or use ModelBuilder.finalize"
                )
            fields.update(damping_arrays(self.materials, self.group_names, damping, beta_choice))
            new_damping = damping if beta_choice is None else replace(damping, beta=beta_choice.beta)
            choice = beta_choice
        elif beta_choice is not None:
            raise ValueError("with_inputs: beta_choice goes with the damping it resolves (give damping=)")
        if builder is not None:
            if tuple(builder.block_names()) != self.block_names:
                raise ValueError("with_inputs: the builder's blocks are not this model's")
            fields.update(builder.input_arrays())
        model = replace(self, arrays=self.arrays._replace(**fields), damping=new_damping, beta_choice=choice)
        if damping is not None:
            _warn_implausible_damping(model, damping)
        return model

    def summary(self) -> dict[str, str]:
        """Short description, label -> text: blocks, points, groups, joints, damping, loading, size."""
        m = self.arrays
        free = m.block_free.astype(bool)
        driven = [n for n, f in zip(self.block_names, free) if not f]
        v = self.arrays.vertex_local
        owner = np.repeat(np.arange(self.block_count), np.diff(m.block_vertex_start))
        from .kernels.rotation import quats_to_matrices

        world = np.einsum("vij,vj->vi", quats_to_matrices(self.quaternion0)[owner], v) + self.position0[owner]
        lo, hi = world[free[owner]].min(axis=0), world[free[owner]].max(axis=0)
        tiny = 1e-9 * max(float(np.max(hi - lo)), 1e-300)
        lo, hi = np.where(np.abs(lo) < tiny, 0.0, lo), np.where(np.abs(hi) < tiny, 0.0, hi)
        kn = sorted({f"{mat.kn:.3g}" for mat in self.materials.values()})
        phi = sorted({f"{math.degrees(math.atan(mat.tan_friction)):.3g}" for mat in self.materials.values()})
        loading = []
        if m.ground_motion >= 0:
            loading.append(f"ground motion ({m.motion_time[-1]:.3g} s)" if m.motion_time.size else "ground motion")
        if m.body_time.size:
            loading.append(f"body acceleration ({m.body_time[-1]:.3g} s)")
        if np.any(m.block_motion[~free] > (0 if m.ground_motion >= 0 else -1)):
            loading.append("prescribed motion of driven blocks")
        tilted = int(np.count_nonzero(np.any(self.quaternion0 != self.quaternion_ref, axis=1)))
        if tilted:
            loading.append(f"{tilted} block(s) tilted")
        d = self.damping
        return {
            "blocks": f"{self.block_count} ({int(free.sum())} free, {len(driven)} driven: {_short_list(driven)})",
            "free blocks": _short_list([n for n, f in zip(self.block_names, free) if f]),
            "free mass": f"{float(m.block_mass[free].sum()):.4g} kg",
            "free blocks span": "  ".join(f"{a} {lo[i]:.3g}..{hi[i]:.3g}" for i, a in enumerate("xyz")) + " m",
            "interface points": f"{self.point_count}",
            "groups": ", ".join(self.group_names),
            "joints": f"kn {'/'.join(kn)} Pa/m, friction {'/'.join(phi)} deg",
            "damping": f"alpha {d.alpha:g} 1/s, beta {d.beta:g} s"
            + (f" (beta = \"{self.beta_choice.mode}\")" if self.beta_choice is not None else "")
            + (f", local {d.local:g}" if d.local else ""),
            "loading": ", ".join(loading) or "gravity only",
        }

    def __repr__(self) -> str:
        rows = self.summary()
        return "rockdem Model\n" + "\n".join(f"  {k:<17} {v}" for k, v in rows.items())

    def _repr_html_(self) -> str:
        from html import escape

        rows = "".join(f"<tr><th style='text-align:left'>{escape(k)}</th><td style='text-align:left'>{escape(v)}</td></tr>"
                       for k, v in self.summary().items())
        return f"<b>rockdem Model</b><table>{rows}</table>"

    def block_id(self, name: str) -> int:
        """Index of the block called ``name``."""
        try:
            return self.block_names.index(name)
        except ValueError:
            raise KeyError(f"no block named {name!r}; blocks are {list(self.block_names)}") from None

    def world_points(self, block: int, local_points: ArrayLike) -> NDArray[np.float64]:
        """Initial world coordinates of points given in the block's body frame."""
        from .kernels.rotation import quats_to_matrices

        r = quats_to_matrices(self.quaternion0[block])
        return np.asarray(local_points, dtype=float) @ r.T + self.position0[block]

    def local_points(self, block: int, world_points: ArrayLike) -> NDArray[np.float64]:
        """Body-frame coordinates of points given in world coordinates at the initial pose."""
        from .kernels.rotation import quats_to_matrices

        r = quats_to_matrices(self.quaternion0[block])
        return (np.asarray(world_points, dtype=float) - self.position0[block]) @ r


class ModelBuilder:
    """Collects blocks, groups and materials, then :meth:`finalize` freezes a :class:`Model`.

    Args:
        gravity: gravitational acceleration vector [m/s^2]; z is up.
        points: default interface points per face (across the thickness, along the length).
    """

    def __init__(self, *, gravity: ArrayLike = (0.0, 0.0, -9.81), points: tuple[int, int] = (2, 2)) -> None:
        self.gravity = _vector3(gravity, "gravity [m/s^2]")
        self.points = _check_points(points, "builder points")
        self._blocks: list[_Block] = []
        self._materials: dict[frozenset[str], JointMaterial] = {}
        self._default_material: JointMaterial | None = None
        self.ground_motion: Motion | None = None
        self.body_acceleration: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self._release: Release | None = None
        self._load_direction: NDArray[np.float64] | None = None

    def load_along(self, direction: ArrayLike) -> None:
        """Record the horizontal direction [-] (3,) of the model's loading (an earthquake, a
        pushover: :mod:`rockdem.loading` calls this), so that :meth:`finalize` takes up x d as its
        default rocking axis and ``rocking_angle`` tips blocks along the load (before 2026-11-30 an
        earthquake along y was measured about y: a block it overturned read 0 rad, "not overturned").
        A later :meth:`tilt` takes the axis back."""
        self._load_direction = self._horizontal(_vector3(direction, "loading direction"))

    @property
    def release(self) -> Release | None:
        """The last free-rocking release made by :meth:`tilt` (None: the blocks were not tilted)."""
        return self._release

    @property
    def default_material(self) -> JointMaterial | None:
        """Joint material of every group pair without its own :meth:`set_material` (None: none)."""
        return self._default_material

    @default_material.setter
    def default_material(self, material: JointMaterial | None) -> None:
        if material is not None and not isinstance(material, JointMaterial):
            raise ValueError(f"default_material must be a JointMaterial (or None), got {material!r}")
        self._default_material = material

    # -- blocks -------------------------------------------------------------------------------
    def add_block(
        self,
        poly: Polyhedron,
        *,
        density: float = 2000.0,
        group: str = "block",
        name: str | None = None,
        driven: bool | str | Motion = False,
        points: tuple[int, int] | None = None,
        velocity: ArrayLike = (0.0, 0.0, 0.0),
        angular_velocity: ArrayLike = (0.0, 0.0, 0.0),
    ) -> int:
        """Add a convex block; returns its id.

        Args:
            poly: geometry at its initial position [m].
            density: [kg/m^3] (irrelevant for driven blocks, used for their reported mass).
            group: joint-material group name.
            name: unique block name (default ``block<i>``).
            driven: False for a free block; True (fixed), ``"ground"`` (follows the ground motion,
                fixed if none) or a :class:`Motion` for a block with prescribed velocity.
            points: interface points per face (across, along); default the builder's.
            velocity: initial velocity [m/s]; angular_velocity: initial, world frame [rad/s].
        """
        i = len(self._blocks)
        name = f"block{i}" if name is None else str(name)
        if not isinstance(poly, Polyhedron):
            raise ValueError(f"block {name!r}: poly must be a Polyhedron (rockdem.geometry.box or convex_hull), got {poly!r}")
        if any(b.name == name for b in self._blocks):
            raise ValueError(f"block name {name!r} is used twice; give each block a unique name")
        if isinstance(density, bool) or not isinstance(density, (int, float, np.number)) or not (math.isfinite(density) and density > 0.0):
            raise ValueError(f"block {name!r}: density must be positive [kg/m^3], got {density!r}")
        if not isinstance(group, str) or not group:
            raise ValueError(f"block {name!r}: group must be a non-empty name (a string), got {group!r}")
        if not (driven is False or driven is True or isinstance(driven, Motion) or (isinstance(driven, str) and driven == GROUND)):
            raise ValueError(f"block {name!r}: driven must be False, True, 'ground' or a Motion, got {driven!r}")
        pts = self.points if points is None else _check_points(points, f"block {name!r} points")
        if driven is False and min(pts) < 2:
            warn_user(f"block {name!r}: {pts[0]} x {pts[1]} interface points per face: a face's only point across "
                      "(or along) it sits at its middle, so the block balances on it instead of rocking about its "
                      "edges; give 2 or more (points=(across, along))")
        self._blocks.append(
            _Block(
                name,
                poly,
                float(density),
                group,
                driven,
                pts,
                _vector3(velocity, f"block {name!r}: velocity [m/s]"),
                _vector3(angular_velocity, f"block {name!r}: angular_velocity [rad/s]"),
            )
        )
        return i

    def add_box(
        self,
        b: float,
        l: float,
        h: float,
        *,
        base_center: ArrayLike = (0.0, 0.0, 0.0),
        **kwargs: object,
    ) -> int:
        """Add a box of width b (x), length l (y), height h (z) [m] whose base centre is ``base_center``."""
        name = str(kwargs.get("name") or "box")
        hh = real_number(h, f"{name}: h (height, z) [m]")
        c = _vector3(base_center, f"{name}: base_center [m]") + np.array([0.0, 0.0, 0.5 * hh])
        return self.add_block(box(b, l, h, center=c, name=name), **kwargs)  # type: ignore[arg-type]

    def block(self, i: int | str) -> Polyhedron:
        """Current geometry of block ``i`` (id or name)."""
        return self._blocks[self._index(i)].poly

    def transform_block(
        self,
        i: int | str,
        rotation: ArrayLike = np.eye(3),
        about: ArrayLike = (0.0, 0.0, 0.0),
        translation: ArrayLike = (0.0, 0.0, 0.0),
    ) -> None:
        """Move block ``i`` rigidly: rotate by matrix ``rotation`` about point ``about``, then
        translate by ``translation`` [m]."""
        blk = self._blocks[self._index(i)]
        r = _float_array(rotation, f"block {blk.name!r}: rotation")
        if r.shape != (3, 3) or not np.all(np.isfinite(r)) or not np.allclose(r @ r.T, np.eye(3), atol=1e-9) \
                or np.linalg.det(r) < 0.0:
            raise ValueError(f"block {blk.name!r}: rotation must be a 3 x 3 rotation matrix (orthonormal, determinant +1: "
                             f"a rigid move, no scaling, shear or mirror), got {np.array2string(r, precision=4)}")
        a = _vector3(about, f"block {blk.name!r}: about [m]")
        blk.poly = blk.poly.transformed(r, a - r @ a + _vector3(translation, f"block {blk.name!r}: translation [m]"))

    def group(self, i: int | str) -> str:
        """Joint-material group of block ``i`` (id or name)."""
        return self._blocks[self._index(i)].group

    def density(self, i: int | str) -> float:
        """Density of block ``i`` (id or name) [kg/m^3]."""
        return self._blocks[self._index(i)].density

    def block_names(self, *, driven: bool | str | None = None) -> list[str]:
        """Names of the blocks added so far: all (``driven=None``), the free ones (``False``), the
        driven ones (``True``: fixed, ground-following or with a prescribed motion) or those that
        follow the ground motion (``"ground"``)."""
        if driven is None:
            return [b.name for b in self._blocks]
        if driven is False:
            return [b.name for b in self._blocks if b.driven is False]
        if driven is True:
            return [b.name for b in self._blocks if b.driven is not False]
        if driven == GROUND:
            return [b.name for b in self._blocks if isinstance(b.driven, str) and b.driven == GROUND]
        raise ValueError(f"driven must be None, False, True or 'ground', got {driven!r}")

    def tilt(
        self,
        i: int | str | Sequence[int | str],
        fraction: float,
        *,
        direction: ArrayLike = (1.0, 0.0, 0.0),
    ) -> float:
        """Tilt block ``i`` (or the blocks ``i``, as one rigid assembly) about the base edge on the
        ``direction`` side to ``fraction`` of the instability angle (free rocking from a fraction
        of the instability displacement, paper §3.1 and §3.2).

        The pivot is the lowest edge of the block (assembly) furthest along the horizontal
        ``direction``; the assembly turns about it so that its top moves towards ``direction``.
        The instability angle is that of the assembly's centre of mass about the pivot, so a
        discretised wall is released exactly as the equivalent single block. Returns the tilt
        angle [rad].
        """
        try:
            ids = [self._index(i)] if isinstance(i, (str, int, np.integer)) else [self._index(k) for k in i]
        except (KeyError, IndexError, TypeError) as exc:
            raise ValueError(
                f"tilt: give a block name or id, or a list of them (blocks are {self.block_names()[:10]}), got {i!r}: "
                f"{exc.args[0] if exc.args else exc}"
            ) from None
        if not ids:
            raise ValueError("tilt: give at least one block")
        if len(set(ids)) != len(ids):
            raise ValueError("tilt: a block is listed twice")
        blocks = [self._blocks[k] for k in ids]
        driven = [b.name for b in blocks if b.driven is not False]
        if driven:
            raise ValueError(f"tilt: blocks {driven} are driven; only free blocks can be tilted")
        if isinstance(fraction, bool) or not (isinstance(fraction, (int, float)) and math.isfinite(fraction) and 0.0 <= fraction):
            raise ValueError(f"tilt fraction must be >= 0 (0.9 = 90 % of the instability angle), got {fraction!r}")
        d = _vector3(direction, "tilt direction")
        geo = self._tilt(ids, fraction, d)
        self._release = Release(tuple(b.name for b in blocks), float(fraction), self._horizontal(d))
        self._load_direction = None
        return geo.angle

    def default_rocking_axis(self) -> NDArray[np.float64]:
        """(3,) the rocking axis :meth:`finalize` takes by default: the line the last :meth:`tilt`
        turned the blocks about, oriented along +y where it has a y component, else along -x (so
        that a positive ``rocking_angle`` tips towards +x, or towards +y for rocking in y-z,
        whichever way the tilt went); y without a tilt. After a loading along d (:meth:`load_along`)
        up x d, so that a positive angle tips blocks along the load."""
        if self._load_direction is not None:
            return np.cross(self._up(), self._load_direction) + 0.0
        if self._release is None:
            return np.array([0.0, 1.0, 0.0])
        turn = np.cross(self._up(), self._release.direction)
        ref = np.array([0.0, 1.0, 0.0]) if abs(turn[1]) > 1e-9 else np.array([-1.0, 0.0, 0.0])
        return (turn if turn @ ref >= 0.0 else -turn) + 0.0

    def _up(self) -> NDArray[np.float64]:
        gn = np.linalg.norm(self.gravity)
        return -self.gravity / gn if gn > 0 else np.array([0.0, 0.0, 1.0])

    def _horizontal(self, direction: NDArray[np.float64]) -> NDArray[np.float64]:
        """``direction`` projected on the horizontal plane, unit length."""
        up = self._up()
        d = direction - up * (up @ direction)
        if not np.linalg.norm(d) > 0:
            raise ValueError("tilt direction must have a horizontal component")
        return d / np.linalg.norm(d)

    def _tilt(self, ids: list[int], fraction: float, direction: NDArray[np.float64]) -> ReleaseGeometry:
        """Turn blocks ``ids`` as one rigid assembly about their pivot edge (see :meth:`tilt`)."""
        blocks = [self._blocks[k] for k in ids]
        up = self._up()
        d = self._horizontal(direction)
        v = np.vstack([b.poly.vertices for b in blocks])
        size = max(b.poly.size for b in blocks)
        h = v @ up
        base = v[h <= h.min() + 1e-9 * size]
        along = base @ d
        pivot = base[along >= along.max() - 1e-9 * size].mean(axis=0)
        props = [mass_properties(b.poly, b.density) for b in blocks]
        mass = sum(p.mass for p in props)
        c = sum(p.mass * p.centroid for p in props) / mass
        rel = c - pivot
        eta = math.atan2(max(float(-(rel @ d)), 0.0), float(rel @ up))
        theta = fraction * eta
        if not theta < 0.5 * math.pi:
            raise ValueError(
                f"tilt fraction {fraction!r} of the instability angle ({math.degrees(eta):.3g} deg) tilts the blocks "
                "by 90 deg or more; give a fraction below 1 for a release from rest (paper §3.1)"
            )
        axis = np.cross(up, d)
        r = axis_angle_matrix(axis, theta)
        for k, blk in zip(ids, blocks):
            if blk.reference is None:
                blk.reference = blk.poly
            self.transform_block(k, r, about=pivot)
            blk.tilt = r @ blk.tilt
        return ReleaseGeometry(theta, eta, pivot, axis)

    def reference_poly(self, i: int | str) -> Polyhedron:
        """Geometry of block ``i`` in its reference pose (before any :meth:`tilt`) [m]."""
        blk = self._blocks[self._index(i)]
        return blk.poly if blk.reference is None else blk.reference

    def released_copy(
        self, blocks: Sequence[str], fraction: float, direction: ArrayLike, *, keep: Sequence[str] | None = None
    ) -> tuple["ModelBuilder", ReleaseGeometry]:
        """A copy of this builder for a free-rocking probe (the ``beta = "auto"`` search).

        In the copy every block is in its reference (untilted) pose, at rest, driven blocks are fixed,
        there is no ground motion or body acceleration, only the blocks ``keep`` (default all) remain,
        and ``blocks`` are tilted as one rigid assembly to ``fraction`` of their instability angle
        towards ``direction`` (as :meth:`tilt`). Materials and groups are shared with this builder.

        Returns:
            The copy and the release's geometry (angle, eta, pivot, axis).
        """
        names = set(self.block_names()) if keep is None else set(keep) | set(blocks)
        out = ModelBuilder(gravity=self.gravity.copy(), points=self.points)
        out._materials = dict(self._materials)
        out._default_material = self._default_material
        for blk in self._blocks:
            if blk.name not in names:
                continue
            out._blocks.append(
                _Block(blk.name, self.reference_poly(blk.name), blk.density, blk.group,
                       blk.driven if blk.driven is False else True, blk.points, np.zeros(3), np.zeros(3))
            )
        ids = [out._index(n) for n in blocks]
        geo = out._tilt(ids, fraction, _vector3(direction, "release direction"))
        return out, geo

    # -- materials and loading ----------------------------------------------------------------
    def set_material(self, group_a: str, group_b: str, material: JointMaterial) -> None:
        """Joint material between groups ``group_a`` and ``group_b`` (order irrelevant)."""
        if not (isinstance(group_a, str) and isinstance(group_b, str)):
            raise ValueError(f"set_material: groups are names (strings), got {group_a!r} and {group_b!r} (material)")
        if not isinstance(material, JointMaterial):
            raise ValueError(f"set_material {group_a!r}-{group_b!r}: material must be a JointMaterial, got {material!r}")
        material.validate(f"material {group_a!r}-{group_b!r}")
        self._materials[frozenset((group_a, group_b))] = material

    def set_ground_motion(self, motion: Motion | None) -> None:
        """Velocity history of every block added with ``driven="ground"``."""
        if motion is not None and not isinstance(motion, Motion):
            raise ValueError(f"set_ground_motion: give a Motion (velocity history) or None, got {motion!r}")
        self.ground_motion = motion

    def set_body_acceleration(self, time: ArrayLike, acceleration: ArrayLike) -> None:
        """Acceleration history a(t) (n, 3) [m/s^2] applied as body force m a(t) on every free block."""
        t = _float_array(time, "body acceleration: time [s]").reshape(-1)
        a = _float_array(acceleration, "body acceleration: acceleration [m/s^2]")
        if a.shape != (t.shape[0], 3) or t.shape[0] < 1:
            raise ValueError(f"body acceleration: time (n,) and acceleration (n, 3) must match, got {t.shape} and {a.shape}")
        if np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
            raise ValueError("body acceleration: time samples must be finite and strictly increasing")
        if not np.all(np.isfinite(a)):
            raise ValueError("body acceleration: acceleration values must be finite")
        self.body_acceleration = (t, a)

    def input_arrays(self) -> dict[str, Any]:
        """The prescribed-kinematics fields of :class:`ModelArrays` (``block_motion``,
        ``motion_start``, ``motion_time``, ``motion_velocity``, ``ground_motion``, ``body_time``,
        ``body_acceleration``) of the blocks and loading set so far. :meth:`finalize` uses it, and
        :meth:`Model.with_inputs` swaps them into a built model (another record or scale)."""
        motions: list[Motion] = []
        ground_index = -1
        if self.ground_motion is not None:
            motions.append(self.ground_motion)
            ground_index = 0
        block_motion = []
        for blk in self._blocks:
            if isinstance(blk.driven, Motion):
                motions.append(blk.driven)
                block_motion.append(len(motions) - 1)
            elif blk.driven == GROUND:
                block_motion.append(ground_index)
            else:
                block_motion.append(-1)
        bt, ba = self.body_acceleration if self.body_acceleration is not None else (np.zeros(0), np.zeros((0, 3)))
        return {
            "block_motion": np.array(block_motion, dtype=np.int64),
            "motion_start": np.cumsum([0] + [len(mo.time) for mo in motions]).astype(np.int64),
            "motion_time": np.concatenate([mo.time for mo in motions]) if motions else np.zeros(0),
            "motion_velocity": np.concatenate([mo.velocity for mo in motions]) if motions else np.zeros((0, 3)),
            "ground_motion": int(ground_index),
            "body_time": bt,
            "body_acceleration": ba,
        }

    # -- freeze -------------------------------------------------------------------------------
    def finalize(
        self,
        *,
        damping: Damping = Damping(),
        contact_tolerance: float | None = None,
        rocking_axis: ArrayLike | None = None,
    ) -> Model:
        """Validate and freeze the model.

        Args:
            damping: Rayleigh / local damping.
            contact_tolerance: gap [m] within which sub-contacts are tracked between detections;
                default 1 % of the smallest dimension of the free blocks, and at least 1.5 times
                the largest elastic opening or slip of a bonded joint at its strength (ft / kn,
                c / ks), so that a bond is never lost to the tolerance before it breaks. The
                point-in-face test uses it plus the point's own penetration.
            rocking_axis: world axis of the recorded ``rocking_angle``; default the line the
                :meth:`tilt` turned the blocks about, oriented along +y where it has a y component
                (y for a tilt along +x or -x: a positive angle tips towards +x), else along -x (a
                tilt along +y or -y: a positive angle tips towards +y); without a tilt, y.
        """
        if not self._blocks:
            raise ValueError("the model has no blocks; add blocks before finalize()")
        damping.validate()
        if not any(b.driven is False for b in self._blocks):
            raise ValueError("the model has no free block: every block is driven")
        if all(b.driven is False for b in self._blocks) and np.any(self.gravity):
            warn_user("the model has no driven block: nothing supports its free blocks, which fall freely under gravity "
                      "from t = 0; add a foundation (add_box(..., driven=True))")
        groups = sorted({b.group for b in self._blocks})
        gi = {g: k for k, g in enumerate(groups)}
        ng = len(groups)
        mats: dict[tuple[str, str], JointMaterial] = {}
        for ga in groups:
            for gb in groups:
                mat = self._materials.get(frozenset((ga, gb)), self.default_material)
                if mat is None:
                    raise ValueError(
                        f"no joint material between groups {ga!r} and {gb!r}: call "
                        "set_material(...) for that pair or set builder.default_material"
                    )
                mats[(ga, gb)] = mat
        tables = {name: np.zeros((ng, ng)) for name in ("kn", "ks", "c", "ft", "tf", "rc", "rtf")}
        bonded = np.zeros((ng, ng), dtype=np.bool_)
        for (ga, gb), mat in mats.items():
            a, b = gi[ga], gi[gb]
            tables["kn"][a, b] = mat.kn
            tables["ks"][a, b] = mat.shear_stiffness
            tables["c"][a, b] = mat.cohesion
            tables["ft"][a, b] = mat.tension
            tables["tf"][a, b] = mat.tan_friction
            tables["rc"][a, b] = mat.residual_cohesion
            tables["rtf"][a, b] = mat.tan_residual_friction
            bonded[a, b] = mat.bonded
        inputs = self.input_arrays()
        block_motion = inputs.pop("block_motion")

        nb = len(self._blocks)
        mass = np.zeros(nb)
        inertia = np.zeros((nb, 3))
        pos0 = np.zeros((nb, 3))
        quat0 = np.zeros((nb, 4))
        quat_ref = np.zeros((nb, 4))
        pos_ref = np.zeros((nb, 3))
        vel0 = np.zeros((nb, 3))
        om0 = np.zeros((nb, 3))
        radius = np.zeros(nb)
        frames: list[BlockFrame] = []
        faces_out = []
        min_dim = np.inf
        vcount = 0
        for b, blk in enumerate(self._blocks):
            mp = mass_properties(blk.poly, blk.density)
            if not mp.volume > 0:
                raise ValueError(f"block {blk.name!r}: non-positive volume {mp.volume!r} m^3")
            evals, evecs = np.linalg.eigh(mp.inertia)
            if np.linalg.det(evecs) < 0:
                evecs[:, 2] *= -1.0
            rot = evecs  # columns: principal axes in world; body -> world
            mass[b], inertia[b], pos0[b] = mp.mass, evals, mp.centroid
            quat0[b] = matrix_to_quat(rot)
            quat_ref[b] = matrix_to_quat(blk.tilt.T @ rot)
            pos_ref[b] = mp.centroid if blk.reference is None else mass_properties(blk.reference, blk.density).centroid
            free = blk.driven is False
            vel0[b] = blk.velocity if free else 0.0
            om0[b] = rot.T @ blk.angular_velocity if free else 0.0
            local = (blk.poly.vertices - mp.centroid) @ rot
            radius[b] = float(np.max(np.linalg.norm(local, axis=1)))
            if free:
                min_dim = min(min_dim, float(np.ptp(local, axis=0).min()))
            faces_out.append(tuple(f + vcount for f in blk.poly.faces))
            vcount += len(local)
            frames.append(BlockFrame(blk.poly, mp.centroid, rot, blk.points))
        geometry = flatten_geometry(frames)

        free_mask = np.array([blk.driven is False for blk in self._blocks])
        _warn_implausible_units(self._blocks, mats, min_dim)
        if contact_tolerance is None:
            # a bonded point must stay tracked until its bond breaks: at least 1.5 x the elastic
            # opening at the tensile strength (ft / kn) and slip at the cohesion (c / ks)
            opening = max(
                (max(m_.tension / m_.kn, m_.cohesion / m_.shear_stiffness) for m_ in mats.values() if m_.bonded),
                default=0.0,
            )
            contact_tolerance = max(0.01 * min_dim, 1.5 * opening)
        if not (math.isfinite(contact_tolerance) and contact_tolerance > 0):
            raise ValueError(f"contact_tolerance must be a positive length [m], got {contact_tolerance!r}")
        if contact_tolerance > 0.5 * min_dim:
            warn_user(f"contact_tolerance = {contact_tolerance:g} m exceeds half the smallest block dimension "
                      f"({min_dim:g} m): faces that are far apart are tracked as near contact (slow, and the "
                      "contact figures lose their meaning); the default is 1 % of that dimension")
        if rocking_axis is None:
            rocking_axis = self.default_rocking_axis()
        axis = np.asarray(rocking_axis, dtype=float).reshape(3) + 0.0  # + 0.0: no -0.0
        if not np.linalg.norm(axis) > 0:
            raise ValueError("rocking_axis must be a non-zero 3-vector")
        arrays = ModelArrays(
            block_mass=mass,
            block_inv_mass=np.where(free_mask, 1.0 / mass, 0.0),
            block_inertia=inertia,
            block_inv_inertia=np.where(free_mask[:, None], 1.0 / inertia, 0.0),
            block_free=free_mask,
            block_motion=block_motion,
            block_group=np.array([gi[blk.group] for blk in self._blocks], dtype=np.int64),
            block_radius=radius,
            **geometry,
            mat_kn=tables["kn"],
            mat_ks=tables["ks"],
            mat_cohesion=tables["c"],
            mat_tension=tables["ft"],
            mat_tan_friction=tables["tf"],
            mat_res_cohesion=tables["rc"],
            mat_res_tan_friction=tables["rtf"],
            mat_bonded=bonded,
            gravity=self.gravity.copy(),
            **damping_arrays(mats, tuple(groups), damping),
            **inputs,
            contact_tol=float(contact_tolerance),
            touch_tol=0.1 * float(contact_tolerance),
            **_extent(geometry["vertex_local"], geometry["block_vertex_start"], pos0, quat0, free_mask),
        )
        model = Model(
            arrays=arrays,
            block_names=tuple(b.name for b in self._blocks),
            group_names=tuple(groups),
            faces=tuple(faces_out),
            position0=pos0,
            quaternion0=quat0,
            quaternion_ref=quat_ref,
            position_ref=pos_ref,
            velocity0=vel0,
            omega0=om0,
            damping=damping,
            rocking_axis=axis / np.linalg.norm(axis),
            materials=mats,
        )
        _warn_implausible_damping(model, damping)
        if damping.beta_mode is None:
            return model
        from .targeting import choose_beta  # runs simulations of the model (imports simulate)

        return model.with_inputs(damping=damping, beta_choice=choose_beta(self, model))

    def _index(self, i: int | str) -> int:
        if isinstance(i, str):
            for k, b in enumerate(self._blocks):
                if b.name == i:
                    return k
            raise KeyError(f"no block named {i!r}")
        if not 0 <= i < len(self._blocks):
            raise IndexError(f"block id {i} out of range (0..{len(self._blocks) - 1})")
        return i


def damping_arrays(
    materials: Mapping[tuple[str, str], JointMaterial],
    group_names: Sequence[str],
    damping: Damping,
    beta_choice: BetaChoice | None = None,
) -> dict[str, Any]:
    """The damping fields of :class:`ModelArrays`: ``mat_beta`` (ng, ng) [s], ``alpha`` [1/s],
    ``alpha_relative``, ``local_damping``. ``mat_beta`` holds each pair's beta of ``beta_choice``
    when given (an automatic beta resolved), else a material's own beta, else ``damping.beta``
    (0 while ``damping.beta`` is ``"auto"`` or ``"critical"`` and not yet resolved)."""
    gi = {g: k for k, g in enumerate(group_names)}
    beta = np.zeros((len(group_names), len(group_names)))
    for (ga, gb), mat in materials.items():
        if beta_choice is not None:
            beta[gi[ga], gi[gb]] = beta_choice.pair(ga, gb).beta
        else:
            beta[gi[ga], gi[gb]] = (0.0 if damping.beta_mode else damping.beta) if mat.beta is None else mat.beta
    return {
        "mat_beta": beta,
        "alpha": float(damping.alpha),
        "alpha_relative": bool(damping.alpha_relative),
        "local_damping": float(damping.local),
    }


def _short_list(names: Sequence[str], n: int = 6) -> str:
    """The first ``n`` names, comma-separated, with the count of the rest."""
    names = list(names)
    more = f", ... ({len(names) - n} more)" if len(names) > n else ""
    return ", ".join(names[:n]) + more if names else "none"


MAX_MOTION_SAMPLES = 10_000_000
"""Most samples of a prescribed motion built by :meth:`Motion.from_function`."""


def _world_vertices(
    vertex_local: NDArray[np.float64], vstart: NDArray[np.int64], pos: NDArray[np.float64], quat: NDArray[np.float64],
    blocks: Sequence[int] | NDArray[np.int64],
) -> NDArray[np.float64]:
    """(V, 3) world vertices [m] of ``blocks`` at centroids ``pos`` (nb, 3) and orientations ``quat``
    (nb, 4), in block order (each block's ``vstart`` range of ``vertex_local``)."""
    from .kernels.rotation import quats_to_matrices

    r = quats_to_matrices(quat)
    return np.vstack([vertex_local[vstart[b] : vstart[b + 1]] @ r[b].T + pos[b] for b in blocks])


def _extent(
    vertex_local: NDArray[np.float64], vstart: NDArray[np.int64], pos: NDArray[np.float64], quat: NDArray[np.float64], free: NDArray[np.bool_]
) -> dict[str, NDArray[np.float64]]:
    """The model's extent: the bounding box of every block at the start, enlarged on each side by
    its largest dimension (at least 1 m); and the plan footprint (x, y) of the driven blocks at the
    start (empty when there are none). A free block whose centroid leaves the extent through its
    bottom outside that footprint, or through a side, has left the supports (fell off their edge or
    was thrown clear) and falls on unhindered; one leaving it through its bottom inside the footprint
    has fallen through its support, one leaving it through its top has flown away, and the run
    stops there."""
    world = _world_vertices(vertex_local, vstart, pos, quat, range(len(pos)))
    lo, hi = world.min(axis=0), world.max(axis=0)
    margin = max(float(np.max(hi - lo)), 1.0)
    driven = [b for b in range(len(pos)) if not free[b]]
    if driven:
        support = np.vstack([world[vstart[b] : vstart[b + 1]] for b in driven])
        s_lo, s_hi = support[:, :2].min(axis=0), support[:, :2].max(axis=0)
    else:
        s_lo, s_hi = np.full(2, np.inf), np.full(2, -np.inf)
    return {"extent_low": lo - margin, "extent_high": hi + margin, "support_low": s_lo, "support_high": s_hi}


def _check_points(points: Sequence[int], what: str) -> tuple[int, int]:
    if isinstance(points, (str, bytes)) or not hasattr(points, "__len__") or len(points) != 2:
        raise ValueError(f"{what}: give (across, along) interface point counts, got {points!r}")
    if any(isinstance(p, bool) or not isinstance(p, (int, np.integer)) or p < 1 for p in points):
        raise ValueError(f"{what}: counts must be integers >= 1 (the paper uses 2..15 across), got {points!r}")
    a, b = int(points[0]), int(points[1])
    if a * b > MAX_FACE_POINTS:
        raise ValueError(f"{what}: {a} x {b} points per face exceed the limit of {MAX_FACE_POINTS} (the paper uses 2..15 across)")
    return a, b


def _float_array(value: ArrayLike, what: str) -> NDArray[np.float64]:
    """``value`` as a float array, or ValueError naming ``what``."""
    if isinstance(value, (str, bytes)) or value is None:
        raise ValueError(f"{what} must be numbers, got {value!r}")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be numbers, got {value!r}") from None


def _vector3(value: ArrayLike, what: str) -> NDArray[np.float64]:
    """A finite 3-vector, or ValueError naming ``what``."""
    v = _float_array(value, what)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{what} must be a finite 3-vector (x, y, z), got {value!r}")
    return v




OVERDAMPED_BETA = 10.0
"""A numeric beta this many times the critical value 2 / omega of the model's slowest impact is
warned about (:func:`_warn_implausible_damping`; DeJong's beta, paper §2.2, is a critical one)."""

SETTLE_HINT = ", or start from the blocks settled (a case's [run] settle = true)"
"""The undamped-model warning's last suggestion, left out while :data:`SETTLING` is true."""

SETTLING: contextvars.ContextVar[bool] = contextvars.ContextVar("rockdem_settling", default=False)
"""True while a case that settles its blocks (``[run] settle``) builds its model
(:func:`rockdem.case._chosen_damping`): the undamped-model warning does not suggest settling."""


UNDAMPED_HINT = 0.4
"""The share of the critical beta of the slowest impact that the warning about an undamped model
suggests (:func:`_warn_implausible_damping`). 0.05 left a 0.5 m cube with 3 x 3 points creeping
down a slope below its friction angle (1.8 to 10 mm/s at 25 to 29.8 deg, 30 deg friction) and
sliding 15 % fast at 31 deg; 0.2 held it but left 3.7 % at 33 deg; 0.4 held and slid it within
0.1 % of Coulomb in every case tried (cubes with 2 x 2 and 3 x 3 points, a 0.4 x 0.4 x 0.2 and a
0.6 x 0.4 x 0.3 m block with 4 x 4 points, slopes 20 to 33 deg; 2026-11-29)."""


def _warn_implausible_damping(model: Model, damping: Damping) -> None:
    """Warn about Rayleigh coefficients that over-damp every motion of the model.

    * alpha [1/s] above 2 p, p = sqrt(3 g / 4 R) the rocking frequency parameter of the slowest
      free block (Housner's, of a rectangular block; R its half diagonal across its thickness and
      height, its smallest and largest extents), or of all the free blocks rocking as one body
      (R from their extent along the rocking direction and up): MP damping then over-damps that
      rocking, which creeps instead of swinging (the paper's MP values are 0.05 to 1 1/s).
    * a numeric beta [s] above :data:`OVERDAMPED_BETA` times the largest critical beta 2 / omega,
      omega = sqrt(kn A / m) of a free block on its smallest face (its two smallest extents: the
      slowest of its impacts, DeJong's omega_e of a block standing on its base) and softest
      joint: every impact is over-damped that many times, and a block settles into its joint
      over about beta seconds instead of bouncing.
    * no damping at all (alpha = beta = local = 0) under gravity: the joints ring for ever, which
      ratchets blocks held by friction near its limit.
    """
    m = model.arrays
    free = np.flatnonzero(m.block_free)
    g = float(np.linalg.norm(m.gravity))
    if not free.size:
        return
    start = m.block_vertex_start
    extents = np.array([np.sort(np.ptp(m.vertex_local[start[b]:start[b + 1]], axis=0)) for b in free])  # (nf, 3) ascending
    radius = 0.5 * np.hypot(extents[:, 0], extents[:, 2])  # (nf,) half diagonal [m]
    slowest = int(np.argmax(radius))
    who, r_max = f"block {model.block_names[int(free[slowest])]!r}", float(radius[slowest])
    if free.size > 1 and g > 0.0:
        # The free blocks rocking as one body (a discretised wall): its thickness along the
        # rocking direction and its height, at the start.
        world = _world_vertices(m.vertex_local, start, model.position0, model.quaternion0, free)
        up = -m.gravity / g
        d = np.cross(model.rocking_axis, up)
        r_body = 0.5 * math.hypot(float(np.ptp(world @ d)), float(np.ptp(world @ up)))
        if r_body > r_max:
            who, r_max = "the free blocks rocking as one body", r_body
    p = math.sqrt(0.75 * g / r_max) if g > 0.0 else 0.0
    if g > 0.0 and damping.alpha > 2.0 * p:
        warn_user(
            f"damping.alpha = {damping.alpha:g} 1/s over-damps the rocking of {who}: "
            f"it is above 2 p = {2.0 * p:.3g} 1/s, critical for its rocking frequency p = sqrt(3 g / 4 R) = {p:.3g} rad/s "
            f"(R = {r_max:.3g} m), and velocities decay within 1/alpha = {1.0 / damping.alpha:.3g} s; the "
            "paper's MP values are 0.05 to 1 1/s (alpha = 22.4 beta + 0.05)")
    beta = damping.beta
    if isinstance(beta, str):
        return
    groups = m.block_group[free]
    softest = np.array([float(np.min(m.mat_kn[gr][m.mat_kn[gr] > 0.0])) if np.any(m.mat_kn[gr] > 0.0) else np.inf for gr in groups])
    omega = np.sqrt(softest * extents[:, 0] * extents[:, 1] / m.block_mass[free])
    k = int(np.argmin(omega))
    critical = 2.0 / float(omega[k])
    undamped = beta == 0.0 and damping.alpha == 0.0 and damping.local == 0.0 and not np.any(m.mat_beta > 0.0)  # joints' own beta too
    if undamped and g > 0.0 and math.isfinite(critical):
        warn_user(
            "no damping (alpha = beta = 0): the joints' elastic vibration, started as gravity loads them, never "
            "decays; a block held by friction near its limit (on a slope, in a wedge) creeps at every cycle (1 mm/s "
            "on a 20 deg slope at a 30 deg friction angle) and sliding outruns Coulomb's law (by about 0.007 g "
            "there: 67 % of the acceleration 0.5 deg past the friction angle, 3 % at 10 deg past); a small "
            f"SP damping removes both, e.g. damping.beta = {UNDAMPED_HINT * critical:.2g} s ({UNDAMPED_HINT:.0%} of "
            f"critical on the slowest impact){'' if SETTLING.get() else SETTLE_HINT}")
        return
    if not beta > 0.0:
        return
    if beta > OVERDAMPED_BETA * critical:
        warn_user(
            f"damping.beta = {beta:g} s is {beta / critical:.3g} times the critical value 2 / omega = {critical:.3g} s "
            f"of the slowest impact (block {model.block_names[int(free[k])]!r} on its smallest face, omega = "
            f"{float(omega[k]):.4g} rad/s): every impact is over-damped, blocks settle into their joints over about "
            f"beta seconds; DeJong's rule (paper §2.2, rockdem advise) gives a beta of the order of the critical one, "
            f"damping.beta = \"critical\" each joint's own")


def _warn_implausible_units(blocks: Sequence, mats: dict[tuple[str, str], JointMaterial], size: float) -> None:
    """Warn about a density or a joint stiffness that looks given in t/m3 or MPa (SI is expected),
    a density heavier than any building material, and a friction angle that looks like a friction
    coefficient.

    The joint stiffness is compared as the modulus it implies over the smallest free block
    dimension ``size`` [m] (kn = E / l, paper Eq. 12).
    """
    for blk in blocks:
        if blk.driven is False and blk.density < PLAUSIBLE_DENSITY:
            warn_user(
                f"block {blk.name!r}: density {blk.density:g} kg/m^3 is lighter than any masonry "
                f"(1500-2500 kg/m^3); if it is in t/m3, give it x 1000 (SI units: kg/m^3)")
            break
        if blk.driven is False and blk.density > HEAVIEST_DENSITY:
            warn_user(
                f"block {blk.name!r}: density {blk.density:g} kg/m^3 is heavier than any building material "
                f"(masonry 1500-2500 kg/m^3, steel 7850); check its units (SI: kg/m^3)")
            break
    for (ga, gb), mat in mats.items():
        for label, angle in (("friction_angle", mat.friction_angle), ("residual_friction_angle", mat.residual_friction_angle)):
            if angle is not None and 0.0 < angle < PLAUSIBLE_FRICTION_ANGLE:
                warn_user(
                    f"joint {ga!r}-{gb!r}: {label} = {angle:g} deg is almost frictionless; if {angle:g} is a friction "
                    f"coefficient mu, give the angle atan(mu) = {math.degrees(math.atan(angle)):.3g} deg")
                break
    for (ga, gb), mat in mats.items():
        modulus = mat.kn * size
        if modulus < PLAUSIBLE_MODULUS:
            warn_user(
                f"joint {ga!r}-{gb!r}: kn = {mat.kn:g} N/m^3 implies a youngs_modulus of about kn x {size:g} m = "
                f"{modulus:g} Pa, below 1 MPa; moduli are in Pa (1.8 GPa is 1.8e9), not MPa")
            break
        if modulus > STIFFEST_MODULUS:
            warn_user(
                f"joint {ga!r}-{gb!r}: kn = {mat.kn:g} N/m^3 implies a youngs_modulus of about kn x {size:g} m = "
                f"{modulus:g} Pa, stiffer than any material (steel 2e11 Pa, masonry 1e9 to 1e10); its overlaps come "
                "near the round-off of the blocks' positions, and a run may stop for energy created at rest; check "
                "its units (Pa/m)")
            break

