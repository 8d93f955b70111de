"""URDF parsing: capsules accepted, transmissions choose actuators, raw-XML checks."""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import pytest

import converters
from converters.errors import BadNumberError, MalformedXMLError, URDFStructureError
from converters.pipeline import convert_full
from converters.urdf.reader import parse_urdf

LINK = (
    '<link name="{n}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
    'ixy="0" ixz="0" iyz="0"/></inertial>{geom}</link>'
)
CAPSULE = '<collision><geometry><capsule radius="0.05" length="0.3"/></geometry></collision>'


def _joint(name: str, child: str) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="base"/><child link="{child}"/>'
        '<limit lower="-1" upper="1" effort="3" velocity="1"/></joint>'
    )


def test_public_names_exist() -> None:
    for name in converters.__all__:
        assert getattr(converters, name) is not None, name


def test_capsule_becomes_a_mujoco_capsule(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r">{LINK.format(n="base", geom=CAPSULE)}</robot>')
    model = convert_full(path).spec.compile()
    geom = model.geom("base_collision_0")
    assert geom.type[0] == mujoco.mjtGeom.mjGEOM_CAPSULE, "geom type"
    assert geom.size[:2].tolist() == pytest.approx([0.05, 0.15]), "radius, half length [m]"


def test_transmissions_choose_the_actuated_joints(tmp_path: Path) -> None:
    links = "".join(LINK.format(n=n, geom="") for n in ("base", "a", "b"))
    transmission = (
        '<transmission name="t"><type>x</type><joint name="jb">'
        "<hardwareInterface>EffortJointInterface</hardwareInterface></joint>"
        "</transmission>"
    )
    path = tmp_path / "r.urdf"
    path.write_text(
        f'<robot name="r">{links}{_joint("ja", "a")}{_joint("jb", "b")}{transmission}</robot>'
    )
    spec = convert_full(path).spec
    model = spec.compile()
    assert [model.actuator(i).name for i in range(model.nu)] == ["jb", "ja"], "motors"
    records = json.loads(spec.text("control").data)
    assert records["jb"]["modes"] == ["effort"], "the transmission's interface"
    assert (records["ja"]["source"], records["ja"]["modes"]) == ("passive", ["effort", "velocity"])


@pytest.mark.parametrize(
    ("text", "error", "needle"),
    [
        ('<robot name="r"><link name="a">', MalformedXMLError, "r.urdf:1:"),
        (
            '<robot name="r"><link name="a"><visual><origin xyz="1 2"/></visual></link></robot>',
            BadNumberError,
            "xyz='1 2'",
        ),
        (
            '<robot name="r"><link name="a"/><joint name="j" type="fixed"><parent link="a"/>'
            '<child link="a"/></joint></robot>',
            URDFStructureError,
            "joins link 'a' to itself",
        ),
        (
            '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">'
            '<parent link="a"/><child link="b"/></joint><joint name="j" type="fixed">'
            '<parent link="a"/><child link="b"/></joint></robot>',
            URDFStructureError,
            "joint 'j'",
        ),
        (
            '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixd">'
            '<parent link="a"/><child link="b"/></joint></robot>',
            URDFStructureError,
            "type 'fixd' is not a URDF joint type; use one of: revolute, continuous",
        ),
        (
            '<robot name="r"><link name="a"><collision><geometry/></collision></link></robot>',
            URDFStructureError,
            "link 'a' <collision> 0 <geometry>: holds nothing; give exactly one of: <box>",
        ),
    ],
)
def test_structural_errors_name_the_culprit(text: str, error: type, needle: str) -> None:
    with pytest.raises(error, match=None) as caught:
        parse_urdf(text, "r.urdf", Path("."))
    assert needle in str(caught.value), str(caught.value)


def test_default_xml_namespace_on_robot_is_accepted(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    link = LINK.format(n="base", geom=CAPSULE)
    path.write_text(f'<robot name="r" xmlns="http://www.ros.org">{link}</robot>')
    assert convert_full(path).spec.compile().nbody == 2, "world + base"
