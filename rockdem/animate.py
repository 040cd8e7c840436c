"""Animations of the recorded block motion: GIF (Pillow) or MP4 (H.264 through imageio-ffmpeg's
own ffmpeg binary, installed with rockdem by pip: no system ffmpeg needed).

Blocks are drawn from their geometry and recorded poses (world vertex = R(q) v_local + x), faces
shaded by a fixed light, driven blocks in grey. Displacements and rotations since t = 0 can be
magnified. Sub-contacts that failed in tension (orange) or shear (red) are drawn from the contact
snapshots (``simulate(..., contact_interval=...)``); the failure counts are in every frame's title.
``view="side"`` draws a 2D side view (projection on the plane normal to the rocking axis) for
planar rocking; other views are 3D.

Playback keeps real time by default (``speed`` = 1 simulated second per second): when the run
needs more than ``max_frames`` frames at ``fps``, the frame rate is lowered (down to
:data:`MIN_FPS`), and only then is the playback sped up, which every frame's title then states
("2.2x real time", as the CLI does). GIF frame delays are whole hundredths of a second: the frame
rate is rounded to one (20 fps = 5/100 s) and the frames chosen for it, so that timing stays exact.

The CLI is ``rockdem animate RESULT.nc -o OUT.gif|mp4``.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
import xarray as xr
from matplotlib import colormaps, rc_context
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .cli import dots_per_inch, integer_at_least, output_file, positive_float, positive_int
from .kernels.rotation import axis_angle_matrix, quats_to_matrices, rotation_vector
from .plots import STYLE, Result, load_result, read_result_file, rocking_direction

__all__ = ["VIEWS", "MIN_FPS", "ANIMATION_STYLE", "Playback", "playback", "frame_indices", "posed_vertices",
           "render_frames", "animate", "register_cli"]

MIN_FPS = 5.0
"""Lowest frame rate used to keep real time before the playback is sped up [frames/s]."""

ANIMATION_STYLE: dict[str, object] = {**STYLE, "font.size": 10.0, "axes.titlesize": 12.0, "axes.labelsize": 10.0}
"""Matplotlib settings of the animation frames (larger text than the static plots)."""

VIEWS: dict[str, tuple[float, float] | None] = {
    "iso": (20.0, -60.0),
    "front": (5.0, -90.0),
    "top": (89.0, -90.0),
    "side": None,  # 2D projection on the plane normal to the rocking axis
}
"""Named viewpoints: (elevation, azimuth) [deg] of the 3D camera, or None for the 2D side view."""

_LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
_FAIL_COLORS = {1: ("tab:orange", "failed in tension"), 2: ("tab:red", "failed in shear")}


@dataclass(frozen=True)
class Playback:
    """How a run is played back.

    Attributes:
        frames: recorded frame indices shown, in order.
        fps: frames per second of playback.
        speed: simulated seconds per second of playback (1: real time).
        requested_speed: the speed asked for; ``speed`` exceeds it when ``max_frames`` forced it.
    """

    frames: np.ndarray
    fps: float
    speed: float
    requested_speed: float

    @property
    def sped_up(self) -> bool:
        """Whether the playback is faster than asked for (the frame cap forced it)."""
        return self.speed > self.requested_speed * (1.0 + 1e-9)

    def note(self) -> str:
        """One line: frames, rate and speed relative to real time."""
        rate = "real time" if abs(self.speed - 1.0) < 1e-9 else f"{self.speed:.3g}x real time"
        text = f"{self.frames.size} frames at {self.fps:.3g} fps, {rate}"
        if self.sped_up:
            text += f" (sped up from {self.requested_speed:g}x to fit max_frames: raise it to slow the playback)"
        return text


def _gif_rate(fps: float, gif: bool) -> float:
    """The playback rate a GIF can hold: 100 / (whole hundredths of a second, at least 2)."""
    return 100.0 / max(2, round(100.0 / fps)) if gif else fps


def playback(time: np.ndarray, *, fps: float, speed: float, max_frames: int, gif: bool = False) -> Playback:
    """The frames to show at ``speed`` x real time and ``fps``, at most ``max_frames`` of them:
    the frame rate drops (to :data:`MIN_FPS` at least) before the speed rises. Each shown frame is
    the recorded one nearest its playback time; ``gif`` rounds the rate to whole 1/100 s delays."""
    if not (fps > 0 and speed > 0 and max_frames >= 1):
        raise ValueError("fps, speed and max_frames must be positive; e.g. --fps 20 --speed 1 --max-frames 300")
    if time.size == 0:
        raise ValueError("the result has no recorded frame to animate")
    span = float(time[-1] - time[0])
    rate, pace = _gif_rate(fps, gif), speed
    if span > 0 and span * rate / pace + 1 > max_frames:
        low = max(min(MIN_FPS, fps), (max_frames - 1) * pace / span)
        rate = 100.0 / math.ceil(100.0 / low) if gif else low
        if span * rate / pace + 1 > max_frames + 1e-9:
            pace = span * rate / max(max_frames - 1, 1)
    if span <= 0:
        return Playback(np.array([0]), rate, pace, speed)
    step = pace / rate
    slack = 0.5 * float(np.median(np.diff(time))) if time.size > 1 else 0.0  # the last frame's time jitter
    targets = time[0] + step * np.arange(min(int(math.floor((span + slack) / step)) + 1, max_frames))
    right = np.clip(np.searchsorted(time, targets), 1, time.size - 1)
    nearest = np.where(np.abs(time[right - 1] - targets) <= np.abs(time[right] - targets), right - 1, right)
    return Playback(np.unique(nearest)[:max_frames], rate, pace, speed)


def frame_indices(time: np.ndarray, *, fps: float, speed: float, max_frames: int) -> np.ndarray:
    """Recorded frames to show (:func:`playback`'s frames)."""
    return playback(time, fps=fps, speed=speed, max_frames=max_frames).frames


def _magnified_rotations(q: np.ndarray, q0: np.ndarray, magnify: float) -> np.ndarray:
    """R(t) with the rotation since t = 0 scaled by ``magnify``: exp(k rv(R R0^T)) R0, (nb, 3, 3)."""
    r, r0 = quats_to_matrices(q), quats_to_matrices(q0)
    if magnify == 1.0:
        return r
    rv = rotation_vector(np.einsum("bij,bkj->bik", r, r0)) * magnify
    out = np.empty_like(r)
    for b in range(r.shape[0]):
        ang = float(np.linalg.norm(rv[b]))
        out[b] = (axis_angle_matrix(rv[b] / ang, ang) if ang > 1e-15 else np.eye(3)) @ r0[b]
    return out


def posed_vertices(ds: xr.Dataset, frame: int, magnify: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World vertices (nv, 3) [m] at a frame with magnified motion, and the poses used.

    Returns:
        vertices (nv, 3), rotations (nb, 3, 3), positions (nb, 3).
    """
    x0 = ds.block_position.values[0]
    x = x0 + magnify * (ds.block_position.values[frame] - x0)
    r = _magnified_rotations(ds.block_quaternion.values[frame], ds.block_quaternion.values[0], magnify)
    start = ds.block_vertex_start.values
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    v = np.einsum("vij,vj->vi", r[owner], ds.vertex_local.values) + x[owner]
    return v, r, x


def _faces(ds: xr.Dataset) -> tuple[list[np.ndarray], np.ndarray]:
    """Vertex ids of every face and the block owning it."""
    fv, fs, bfs = ds.face_vertex.values, ds.face_corner_start.values, ds.block_face_start.values
    faces = [fv[fs[f] : fs[f + 1]] for f in range(len(fs) - 1)]
    owner = np.repeat(np.arange(len(bfs) - 1), np.diff(bfs))
    return faces, owner


def _block_colors(ds: xr.Dataset) -> np.ndarray:
    """RGB (nb, 3): one colour per group for free blocks, grey for driven ones."""
    groups = [str(g) for g in ds.block_group.values]
    names = sorted(set(groups))
    cmap = colormaps["tab10"]
    col = np.array([cmap(names.index(g) % 10)[:3] for g in groups])
    col[~ds.block_free.values] = (0.62, 0.62, 0.62)
    return col


def _bounds(ds: xr.Dataset, frames: np.ndarray, magnify: float) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned view box (lo, hi) [m] around the free blocks over the shown frames."""
    start = ds.block_vertex_start.values
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    free = ds.block_free.values[owner] if ds.block_free.values.any() else np.ones(owner.size, bool)
    pts = np.concatenate([posed_vertices(ds, int(f), magnify)[0][free] for f in frames])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.15 * float(np.max(hi - lo)) + 1e-3
    return lo - pad, hi + pad


def _snapshot(ds: xr.Dataset, t: float) -> int | None:
    """Index of the latest contact snapshot at or before time t, or None without snapshots."""
    if "contact_time" not in ds.coords or ds.sizes["contact_time"] == 0:
        return None
    k = int(np.searchsorted(ds.contact_time.values, t + 1e-9, side="right")) - 1
    return max(k, 0)


def _failed_points(ds: xr.Dataset, t: float, r: np.ndarray, x: np.ndarray) -> dict[int, np.ndarray]:
    """World positions of points failed in tension (1) and shear (2) at time t, on the drawn poses."""
    k = _snapshot(ds, t)
    if k is None or "point_local" not in ds:
        return {}
    failed = ds.point_failed.values[k]
    pb = ds.point_block.values
    out = {}
    for mode in _FAIL_COLORS:
        sel = np.flatnonzero(failed == mode)
        out[mode] = np.einsum("pij,pj->pi", r[pb[sel]], ds.point_local.values[sel]) + x[pb[sel]]
    return out


def _title(ds: xr.Dataset, frame: int, magnify: float, speed: float = 1.0) -> str:
    t = float(ds.time.values[frame])
    text = f"t = {t:.2f} s"
    if abs(speed - 1.0) > 1e-9:
        text += f" ({speed:.2g}x real time)"
    if magnify != 1.0:
        text += f", motion x{magnify:g}"
    ften, fsh = int(ds.contacts_failed_tension.values[frame]), int(ds.contacts_failed_shear.values[frame])
    if ften or fsh:
        text += f"; failed: {ften} tension, {fsh} shear"
    return text


def _draw_3d(ax, ds, frame, magnify, view, lo, hi, faces, owner, colors) -> None:  # type: ignore[no-untyped-def]
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    v, r, x = posed_vertices(ds, frame, magnify)
    free_v = np.repeat(ds.block_free.values, np.diff(ds.block_vertex_start.values))
    v = np.where(free_v[:, None], v, np.clip(v, lo, hi))  # cut the (large) foundation to the view box
    polys, shades = [], []
    for f, ids in enumerate(faces):
        p = v[ids]
        n = np.cross(p[1] - p[0], p[2] - p[0])
        n = n / (np.linalg.norm(n) + 1e-300)
        polys.append(p)
        shades.append(colors[owner[f]] * (0.45 + 0.55 * max(0.0, float(n @ _LIGHT))))
    ax.computed_zorder = False  # failed points stay visible in front of the faces (x-ray overlay)
    ax.add_collection3d(Poly3DCollection(polys, facecolors=shades, edgecolors="k", linewidths=0.3, zorder=1))
    for mode, pts in _failed_points(ds, float(ds.time.values[frame]), r, x).items():
        if len(pts):
            c, lab = _FAIL_COLORS[mode]
            ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], color=c, s=10, depthshade=False, label=lab, zorder=3)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_proj_type("ortho")
    ax.locator_params(nbins=4)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")


