"""`twin load` of a damaged or hostile save file: one message naming the bad field, never a crash,
and the world it would have replaced stays exactly as it was."""

from __future__ import annotations

import copy
import json
import os
import stat
from pathlib import Path

import pytest
from models import block, write_urdf

from converters.errors import ConversionError
from twin_cli.errors import TwinError, WorldFileError
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World, savefile


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> tuple[Path, dict]:
    """A real save: a box with a held joint-free spawn, one step taken."""
    directory = tmp_path_factory.mktemp("save")
    world = World()
    world.spawn(SpawnRequest(write_urdf(directory, block(name="box"))), name="box", pose=Pose(z=1))
    world.step(10)
    path = directory / "world.json"
    savefile.save(world, path)
    return path, json.loads(path.read_text())


def _set(doc: dict, where: str, value: object) -> dict:
    """A copy of `doc` with the field at dotted path `where` set to `value` (DROP: removed)."""
    out = copy.deepcopy(doc)
    *parents, last = where.split(".")
    node = out
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    if value is DROP:
        del node[last]
    elif isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return out


DROP = object()
TOP = ("name", "settings", "paused", "iterations", "divergences", "entities", "commands")
TOP += ("pushes", "layout", "state")
CASES = [
    *[(f"no {key}", key, DROP) for key in TOP],
    *[(f"{key} null", key, None) for key in TOP],
    ("iterations negative", "iterations", -5),
    ("iterations huge", "iterations", 1e300),
    ("iterations text", "iterations", "many"),
    ("entities a dict", "entities", {}),
    ("state text", "state", "abc"),
    ("state NaN", "state.0", float("nan")),
    ("state shortened", "state", [0.0, 1.0]),
    ("pose x infinite", "entities.0.pose.x", float("inf")),
    ("pose missing yaw", "entities.0.pose.yaw", DROP),
    ("entity name with a slash", "entities.0.name", "a/b"),
    ("spawn state NaN", "entities.0.spawn_state.qpos", [float("nan")] * 7),
    ("spawn state wrong size", "entities.0.spawn_state.qpos", [0.0]),
    ("spawn state unknown array", "entities.0.spawn_state.bogus", [0.0]),
    ("entity xml not MJCF", "entities.0.xml", "<mujoco><worldbody><bad"),
    ("entity source missing", "entities.0.source", "/nonexistent/robot.urdf"),
    ("settings timestep negative", "settings.timestep", -0.001),
    ("settings unknown solver", "settings.solver", "magic"),
    ("settings gravity short", "settings.gravity", [0.0, 0.0]),
    ("layout mismatch", "layout.nq", 99),
    (
        "a push wrench of three",
        "pushes",
        [{"body": "box/base", "wrench": [1, 2, 3], "end_step": 5}],
    ),
    (
        "an unknown command mode",
        "commands",
        [{"actuator": "a", "mode": "fly", "target": 0, "kp": 1, "kv": 1, "effort": 1}],
    ),  # fmt: skip
    ("an unknown field", "extra", 1),
]


@pytest.mark.parametrize(("case", "where", "value"), CASES, ids=[c[0] for c in CASES])
def test_a_damaged_save_is_refused_with_one_message_naming_the_file(
    saved, tmp_path, case: str, where: str, value: object
) -> None:
    path, doc = saved
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(_set(doc, where, value)))
    with pytest.raises((TwinError, ConversionError)) as caught:
        savefile.load(bad)
    message = str(caught.value)
    assert str(bad) in message, f"{case}: the message names no file: {message}"
    keys = [k for k in where.split(".") if not k.isdigit()]
    assert any(k in message for k in keys), f"{case}: the message names none of {keys}: {message}"


@pytest.mark.parametrize(
    "text",
    ['{"format": "twin-world", "version": 1, "name": ' + "[" * 100_000 + "]" * 100_000 + "}",
     "{\"format\": \"twin-world\"", "\ufeff\x00\x01", ""],
    ids=["deeply nested", "truncated", "binary", "empty"],
)  # fmt: skip
def test_unreadable_json_is_refused_not_crashed_on(tmp_path, text: str) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    with pytest.raises(WorldFileError, match="bad.json"):
        savefile.load(bad)


def test_the_save_itself_still_loads(saved) -> None:
    path, _ = saved
    assert savefile.load(path).entity_names() == ["box"]


def test_a_save_is_refused_on_a_device_and_written_through_a_symlink(saved, tmp_path) -> None:
    path, _ = saved
    world = savefile.load(path)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(WorldFileError, match="not a regular file"):
        savefile.save(world, fifo)
    assert stat.S_ISFIFO(fifo.stat().st_mode), "the FIFO is still a FIFO"
    with pytest.raises(WorldFileError, match="is a directory"):
        savefile.save(world, tmp_path)
    target = tmp_path / "real.json"
    target.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    savefile.save(world, link, force=True)  # "old" is not a save: replacing it is asked for
    assert link.is_symlink() and json.loads(target.read_text())["format"] == "twin-world"
    assert stat.S_IMODE(target.stat().st_mode) == 0o600, "a save holds a world's state: 0600"
