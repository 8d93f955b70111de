"""A real world server on a temporary socket: bad requests get clear errors, it keeps stepping."""

from __future__ import annotations

import json
import os
import socket
import stat
import time
from pathlib import Path

import httpx
import pytest
from models import block

from converters.errors import ConversionError
from twin_cli.errors import EntityExistsError, EntityNotFoundError, RequestError, TwinError
from twin_cli.server.client import Client

WORLD = "srv"
BOX_URDF = block(size=0.2, name="box")
# Not well-formed XML: the converter must refuse it with its file name in the message.
BROKEN_URDF = "<robot name='broken'><link name='a'></robot>"


@pytest.fixture(scope="module")
def server(tmp_path_factory, serve_world):
    """`twin serve --tcp 127.0.0.1:0` in a temporary runtime dir; SIGTERM in teardown."""
    with serve_world(tmp_path_factory.mktemp("rt"), WORLD, "--tcp", "127.0.0.1:0") as served:
        yield served


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("robots")
    (d / "box.urdf").write_text(BOX_URDF)
    (d / "broken.urdf").write_text(BROKEN_URDF)
    return d


def _sim_time(client: Client) -> float:
    return float(client.stats()["sim_time"])


def _assert_still_stepping(client: Client, before: float) -> None:
    deadline = time.monotonic() + 5.0
    while _sim_time(client) <= before and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _sim_time(client) > before, f"sim_time stuck at {before} s after bad requests"


def test_runtime_files_are_private(server):
    client, _ = server
    assert stat.S_IMODE(client.paths.directory.stat().st_mode) == 0o700, "runtime dir mode"
    assert stat.S_IMODE(client.paths.socket.stat().st_mode) == 0o600, "socket mode"
    assert stat.S_IMODE(client.paths.token.stat().st_mode) == 0o600, "token file mode"


def test_unknown_entity_is_404_naming_it(server):
    client, _ = server
    with pytest.raises(EntityNotFoundError, match=r"Entity \[ghost\] does not exist"):
        client.pose("ghost")
    with pytest.raises(EntityNotFoundError, match="ghost"):
        client.delete("ghost")


def test_a_body_over_the_limit_is_refused_at_once_with_413(server):
    from twin_cli.errors import RequestError
    from twin_cli.server.body_limit import MAX_BODY_BYTES

    client, _ = server
    before, entities = _sim_time(client), client.entities()
    huge = {"xml": "<robot>" + " " * (MAX_BODY_BYTES + 1024) + "</robot>"}
    start = time.monotonic()
    with pytest.raises(RequestError, match="over the server's limit") as caught:
        client.request("POST", "/entities", body=huge, timeout=30.0)
    took = time.monotonic() - start
    assert "POST /entities" in str(caught.value), str(caught.value)
    assert took < 5.0, f"a refused {MAX_BODY_BYTES} byte body took {took:.1f} s to answer"
    _assert_still_stepping(client, before)
    assert [e["name"] for e in client.entities()] == [e["name"] for e in entities], "no spawn"


def test_malformed_pose_is_422_naming_the_field(server):
    client, _ = server
    before = _sim_time(client)
    with pytest.raises(RequestError, match=r"x: .*number"):
        client.request("PUT", "/entities/anything/pose", body={"x": "one metre"})
    with pytest.raises(RequestError, match="yaww"):
        client.request("PUT", "/entities/anything/pose", body={"yaww": 1.0})
    reply = client._http.request(
        "PUT",
        "/entities/anything/pose",
        content=b'{"x": NaN}',
        headers={"content-type": "application/json"},
    )
    assert reply.status_code == 422 and "finite" in reply.json()["message"], reply.text
    with pytest.raises(RequestError, match="exactly one"):
        client.request("PUT", "/gravity", body={"preset": "moon", "vector": [0, 0, 1]})
    _assert_still_stepping(client, before)


def test_missing_file_is_a_clear_4xx(server, tmp_path):
    client, _ = server
    missing = tmp_path / "nowhere" / "robot.urdf"
    with pytest.raises((TwinError, ConversionError), match="robot.urdf") as info:
        client.spawn(missing)
    assert "Traceback" not in str(info.value)


def test_file_that_fails_to_convert_is_a_4xx_with_its_message(server, files):
    client, _ = server
    before = _sim_time(client)
    names = {e["name"] for e in client.entities()}
    reply = client._http.request("POST", "/entities", json={"source": str(files / "broken.urdf")})
    assert 400 <= reply.status_code < 500, f"status {reply.status_code}: {reply.text}"
    assert "broken.urdf" in reply.json()["message"], reply.text
    assert {e["name"] for e in client.entities()} == names, "a failed spawn changed the world"
    _assert_still_stepping(client, before)


def test_taken_name_is_entity_exists(server, files):
    client, _ = server
    assert client.spawn(files / "box.urdf", name="taken", pose={"z": 2.0})["name"] == "taken"
    with pytest.raises(EntityExistsError, match=r"Entity \[taken\] already exists"):
        client.spawn(files / "box.urdf", name="taken")
    client.delete("taken")