def _draw_side(ax, ds, frame, magnify, lo, hi, colors) -> None:  # type: ignore[no-untyped-def]
    from matplotlib.patches import Polygon
    from scipy.spatial import ConvexHull

    d = rocking_direction(ds)
    up = np.cross(d, np.asarray(ds.attrs.get("rocking_axis", (0.0, 1.0, 0.0)), dtype=float))
    v, r, x = posed_vertices(ds, frame, magnify)
    start = ds.block_vertex_start.values
    for b in range(len(start) - 1):
        p2 = np.stack([v[start[b] : start[b + 1]] @ d, v[start[b] : start[b + 1]] @ up], axis=1)
        hull = p2[ConvexHull(p2).vertices]  # a convex block projects onto the hull of its vertices
        ax.add_patch(Polygon(hull, closed=True, facecolor=colors[b], edgecolor="k", lw=0.5))
    for mode, pts in _failed_points(ds, float(ds.time.values[frame]), r, x).items():
        if len(pts):
            c, lab = _FAIL_COLORS[mode]
            ax.plot(pts @ d, pts @ up, "o", color=c, ms=3, label=lab)
    corners = np.array([[lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]]])
    h = np.sort(np.stack([corners @ d, corners @ up], axis=1), axis=0)
    ax.set_xlim(h[0, 0], h[1, 0])
    ax.set_ylim(h[0, 1], h[1, 1])
    ax.set_aspect("equal")
    ax.set_xlabel("horizontal, rocking direction [m]")
    ax.set_ylabel("vertical [m]")


