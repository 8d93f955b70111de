"""The world services a launch file calls, answered by `twin serve --ros --ros-services` and
called by a client that shares no code with twin (`service_peer.py`: types from gazebo_msgs',
std_srvs' and ros_gz_interfaces' definitions, replies decoded by rosbags): gazebo_ros' entity
state, pause and reset services, and ros_gz's create, remove, set_pose and control.

Oracles: the poses and twists a request sets, read back through `twin pose` and the service
itself; a relative state worked by hand; free flight over a number of steps (x = x0 + v·t and
z = z0 + vz·t − g·t²/2 with MuJoCo's semi-implicit Euler: −g·h²·n(n+1)/2). The world runs
paused, in a DDS domain of this module's own, loopback only.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import pytest
from ros_cli import ros_env, script_json, twin_ok

pytest.importorskip("cyclonedds", reason="cyclonedds is not installed (CI installs it)")
pytestmark = pytest.mark.xdist_group("ros_services")

WORLD = "ros_services"
PEER = Path(__file__).with_name("service_peer.py")
DOMAIN_ID = str(90 + os.getpid() % 10)  # 90-99: other modules take 30-89
G, H = 9.81, 0.001  # [m/s²] the served world's gravity, [s] its step
TOL = 1e-9  # [m, m/s, rad] a value set and read back
BOX = (
    '<sdf version="1.9"><model name="box"><link name="link"><inertial><mass>1</mass><inertia>'
    "<ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial><collision name='c'>"
    "<geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision></link></model></sdf>"
)
URDF = (
    '<robot name="cube"><link name="base"><inertial><mass value="1"/><inertia ixx="0.01" '
    'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box '
    'size="0.2 0.2 0.2"/></geometry></collision></link></robot>'
)


def _env(runtime: Path) -> dict[str, str]:
    return ros_env(runtime, DOMAIN_ID)


def _twin(runtime: Path, *args: str) -> str:
    return twin_ok(runtime, DOMAIN_ID, WORLD, *args)


def _call(runtime: Path, service: str, kind: str, fields: dict) -> dict:
    reply = script_json(PEER, runtime, DOMAIN_ID, service, kind, json.dumps(fields))
    assert reply.get("header") == [0x5EED_0000_0000_0002, 11], f"{service}: {reply}"
    return reply["reply"]


def _create(runtime: Path, **fields: object) -> bool:
    """ros_gz's create with an EntityFactory's `fields`; its success."""
    return _call(runtime, f"/world/{WORLD}/create", "gz_create", fields)["success"]


def _control(runtime: Path, **fields: object) -> bool:
    """ros_gz's control with a WorldControl's `fields`; its success."""
    return _call(runtime, f"/world/{WORLD}/control", "gz_control", fields)["success"]


def _pose(x: float, y: float, z: float, yaw: float = 0.0) -> dict:
    return {
        "position": [x, y, z],
        "orientation": [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)],  # x, y, z, w
    }


def _names(runtime: Path) -> list[str]:
    return sorted(e["name"] for e in json.loads(_twin(runtime, "list", "--json")))


def _at(runtime: Path, name: str) -> dict:
    return json.loads(_twin(runtime, "pose", name, "--json"))


def _sim_time(runtime: Path) -> float:
    line = _twin(runtime, "stats", "--json", "--duration", "0.3").splitlines()[-1]
    return json.loads(line)["sim_time"]


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A paused world served with --ros --ros-services, and the world name's gz services; its
    model path (GZ_SIM_RESOURCE_PATH) is `models` in the runtime folder."""
    root = tmp_path_factory.mktemp("ros_services")
    (root / "models").mkdir()
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("GZ_SIM_RESOURCE_PATH", str(root / "models"))
        patch.setenv("ROS_DOMAIN_ID", DOMAIN_ID)
        patch.delenv("ROS_AUTOMATIC_DISCOVERY_RANGE", raising=False)
        with serve_world(root, WORLD, "--ros", "--ros-services", "--paused"):
            yield root


