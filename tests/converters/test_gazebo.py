"""`<gazebo>` tags: parsed values, one table row per tag checked on the compiled MjModel, errors."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest
from corpus_registry import PACKAGES_ROOT, needs_corpus

from converters.errors import GazeboTagError
from converters.gazebo.blocks import parse_gazebo
from converters.gazebo.contact import (
    CONTACT_MU_MAX,
    SOFT_IMPEDANCE,
    friction_priority,
    max_contact_stiffness,
)
from converters.mjcf.builder import ConvertOptions
from converters.pipeline import convert_full
from converters.report import Outcome

BASE_MASS = 2.0
ARM_MASS = 0.5


def tagbot(tags: str) -> str:
    """A floating base with a hinged 'arm' and a 'tip' fixed to the arm (lumped unless kept)."""
    return f"""<robot name="tagbot">
  <link name="base">
    <inertial><mass value="{BASE_MASS}"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="{ARM_MASS}"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.2"/></geometry>
    </collision>
    <visual><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.2"/></geometry></visual>
  </link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="5"/></joint>
  <link name="tip">
    <inertial><mass value="0.1"/>
      <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <joint name="tip_joint" type="fixed"><parent link="arm"/><child link="tip"/>
    <origin xyz="0 0 0.35"/></joint>
  {tags}
