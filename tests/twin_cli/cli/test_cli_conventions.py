"""Output for people follows gz and ROS conventions; `--json` keeps every value machine-readable.

One served world, `twin` run as a user runs it (a subprocess with `--world`, output piped):
a missing value prints as `-` (JSON: null), a lidar ray without a return as `.inf` (JSON: null),
and every `--json` stream says in its help when it ends.
"""

from __future__ import annotations

import json
import re

import pytest
from cli_world import twin_ok
from models import block, pendulum_pair
from sensor_models import lidar_post

WORLD = "conventions"
POST_Y = 5.0  # [m] the lidar post's y, away from the pendulums (farther than its 3.5 m range)
WALL_X = 1.0  # [m] centre of the wall in front of the post, on its +x ray
WALL_SIZE = 0.4  # [m] the wall's depth and width (1 m high: every ray at 0.3 m meets it)
RANGE_TOLERANCE = 0.02  # [m] the lidar's 0.015 m resolution and float32 rounding


@pytest.fixture(scope="module")
def world(tmp_path_factory, serve_world):
    """A served world: passive pendulums (no joint has a command target), and a lidar post
    facing a wall that fills a few of its rays; the others see nothing within range."""
    runtime_dir = tmp_path_factory.mktemp("rt")
    with serve_world(runtime_dir, WORLD) as (client, _proc):
        path = runtime_dir / "pendulums.urdf"
        path.write_text(pendulum_pair())
        client.spawn(str(path), name="pendulums", pose={"z": 1.0})
        (runtime_dir / "post.urdf").write_text(lidar_post())
        client.spawn(str(runtime_dir / "post.urdf"), name="post", pose={"y": POST_Y})
        (runtime_dir / "wall.urdf").write_text(block(size=WALL_SIZE, height=1.0, name="wall"))
        client.spawn(
            str(runtime_dir / "wall.urdf"), name="wall", pose={"x": WALL_X, "y": POST_Y, "z": 0.5}
        )
        yield runtime_dir


def _table(text: str) -> list[dict[str, str]]:
    """Rows of a piped table (tab-separated, a header line) by column name."""
    header, *rows = text.splitlines()
    return [dict(zip(header.split("\t"), row.split("\t"), strict=True)) for row in rows]


def test_joints_print_a_missing_target_as_a_dash_and_json_as_null(world):
    rows = _table(twin_ok(world, WORLD, "joints", "pendulums"))
    assert [r["joint"] for r in rows] == ["left_hinge", "right_hinge"]
    assert all(r["target"] == "-" for r in rows), rows
    assert not any("None" in value for r in rows for value in r.values()), rows
    data = json.loads(twin_ok(world, WORLD, "joints", "pendulums", "--json"))
    assert [j["target"] for j in data] == [None, None], "JSON keeps null"


def test_physics_shows_each_setting_once_and_a_field_without_effect_as_not_applicable(world):
    data = json.loads(twin_ok(world, WORLD, "physics", "--json"))
    rows = {r["setting"]: r["value"] for r in _table(twin_ok(world, WORLD, "physics"))}
    unused = rows.pop("not_applicable").split(", ")
    assert "contact_max_correcting_vel=100" in unused, "ODE's default [m/s], not applied"
    names = {item.partition("=")[0] for item in unused}
    assert names == set(data["not_applicable"]), unused
    assert not names & set(rows), f"shown as a setting and as not applicable: {names & set(rows)}"
    assert rows["gravity"] == "0 0 -9.81", "as `twin gravity` prints it [m/s²]"
    assert rows["timestep"] == f"{data['timestep']:g}"


def _strict(constant: str) -> None:
    raise AssertionError(f"{constant} is not JSON")


def _ranges(text: str) -> list[str]:
    """The `- value` items under `ranges:` in `ros2 topic echo`'s text of a LaserScan."""
    lines = text.splitlines()
    start = lines.index("ranges:") + 1
    items = []
    for line in lines[start:]:
        if not line.startswith("- "):
            break
        items.append(line[2:])
    return items


def test_echo_prints_a_ray_without_return_as_inf_and_json_as_null(world):
    text = twin_ok(world, WORLD, "topics", "echo", "/post/scan", "-n", "1")
    ranges = _ranges(text)
    assert len(ranges) == 128 + 1 and ranges[-1] == "'...'", "ros2 topic echo's 128 items"
    ranges = ranges[:-1]
    hits = [float(r) for r in ranges if r != ".inf"]
    assert "null" not in text and "None" not in text
    assert 10 <= len(hits) < len(ranges), f"{len(hits)} rays meet the wall: {ranges}"
    near = WALL_X - WALL_SIZE / 2  # [m] the wall's face, straight ahead
    assert min(hits) == pytest.approx(near, abs=RANGE_TOLERANCE)
    line = twin_ok(world, WORLD, "topics", "echo", "/post/scan", "-n", "1", "--json")
    message = json.loads(line, parse_constant=_strict)["message"]
    as_json = message["ranges"][:128]
    assert [r is None for r in as_json] == [r == ".inf" for r in ranges], "inf: null in JSON"
    assert [r for r in as_json if r is not None] == pytest.approx(hits, abs=RANGE_TOLERANCE)
    help_text = twin_ok(world, WORLD, "topics", "echo", "--help")
    words = " ".join(help_text.replace("│", " ").split())
    assert re.search(r"non-finite number \(.*\) is null", words), help_text


def _json_help(runtime, *command: str) -> str:
    """The words of the --json option's help in `twin COMMAND --help`."""
    text = twin_ok(runtime, WORLD, *command, "--help").replace("│", " ")
    words = " ".join(text.split())
    found = re.search(r"--json (.*?) --help Show this message", words)
    assert found, words
    return found.group(1)


@pytest.mark.parametrize(
    ("command", "ends"),
    [
        (("stats",), r"streamed until --duration ends or Ctrl-C \(without -d it never ends\)"),
        (("topics", "echo"), r"streamed until -n N or Ctrl-C \(without -n it never ends\)"),
        (("sensors",), r"streamed until --duration ends"),
        (("record",), r"when it ends .*Ctrl-C"),
    ],
    ids=["stats", "topics echo", "sensors", "record"],
)
def test_every_json_stream_says_in_its_help_when_it_ends(world, command, ends):
    assert re.search(ends, _json_help(world, *command)), _json_help(world, *command)


def test_stats_json_streams_one_object_a_line_until_its_duration(world):
    lines = twin_ok(world, WORLD, "stats", "--json", "-d", "0.5").splitlines()
    stats = [json.loads(line) for line in lines]
    assert 2 <= len(stats) <= 4, f"0.5 s at 0.2 s a line: {len(stats)} lines"
    assert all({"factor", "sim_time", "real_time", "paused"} <= set(s) for s in stats)