def test_ros_gz_create_spawns_from_text_a_file_or_a_clone_and_renames_on_request(
    served: Path,
) -> None:
    root = served
    assert _create(root, name="box", sdf=BOX, pose=_pose(1.0, 2.0, 0.5, math.pi / 2))
    at = _at(root, "box")
    assert (at["x"], at["y"], at["z"]) == pytest.approx((1, 2, 0.5), abs=TOL)
    assert at["yaw"] == pytest.approx(math.pi / 2, abs=TOL)
    before = _names(root)
    assert not _create(root, name="box", sdf=BOX, pose=_pose(0, 0, 1)), "a taken name"
    assert _names(root) == before, "a refused create changed the world"
    assert _create(root, name="box", sdf=BOX, allow_renaming=True, pose=_pose(0, 3, 1))
    assert "box_1" in _names(root), _names(root)
    assert _create(root, name="box_copy", clone_name="box", pose=_pose(1, 0, 0), relative_to="box")
    copy = _at(root, "box_copy")  # 1 m along the box's x, which points along the world's y
    assert (copy["x"], copy["y"], copy["z"]) == pytest.approx((1.0, 3.0, 0.5), abs=TOL)
    (root / "models" / "cube.urdf").write_text(URDF)
    cube = str(root / "models" / "cube.urdf")
    assert _create(root, name="cube", sdf_filename=cube, pose=_pose(-2, 0, 0.3))
    assert _at(root, "cube")["x"] == pytest.approx(-2.0, abs=TOL)
    before = _names(root)
    for bad in (
        {"name": "rel", "sdf_filename": "cube.urdf", "pose": _pose(0, 0, 1)},  # relative path
        {"name": "two", "sdf": BOX, "clone_name": "box", "pose": _pose(0, 0, 1)},  # two sources
        {"name": "none", "pose": _pose(0, 0, 1)},  # no source
        {"name": "lost", "clone_name": "no_such", "pose": _pose(0, 0, 1)},
        {"name": "far", "sdf": BOX, "pose": _pose(1e300, 0, 1)},
    ):
        assert not _create(root, **bad), f"{bad['name']} was created"
    assert _names(root) == before, "refused requests changed the world"


@pytest.mark.parametrize(
    ("linear", "angular"),
    [((1.0, 0.0, 0.0), (0.0, 0.0, 0.5)), ((-0.3, 0.8, 2.0), (1.0, -2.0, 0.0))],
)
def test_entity_state_set_is_read_back_and_flies_as_physics_says(
    served: Path, linear: tuple, angular: tuple
) -> None:
    root = served
    assert _create(root, name="flyer", sdf=BOX, pose=_pose(0, 5, 1))
    state = {"name": "flyer", "pose": _pose(0.5, 5.0, 3.0, 0.4), "linear": list(linear),
             "angular": list(angular), "frame": "world"}  # fmt: skip
    assert _call(root, "/set_entity_state", "set_state", {"state": state})["success"]
    got = _call(root, "/get_entity_state", "get_state", {"name": "flyer", "reference_frame": ""})
    assert got["success"], got
    p, q = got["state"]["pose"]["position"], got["state"]["pose"]["orientation"]
    assert (p["x"], p["y"], p["z"]) == pytest.approx((0.5, 5.0, 3.0), abs=TOL)
    assert (q["z"], q["w"]) == pytest.approx((math.sin(0.2), math.cos(0.2)), abs=TOL)
    twist = got["state"]["twist"]
    assert [twist["linear"][k] for k in "xyz"] == pytest.approx(list(linear), abs=TOL)
    assert [twist["angular"][k] for k in "xyz"] == pytest.approx(list(angular), abs=TOL)
    start = _sim_time(root)
    n = 200
    assert _control(root, pause=True, multi_step=n)
    assert _sim_time(root) == pytest.approx(start + n * H, abs=1e-9), "stepped n steps, paused"
    flown = _at(root, "flyer")
    t = n * H
    fall = G * H * H * n * (n + 1) / 2  # semi-implicit Euler's free fall after n steps
    expect = (0.5 + linear[0] * t, 5.0 + linear[1] * t, 3.0 + linear[2] * t - fall)
    assert (flown["x"], flown["y"], flown["z"]) == pytest.approx(expect, abs=1e-6)
    _twin(root, "delete", "flyer")


