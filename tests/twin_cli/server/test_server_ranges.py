"""Every number a client or a save file gives has a physical range (`twin_cli.physical_ranges`).

Finite is not enough: a timestep of 2^64 s, a push of 1e308 N or a pose at x = 1e308 m were
accepted and turned the world's state into infinities. Oracles: a real server answers 422 naming
the field for each out-of-range value, and the world saved before and after the refusals is the
same file to the byte; a save file with such a value is refused naming the field.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from models import block

from twin_cli.errors import WorldFileError
from twin_cli.world import savefile

WORLD = "ranges"
HUGE = (1e308, -1e308, math.nan)


def _requests(box_urdf: str) -> list[tuple[str, str, str, object]]:
    """(method, route, field, body for a value v) of every numeric field the API takes."""
    return [
        ("PUT", "/entities/box/pose", "x", lambda v: {"x": v}),
        ("PUT", "/entities/box/pose", "yaw", lambda v: {"yaw": v}),
        ("PUT", "/entities/box/pose", "quat", lambda v: {"quat": [v, 0.0, 0.0, 1.0]}),
        ("PUT", "/gravity", "vector", lambda v: {"vector": [0.0, 0.0, v]}),
        ("POST", "/entities/box/push", "force", lambda v: {"force": [v, 0.0, 0.0]}),
        ("POST", "/entities/box/push", "torque", lambda v: {"torque": [0.0, v, 0.0]}),
        (
            "POST",
            "/entities/box/command",
            "value",
            lambda v: {"joint": "j", "mode": "effort", "value": v},
        ),
        ("POST", "/entities/box/commands", "targets", lambda v: {"targets": {"j": v}}),
        ("POST", "/entities/box/drive", "linear", lambda v: {"linear": v}),
        ("PUT", "/physics", "timestep", lambda v: {"timestep": v}),
        ("PUT", "/physics", "rate", lambda v: {"rate": v}),
        (
            "POST",
            "/entities",
            "pose",
            lambda v: {"source": box_urdf, "name": "b2", "pose": {"z": v}},
        ),
        (
            "POST",
            "/entities",
            "joints",
            lambda v: {"source": box_urdf, "name": "b3", "joints": {"j": v}},
        ),
    ]


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    with serve_world(tmp_path_factory.mktemp("rt"), WORLD) as (client, proc):
        urdf = tmp_path_factory.mktemp("robots") / "box.urdf"
        urdf.write_text(block(size=0.2, name="box"))
        client.spawn(str(urdf), name="box")
        yield client, str(urdf)


def _send(client, method: str, route: str, body: dict):
    # allow_nan: JSON's NaN as Python writes it (a non-standard constant the server must refuse)
    content = json.dumps(body, allow_nan=True).encode()
    return client._http.request(
        method, route, content=content, headers={"content-type": "application/json"}
    )


def test_out_of_range_numbers_are_422_naming_the_field_and_change_nothing(served, tmp_path):
    client, urdf = served
    client.pause()
    try:
        client.save(tmp_path / "before.json")
        for method, route, field, body in _requests(urdf):
            values = HUGE + ((5e-324,) if field in ("timestep", "rate") else ())
            for value in values:
                reply = _send(client, method, route, body(value))
                assert reply.status_code == 422, (route, field, value, reply.text)
                assert field in reply.text, (route, field, value, reply.text)
        client.save(tmp_path / "after.json")
    finally:
        client.resume()
    before, after = ((tmp_path / n).read_bytes() for n in ("before.json", "after.json"))
    assert before == after, "the world changed after refused requests"


def test_values_inside_the_ranges_are_taken(served):
    client, _ = served
    assert _send(client, "PUT", "/entities/box/pose", {"x": 1e5, "z": 1.0}).status_code == 200
    assert _send(client, "PUT", "/gravity", {"vector": [0.0, 0.0, -100.0]}).status_code == 200
    assert _send(client, "PUT", "/physics", {"rate": 0.0}).status_code == 200
    assert _send(client, "PUT", "/physics", {"rate": 1000.0}).status_code == 200
    assert _send(client, "PUT", "/gravity", {"preset": "earth"}).status_code == 200


@pytest.mark.parametrize(
    ("where", "value"),
    [
        (("entities", 0, "pose", "x"), 1e308),
        (("entities", 0, "pose", "roll"), -1e308),
        (("settings", "timestep"), 2.0**64),
        (("settings", "timestep"), 5e-324),
        (("settings", "rate"), 1e308),
        (("settings", "gravity", 2), -1e308),
        (("state", 0), 1e300),
    ],
)
def test_a_save_with_an_out_of_range_number_is_refused_naming_it(tmp_path: Path, where, value):
    from twin_cli.world import World

    (tmp_path / "box.urdf").write_text(block(size=0.2, name="box"))
    world = World()
    world.spawn(str(tmp_path / "box.urdf"), name="box")
    savefile.save(world, tmp_path / "ok.json")
    doc = json.loads((tmp_path / "ok.json").read_text())
    node = doc
    for key in where[:-1]:
        node = node[key]
    node[where[-1]] = value
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    field = [key for key in where if isinstance(key, str)][-1]
    with pytest.raises(WorldFileError, match=field):
        savefile.load(tmp_path / "bad.json")


def test_a_world_at_the_edge_of_every_range_saves_and_loads_and_past_it_is_refused(tmp_path):
    """The world checks its settings against the same ranges as the save schema, so a world
    twin runs always reloads from its own save."""
    from twin_cli.errors import InvalidRequestError
    from twin_cli.world import World
    from twin_cli.world.values import WorldSettings

    edge = WorldSettings(timestep=1.0, rate=1e7, iterations=1_000_000, gravity=(0.0, 0.0, -1e3))
    savefile.save(World(edge), tmp_path / "edge.json")
    loaded = savefile.load(tmp_path / "edge.json")
    assert loaded.settings.timestep == 1.0 and loaded.settings.iterations == 1_000_000
    for past in (
        {"timestep": 1.5},
        {"rate": 2e7},
        {"rate": 1e-7},
        {"iterations": 2_000_000},
        {"gravity": (0.0, 0.0, -2e3)},
    ):
        with pytest.raises(InvalidRequestError, match=next(iter(past))):
            World(WorldSettings(**past))
