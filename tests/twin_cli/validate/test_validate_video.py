"""`twin validate --video`: one playable MP4 per physics scenario, read back by another decoder."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from view_helpers import egl_missing

import scenarios

HUMANOID = Path(scenarios.HUMANOID)
FPS = 20  # frames per simulated second (twin_cli.view.video.FPS)
# The two scenarios the test runs and their durations [s] (scenarios/*.toml).
DURATIONS = {"free_fall": 0.5, "zero_gravity": 1.0}


@pytest.mark.skipif(bool(egl_missing()), reason=egl_missing() or "")
def test_validate_video_writes_one_playable_video_per_physics_scenario(tmp_path):
    import imageio_ffmpeg  # its own ffmpeg binary: a decoder independent of PyAV's encoder

    out = tmp_path / "videos"
    proc = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "validate", str(HUMANOID),
         "--only", "gravity", "--only", "zero_gravity", "--video", str(out)],
        capture_output=True, text=True, timeout=300, env=os.environ.copy(),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert sorted(p.name for p in out.iterdir()) == sorted(f"{n}.mp4" for n in DURATIONS)
    for name, duration in DURATIONS.items():
        path = str(out / f"{name}.mp4")
        frames = imageio_ffmpeg.read_frames(path)
        meta = next(frames)
        width, height = meta["size"]
        pictures = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in frames]
        # A frame at t = 0 and one per 1/FPS of simulated time after it.
        expected = 1 + round(duration * FPS)
        assert len(pictures) == expected, f"{name}: {len(pictures)} frames, expected {expected}"
        assert meta["fps"] == pytest.approx(FPS), f"{name}: {meta['fps']} fps"
        assert (width, height) == (320, 240)
        lit = [float((p.max(axis=2) > 60).mean()) for p in pictures]
        assert min(lit) > 0.01, f"{name}: a frame shows no robot (lit fractions {lit})"
    falling = imageio_ffmpeg.read_frames(str(out / "free_fall.mp4"))
    next(falling)
    first, *_, last = (np.frombuffer(f, np.uint8) for f in falling)
    assert np.abs(first.astype(int) - last).mean() > 1.0, "the falling robot does not move"


def test_plots_draw_the_threshold_and_the_markdown_report_embeds_them(tmp_path):
    """The slip plot has its threshold line, free fall its allowed band; the report links both."""
    from PIL import Image

    plots, report = tmp_path / "plots", tmp_path / "report.md"
    proc = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "validate", str(HUMANOID),
         "--only", "gravity", "--only", "friction_standing",
         "--plots", str(plots), "--markdown", str(report)],
        capture_output=True, text=True, timeout=300, env=os.environ.copy(),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    text = report.read_text()
    for name in ("gravity_free_fall.png", "friction_standing_foot_slip.png"):
        assert f"](plots/{name})" in text, f"{name} is not embedded in the report"
        assert (plots / name).is_file()
    slip = np.asarray(Image.open(plots / "friction_standing_foot_slip.png").convert("RGB"))
    red = (slip[..., 0] > 180) & (slip[..., 1] < 100) & (slip[..., 2] < 100)
    rows = np.flatnonzero(red.sum(axis=1) > slip.shape[1] // 5)  # a dotted line: ~30 % red
    assert len(rows), "no red threshold line across the slip plot"
    fall = np.asarray(Image.open(plots / "gravity_free_fall.png").convert("RGB")).astype(int)
    green = (fall[..., 1] > fall[..., 0] + 20) & (fall[..., 1] > fall[..., 2] + 20)
    assert green.sum() > 50, "no allowed band drawn on the free-fall plot"