def render_frames(
    result: Result,
    *,
    view: str | tuple[float, float] = "iso",
    magnify: float = 1.0,
    fps: float = 20.0,
    speed: float = 1.0,
    max_frames: int = 300,
    size: tuple[float, float] = (6.4, 4.8),
    dpi: float = 100.0,
    gif: bool = False,
) -> list[np.ndarray]:
    """Render the shown frames as RGB images (H, W, 3) uint8.

    Args:
        result: a result or its NetCDF path.
        view: a name of :data:`VIEWS` or (elevation, azimuth) [deg].
        magnify: factor on displacements and rotations since t = 0 [-].
        fps: frames per second of playback; speed: simulated seconds per playback second.
        max_frames: cap on the number of frames (see :func:`playback`: the rate drops, then the
            speed rises to fit, said in the titles).
        size: figure size [in]; dpi: pixels per inch (default 640 x 480 pixels).
        gif: frame rate rounded to whole 1/100 s delays (as a GIF stores them).
    """
    ds = load_result(result)
    if isinstance(view, str):
        if view not in VIEWS:
            raise ValueError(f"view {view!r} unknown; use one of {sorted(VIEWS)} or (elevation, azimuth) in degrees")
        cam = VIEWS[view]
    else:
        cam = (float(view[0]), float(view[1]))
    if not (np.isfinite(magnify) and magnify > 0):
        raise ValueError(f"magnify must be a positive factor, got {magnify!r}")
    play = playback(ds.time.values, fps=fps, speed=speed, max_frames=max_frames, gif=gif)
    frames = play.frames
    lo, hi = _bounds(ds, frames, magnify)
    faces, owner = _faces(ds)
    colors = _block_colors(ds)
    images = []
    with rc_context(ANIMATION_STYLE):
        for f in frames:
            fig = Figure(figsize=size, dpi=dpi)
            canvas = FigureCanvasAgg(fig)
            if cam is None:
                ax = fig.add_subplot()
                _draw_side(ax, ds, int(f), magnify, lo, hi, colors)
            else:
                ax = fig.add_subplot(projection="3d")
                _draw_3d(ax, ds, int(f), magnify, cam, lo, hi, faces, owner, colors)
            ax.set_title(_title(ds, int(f), magnify, play.speed))
            if ax.get_legend_handles_labels()[0]:
                ax.legend(loc="upper right", fontsize=9)
            canvas.draw()
            images.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    return images