</robot>"""


def _convert(tmp_path: Path, tags: str):
    path = tmp_path / "tagbot.urdf"
    path.write_text(tagbot(tags))
    done = convert_full(path)
    return done, done.spec.compile()


def _geom(done, model, link: str, role: str = "collision"):
    origin = done.provenance.geoms_of_link(link, role)[0]
    return model.geom(origin.geom)


def _entry(done, tag: str):
    found = [e for e in done.report.entries if e.tag == tag]
    assert found, f"report has no entry for tag {tag}"
    return found[0]


def _ref(reference: str, body: str) -> str:
    return f'<gazebo reference="{reference}">{body}</gazebo>'


def _stiffness(mass: float, kp: float) -> float:
    return (1 - SOFT_IMPEDANCE) * kp / mass


# (row id, <gazebo> XML, check(done, model)); each check names the quantity it asserts.
TAG_TABLE = [
    (
        "mu1",
        _ref("arm", "<mu1>0.25</mu1>"),
        lambda d, m: (
            _geom(d, m, "arm").friction[0] == pytest.approx(0.25)
            and _geom(d, m, "arm").priority[0] == friction_priority(0.25)
        ),
    ),
    (
        "mu1 of 'no slip' capped, approximated",
        _ref("arm", "<mu1>100000</mu1><mu2>100000</mu2>"),
        lambda d, m: (
            _geom(d, m, "arm").friction[0] == pytest.approx(CONTACT_MU_MAX)
            and _geom(d, m, "arm").priority[0] == friction_priority(CONTACT_MU_MAX)
            and _entry(d, "mu1").outcome is Outcome.APPROXIMATED
        ),
    ),
    (
        "mu2 differs: mu1 on the geom, both in the world's pairs",
        _ref("arm", "<mu1>0.4</mu1><mu2>0.8</mu2>"),
        lambda d, m: (
            _geom(d, m, "arm").friction[0] == pytest.approx(0.4)
            and _entry(d, "mu2").outcome is Outcome.MAPPED
            and list(m.numeric_data[:2]) == pytest.approx([0.4, 0.8])
        ),
    ),
    (
        "kp kd",
        _ref("arm", "<kp>1e4</kp><kd>50</kd>"),
        lambda d, m: (
            _geom(d, m, "arm").solref[0] == pytest.approx(-_stiffness(0.6, 1e4))
            and _geom(d, m, "arm").solimp[0] == pytest.approx(SOFT_IMPEDANCE)
        ),
    ),
    (
        "kp stiffer than the step resolves: clamped, reported with figures",
        _ref("arm", "<kp>1e9</kp><kd>1e5</kd>"),
        lambda d, m: (
            _geom(d, m, "arm").solref[0] == pytest.approx(-max_contact_stiffness())
            and "clamped" in _entry(d, "kp").detail
            and _entry(d, "kp").outcome is Outcome.APPROXIMATED
        ),
    ),
    (
        "kd below the damping floor: raised, reported",
        _ref("arm", "<kp>1e4</kp><kd>1</kd>"),
        lambda d, m: (
            _entry(d, "kd").outcome is Outcome.APPROXIMATED and "raised" in _entry(d, "kd").detail
        ),
    ),
    (
        "kp value attribute",
        _ref("base", '<kp value="2e4"/><kd value="100"/>'),
        lambda d, m: _geom(d, m, "base").solref[0] == pytest.approx(-_stiffness(BASE_MASS, 2e4)),
    ),
    (
        "turnGravityOff",
        _ref("arm", "<turnGravityOff>true</turnGravityOff>"),
        lambda d, m: (
            m.body_gravcomp[m.body("arm").id] == 1.0 and m.body_gravcomp[m.body("base").id] == 0.0
        ),
    ),
    (
        "turnGravityOff false keeps gravity",
        _ref("arm", "<turnGravityOff>false</turnGravityOff>"),
        lambda d, m: m.body_gravcomp[m.body("arm").id] == 0.0,
    ),
    (
        "gravity 0",
        _ref("arm", "<gravity>0</gravity>"),
        lambda d, m: m.body_gravcomp[m.body("arm").id] == 1,
    ),
    (
        "dampingFactor",
        _ref("arm", "<dampingFactor>0.02</dampingFactor>"),
        # b = f/((1 − f)·1 ms) × the arm body's own inertia about the hinge: arm 0.001 + tip
        # (lumped) 1e-4 + 0.1 kg·(0.35 m)² = 0.01335 kg m², by hand.
        lambda d, m: (
            m.dof_damping[m.joint("hinge").dofadr[0]]
            == pytest.approx(0.02 / (0.98 * 0.001) * 0.01335, rel=1e-9)
        ),
    ),
    (
        "material",
        _ref("arm", "<material>Gazebo/Red</material>"),
        lambda d, m: np.allclose(_geom(d, m, "arm", "visual").rgba, [1, 0, 0, 1]),
    ),
    (
        "selfCollide: only the non-adjacent pair base-tip may touch",
        _ref("tip", "<selfCollide>true</selfCollide>")
        + _ref("tip_joint", "<preserveFixedJoint>true</preserveFixedJoint>"),
        lambda d, m: m.nexclude == 2,
    ),
    (
        "springStiffness springReference",
        _ref(
            "hinge", "<springStiffness>3.5</springStiffness><springReference>0.2</springReference>"
        ),
        lambda d, m: (
            m.jnt_stiffness[m.joint("hinge").id] == pytest.approx(3.5)
            and m.qpos_spring[m.joint("hinge").qposadr[0]] == pytest.approx(0.2)
        ),
    ),
    (
        "stopErp",
        _ref("hinge", "<stopErp>0.4</stopErp>"),
        lambda d, m: np.allclose(m.jnt_solref[m.joint("hinge").id], [0.002, 0.5 / 0.4**0.5]),
    ),
    (
        "provideFeedback",
        _ref("hinge", "<provideFeedback>true</provideFeedback>"),
        lambda d, m: _entry(d, "provideFeedback").outcome is Outcome.MAPPED,
    ),
    (
        "implicitSpringDamper",
        _ref("hinge", "<implicitSpringDamper>1</implicitSpringDamper>"),
        lambda d, m: _entry(d, "implicitSpringDamper").outcome is Outcome.APPROXIMATED,
    ),
    (
        "fudgeFactor",
        _ref("hinge", "<fudgeFactor>0.5</fudgeFactor>"),
        lambda d, m: _entry(d, "fudgeFactor").outcome is Outcome.IGNORED,
    ),
    (
        "preserveFixedJoint",
        _ref("tip_joint", "<preserveFixedJoint>true</preserveFixedJoint>"),
        lambda d, m: m.body("tip").parentid[0] == m.body("arm").id,
    ),
    (
        "disableFixedJointLumping",
        _ref("tip_joint", "<disableFixedJointLumping>true</disableFixedJointLumping>"),
        lambda d, m: m.body("tip").parentid[0] == m.body("arm").id,
    ),
    (
        "static",
        "<gazebo><static>true</static></gazebo>",
        lambda d, m: mujoco.mjtJoint.mjJNT_FREE not in list(m.jnt_type),
    ),
    *[
        (
            tag,
            _ref("arm", f"<{tag}>{value}</{tag}>"),
            lambda d, m, tag=tag, outcome=outcome: _entry(d, tag).outcome is outcome,
        )
        for tag, value, outcome in [
            ("fdir1", "1 0 0", Outcome.MAPPED),  # μ1 = μ2 (SDF defaults): no direction
            ("maxVel", "0.5", Outcome.IGNORED),
            ("minDepth", "0.001", Outcome.IGNORED),
        ]
    ],
    (
        "maxContacts laserRetro",
        _ref("arm", "<maxContacts>4</maxContacts><laserRetro>100</laserRetro>"),
        lambda d, m: (
            _entry(d, "maxContacts").outcome is Outcome.IGNORED
            and _entry(d, "laserRetro").outcome is Outcome.IGNORED
        ),
    ),
    (
        "plugin",
        '<gazebo><plugin name="ctl" filename="libgazebo_ros_control.so"/></gazebo>',
        lambda d, m: "libgazebo_ros_control.so" in _entry(d, "plugin").detail,
    ),
    (
        "sensor",
        _ref("arm", '<sensor name="imu" type="imu"><update_rate>100</update_rate></sensor>'),
        lambda d, m: _entry(d, "sensor").outcome is Outcome.MAPPED and m.site("sensor:imu"),
    ),
    (
        "collision block torsional friction",
        _ref(
            "arm",
            "<collision><surface><friction><torsional><coefficient>0.03</coefficient>"
            "</torsional></friction></surface></collision>",
        ),
        lambda d, m: (
            _geom(d, m, "arm").condim[0] == 4
            and _geom(d, m, "arm").friction[1] == pytest.approx(0.03)
        ),
    ),
    (
        "lumped link: collision tag only on its own geoms",
        _ref("tip", "<mu1>0.1</mu1>"),
        lambda d, m: (
            _geom(d, m, "tip").friction[0] == pytest.approx(0.1)
            and _geom(d, m, "arm").friction[0] == pytest.approx(1.0)
            and _geom(d, m, "tip").bodyid[0] == m.body("arm").id
        ),
    ),
    (
        "lumped link: link tag on the merged body",
        _ref("tip", "<turnGravityOff>true</turnGravityOff>"),
        lambda d, m: m.body_gravcomp[m.body("arm").id] == 1.0,
    ),
    (
        "no tags: Gazebo defaults (μ=1 priority, no self-collision, limit erp 0.2, kp 1e12)",
        "",
        lambda d, m: (
            all(m.geom_priority[_geom(d, m, link).id] == 9000 for link in ("base", "arm"))
            and m.nexclude == 1
            and np.allclose(m.jnt_solref[m.joint("hinge").id], [0.002, 0.5 / 0.2**0.5])
            and np.allclose(m.jnt_solimp[m.joint("hinge").id][:2], [0.9999, 0.9999])
            and _geom(d, m, "arm").solref[0] == pytest.approx(-max_contact_stiffness())
        ),
    ),
]


@pytest.mark.parametrize("tags,check", [r[1:] for r in TAG_TABLE], ids=[r[0] for r in TAG_TABLE])
def test_gazebo_tag_maps_onto_compiled_model(tmp_path, tags, check):
    done, model = _convert(tmp_path, tags)
    assert check(done, model), f"compiled model does not show the tag's mapping: {tags}"


def _parse(text: str):
    return parse_gazebo(ET.fromstring(text), "robot.urdf")


def test_value_attribute_text_and_later_block_wins():
    ext = _parse(
        tagbot(
            _ref("arm", '<kp value="5e5"/><mu1> 0.3 </mu1>')
            + _ref("arm", "<mu1>0.7</mu1>")
            + _ref("hinge", "<provideFeedback>Yes</provideFeedback>")
        )
    )
    surface = ext.link("arm").surface
    assert surface.kp == 5e5, "kp from value attribute"
    assert surface.mu1 == 0.7, "the later <gazebo> block overwrites mu1"
    assert ext.joints["hinge"].provide_feedback is True, "boolean 'Yes'"
    assert ext.link("base").surface.is_empty(), "untagged link has an empty surface"


def test_preserved_joints_are_only_fixed_joints_with_the_flag():
    ext = _parse(
        tagbot(
            _ref("tip_joint", "<disableFixedJointLumping>true</disableFixedJointLumping>")
            + _ref("hinge", "<preserveFixedJoint>true</preserveFixedJoint>")
        )
    )
    assert ext.preserved_joints == frozenset({"tip_joint"}), "preserved fixed joints"


def _inline_surface_bot() -> str:
    return tagbot(_ref("base", "<kd>7</kd>")).replace(
        '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>',
        '<collision><geometry><box size="0.2 0.2 0.2"/></geometry><surface><friction><ode>'
        "<mu1>3</mu1><mu2>3</mu2></ode></friction><contact><ode><kp>1e5</kp><kd>1</kd>"
        "</ode></contact></surface></collision>",
    )


def test_inline_surface_and_gazebo_tag_precedence_as_written():
    root = ET.fromstring(_inline_surface_bot())
    surface = parse_gazebo(root, "t.urdf", as_written=True).surface_of("base", 0)
    assert (surface.mu1, surface.kp, surface.kd) == (3.0, 1e5, 7.0), "inline, then <gazebo>"


def test_inline_surface_is_dropped_as_gazebo_drops_it():
    ext = _parse(_inline_surface_bot())
    surface = ext.surface_of("base", 0)
    assert (surface.mu1, surface.kp, surface.kd) == (None, None, 7.0), "only <gazebo> values"
    assert [(d.link, d.index, d.surface.mu1) for d in ext.dropped_surfaces] == [("base", 0, 3.0)]


def test_model_level_tags():
    ext = _parse(
        tagbot(
            '<gazebo><static>1</static><self_collide>true</self_collide><plugin name="p" '
            'filename="libx.so"/></gazebo>'
        )
    )
    assert ext.static and ext.self_collide, "static and self_collide"
    assert [(p.name, p.kind) for p in ext.plugins] == [("p", "libx.so")], "plugin blob"


@pytest.mark.parametrize(
    "tags,tag,value",
    [
        (_ref("arm", "<mu1>slippery</mu1>"), "mu1", "slippery"),
        (_ref("arm", '<kp value="1e5N"/>'), "kp", "1e5N"),
        (_ref("arm", "<fdir1>1 0</fdir1>"), "fdir1", "1 0"),
        (_ref("hinge", "<springStiffness>stiff</springStiffness>"), "springStiffness", "stiff"),
        (_ref("arm", "<selfCollide>maybe</selfCollide>"), "selfCollide", "maybe"),
    ],
)
def test_bad_value_names_file_reference_tag_and_value(tmp_path, tags, tag, value):
    path = tmp_path / "bad.urdf"
    path.write_text(tagbot(tags))
    with pytest.raises(GazeboTagError) as caught:
        convert_full(path)
    message = str(caught.value)
    for part in ("bad.urdf", f"<{tag}>", repr(value), "write "):
        assert part in message, f"error message lacks {part!r}: {message}"
    assert "reference='arm'" in message or "reference='hinge'" in message, message


LIDAR = (
    '<sensor type="ray" name="front_lidar"><ray><scan><horizontal><samples>8</samples>'
    "<min_angle>-0.5</min_angle><max_angle>0.5</max_angle></horizontal></scan>"
    "<range><min>0.1</min><max>5</max></range></ray></sensor>"
)
TRANSMISSION = """<transmission name="t"><type>transmission_interface/SimpleTransmission</type>
  <joint name="elbow"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>
  </joint><actuator name="m"/></transmission>"""


@pytest.mark.parametrize(
    ("tags", "named"),
    [
        (_ref("camera_link", "<material>Gazebo/Red</material>"), ["camera_link", "material"]),
        (_ref("lidar_linkk", LIDAR), ["lidar_linkk", "sensor 'front_lidar'"]),
        (TRANSMISSION, ["<transmission name='t'> joint", "'elbow'"]),
    ],
    ids=["tags", "sensor", "transmission"],
)
def test_a_reference_to_a_missing_part_is_refused_when_strict_naming_it_and_the_valid_names(
    tmp_path, tags: str, named: list[str]
):
    from converters.errors import DanglingReferenceError

    path = tmp_path / "tagbot.urdf"
    path.write_text(tagbot(tags))
    with pytest.raises(DanglingReferenceError) as caught:
        convert_full(path, options=ConvertOptions(strict=True))
    message = str(caught.value)
    for part in [*named, "does not exist", "base, arm", "without --strict", "tagbot.urdf"]:
        assert part in message, f"{part!r} missing from {message!r}"


def test_a_reference_to_a_missing_part_is_left_out_and_reported(tmp_path):
    path = tmp_path / "tagbot.urdf"
    path.write_text(tagbot(_ref("lidar_linkk", LIDAR) + _ref("arm", "<mu1>0.25</mu1>")))
    done = convert_full(path)
    warnings = [e for e in done.report.of(Outcome.WARNING) if "lidar_linkk" in e.subject]
    assert warnings and "sensor 'front_lidar'" in warnings[0].detail, warnings
    assert not done.sensors, "the lidar on a missing link is left out"
    model = done.spec.compile()
    assert model.geom_friction[_geom(done, model, "arm").id][0] == pytest.approx(0.25), "mu1"


@needs_corpus
def test_corpus_hyq_tags_parse_with_sdformat_meanings():
    urdf = PACKAGES_ROOT / "example-robot-data/robots/hyq_description/robots/hyq_no_sensors.urdf"
    ext = parse_gazebo(ET.parse(urdf).getroot(), urdf.name)
    assert len([j for j in ext.joints.values() if j.provide_feedback]) == 12, "12 joints"
    upper = ext.link("lf_upperleg").surface
    assert (upper.kp, upper.kd, upper.mu1, upper.fdir1) == (1e6, 100.0, 1.5, (1.0, 0.0, 0.0))
    assert upper.max_vel == 1.0 and upper.min_depth == 0.0, "maxVel/minDepth"
    assert ext.unresolved == (), "hyq references only existing links and joints"