def test_raw_garbage_on_the_socket_gets_an_error_and_server_lives(server):
    client, _ = server
    before = _sim_time(client)
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as raw:
        raw.settimeout(5.0)
        raw.connect(str(client.paths.socket))
        raw.sendall(b"\x00\xff\xfeNOT HTTP AT ALL\r\n\r\n" + os.urandom(256))
        try:
            reply = raw.recv(4096)
        except (ConnectionResetError, TimeoutError):
            reply = b""
    assert reply == b"" or reply.startswith(b"HTTP/1.1 4"), f"reply to garbage: {reply[:80]!r}"
    _assert_still_stepping(client, before)
    assert client.alive()


def test_tcp_needs_the_bearer_token(server):
    client, _ = server
    host, port = client.paths.tcp.read_text().strip().rsplit(":", 1)
    assert host == "127.0.0.1", f"default TCP host {host}"
    url = f"http://{host}:{port}"
    assert httpx.get(url + "/stats").status_code == 401, "TCP without token must be refused"
    bad = httpx.get(url + "/stats", headers={"Authorization": "Bearer wrong"})
    assert bad.status_code == 401
    token = client.paths.token.read_text().strip()
    with Client(WORLD, url=url, token=token) as tcp_client:
        assert tcp_client.stats()["sim_time"] >= 0.0


def test_openapi_schema_is_served(server):
    client, _ = server
    schema = client.request("GET", "/openapi.json")
    for path in ("/entities", "/gravity", "/stats", "/entities/{name}/pose"):
        assert path in schema["paths"], f"{path} missing from the OpenAPI schema"


def test_serve_a_saved_world_paused_then_sigterm_ends_cleanly(tmp_path, files, serve_world):
    from twin_cli.world import Pose, World, savefile

    saved = World()
    saved.spawn(str(files / "box.urdf"), name="crate", pose=Pose(z=3.0))
    savefile.save(saved, tmp_path / "saved.twin")
    args = (str(tmp_path / "saved.twin"), "--paused", "--rate", "500")
    with serve_world(tmp_path, "t", *args) as (client, proc):
        assert [e["name"] for e in client.entities()] == ["crate"], "saved entities not served"
        assert client.stats()["paused"] is True, "--paused not applied"
        assert client.physics()["rate"] == pytest.approx(500.0), "--rate not applied"
        assert client.pose("crate")["z"] == pytest.approx(3.0, abs=1e-9), "saved pose z [m]"
        proc.terminate()
        assert proc.wait(timeout=20) == 0, f"exit code after SIGTERM: {proc.returncode}"
        leftovers = [p for p in client.paths.transient() if p.exists()]
        assert leftovers == [], f"files left after SIGTERM: {leftovers}"
        assert "stopped" in Path(client.paths.log).read_text()


def test_save_then_load_restores_entities_and_pose(server, files, tmp_path):
    client, _ = server
    client.spawn(files / "box.urdf", name="kept", pose={"x": 1.0, "z": 0.1})
    client.pause()
    try:
        pose = client.pose("kept")
        client.save(tmp_path / "world.twin")
        client.delete("kept")
        loaded = client.load(tmp_path / "world.twin")
        assert "kept" in loaded["entities"], f"loaded entities: {loaded['entities']}"
        again = client.pose("kept")
        for key in ("x", "y", "z"):
            assert again[key] == pytest.approx(pose[key], abs=1e-9), f"{key} after load [m]"
    finally:
        client.resume()
        client.delete("kept")
    with pytest.raises(TwinError, match="nowhere.twin"):
        client.load(tmp_path / "nowhere.twin")


def test_set_pose_then_push_moves_by_half_a_t_squared(server, files):
    """A 1 kg box in zero gravity pushed with 10 N for 0.1 s moves 1/2 a t^2 = 0.05 m."""
    client, _ = server
    client.pause()
    client.set_gravity(preset="zero")
    try:
        client.spawn(files / "box.urdf", name="puck", pose={"z": 5.0})
        moved = client.set_pose("puck", {"x": 1.0, "y": 2.0, "z": 3.0, "yaw": 0.5})
        assert (moved["x"], moved["y"], moved["z"]) == pytest.approx((1.0, 2.0, 3.0), abs=1e-9)
        assert moved["yaw"] == pytest.approx(0.5, abs=1e-9), "yaw after set_pose [rad]"
        client.push("puck", (10.0, 0.0, 0.0), (0.0, 0.0, 0.0), duration=0.1)
        client.step(100)
        dx = client.pose("puck")["x"] - 1.0
        # Semi-implicit Euler over 100 steps of 1 ms: a*dt^2*n(n+1)/2 = 0.0505 m.
        assert dx == pytest.approx(10.0 * 1e-6 * 100 * 101 / 2, rel=0.02), f"push moved {dx} m"
    finally:
        client.delete("puck")
        client.set_gravity(preset="earth")
        client.resume()


def test_a_rejected_load_leaves_the_world_byte_identical(server, tmp_path):
    from twin_cli.errors import WorldFileError

    client, _ = server
    client.pause()
    try:
        client.save(tmp_path / "before.json")
        bad = json.loads((tmp_path / "before.json").read_text())
        bad["state"] = bad["state"][:3]  # a truncated state vector
        (tmp_path / "bad.json").write_text(json.dumps(bad))
        with pytest.raises(WorldFileError, match="bad.json"):
            client.load(tmp_path / "bad.json")
        client.save(tmp_path / "after.json")
    finally:
        client.resume()
    before, after = ((tmp_path / n).read_bytes() for n in ("before.json", "after.json"))
    assert before == after, "the world changed after a refused load"
