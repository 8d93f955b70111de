"""Camera and depth sensors rendered offscreen (MUJOCO_GL=egl) against a pinhole projection.

MuJoCo picks its GL backend at import, so the rendering runs in a child Python with
MUJOCO_GL=egl; without an EGL here the test skips saying so (CI installs Mesa's EGL).
Oracle: a red box 2 m ahead and 0.3 m to the left of a camera with horizontal field of view
1.0 rad projects, by the pinhole model (f = (W/2)/tan(hfov/2) px), to a known pixel rectangle;
a depth camera reads the distance from the camera to the box's near face along its view axis.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from camera_models import BOX, CLIPS, POST, SCENE, H, W, projection, red
from models import write_urdf

CHILD = (
    """
import json, sys
import mujoco, numpy as np
from twin_cli.sensors import SensorSuite
from twin_cli.world import World, WorldSettings
try:
    mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8).close()
except Exception as exc:
    print(json.dumps({"no_gl": str(exc).splitlines()[0]})); sys.exit(0)
post, box = sys.argv[1], sys.argv[2]
"""
    + SCENE
    + """
readings = SensorSuite(world, "post").read()
rgb = np.frombuffer(readings["cam"].data, np.uint8).reshape(HEIGHT, WIDTH, 3)
depth = np.frombuffer(readings["depth"].data, np.float32).reshape(HEIGHT, WIDTH)
def image(reading):
    if reading.encoding == "32FC1":
        return np.frombuffer(reading.data, np.float32).reshape(HEIGHT, WIDTH).tolist()
    return np.frombuffer(reading.data, np.uint8).reshape(HEIGHT, WIDTH, 3).tolist()
print(json.dumps({"rgb": rgb.tolist(), "depth": depth.tolist(),
                  "encodings": [readings["cam"].encoding, readings["depth"].encoding],
                  "clipped": {name: image(r) for name, r in readings.items()}}))
""".replace("HEIGHT", str(H)).replace("WIDTH", str(W))
)


@pytest.fixture(scope="module")
def images(tmp_path_factory) -> dict:
    post = write_urdf(tmp_path_factory.mktemp("cam"), POST, "campost.urdf")
    env = {**os.environ, "MUJOCO_GL": "egl"}
    command = [sys.executable, "-c", CHILD, str(post), json.dumps(BOX)]
    done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.strip().splitlines()[-1])
    if "no_gl" in out:
        pytest.skip(f"no offscreen EGL here ({out['no_gl']}); install libegl-mesa0")
    return out


def test_camera_sees_the_red_box_where_the_pinhole_projection_puts_it(images) -> None:
    rgb = np.array(images["rgb"], np.float64)
    assert images["encodings"] == ["rgb8", "32FC1"]
    u, v, half = projection()
    red = (rgb[..., 0] > 2 * rgb[..., 1] + 20) & (rgb[..., 0] > 2 * rgb[..., 2] + 20)
    rows, cols = np.nonzero(red)
    assert len(cols), "the box is in view"
    # The red region's centre and extent match the projection within 1.5 px (pixel rounding,
    # and the box's side faces, seen obliquely, add under 1 px here).
    assert cols.mean() == pytest.approx(u - 0.5, abs=1.5), (cols.mean(), u)
    assert rows.mean() == pytest.approx(v - 0.5, abs=1.5), (rows.mean(), v)
    assert cols.max() - cols.min() + 1 == pytest.approx(2 * half, abs=2.0)
    assert not red[:, W // 2 :].any(), "nothing red in the right half (the box is to the left)"


def test_depth_camera_reads_the_distance_to_the_near_face(images) -> None:
    depth = np.array(images["depth"])
    u, v, _ = projection()
    x, _, _, h = BOX
    centre = depth[int(v), int(u)]
    assert centre == pytest.approx(x - h, abs=0.01), "metres along the view axis to the face"
    assert depth[int(v), 2] > 10.0, "nothing to the right within range: far background"


def test_depth_beyond_the_far_clip_is_inf_and_within_it_the_box_reads_its_distance(
    images,
) -> None:
    u, v, _ = projection()
    x, _, _, h = BOX
    # JSON carries ±inf as ±Infinity; json.loads reads them back as floats.
    short = np.array(images["clipped"]["depth_short"])
    assert np.isposinf(short).all(), "far 1.5 m < 1.9 m to the box: nothing within range"
    long = np.array(images["clipped"]["depth_long"])
    assert long[int(v), int(u)] == pytest.approx(x - h, abs=0.01), "far 3 m: the box at 1.9 m"
    assert np.isposinf(long[int(v), 2]), "background beyond far reads +inf (REP 117)"
    assert np.isfinite(long).sum() > 20, "the box's pixels are finite"


def test_a_box_nearer_than_the_near_clip_reads_minus_inf(images) -> None:
    u, v, _ = projection()
    near = np.array(images["clipped"]["depth_near"])
    assert np.isneginf(near[int(v), int(u)]), "box 1.9 m ahead, near plane 2.5 m: −inf"
    assert not np.isfinite(near).any(), "nothing between 2.5 m and 10 m in view"
    assert np.isposinf(near[int(v), 2])


def test_colour_cameras_do_not_draw_what_lies_outside_their_clip_planes(images) -> None:
    assert red(np.array(images["rgb"], np.float64)).sum() > 20, "50 m far plane: the box shows"
    for name in ("cam_short", "cam_near"):
        rgb = np.array(images["clipped"][name], np.float64)
        assert not red(rgb).any(), f"{name}: the box at 1.9 m is outside {CLIPS[name][1:]} m"