def test_a_state_relative_to_another_entity_is_the_hand_worked_one(served: Path) -> None:
    root, gz = served, f"/world/{WORLD}"
    for name, pose in (("ref", _pose(2.0, -1.0, 4.0, math.pi / 2)), ("obj", _pose(3.0, 1.0, 4.5))):
        assert _create(root, name=name, sdf=BOX, pose=pose)
    moves = {"ref": ((0.5, 0.0, 0.0), (0.0, 0.0, 1.0)), "obj": ((0.0, 2.0, 0.0), (0.0, 0.0, 0.0))}
    for name, (linear, angular) in moves.items():
        at = _at(root, name)
        pose = _pose(at["x"], at["y"], at["z"], at["yaw"])
        state = {"name": name, "pose": pose, "linear": list(linear), "angular": list(angular),
                 "frame": "world"}  # fmt: skip
        assert _call(root, "/set_entity_state", "set_state", {"state": state})["success"]
    got = _call(root, "/get_entity_state", "get_state", {"name": "obj", "reference_frame": "ref"})
    assert got["success"] and got["header"]["frame_id"] == "ref", got
    p = got["state"]["pose"]["position"]
    # obj − ref = (1, 2, 0.5) in the world; ref's x points along the world's y: (2, −1, 0.5)
    assert (p["x"], p["y"], p["z"]) == pytest.approx((2.0, -1.0, 0.5), abs=TOL)
    q = got["state"]["pose"]["orientation"]
    assert (q["z"], q["w"]) == pytest.approx((-math.sqrt(0.5), math.sqrt(0.5)), abs=TOL)
    v, w = got["state"]["twist"]["linear"], got["state"]["twist"]["angular"]
    # v − v_ref = (−0.5, 2, 0) turned into ref's axes: (2, 0.5, 0); ω − ω_ref = (0, 0, −1)
    assert [v[k] for k in "xyz"] == pytest.approx([2.0, 0.5, 0.0], abs=TOL)
    assert [w[k] for k in "xyz"] == pytest.approx([0.0, 0.0, -1.0], abs=TOL)
    for name in ("ref", "obj"):
        assert _call(root, f"{gz}/remove", "gz_remove", {"name": name})["success"]


def test_bad_entity_requests_fail_and_leave_the_world_as_it_was(served: Path) -> None:
    root, gz = served, f"/world/{WORLD}"
    assert _create(root, name="still", sdf=BOX, pose=_pose(0, -5, 1))
    names, at = _names(root), _at(root, "still")
    for name, frame in (("no_such", ""), ("still::link", ""), ("still", "no_frame")):
        got = _call(
            root, "/get_entity_state", "get_state", {"name": name, "reference_frame": frame}
        )
        assert not got["success"], f"{name} in {frame!r}: {got}"
    far = {"name": "still", "pose": _pose(0, 0, 1), "linear": [1e6, 0, 0], "angular": [0, 0, 0],
           "frame": "world"}  # fmt: skip
    assert not _call(root, "/set_entity_state", "set_state", {"state": far})["success"]
    assert not _call(root, f"{gz}/remove", "gz_remove", {"name": "no_such"})["success"]
    static = BOX.replace('<model name="box">', '<model name="post"><static>true</static>')
    assert _create(root, name="post", sdf=static, pose=_pose(3, -5, 0.5))
    spin = {"name": "post", "pose": _pose(3, -6, 0.5), "linear": [1, 0, 0], "angular": [0, 0, 1],
            "frame": "world"}  # fmt: skip
    assert _call(root, "/set_entity_state", "set_state", {"state": spin})["success"], (
        "twist ignored"
    )
    assert _at(root, "post")["y"] == pytest.approx(-6.0, abs=TOL), "the pose is set"
    _twin(root, "delete", "post")
    names = _names(root)
    link = {"name": "still", "type": 3, "pose": _pose(0, 0, 9)}  # a LINK-type entity
    assert not _call(root, f"{gz}/set_pose", "gz_set_pose", link)["success"]
    assert _names(root) == names and _at(root, "still") == at, "the world changed"
    assert _call(root, f"{gz}/set_pose", "gz_set_pose", {"name": "still", "pose": _pose(7, 7, 2)})[
        "success"
    ]
    assert (_at(root, "still")["x"], _at(root, "still")["y"]) == pytest.approx((7, 7), abs=TOL)
    assert _call(root, f"{gz}/remove", "gz_remove", {"name": "still"})["success"]
    assert "still" not in _names(root)


