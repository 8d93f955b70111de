"""Output for people follows gz and ROS conventions; `--json` keeps every value machine-readable.

One served world, `twin` run as a user runs it (a subprocess with `--world`, output piped):
a missing value prints as `-` (JSON: null).
"""

from __future__ import annotations

import json

import pytest
from cli_world import twin_ok
from models import pendulum_pair

WORLD = "conventions"


@pytest.fixture(scope="module")
def world(tmp_path_factory, serve_world):
    """A served world with a pair of passive pendulums (no joint has a command target)."""
    runtime_dir = tmp_path_factory.mktemp("rt")
    with serve_world(runtime_dir, WORLD) as (client, _proc):
        path = runtime_dir / "pendulums.urdf"
        path.write_text(pendulum_pair())
        client.spawn(str(path), name="pendulums", pose={"z": 1.0})
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
