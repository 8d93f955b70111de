"""Model and link names with spaces and Unicode, accepted and kept as libsdformat keeps them.

gz-sim's own heightmap example names a model `Heightmap Bowl`. Such a name is the entity's
name in a served world and in `twin spawn`/`twin list`/`twin delete` (quoted in a shell), the
MJCF model's and bodies' names; only a file name is mapped (`Heightmap_Bowl.xml`).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from sdf_frame_models import X, assert_pose
from sdf_libsdformat_models import world_link_poses

from converters.pipeline import convert_full
from twin_cli.names import as_entity_name, name_problem, topic_segment
from twin_cli.world.sdf_world import world_from_sdf

TOL = 1e-9  # [kg], [kg m²], [m]
BOWL = "Heightmap Bowl"
BOT = "Ünïcödé bot"
LINK = "körper"


def _link(name: str, mass: float) -> str:
    """A link of `mass` [kg] with inertia diag(0.1, 0.2, 0.3) [kg m²] and a small box."""
    return (
        f'<link name="{name}"><inertial><mass>{mass}</mass><inertia><ixx>0.1</ixx><iyy>0.2</iyy>'
        "<izz>0.3</izz></inertia></inertial><collision name='c'><geometry><box>"
        "<size>0.2 0.2 0.2</size></box></geometry></collision></link>"
    )


def test_a_world_keeps_model_and_link_names_with_spaces_and_unicode(tmp_path: Path) -> None:
    path = tmp_path / "bowl.sdf"
    path.write_text(
        '<?xml version="1.0"?>\n<sdf version="1.9"><world name="w">'
        f'<model name="{BOWL}"><static>true</static><pose>1 2 0 0 0 0</pose>'
        f"{_link('base link', 1.0)}</model>"
        f'<model name="{BOT}"><pose>0 0 1 0 0 0.5</pose>{_link(LINK, 2.0)}</model>'
        "</world></sdf>\n",
        encoding="utf-8",
    )
    world = world_from_sdf(path)
    assert [e.name for e in world.entities()] == [BOWL, BOT]
    poses = world_link_poses(world)
    assert_pose(poses[f"{BOWL}/base link"], X(1, 2, 0), f"{BOWL}/base link")
    assert_pose(poses[f"{BOT}/{LINK}"], X(0, 0, 1, 0, 0, 0.5), f"{BOT}/{LINK}")
    body = world.model.body(f"{BOT}/{LINK}").id
    assert world.model.body_mass[body] == pytest.approx(2.0, abs=TOL), "[kg]"
    np.testing.assert_allclose(world.model.body_inertia[body], [0.1, 0.2, 0.3], rtol=0, atol=TOL)


def test_convert_keeps_the_name_in_the_mjcf_and_maps_only_the_file_name(tmp_path: Path) -> None:
    path = tmp_path / "bowl.sdf"
    path.write_text(
        f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="{BOWL}">'
        f"{_link('base link', 3.0)}</model></sdf>\n"
    )
    done = convert_full(path)
    assert done.spec.modelname == BOWL and done.report.robot == BOWL
    out = tmp_path / "out"
    cli = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "convert", str(path), "-o", str(out)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert cli.returncode == 0, cli.stderr
    model = mujoco.MjModel.from_xml_path(str(out / "Heightmap_Bowl.xml"))
    assert model.body(1).name == "base link"
    assert model.body_mass[1] == pytest.approx(3.0, abs=TOL), "[kg]"


def _twin(env: dict[str, str], *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *args],
        env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip


def test_spawn_list_pose_and_delete_an_entity_whose_name_has_a_space(tmp_path: Path) -> None:
    path = tmp_path / "bowl.sdf"
    path.write_text(
        f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="{BOWL}">'
        f"{_link('base link', 1.0)}</model></sdf>\n"
    )
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(tmp_path / "rt"), "TWIN_AUTOSAVE": "0"}
    try:
        spawned = _twin(env, "spawn", str(path), "-x", "1", "-z", "2")
        assert spawned.returncode == 0, spawned.stderr
        assert spawned.stdout.strip() == BOWL, "the model's own name, as given"
        named = _twin(env, "spawn", str(path), "--name", BOT, "-x", "-1", "-z", "2")
        assert named.returncode == 0, named.stderr
        listed = _twin(env, "list", "--json")
        entities = {e["name"]: e for e in json.loads(listed.stdout)}
        assert set(entities) == {BOWL, BOT}, listed.stdout
        assert entities[BOWL]["position"][0] == pytest.approx(1.0, abs=1e-6), "x [m]"
        pose = _twin(env, "pose", BOWL)
        assert pose.returncode == 0 and float(pose.stdout.split()[0]) == pytest.approx(1.0), pose
        assert _twin(env, "delete", BOWL).returncode == 0
        listed = _twin(env, "list", "--json")
        assert [e["name"] for e in json.loads(listed.stdout)] == [BOT]
        missing = _twin(env, "delete", BOWL)
        assert missing.returncode == 2 and f"Entity [{BOWL}] does not exist" in missing.stderr
        assert "Traceback" not in missing.stderr
    finally:
        _twin(env, "stop")


@pytest.mark.parametrize(
    ("given", "entity"),
    [(BOWL, BOWL), (BOT, BOT), ("arm/left", "arm_left"), (" padded ", "padded"),
     ("tab\there", "tab_here"), ("/", "_"), ("", "model")],
)  # fmt: skip
def test_a_models_name_becomes_an_entity_name_changed_only_where_it_must(given, entity) -> None:
    assert as_entity_name(given) == entity
    assert name_problem(entity) is None


@pytest.mark.parametrize(
    ("entity", "segment"),
    [(BOWL, "Heightmap_Bowl"), (BOT, "Unicode_bot"), ("robot_1", "robot_1"), ("3pi", "_3pi"),
     ("a-b.c", "a_b_c")],
)  # fmt: skip
def test_an_entity_name_as_a_ros_topic_segment(entity, segment) -> None:
    assert topic_segment(entity) == segment
    assert re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", segment), "a valid ROS 2 name token"
