"""Camera and depth sensors in a recording: sensor_msgs/Image in the bag, read back by rosbags.

The recording runs in a child Python (MuJoCo picks its GL backend at import): with
MUJOCO_GL=egl the cameras are rendered by the recorder's sensor thread, off the stepping thread;
with GLFW and no display they cannot be, and the recording goes on without them, saying so.
Oracles: the pinhole projection of a red box 2 m ahead (as `test_camera_sensor`), the depth of
its near face, and the sensors' update rates in sim time.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from camera_models import BOX, CAM_Z, HFOV, SCENE, H, W, projection, red
from models import write_urdf
from view_helpers import egl_missing

SECONDS = 0.3  # [s] of sim time recorded at a 1 ms step
CAMERA_HZ, IMU_HZ = 30.0, 100.0
SENSORS = f"""<sensor type="camera" name="cam"><pose>0 0 {CAM_Z} 0 0 0</pose>
    <update_rate>{CAMERA_HZ}</update_rate><camera><horizontal_fov>{HFOV}</horizontal_fov>
    <image><width>{W}</width><height>{H}</height></image></camera></sensor>
  <sensor type="depth" name="depth"><pose>0 0 {CAM_Z} 0 0 0</pose>
    <update_rate>{CAMERA_HZ}</update_rate><camera><horizontal_fov>{HFOV}</horizontal_fov>
    <image><width>{W}</width><height>{H}</height></image></camera></sensor>
  <sensor type="imu" name="imu"><update_rate>{IMU_HZ}</update_rate></sensor>"""
POST = f"""<robot name="campost">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <gazebo><static>true</static></gazebo>
  <gazebo reference="base">{SENSORS}</gazebo>
</robot>"""

CHILD = (
    """
import json, logging, sys
import mujoco
from twin_cli.record import BagRecording
from twin_cli.world import World, WorldSettings
logging.basicConfig(level=logging.WARNING, stream=sys.stderr)
post, box = sys.argv[1], sys.argv[3]
"""
    + SCENE
    + """
recording = BagRecording(world, sys.argv[2], rate=100.0).start()
world.step(int(round(float(sys.argv[4]) / world.model.opt.timestep)))
status = recording.stop()
print(json.dumps({"error": status.error, "dropped": [list(k) for k in recording._feed.dropped]}))
"""
)


def _record(tmp: Path, env: dict) -> tuple[Path, dict, str]:
    post = write_urdf(tmp, POST, "campost.urdf")
    bag = tmp / "cams.mcap"
    command = [sys.executable, "-c", CHILD, str(post), str(bag), json.dumps(BOX), str(SECONDS)]
    done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    return bag, json.loads(done.stdout.strip().splitlines()[-1]), done.stderr


def _messages(bag: Path) -> dict[str, list]:
    from rosbags.highlevel import AnyReader

    out: dict[str, list] = {}
    with AnyReader([bag]) as reader:
        for connection, _, raw in reader.messages():
            message = reader.deserialize(raw, connection.msgtype)
            out.setdefault(connection.topic, []).append((connection.msgtype, message))
    return out


def _stamp(message) -> float:  # noqa: ANN001
    return message.header.stamp.sec + message.header.stamp.nanosec * 1e-9


@pytest.fixture(scope="module")
def egl_bag(tmp_path_factory) -> dict[str, list]:
    if why := egl_missing():
        pytest.skip(why)
    env = {**os.environ, "MUJOCO_GL": "egl"}
    bag, out, _ = _record(tmp_path_factory.mktemp("egl"), env)
    assert out == {"error": None, "dropped": []}
    return _messages(bag)


def test_recorded_images_are_sensor_msgs_image_at_the_camera_rate(egl_bag) -> None:
    for topic, encoding, step in (("cam", "rgb8", 3 * W), ("depth", "32FC1", 4 * W)):
        messages = egl_bag[f"/post/{topic}/image_raw"]
        assert {t for t, _ in messages} == {"sensor_msgs/msg/Image"}
        # One image per 1/30 s period of sim time, periods 0..9 in [0, 0.3] s, each taken at
        # the first step of its period (1 ms).
        expected = math.floor(SECONDS * CAMERA_HZ + 1e-9) + 1
        stamps = [_stamp(m) for _, m in messages]
        assert len(stamps) == expected, stamps
        for k, stamp in enumerate(stamps):
            assert k / CAMERA_HZ - 1e-9 <= stamp < k / CAMERA_HZ + 1e-3 + 1e-9
        for _, m in messages:
            assert (m.width, m.height, m.encoding, m.step, m.is_bigendian) == (
                W, H, encoding, step, 0,
            )  # fmt: skip
            assert len(m.data) == H * step
    imu = [_stamp(m) for _, m in egl_bag["/post/imu"]]  # the samples MuJoCo kept, t = 0 ...
    assert np.allclose(imu, [k / IMU_HZ for k in range(round(SECONDS * IMU_HZ))], atol=1e-9)


def test_the_recorded_picture_shows_the_box_where_the_pinhole_model_puts_it(egl_bag) -> None:
    _, last = egl_bag["/post/cam/image_raw"][-1]
    rgb = np.asarray(last.data, np.uint8).reshape(H, W, 3).astype(np.float64)
    u, v, half = projection()
    rows, cols = np.nonzero(red(rgb))
    assert len(cols), "the box is in view"
    assert cols.mean() == pytest.approx(u - 0.5, abs=1.5)
    assert rows.mean() == pytest.approx(v - 0.5, abs=1.5)
    assert cols.max() - cols.min() + 1 == pytest.approx(2 * half, abs=2.0)
    _, depth_msg = egl_bag["/post/depth/image_raw"][-1]
    depth = np.frombuffer(np.asarray(depth_msg.data, np.uint8).tobytes(), "<f4").reshape(H, W)
    x, _, _, h = BOX
    assert depth[int(v), int(u)] == pytest.approx(x - h, abs=0.01), "metres to the near face"


def test_without_offscreen_gl_the_recording_goes_on_without_the_cameras(tmp_path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MUJOCO_GL"] = "glfw"  # a desktop's backend, here without a display
    bag, out, log = _record(tmp_path, env)
    assert out["error"] is None
    assert sorted(map(tuple, out["dropped"])) == [("post", "cam"), ("post", "depth")]
    assert "not recording sensor 'cam' of [post]" in log and "MUJOCO_GL=egl" in log
    messages = _messages(bag)
    assert not [t for t in messages if t.endswith("image_raw")]
    assert len(messages["/post/imu"]) == round(SECONDS * IMU_HZ), "t = 0 ... 0.29 s"
    assert len(messages["/clock"]) == round(SECONDS * 100) + 1, "the state samples go on"