def test_pause_unpause_and_resets_act_as_gazebos(served: Path) -> None:
    root, gz = served, f"/world/{WORLD}"
    assert _create(root, name="drop", sdf=BOX, pose=_pose(0, -8, 2))
    _call(root, "/unpause_physics", "empty", {})
    running = json.loads(_twin(root, "stats", "--json", "--duration", "0.5").splitlines()[-1])
    assert running["paused"] is False, running
    _call(root, "/pause_physics", "empty", {})
    paused = json.loads(_twin(root, "stats", "--json", "--duration", "0.3").splitlines()[-1])
    assert paused["paused"] is True and paused["sim_time"] > 0, paused
    assert _at(root, "drop")["z"] < 2.0 - 1e-3, "it fell while running"
    _call(root, "/reset_simulation", "empty", {})
    assert _sim_time(root) == 0.0
    assert _at(root, "drop")["z"] == pytest.approx(2.0, abs=TOL), "back at its spawn pose"
    assert _control(root, pause=True, multi_step=100)
    fallen = _at(root, "drop")["z"]
    assert fallen < 2.0 - 1e-3 and _sim_time(root) == pytest.approx(0.1, abs=1e-9)
    assert _control(root, pause=True, reset=[False, False, True]), "model only: ignored"
    assert _sim_time(root) == pytest.approx(0.1, abs=1e-9) and _at(root, "drop")["z"] == fallen
    assert _control(root, pause=True, reset=[False, True, False]), "time only: gz-sim rewinds"
    assert _sim_time(root) == 0.0 and _at(root, "drop")["z"] == pytest.approx(2.0, abs=TOL)
    assert _control(root, pause=False, run_to=[0, 250_000_000]), "runs there, then pauses"
    assert _sim_time(root) == pytest.approx(0.25, abs=1e-9), "paused at 0.25 s"
    refused = {"pause": True, "reset": [True, False, False], "multi_step": 4_000_000_000}
    assert not _call(root, f"{gz}/control", "gz_control", refused)["success"]
    assert _sim_time(root) == pytest.approx(0.25, abs=1e-9), "a refused request reset nothing"
    assert _control(root, pause=True, reset=[True, False, False])
    assert _sim_time(root) == 0.0 and _at(root, "drop")["z"] == pytest.approx(2.0, abs=TOL)
    missing = {"name": "gone", "sdf_filename": "/no/such/model.sdf", "pose": _pose(0, 0, 1)}
    assert not _create(root, **missing), "a file that is not there"
    _twin(root, "delete", "drop")


MJCF = '<mujoco model="m"><worldbody><body><geom size="0.1"/></body></worldbody></mujoco>'


def _mesh_urdf(name: str, mesh: Path | str) -> str:
    """The cube with a mesh: a path as a file:// URI, a string as it is written."""
    filename = f"file://{mesh}" if isinstance(mesh, Path) else mesh
    return URDF.replace('name="cube"', f'name="{name}"').replace(
        '<box size="0.2 0.2 0.2"/>', f'<mesh filename="{filename}"/>'
    )