def _ffmpeg() -> str:
    """The ffmpeg binary of imageio-ffmpeg (a pip dependency of rockdem; ``IMAGEIO_FFMPEG_EXE``
    chooses another)."""
    try:
        import imageio_ffmpeg
    except ImportError:
        raise ValueError("output .mp4 needs the imageio-ffmpeg package (pip install imageio-ffmpeg, a rockdem "
                         "dependency: reinstall rockdem) or write a .gif instead") from None
    try:
        return str(imageio_ffmpeg.get_ffmpeg_exe())
    except RuntimeError as exc:
        raise ValueError(f"output .mp4: imageio-ffmpeg found no ffmpeg binary ({exc}); write a .gif instead") from None


def _write_gif(images: Sequence[np.ndarray], path: Path, fps: float) -> None:
    from PIL import Image

    frames = [Image.fromarray(im).convert("P", palette=Image.Palette.ADAPTIVE, colors=255) for im in images]
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=10 * round(100.0 / fps), loop=0)


def _write_mp4(images: Sequence[np.ndarray], path: Path, fps: float) -> None:
    import imageio_ffmpeg

    h, w = images[0].shape[:2]
    pad = ((0, h % 2), (0, w % 2), (0, 0))  # H.264 in yuv420p needs even sizes
    writer = imageio_ffmpeg.write_frames(
        str(path), (w + w % 2, h + h % 2), fps=fps, codec="libx264", pix_fmt_in="rgb24", pix_fmt_out="yuv420p",
        macro_block_size=1, ffmpeg_log_level="error", output_params=["-movflags", "+faststart"],
    )
    try:
        writer.send(None)
        for im in images:
            writer.send(np.ascontiguousarray(np.pad(im, pad, mode="edge")))
        writer.close()
    except (OSError, RuntimeError) as exc:
        raise ValueError(f"ffmpeg failed writing {path}: {exc}") from None


