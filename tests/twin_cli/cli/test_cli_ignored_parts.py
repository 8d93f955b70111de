"""What Gazebo loads a robot without, end to end: `twin convert`, `twin spawn` on a real server
and `twin validate --junit/--markdown` on a URDF with tags naming missing parts and visuals
whose mesh is missing.

Gazebo loads such a robot without those parts; twin does too, warning about each, `--strict`
refuses them (exit 2, each named with the fix) and `twin validate` fails `ignored_parts` naming
each. A missing collision mesh stays an error (`test_cli_convert.BAD_INPUTS`).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from corpus_registry import (
    CORPUS,
    DANGLING,
    NON_PHYSICAL_INERTIA,
    PACKAGES_ROOT,
    corpus_ids,
    package_paths,
)

WORLD = "ignored_parts"
INERTIAL = (
    '<inertial><mass value="{m}"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)
MESH_VISUAL = '<visual name="{n}"><geometry><mesh filename="{uri}"/></geometry></visual>'
LIDAR = (
    '<gazebo reference="lidar_linkk"><sensor type="ray" name="front_lidar"><ray><scan>'
    "<horizontal><samples>8</samples></horizontal></scan><range><min>0.1</min>"
    "<max>5</max></range></ray></sensor></gazebo>"
)
TRANSMISSION = (
    '<transmission name="t"><type>transmission_interface/SimpleTransmission</type>'
    '<joint name="elbow"><hardwareInterface>hardware_interface/EffortJointInterface'
    '</hardwareInterface></joint><actuator name="m"/></transmission>'
)
# What each left-out part's warning, refusal and failed check must name.
DANGLING_NAMED = ("<gazebo reference='lidar_linkk'>", "sensor 'front_lidar'", "'elbow'")
VISUAL_NAMED = ("package://no_such_pkg/meshes/shell.stl", "meshes/nothere.stl")


def robot_urdf(*, dangling: bool = True, missing_visuals: bool = True) -> str:
    """A base with a box visual and a hinged arm; optionally a lidar on a misspelt link, a
    transmission on a joint it lacks, and two visuals whose mesh (or package) is missing."""
    visuals = '<visual name="box"><geometry><box size="0.2 0.2 0.2"/></geometry></visual>'
    if missing_visuals:
        visuals += MESH_VISUAL.format(n="shell", uri="package://no_such_pkg/meshes/shell.stl")
        visuals += MESH_VISUAL.format(n="cover", uri="meshes/nothere.stl")
    tags = LIDAR + TRANSMISSION if dangling else ""
    return f"""<robot name="partbot">
  <link name="base">{INERTIAL.format(m=2)}{visuals}
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="arm">{INERTIAL.format(m=0.5)}
    <collision><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.2"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  {tags}
</robot>"""


def write(tmp_path: Path, text: str, name: str = "partbot.urdf") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def twin(*args: object, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    """The `twin` command line, in a fresh process, as a user runs it."""
    clean = {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"}
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=clean,
    )


def assert_names(text: str, parts: tuple[str, ...] | list[str], what: str) -> None:
    for part in parts:
        assert part in text, f"{what}: {part!r} missing from {text!r}"


# --- twin convert ---------------------------------------------------------------------------


@pytest.mark.parametrize("flag", [(), ("--drop-dangling",)], ids=["default", "drop-dangling"])
def test_convert_leaves_out_dangling_tags_and_missing_visuals_listing_each(tmp_path, flag):
    """Declared: 3 visuals (1 box, 2 missing meshes) and 2 collisions; written: 1 and 2."""
    import mujoco

    path = write(tmp_path, robot_urdf())
    done = twin("convert", path, "-o", tmp_path / "out", "--collision", "mesh", "--json", *flag)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    warned = "\n".join(
        f"{e['subject']}: {e['detail']}" for e in report["entries"] if e["outcome"] == "warning"
    )
    assert_names(warned, [*DANGLING_NAMED, *VISUAL_NAMED, "no_such_pkg=PATH"], "report")
    assert warned.count("left out") == 4, f"4 parts left out, one warning each: {warned}"
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "scene.xml"))
    groups = [int(model.geom_group[i]) for i in range(model.ngeom) if model.geom_bodyid[i] > 0]
    assert groups.count(2) == 1, f"visual geoms (group 2): {groups}; only the box is drawn"
    assert groups.count(3) == 2, f"collision geoms (group 3): {groups}; both are kept"
    assert model.nsensor == 0, "the lidar on a missing link is left out"


def test_convert_strict_refuses_dangling_tags_naming_each_and_the_fix(tmp_path):
    path = write(tmp_path, robot_urdf())
    done = twin("convert", path, "-o", tmp_path / "out", "--strict")
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert_names(done.stderr, [*DANGLING_NAMED, "partbot.urdf", "base, arm", "--strict"], "refusal")
    assert not (tmp_path / "out").exists(), "a refused conversion wrote output"


def test_convert_strict_refuses_missing_visual_meshes_naming_each_and_the_fix(tmp_path):
    path = write(tmp_path, robot_urdf(dangling=False))
    done = twin("convert", path, "-o", tmp_path / "out", "--strict")
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    fixes = ["--package no_such_pkg=PATH", "link 'base' <visual> 1", "--strict"]
    assert_names(done.stderr, [*VISUAL_NAMED, *fixes], "refusal")


SDF_MODEL = """<sdf version="1.9"><model name="sdfbot"><link name="body">
  <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia>
  </inertial>
  <visual name="shell"><geometry><mesh><uri>model://no_such_model/shell.dae</uri></mesh>
  </geometry></visual>
  <collision name="box"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision>
