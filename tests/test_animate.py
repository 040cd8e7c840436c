"""Tests of rockdem.animate: a low-resolution GIF of the built-in example (as CI produces), the
2D side view, the magnified kinematics, the frame selection and the clear MP4 error without ffmpeg.
"""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rockdem.animate import _failed_points, _snapshot, animate, frame_indices, posed_vertices
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


def test_mp4_without_ffmpeg_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setattr("rockdem.animate.shutil.which", lambda name: None)
    with pytest.raises(ValueError, match="ffmpeg.*not on PATH.*gif"):
        animate(example_result(), tmp_path / "x.mp4", **LOW)
    assert not (tmp_path / "x.mp4").exists()
    path = save(example_result(), tmp_path / "ex.nc")
    assert main(["animate", str(path), "-o", str(tmp_path / "x.mp4")]) == 2


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
