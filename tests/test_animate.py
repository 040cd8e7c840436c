"""Tests of rockdem.animate: a low-resolution GIF of the built-in example (as CI produces), the
2D side view, the magnified kinematics, the frame selection and the clear MP4 error without ffmpeg.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rockdem.animate import _failed_points, _snapshot, _title, animate, frame_indices, playback, posed_vertices
from rockdem.cli import main
from rockdem.kernels.rotation import quats_to_matrices, rotation_vector
from rockdem.plots import world_vertices
from rockdem.results import save
from viz_cases import example_result, wall_result

LOW = {"size": (2.0, 1.5), "dpi": 80.0, "max_frames": 8}  # 160 x 120 pixels


def _frames(path) -> list[np.ndarray]:
    with Image.open(path) as im:
        out = []
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB"), dtype=float))
    return out


def test_gif_of_builtin_example_at_low_resolution(tmp_path):
    ds = example_result()
    p = animate(ds, tmp_path / "example.gif", fps=10.0, view="iso", **LOW)
    frames = _frames(p)
    assert len(frames) == len(frame_indices(ds.time.values, fps=10.0, speed=1.0, max_frames=8))
    assert frames[0].shape == (120, 160, 3)
    # The block rocks: the first and a later frame differ.
    assert np.abs(frames[0] - frames[len(frames) // 2]).mean() > 0.5


def test_cli_side_view_of_discretised_wall(tmp_path):
    path = save(wall_result(), tmp_path / "wall.nc")
    out = tmp_path / "wall.gif"
    argv = ["animate", str(path), "-o", str(out), "--view", "side", "--magnify", "5", "--size", "160", "120"]
    assert main(argv + ["--max-frames", "5"]) == 0
    assert len(_frames(out)) == 5


def test_mp4_without_a_system_ffmpeg(tmp_path, monkeypatch):
    # imageio-ffmpeg's own binary writes the MP4: no ffmpeg on PATH is needed. Read back (with that
    # binary), the video has every shown frame, the figure's (even) size and the playback rate.
    import imageio_ffmpeg

    monkeypatch.setenv("PATH", str(tmp_path))  # no system ffmpeg can be found
    monkeypatch.delenv("IMAGEIO_FFMPEG_EXE", raising=False)
    ds = example_result()
    p = animate(ds, tmp_path / "x.mp4", fps=10.0, **LOW)
    reader = imageio_ffmpeg.read_frames(str(p))
    meta = reader.__next__()
    n = sum(1 for _ in reader)
    play = playback(ds.time.values, fps=10.0, speed=1.0, max_frames=8)  # 2 s in 8 frames: 5 fps, sped up
    assert n == len(play.frames) == 8
    assert tuple(meta["size"]) == (160, 120) and meta["fps"] == pytest.approx(play.fps) == 5.0


def test_mp4_without_imageio_ffmpeg_is_a_clear_error(tmp_path, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_imageio_ffmpeg(name, *args, **kwargs):
        if name == "imageio_ffmpeg":
            raise ImportError(name)
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_imageio_ffmpeg)
    with pytest.raises(ValueError, match="imageio-ffmpeg.*gif"):
        animate(example_result(), tmp_path / "x.mp4", **LOW)
    assert not (tmp_path / "x.mp4").exists()
    path = save(example_result(), tmp_path / "ex.nc")
    assert main(["animate", str(path), "-o", str(tmp_path / "x.mp4")]) == 2


def test_playback_keeps_real_time_or_says_the_speed_up():
    # 44 s recorded every 10 ms: 20 fps would need 881 frames. Capped at 300, the rate drops to
    # 299 / 44 s = 6.8 fps and the playback stays real time: frame k shows t = k / fps.
    t = np.linspace(0.0, 44.0, 4401)
    play = playback(t, fps=20.0, speed=1.0, max_frames=300)
    assert play.speed == 1.0 and not play.sped_up and len(play.frames) <= 300
    np.testing.assert_allclose(t[play.frames], np.arange(len(play.frames)) / play.fps, atol=0.005)
    # a GIF holds whole 1/100 s delays: 15 cs per frame, 6.67 fps, still real time
    gif = playback(t, fps=20.0, speed=1.0, max_frames=300, gif=True)
    assert gif.fps == pytest.approx(100 / 15) and gif.speed == 1.0 and len(gif.frames) <= 300
    np.testing.assert_allclose(t[gif.frames], 0.15 * np.arange(len(gif.frames)), atol=0.005)
    # capped at 100 frames: 5 fps is the floor, so the playback speeds up to 44 x 5 / 99 and says so
    fast = playback(t, fps=20.0, speed=1.0, max_frames=100)
    assert fast.fps == 5.0 and fast.speed == pytest.approx(44 * 5 / 99) and fast.sped_up
    assert "2.22x real time" in fast.note() and len(fast.frames) == 100
    assert "(2.2x real time)" in _title(example_result(), 10, 1.0, fast.speed)


def test_gif_frame_delay_is_the_playback_rate(tmp_path):
    # 2 s at 20 fps: 41 frames of 50 ms each, playing in real time
    p = animate(example_result(), tmp_path / "d.gif", fps=20.0, **{**LOW, "max_frames": 50})
    with Image.open(p) as im:
        assert im.info["duration"] == 50 and im.n_frames == 41


def test_unknown_view_and_suffix_are_refused(tmp_path):
    with pytest.raises(ValueError, match="view 'sky' unknown"):
        animate(example_result(), tmp_path / "x.gif", view="sky", **LOW)
    with pytest.raises(ValueError, match=r"\.gif or \.mp4"):
        animate(example_result(), tmp_path / "x.avi", **LOW)


def test_magnified_pose_scales_displacement_and_rotation_since_start():
    ds = example_result()
    f, k = 60, 3.0
    v1, _, _ = posed_vertices(ds, f, 1.0)
    np.testing.assert_allclose(v1, world_vertices(ds, f), atol=1e-12)
    _, r, x = posed_vertices(ds, f, k)
    x0, xt = ds.block_position.values[0], ds.block_position.values[f]
    np.testing.assert_allclose(x - x0, k * (xt - x0), atol=1e-12)
    r0 = quats_to_matrices(ds.block_quaternion.values[0])
    rt = quats_to_matrices(ds.block_quaternion.values[f])
    rv = rotation_vector(np.einsum("bij,bkj->bik", rt, r0))
    rv_mag = rotation_vector(np.einsum("bij,bkj->bik", r, r0))
    np.testing.assert_allclose(rv_mag, k * rv, atol=1e-9)


def test_frame_indices_respect_the_cap_and_playback_rate():
    t = np.linspace(0.0, 4.0, 401)
    idx = frame_indices(t, fps=20.0, speed=1.0, max_frames=1000)
    assert len(idx) == 81 and np.all(np.diff(idx) > 0)  # one frame per 0.05 s of simulation
    assert len(frame_indices(t, fps=20.0, speed=1.0, max_frames=10)) <= 10
    with pytest.raises(ValueError, match="fps"):
        frame_indices(t, fps=0.0, speed=1.0, max_frames=10)


def test_failed_points_come_from_the_latest_snapshot():
    ds = wall_result()
    f = ds.sizes["time"] - 1
    _, r, x = posed_vertices(ds, f)
    pts = _failed_points(ds, float(ds.time.values[f]), r, x)
    last = ds.point_failed.values[_snapshot(ds, float(ds.time.values[f]))]
    assert len(pts[1]) == np.count_nonzero(last == 1) > 0
    assert len(pts[2]) == np.count_nonzero(last == 2)