def animate(result: Result, path: str | Path, *, fps: float = 20.0, **options: object) -> Path:
    """Write an animation of the blocks' motion to ``path`` (.gif, or .mp4 through imageio-ffmpeg).

    Args:
        result: a result or its NetCDF path.
        path: output file; the suffix chooses the format.
        fps: frames per second of playback.
        **options: passed to :func:`render_frames` (view, magnify, speed, max_frames, size, dpi).

    Returns:
        The path written.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"output {p}: the suffix must be .gif or .mp4")
    if suffix == ".mp4":
        _ffmpeg()  # fail before rendering
    gif = suffix == ".gif"
    images = render_frames(result, fps=fps, gif=gif, **options)  # type: ignore[arg-type]
    speed, max_frames = options.get("speed", 1.0), options.get("max_frames", 300)
    play = playback(load_result(result).time.values, fps=fps, speed=float(speed),  # type: ignore[arg-type]
                    max_frames=int(max_frames), gif=gif)  # type: ignore[call-overload]
    p.parent.mkdir(parents=True, exist_ok=True)
    if gif:
        _write_gif(images, p, play.fps)
    else:
        _write_mp4(images, p, play.fps)
    return p


def _view_arg(text: str) -> str | tuple[float, float]:
    if text in VIEWS:
        return text
    try:
        elev, azim = (float(v) for v in text.split(","))
    except ValueError:
        elev = azim = math.nan
    if not (math.isfinite(elev) and math.isfinite(azim) and abs(elev) <= 90.0 and abs(azim) <= 360.0):
        raise argparse.ArgumentTypeError(f"--view: one of {sorted(VIEWS)} or ELEV,AZIM in degrees (|ELEV| <= 90, "
                                         f"|AZIM| <= 360), got {text!r}")
    return elev, azim


MAX_FRAME_PIXELS = 4096
"""Largest width or height of an animation frame [pixels] (4K video is 3840 x 2160)."""


def _frame_size(text: str) -> int:
    """--size W H: each between 16 and MAX_FRAME_PIXELS pixels."""
    v = integer_at_least(16)(text)
    if v > MAX_FRAME_PIXELS:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_FRAME_PIXELS} pixels, got {text!r}")
    return v


def _animate(args: argparse.Namespace) -> int:
    out = Path(args.output) if args.output else Path(args.result).with_suffix(".gif")
    if out.is_dir():
        raise ValueError(f"-o {out} is a folder; give the animation file (.gif or .mp4)")
    if out.suffix.lower() not in (".gif", ".mp4"):
        raise ValueError(f"-o {out}: the suffix must be .gif or .mp4")
    output_file(out, "-o")
    w, h = args.size
    ds = read_result_file(args.result)
    p = animate(
        ds,
        out,
        fps=args.fps,
        view=args.view,
        magnify=args.magnify,
        speed=args.speed,
        max_frames=args.max_frames,
        size=(w / args.dpi, h / args.dpi),
        dpi=args.dpi,
    )
    play = playback(ds.time.values, fps=args.fps, speed=args.speed, max_frames=args.max_frames,
                    gif=out.suffix.lower() == ".gif")
    print(f"rockdem animate: wrote {p}: {play.note()}")
    return 0


def register_cli(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``animate`` sub-command."""
    p = subparsers.add_parser("animate", help="animate the blocks of a result (GIF or MP4, real time by default)")
    p.add_argument("result", metavar="RESULT.nc", help="a result written by rockdem run")
    p.add_argument("-o", "--output", help="output .gif or .mp4 (default RESULT.gif)")
    p.add_argument("--view", type=_view_arg, default="iso", help=f"{', '.join(VIEWS)} or ELEV,AZIM [deg] (default iso)")
    p.add_argument("--magnify", type=positive_float, default=1.0, help="factor on displacements and rotations (default 1)")
    p.add_argument("--fps", type=positive_float, default=20.0, help="frames per second (default 20)")
    p.add_argument("--speed", type=positive_float, default=1.0, help="simulated seconds per playback second (default 1)")
    p.add_argument("--max-frames", type=positive_int, default=300,
                   help=f"most frames (default 300): beyond, the rate drops to {MIN_FPS:g} fps, then the playback speeds up (said)")
    p.add_argument("--size", type=_frame_size, nargs=2, default=(640, 480), metavar=("W", "H"), help="pixels (default 640 480)")
    p.add_argument("--dpi", type=dots_per_inch, default=100.0, help="pixels per inch of the text (default 100)")
    p.set_defaults(func=_animate)