def _include_sdf(directory: Path) -> str:
    return (
        f'<sdf version="1.9"><model name="peek"><include><uri>file://{directory}</uri>'
        "</include></model></sdf>"
    )


def _write_box_stl(path: Path) -> Path:
    """A 0.2 m cube as ASCII STL (12 facets), written without twin's code."""
    import itertools

    path.parent.mkdir(parents=True, exist_ok=True)
    corners = list(itertools.product((-0.1, 0.1), repeat=3))
    facets = []
    for axis, side in itertools.product(range(3), (-0.1, 0.1)):
        face = [c for c in corners if c[axis] == side]
        a, b, c, d = face[0], face[1], face[3], face[2]  # around the face
        facets += [(a, b, c), (a, c, d)]
    lines = ["solid box"]
    for tri in facets:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {x} {y} {z}" for x, y, z in tri] + ["endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid box"]) + "\n")
    return path


def test_a_peers_spawn_reads_only_the_worlds_package_and_model_paths(served: Path) -> None:
    """A DDS peer is not the server's user: its spawns (gazebo_ros' and ros_gz's) read files
    only under the world's package and model paths (here GZ_SIM_RESOURCE_PATH); a file or mesh
    elsewhere, a link out of the path (`/proc/self/root` too), a model folder outside whose
    model.config names a file inside, or MJCF (which MuJoCo would read unwatched) is refused
    with the reason, and the world is left as it was; relative paths start at the first model
    path, not the server's folder. The server's own user spawns them all."""
    root = served
    _write_box_stl(root / "models" / "crate" / "box.stl")
    secret = _write_box_stl(root / "private" / "secret.stl")
    (root / "private" / "bot.urdf").write_text(_mesh_urdf("bot", secret))
    (root / "models" / "link.urdf").symlink_to(root / "private" / "bot.urdf")
    (root / "models" / "box.sdf").write_text(BOX)
    outside_model = root / "private" / "model"
    outside_model.mkdir()
    (outside_model / "model.config").write_text(
        f'<model><name>m</name><sdf version="1.9">{root / "models" / "box.sdf"}</sdf></model>'
    )
    assert _create(
        root, name="crate", sdf=_mesh_urdf("crate", "crate/box.stl"), pose=_pose(0, 9, 1)
    )
    before = _names(root)
    spawn = {"name": "peek", "xml": _mesh_urdf("peek", secret), "pose": _pose(0, 8, 1)}
    refused = _call(root, "/spawn_entity", "spawn", spawn)
    assert not refused["success"], refused
    message = refused["status_message"]
    assert str(secret) in message and "outside" in message and "GZ_SIM_RESOURCE_PATH" in message
    for bad in (
        {"sdf": _mesh_urdf("peek", secret)},  # a mesh outside
        {"sdf": _mesh_urdf("peek", f"file:///proc/self/root{secret}")},  # through /proc
        {"sdf": _mesh_urdf("peek", "../private/secret.stl")},  # relative, out of the path
        {"sdf": _include_sdf(outside_model)},  # its model.config is outside
        {"sdf_filename": str(root / "private" / "bot.urdf")},  # a file outside
        {"sdf_filename": str(root / "models" / "link.urdf")},  # a link to one
        {"sdf": MJCF},
    ):
        assert not _create(root, name="peek", pose=_pose(0, 8, 1), **bad), f"created: {bad}"
    mjcf = {**spawn, "xml": MJCF}
    assert "MJCF" in _call(root, "/spawn_entity", "spawn", mjcf)["status_message"]
    assert _names(root) == before, "a refused spawn changed the world"
    _twin(root, "spawn", str(root / "private" / "bot.urdf"), "-x", "3", "-y", "9")
    assert "bot" in _names(root), "the server's own user spawns from anywhere"
    for name in ("crate", "bot"):
        _twin(root, "delete", name)
