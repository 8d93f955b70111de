"""The viewer and snapshots on a real server: ports, bind address, offscreen pictures."""

from __future__ import annotations

import socket
import subprocess

import numpy as np
import pytest
from view_helpers import box_corners, egl_missing, project, pure_red, red_box, twin_in

PIXEL_TOL = 3  # [px] red region vs projected box: rasterisation and anti-aliasing at the edges


def twin(*args: str, world: str) -> subprocess.CompletedProcess:
    return twin_in(world, *args)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def non_loopback_address() -> str | None:
    """An IPv4 address of this machine other than 127.x (from its routing, no packet sent)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            s.connect(("192.0.2.1", 9))  # TEST-NET-1: connect() on UDP only picks a route
            address = s.getsockname()[0]
        except OSError:
            return None
    return None if address.startswith("127.") else address


def reachable(host: str, port: int) -> bool:
    with socket.socket() as s:
        s.settimeout(2.0)
        return s.connect_ex((host, port)) == 0


def test_the_viewer_port_is_not_reachable_on_a_non_loopback_address_by_default(
    tmp_path, serve_world
):
    address = non_loopback_address()
    if address is None:
        pytest.skip("this machine has no non-loopback IPv4 address to test against")
    port = free_port()
    with serve_world(tmp_path, "viewbind"):
        shown = twin("view", "--port", str(port), world="viewbind")
        assert shown.returncode == 0, shown.stderr
        assert shown.stdout.strip() == f"http://localhost:{port}/"
        assert reachable("127.0.0.1", port), "the page is not served on loopback"
        assert not reachable(address, port), f"the viewer answers on {address}:{port}"
        assert twin("view", "--stop", world="viewbind").returncode == 0
        assert not reachable("127.0.0.1", port), "the viewer still listens after --stop"
        # MuJoCo 4.0's viewer crashes its process when started again after a close: twin
        # refuses with one message, and the world keeps running.
        again = twin("view", "--port", str(port), world="viewbind")
        assert again.returncode == 2, again.stderr
        assert "twin load" in again.stderr and "Traceback" not in again.stderr
        assert twin("list", world="viewbind").returncode == 0, "the world died"
        assert twin("stop", world="viewbind").returncode == 0
    # The probe can fail: asked for all interfaces, the same address answers, with a warning.
    # A fresh port: the first one may still be held by the probes' closing connections.
    port = free_port()
    with serve_world(tmp_path, "viewpublic"):
        public = twin("view", "--host", "0.0.0.0", "--port", str(port), world="viewpublic")
        assert public.returncode == 0, public.stderr
        assert "anyone who can reach that port" in public.stderr
        assert reachable(address, port), f"--host 0.0.0.0 does not answer on {address}"
        assert twin("stop", world="viewpublic").returncode == 0
    assert not reachable("127.0.0.1", port), "twin stop left the viewer listening"


def test_a_taken_viewer_port_is_one_message_and_exit_2(tmp_path, serve_world):
    with socket.socket() as taken, serve_world(tmp_path, "viewtaken"):
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        proc = twin("view", "--port", str(port), world="viewtaken")
    assert proc.returncode == 2, proc.stderr
    assert f"viewer port 127.0.0.1:{port}" in proc.stderr and "--port" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.skipif(bool(egl_missing()), reason=egl_missing() or "")
def test_snapshot_of_a_red_box_has_red_pixels_where_the_camera_projects_it(tmp_path, serve_world):
    size, centre, yaw = 0.4, (0.3, -0.2, 0.2), 0.5
    urdf = tmp_path / "box.urdf"
    urdf.write_text(red_box(size))
    out = tmp_path / "box.png"
    with serve_world(tmp_path, "snap", "--paused"):
        x, y, z = (str(v) for v in centre)
        spawned = twin("spawn", str(urdf), "-x", x, "-y", y, "-z", z, "-Y", str(yaw), world="snap")
        assert spawned.returncode == 0, spawned.stderr
        shot = twin(
            "snapshot", str(out), "--entity", "box", "--width", "320", "--height", "240",
            "--json", world="snap",
        )  # fmt: skip
    assert shot.returncode == 0, shot.stderr
    import json

    from PIL import Image

    camera = json.loads(shot.stdout)["camera"]
    pixels = np.asarray(Image.open(out).convert("RGB"))
    assert pixels.shape == (240, 320, 3)
    uv = project(box_corners(centre, yaw, size), camera)
    red_v, red_u = np.nonzero(pure_red(pixels))
    assert len(red_u) > 1000, f"only {len(red_u)} red pixels"
    found = (red_u.min(), red_u.max(), red_v.min(), red_v.max())
    expected = (uv[:, 0].min(), uv[:, 0].max(), uv[:, 1].min(), uv[:, 1].max())
    assert np.allclose(found, expected, atol=PIXEL_TOL + 1), (
        f"red pixels span u {found[:2]}, v {found[2:]}; the projected box u {expected[:2]}, "
        f"v {expected[2:]} (±{PIXEL_TOL} px)"
    )
    centre_uv = project(np.array([centre]), camera)[0].round().astype(int)
    assert pure_red(pixels)[centre_uv[1], centre_uv[0]], "the box centre's pixel is not red"


def test_a_viewer_perturbation_adds_to_pushes_and_neither_erases_the_other(tmp_path):
    """World.perturb (the page's Ctrl+drag) and World.push (`twin push`) on one body sum in
    xfrc_applied; when the push ends the drag stays, and ending the drag leaves no force."""
    from twin_cli.world import Pose, World, WorldSettings

    urdf = tmp_path / "box.urdf"
    urdf.write_text(red_box(0.2))
    world = World(WorldSettings(gravity=(0.0, 0.0, 0.0), ground=False))
    world.spawn(str(urdf), name="box", pose=Pose(z=1.0))
    body = world.model.body("box/box").id
    world.push("box", (10.0, 0.0, 0.0), duration=0.01)  # 10 steps of 1 ms
    world.perturb({"box/box": (0.0, 4.0, 0.0, 0.0, 0.0, 0.5)})
    assert list(world.data.xfrc_applied[body]) == [10.0, 4.0, 0.0, 0.0, 0.0, 0.5]
    world.step(5)
    world.perturb({"box/box": (0.0, 3.0, 0.0, 0.0, 0.0, 0.0)})  # the next frame of the drag
    assert list(world.data.xfrc_applied[body]) == [10.0, 3.0, 0.0, 0.0, 0.0, 0.0]
    world.step(10)  # the push has ended
    assert list(world.data.xfrc_applied[body]) == [0.0, 3.0, 0.0, 0.0, 0.0, 0.0]
    world.perturb({})
    assert not world.data.xfrc_applied[body].any(), "the ended drag left a force"
    # Momentum oracle: 10 N for 0.01 s + the drag's y forces (4 N × 5 ms, 3 N × 10 ms) on 1 kg.
    vx, vy = world.data.qvel[0], world.data.qvel[1]
    assert abs(vx - 0.1) < 1e-9 and abs(vy - (4 * 0.005 + 3 * 0.010)) < 1e-9, (vx, vy)