</link></model></sdf>"""


def test_sdf_visual_whose_model_is_missing_is_left_out_and_refused_when_strict(tmp_path):
    path = write(tmp_path, SDF_MODEL, "sdfbot.sdf")
    done = twin("convert", path, "-o", tmp_path / "out", "--json")
    assert done.returncode == 0, done.stderr
    warned = [e for e in json.loads(done.stdout)["entries"] if e["outcome"] == "warning"]
    assert [e["subject"] for e in warned] == ["link 'body' <visual name='shell'>"], warned
    assert "no_such_model" in warned[0]["detail"], warned
    refused = twin("convert", path, "-o", tmp_path / "strict", "--strict")
    assert refused.returncode == 2 and "Traceback" not in refused.stderr, refused.stderr
    assert_names(refused.stderr, ["model://no_such_model/shell.dae", "--strict"], "refusal")


# --- twin spawn -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def world(tmp_path_factory, serve_world):
    with serve_world(tmp_path_factory.mktemp("rt"), WORLD) as served:
        yield served


def spawn(*args: object, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    return twin("spawn", *args, "--world", WORLD, timeout=timeout)


def entity_names(world) -> list[str]:
    client, _ = world
    return [e["name"] for e in client.entities()]


def test_spawn_leaves_out_what_gazebo_ignores_with_a_warning_and_strict_refuses(world, tmp_path):
    path = write(tmp_path, robot_urdf())
    done = spawn(path, "--name", "p1")
    assert done.returncode == 0 and done.stdout.strip() == "p1", done.stderr
    warnings = [line for line in done.stderr.splitlines() if line.startswith("twin: warning:")]
    assert_names("\n".join(warnings), [*DANGLING_NAMED, *VISUAL_NAMED], "spawn warnings")
    refused = spawn(path, "--name", "p2", "--strict")
    assert refused.returncode == 2 and "Traceback" not in refused.stderr, refused.stderr
    assert_names(refused.stderr, [*DANGLING_NAMED, "--strict"], "spawn refusal")
    alias = spawn(path, "--name", "p3", "--drop-dangling")
    assert alias.returncode == 0, alias.stderr
    names = entity_names(world)
    assert "p1" in names and "p3" in names and "p2" not in names, names


TETRAHEDRON_STL = """solid t
facet normal 0 0 -1
outer loop
vertex 0 0 0
vertex 0 0.1 0
vertex 0.1 0 0
endloop
endfacet
facet normal 0 -1 0
outer loop
vertex 0 0 0
vertex 0.1 0 0
vertex 0 0 0.1
endloop
endfacet
facet normal -1 0 0
outer loop
vertex 0 0 0
vertex 0 0 0.1
vertex 0 0.1 0
endloop
endfacet
facet normal 0.577 0.577 0.577
outer loop
vertex 0.1 0 0
vertex 0 0.1 0
vertex 0 0 0.1
endloop
endfacet
endsolid t
"""


def test_a_missing_visual_mesh_that_appears_later_is_drawn_on_the_next_spawn(world, tmp_path):
    """The server caches conversions by the files they read; a mesh sought and not found counts
    as one, so a cached conversion without it is not handed out once it exists."""
    robot = robot_urdf(dangling=False, missing_visuals=False).replace(
        "</visual>", "</visual>" + MESH_VISUAL.format(n="late", uri="meshes/late.stl"), 1
    )
    path = write(tmp_path, robot, "late.urdf")
    before = spawn(path, "--name", "late0")
    assert before.returncode == 0 and "meshes/late.stl" in before.stderr, before.stderr
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "late.stl").write_text(TETRAHEDRON_STL)
    after = spawn(path, "--name", "late1")
    assert after.returncode == 0 and "late.stl" not in after.stderr, after.stderr


def test_a_save_of_older_twin_with_drop_dangling_loads_and_a_new_save_records_strict(
    world, tmp_path
):
    """Saves written before dropping was the default carry `drop_dangling`; they still load."""
    path = write(tmp_path, robot_urdf())
    assert spawn(path, "--name", "saved").returncode == 0
    save = tmp_path / "world.json"
    done = twin("save", save, "--world", WORLD)
    assert done.returncode == 0, done.stderr
    saved = json.loads(save.read_text())
    (entity,) = [e for e in saved["entities"] if e["name"] == "saved"]
    assert entity["strict"] is False and "drop_dangling" not in entity, entity.keys()
    for e in saved["entities"]:
        e.pop("strict")
        e["drop_dangling"] = True  # as an older twin wrote it
    save.write_text(json.dumps(saved))
    done = twin("load", save, "--world", WORLD)
    assert done.returncode == 0, done.stderr
    assert "saved" in entity_names(world), entity_names(world)


@pytest.mark.parametrize("robot_id", corpus_ids(DANGLING))
def test_corpus_robot_with_dangling_references_spawns_with_a_warning(world, robot_id):
    """The corpus robots whose Gazebo tags name a link they lack (a quadruped, a small arm)."""
    robot = CORPUS[robot_id]
    options: list[str] = []
    for name, directory in package_paths(robot).items():
        options += ["--package", f"{name}={directory}"]
    for name, value in robot["xacro_args"].items():
        options += ["--arg", f"{name}:={value}"]
    if robot_id in NON_PHYSICAL_INERTIA:
        options.append("--repair-inertia")
    entry = PACKAGES_ROOT / robot["entry"]
    done = spawn(entry, "--name", robot_id, *options, "-z", "1")
    assert done.returncode == 0 and done.stdout.strip() == robot_id, done.stderr
    links = robot["gazebo_references_to_missing_links"]
    references = [f"<gazebo reference='{link}'>" for link in links]
    assert_names(done.stderr, references, f"{robot_id} warnings")
    refused = spawn(entry, "--name", f"{robot_id}_strict", *options, "--strict")
    assert refused.returncode == 2 and "Traceback" not in refused.stderr, refused.stderr
    assert_names(refused.stderr, [*references, "--strict"], f"{robot_id} refusal")
    names = entity_names(world)
    assert robot_id in names and f"{robot_id}_strict" not in names, names


# --- twin validate --------------------------------------------------------------------------


def test_validate_fails_ignored_parts_naming_each_in_junit_and_markdown(tmp_path):
    path = write(tmp_path, robot_urdf())
    junit, markdown = tmp_path / "v.xml", tmp_path / "v.md"
    done = twin(
        "validate", path, "--only", "ignored_parts", "--junit", junit, "--markdown", markdown
    )
    assert done.returncode == 1, done.stdout + done.stderr
    (case,) = [
        c for c in ET.parse(junit).getroot().iter("testcase") if c.get("name") == "ignored_parts"
    ]
    failure = case.find("failure")
    assert failure is not None, ET.tostring(case, encoding="unicode")
    assert "4 part(s) left out" in (failure.text or ""), failure.text
    assert_names(failure.text or "", [*DANGLING_NAMED, *VISUAL_NAMED], "JUnit failure")
    text = markdown.read_text()
    assert_names(text, ["ignored_parts", "lidar_linkk", "no_such_pkg", "nothere.stl"], "Markdown")


def test_validate_passes_ignored_parts_when_nothing_is_left_out(tmp_path):
    path = write(tmp_path, robot_urdf(dangling=False, missing_visuals=False))
    junit = tmp_path / "v.xml"
    done = twin("validate", path, "--only", "ignored_parts", "--junit", junit)
    assert done.returncode == 0, done.stdout + done.stderr
    (case,) = [
        c for c in ET.parse(junit).getroot().iter("testcase") if c.get("name") == "ignored_parts"
    ]
    assert case.find("failure") is None and case.find("skipped") is None, ET.tostring(case)
