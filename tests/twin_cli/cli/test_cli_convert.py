"""`twin convert` / `twin inspect` end to end: outputs, reproducibility, and every input error."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from corpus_registry import CORPUS, PACKAGES_ROOT, needs_corpus

from scenarios import HUMANOID

GOOD_LINK = (
    '<link name="{n}"><inertial><mass value="1"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
)


def twin(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    code = "import sys; from twin_cli.cli.app import main; sys.argv[0] = 'twin'; main()"
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd, timeout=120
    )


def _robot(tmp_path: Path, body: str, name: str = "bad.urdf") -> Path:
    path = tmp_path / name
    path.write_text(body)
    return path


def _joint(name: str, parent: str, child: str) -> str:
    return (
        f'<joint name="{name}" type="continuous"><parent link="{parent}"/>'
        f'<child link="{child}"/></joint>'
    )


BAD_INPUTS = {
    "malformed_xml": (
        '<robot name="r">\n  <link name="a">\n</robot>',
        ["bad.urdf:3:", "malformed"],
    ),
    "unknown_child": (
        f'<robot name="r">{GOOD_LINK.format(n="a")}{_joint("j", "a", "ghost")}</robot>',
        ["joint 'j'", "'ghost'"],
    ),
    "self_joint": (
        '<robot name="r">'
        + "".join(GOOD_LINK.format(n=n) for n in "ab")
        + _joint("j1", "a", "b")
        + _joint("j2", "b", "b")
        + "</robot>",
        ["joint 'j2'", "link 'b' to itself"],
    ),
    "two_parents": (
        '<robot name="r">'
        + "".join(GOOD_LINK.format(n=n) for n in "abc")
        + _joint("j1", "a", "b")
        + _joint("j2", "c", "b")
        + "</robot>",
        ["link 'b'", "two joints", "link 'c' is not joined"],
    ),
    "several_roots": (
        '<robot name="r">' + "".join(GOOD_LINK.format(n=n) for n in "ab") + "</robot>",
        ["a, b", "2 root links"],
    ),
    "duplicate_link": (
        '<robot name="r">' + GOOD_LINK.format(n="a") * 2 + "</robot>",
        ["link 'a'", "defined twice"],
    ),
    "bad_number": (
        '<robot name="r"><link name="a"><inertial><mass value="heavy"/></inertial></link></robot>',
        ["link 'a'", "'heavy'"],
    ),
    "missing_collision_mesh": (  # a missing visual mesh is left out instead, as in Gazebo
        '<robot name="r"><link name="a"><collision><geometry><mesh filename='
        '"meshes/nothere.stl"/></geometry></collision></link></robot>',
        ["nothere.stl", "link 'a'"],
    ),
    "unknown_collision_package": (
        '<robot name="r"><link name="a"><collision><geometry><mesh filename='
        '"package://no_such_pkg/m.stl"/></geometry></collision></link></robot>',
        ["no_such_pkg", "package://no_such_pkg/m.stl", "link 'a'", "tried"],
    ),
    "huge_inertia": (
        '<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="1e308" '
        'iyy="1e308" izz="1e308" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>',
        ["link 'a'", "ixx=1e+308", "beyond", "mass [kg] and inertia [kg m²]"],
    ),
    "nan_inertia": (
        '<robot name="r"><link name="a"><inertial><origin rpy="0.3 0 0"/><mass value="1"/>'
        '<inertia ixx="nan" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>',
        ["link 'a'", "'nan'"],
    ),
    "zero_axis": (
        '<robot name="r">'
        + "".join(GOOD_LINK.format(n=n) for n in "ab")
        + '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<axis xyz="0 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        + "</robot>",
        ["joint 'j' <axis>", "no direction", "xyz='0 0 1'"],
    ),
    "mimic_circle": (
        '<robot name="r">'
        + "".join(GOOD_LINK.format(n=n) for n in "abc")
        + "".join(
            f'<joint name="{j}" type="revolute"><parent link="a"/><child link="{c}"/>'
            f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
            f'<mimic joint="{leader}"/></joint>'
            for j, c, leader in (("j1", "b", "j2"), ("j2", "c", "j1"))
        )
        + "</robot>",
        ["joint 'j1' <mimic>", "j1 → j2 → j1", "remove the <mimic>"],
    ),
    "massless_moving_link": (
        '<robot name="r">'
        + GOOD_LINK.format(n="a")
        + '<link name="b"/>'
        + _joint("j", "a", "b")
        + "</robot>",
        ["link 'b'", "--repair-inertia"],
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_input_exits_2_with_one_message_naming_the_culprit(case: str, tmp_path: Path) -> None:
    text, needles = BAD_INPUTS[case]
    result = twin("convert", str(_robot(tmp_path, text)), "-o", str(tmp_path / "out"))
    assert result.returncode == 2, f"{case}: exit code {result.returncode}, stderr {result.stderr}"
    assert "Traceback" not in result.stderr, f"{case}: traceback leaked:\n{result.stderr}"
    assert result.stderr.startswith("Error: "), f"{case}: stderr {result.stderr!r}"
    for needle in needles:
        assert needle in result.stderr, f"{case}: {needle!r} missing from {result.stderr!r}"
    assert not (tmp_path / "out").exists(), f"{case}: a failed conversion wrote output"


@needs_corpus
def test_xacro_error_names_the_file_and_xacros_message(tmp_path: Path) -> None:
    robot = CORPUS["aliengo"]
    result = twin("convert", str(PACKAGES_ROOT / robot["entry"]), "-o", str(tmp_path / "o"))
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert "robot.xacro" in result.stderr and "DEBUG" in result.stderr, result.stderr


@needs_corpus
def test_non_physical_inertia_exits_2_naming_the_link(tmp_path: Path) -> None:
    robot = CORPUS["hyq"]
    result = twin(
        "convert",
        str(PACKAGES_ROOT / robot["entry"]),
        "--package",
        f"example-robot-data={PACKAGES_ROOT / 'example-robot-data'}",
        "-o",
        str(tmp_path / "o"),
        "--collision",
        "hull",
    )
    assert result.returncode == 2, result.stderr
    assert "link 'base_link'" in result.stderr and "positive definite" in result.stderr


def _digest(directory: Path) -> dict[str, str]:
    return {
        str(p.relative_to(directory)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(directory.rglob("*"))
        if p.is_file()
    }


@needs_corpus
def test_convert_writes_a_loadable_scene_byte_identical_on_repeat(tmp_path: Path) -> None:
    import mujoco

    robot = CORPUS["r2d2_macroed"]
    args = [
        str(PACKAGES_ROOT / robot["entry"]),
        "--package",
        f"urdf_tutorial={PACKAGES_ROOT / 'urdf_tutorial'}",
        "--collision",
        "hull",
        "--json",
    ]
    first = twin("convert", *args, "-o", str(tmp_path / "a"), cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    report = json.loads(first.stdout)
    assert report["robot"] == "macroed" and Path(report["scene"]).is_file(), report.keys()
    assert twin("convert", *args, "-o", str(tmp_path / "b")).returncode == 0
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b"), "same input, different bytes"
    assert any(p.suffix == ".stl" for p in (tmp_path / "a" / "assets").iterdir()), "mesh assets"
    xml = (tmp_path / "a" / "macroed.xml").read_text()
    assert str(tmp_path) not in xml and "package://" not in xml, "paths must be relative"
    scene = mujoco.MjModel.from_xml_path(str(tmp_path / "a" / "scene.xml"))
    assert scene.geom("ground").friction[0] == pytest.approx(100.0), "Gazebo ground μ"


def test_print_writes_mjcf_to_stdout(tmp_path: Path) -> None:
    import mujoco

    result = twin("convert", str(HUMANOID), "--print", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    model = mujoco.MjModel.from_xml_string(result.stdout)
    assert model.nu == 11, f"humanoid motors in printed MJCF: {model.nu}"


def test_print_is_the_model_the_directory_holds(tmp_path: Path) -> None:
    """--print gives what the written file gives: contact priorities and exported servos."""
    import mujoco
    import numpy as np
    from interface_models import panda_arm

    source = tmp_path / "panda.urdf"
    source.write_text(panda_arm())
    printed = twin("convert", str(source), "--print", cwd=tmp_path)
    assert printed.returncode == 0, printed.stderr
    written = twin("convert", str(source), "-o", str(tmp_path / "out"), "--json", cwd=tmp_path)
    assert written.returncode == 0, written.stderr
    a = mujoco.MjModel.from_xml_string(printed.stdout)
    b = mujoco.MjModel.from_xml_path(json.loads(written.stdout)["model"])
    assert (a.geom_priority > 0).any(), "printed geoms carry the Gazebo min-μ priority"
    for field in ("geom_priority", "actuator_gainprm", "actuator_biasprm", "actuator_ctrlrange"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    servos = [e for e in json.loads(written.stdout)["entries"] if "servos" in e["subject"]]
    assert servos and "panda_joint1" in servos[0]["detail"], "the report names the servos"


def test_inspect_json_reports_total_mass_and_tree(tmp_path: Path) -> None:
    from converters.pipeline import convert_full

    result = twin("inspect", str(HUMANOID), "--json")
    assert result.returncode == 0, result.stderr
    stats = json.loads(result.stdout)
    declared = sum(
        float(link.inertial.mass)
        for link in convert_full(HUMANOID).description.links
        if link.inertial is not None
    )
    assert stats["total_mass_kg"] == pytest.approx(declared, rel=1e-12), "total mass [kg]"
    assert stats["tree"][0]["depth"] == 0 and len(stats["center_of_mass_m"]) == 3


def _nan_stl(path: Path) -> None:
    """A binary STL of four triangles, one vertex NaN."""
    import struct

    with path.open("wb") as handle:
        handle.write(b"\0" * 80 + struct.pack("<I", 4))
        for k in range(4):
            handle.write(struct.pack("<3f", 0, 0, 1))
            for vertex in ((float("nan"), 0, 0), (1, 0, 0), (0, 1, k)):
                handle.write(struct.pack("<3f", *vertex))
            handle.write(b"\0\0")


@pytest.mark.parametrize("mesh", ["nan.stl", "/dev/zero"])
def test_a_nan_mesh_or_a_device_as_a_mesh_exits_2_naming_it(tmp_path: Path, mesh: str) -> None:
    _nan_stl(tmp_path / "nan.stl")
    body = GOOD_LINK.format(n="base").replace(
        "</link>", f'<collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>'
    )
    result = twin("convert", str(_robot(tmp_path, f'<robot name="r">{body}</robot>')), "-o",
                  str(tmp_path / "out"))  # fmt: skip
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    expected = "not numbers (NaN" if mesh == "nan.stl" else "not a regular file"
    assert mesh in result.stderr and expected in result.stderr, result.stderr


def test_an_sdf_include_circle_exits_2_naming_the_files(tmp_path: Path) -> None:
    for name, other in (("a", "b"), ("b", "a")):
        folder = tmp_path / "models" / name
        folder.mkdir(parents=True)
        (folder / "model.config").write_text(
            f'<?xml version="1.0"?><model><name>{name}</name><sdf version="1.6">model.sdf</sdf>'
            "</model>"
        )
        (folder / "model.sdf").write_text(
            f'<sdf version="1.6"><model name="{name}"><include><uri>model://{other}</uri>'
            f'</include><link name="l{name}"/></model></sdf>'
        )
    env = {**os.environ, "GAZEBO_MODEL_PATH": str(tmp_path / "models")}
    result = subprocess.run(
        [sys.executable, "-m", "twin_cli", "convert", str(tmp_path / "models/a/model.sdf"), "-o",
         str(tmp_path / "out")],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert "includes it" in result.stderr and "model.sdf" in result.stderr, result.stderr
