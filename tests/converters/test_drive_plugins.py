"""Drive plugins read from the robot's own tags: one row per plugin, its parameters (with the
plugin's defaults where a tag is left out), the motors its joints get, and what the report says.

Oracle: each plugin's documented parameters and defaults (gazebo_ros_pkgs' `Load`, gz-sim's
`Configure`); gazebo_ros' Ackermann and tricycle plugins measure their wheels on the model, so the
expected values are the test robot's own geometry (tests/drive_models.py).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import drive_models as dm
import pytest

from converters.errors import ConversionError, PluginJointError
from converters.gazebo.drive_motors import PLANAR_TAU
from converters.pipeline import convert_full

SKID = (
    '<plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so"><leftFrontJoint>'
    "left_front_joint</leftFrontJoint><rightFrontJoint>right_front_joint</rightFrontJoint>"
    "<leftRearJoint>left_rear_joint</leftRearJoint><rightRearJoint>right_rear_joint"
    "</rightRearJoint><wheelSeparation>0.3</wheelSeparation><wheelDiameter>0.1</wheelDiameter>"
    "<torque>7</torque><robotBaseFrame>base_link</robotBaseFrame></plugin>"
)
GZ_DIFF = (
    '<plugin filename="{file}" name="gz::sim::systems::DiffDrive"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_radius>0.05</wheel_radius>"
    "<max_linear_acceleration>2</max_linear_acceleration></plugin>"
)
ROS_ACKERMANN = (
    '<plugin name="ack" filename="libgazebo_ros_ackermann_drive.so"><front_left_joint>'
    "front_left_joint</front_left_joint><front_right_joint>front_right_joint</front_right_joint>"
    "<rear_left_joint>rear_left_joint</rear_left_joint><rear_right_joint>rear_right_joint"
    "</rear_right_joint><left_steering_joint>left_steering_joint</left_steering_joint>"
    "<right_steering_joint>right_steering_joint</right_steering_joint></plugin>"
)
GZ_ACKERMANN = (
    '<plugin filename="ignition-gazebo-ackermann-steering-system" '
    'name="ignition::gazebo::systems::AckermannSteering"><left_joint>rear_left_joint</left_joint>'
    "<right_joint>rear_right_joint</right_joint><left_steering_joint>left_steering_joint"
    "</left_steering_joint><right_steering_joint>right_steering_joint</right_steering_joint>"
    "<frame_id>world_odom</frame_id></plugin>"
)
TRICYCLE = (
    '<plugin name="tri" filename="libgazebo_ros_tricycle_drive.so"><steering_joint>'
    "front_steering_joint</steering_joint><actuated_wheel_joint>front_wheel_joint"
    "</actuated_wheel_joint><encoder_wheel_left_joint>left_wheel_joint</encoder_wheel_left_joint>"
    "<encoder_wheel_right_joint>right_wheel_joint</encoder_wheel_right_joint>"
    "<max_wheel_acceleration>3</max_wheel_acceleration></plugin>"
)
PLANAR = '<plugin name="mover" filename="libgazebo_ros_planar_move.so"/>'
KOBUKI = (
    '<plugin name="kobuki_controller" filename="libgazebo_ros_kobuki.so"><publish_tf>1'
    "</publish_tf><wheel_left_joint_name>wheel_left_joint</wheel_left_joint_name>"
    "<wheel_right_joint_name>wheel_right_joint</wheel_right_joint_name><wheel_separation>0.23"
    "</wheel_separation><wheel_diameter>0.07</wheel_diameter><torque>1.0</torque>"
    "<velocity_command_timeout>0.6</velocity_command_timeout></plugin>"
)
JOINT_CONTROLLER = (
    '<plugin filename="gz-sim-joint-controller-system" name="gz::sim::systems::JointController">'
    "<joint_name>wheel_left_joint</joint_name><use_force_commands>true</use_force_commands>"
    "<p_gain>0.5</p_gain><cmd_max>2</cmd_max></plugin>"
)
POSITION_CONTROLLER = (
    '<plugin filename="gz-sim-joint-position-controller-system" '
    'name="gz::sim::systems::JointPositionController"><joint_name>wheel_right_joint</joint_name>'
    "<p_gain>30</p_gain><d_gain>2</d_gain><cmd_max>4</cmd_max></plugin>"
)

# (id, robot text, suffix, {record field: expected value})
ROWS = [
    (
        "skid_steer",
        dm.skid_steer_bot(SKID),
        "urdf",
        {
            "kind": "DiffDrive",
            "family": "gazebo_ros_skid_steer_drive",
            "left_joints": ["left_front_joint", "left_rear_joint"],
            "right_joints": ["right_front_joint", "right_rear_joint"],
            "wheel_separation": 0.3,
            "wheel_diameter": 0.1,
            "max_wheel_torque": 7.0,
            "update_rate": 100.0,
            "odometry_source": "world",
            "odometry_frame": "odom",
            "robot_base_frame": "base_link",
        },
    ),
    (
        "gz_diff_drive_sdf",
        dm.sdf_diff_drive(GZ_DIFF.format(file="gz-sim-diff-drive-system")),
        "sdf",
        {
            "kind": "DiffDrive",
            "family": "gz_diff_drive",
            "wheel_separation": 1.0,  # gz-sim's default
            "wheel_diameter": 0.1,
            "max_wheel_torque": None,  # velocity commands: unbounded
            "max_wheel_acceleration": 0.0,  # the twist is bounded, not the rims
            "twist_acceleration": [None, 2.0, None, None],  # unset bounds: none
            "odometry_source": "encoder",
            "odometry_frame": "dd/odom",
            "robot_base_frame": "dd/base_link",
            "update_rate": 0.0,  # every step: PreUpdate sets the wheels' speeds each step
        },
    ),
    (
        "gz_diff_drive_old_name",
        dm.two_wheel_base(GZ_DIFF.format(file="libignition-gazebo6-diff-drive-system.so")),
        "urdf",
        {"kind": "DiffDrive", "family": "gz_diff_drive", "odometry_frame": "base/odom"},
    ),
    (
        "ros_ackermann",
        dm.ackermann_car(ROS_ACKERMANN),
        "urdf",
        {
            "kind": "AckermannDrive",
            "left_joints": ["rear_left_joint"],
            "left_steering_joints": ["left_steering_joint"],
            "wheel_base": dm.WHEEL_BASE,  # measured on the model, as the plugin does
            "wheel_separation": dm.TRACK,
            "wheel_radius": dm.R,
            "steering_limit": 0.6,
            "max_velocity": 20.0,
            "angular_is_steering": True,
            "robot_base_frame": "base_footprint",
        },
    ),
    (
        "gz_ackermann_ignition_name",
        dm.sdf_ackermann(GZ_ACKERMANN),
        "sdf",
        {
            "kind": "AckermannDrive",
            "family": "gz_ackermann_steering",
            "update_rate": 0.0,  # every step, as gz-sim's DiffDrive
            "wheel_base": 1.0,
            "kingpin_width": 0.8,
            "wheel_radius": 0.2,
            "steering_limit": 0.5,
            "odometry_source": "encoder",
            "odometry_frame": "world_odom",
            "robot_base_frame": "car/base_link",
            "angular_is_steering": False,
        },
    ),
    (
        "tricycle",
        dm.tricycle(TRICYCLE),
        "urdf",
        {
            "kind": "TricycleDrive",
            "wheel_base": dm.WHEEL_BASE,
            "actuated_wheel_diameter": 0.15,
            "max_wheel_acceleration": 3.0,
            "max_wheel_deceleration": 3.0,  # the plugin's default: the acceleration
            "max_wheel_torque": 0.15,
            "robot_base_frame": "base_link",
        },
    ),
    (
        "planar_move",
        dm.planar_base(PLANAR),
        "urdf",
        {"kind": "HolonomicDrive", "family": "gazebo_ros_planar_move", "update_rate": 20.0},
    ),
    (
        "planar_move_ros1",  # its odometryRate paces odometry; the velocity is set every step
        dm.planar_base(PLANAR.replace("/>", "><odometryRate>20</odometryRate></plugin>")),
        "urdf",
        {"kind": "HolonomicDrive", "family": "gazebo_ros_planar_move", "update_rate": 0.0},
    ),
    (
        "vendor_kobuki",
        dm.two_wheel_base(KOBUKI),
        "urdf",
        {
            "kind": "DiffDrive",
            "family": "vendor:libgazebo_ros_kobuki.so",
            "left_joints": ["wheel_left_joint"],
            "wheel_separation": 0.23,
            "wheel_diameter": 0.07,
            "max_wheel_torque": 1.0,
        },
    ),
    (
        "joint_controller",
        dm.two_wheel_base(JOINT_CONTROLLER + POSITION_CONTROLLER),
        "urdf",
        {"kind": "JointDrive", "joints": ["wheel_left_joint"], "mode": "velocity"},
    ),
]


def _convert(tmp_path: Path, text: str, suffix: str):  # noqa: ANN202
    path = tmp_path / f"robot.{suffix}"
    path.write_text(text)
    return convert_full(path)


@pytest.mark.parametrize(
    ("text", "suffix", "expected"), [r[1:] for r in ROWS], ids=[r[0] for r in ROWS]
)
def test_drive_plugin_parameters_are_read_with_the_plugins_defaults(
    tmp_path: Path, text: str, suffix: str, expected: dict
) -> None:
    record = _convert(tmp_path, text, suffix).plugins[0].to_dict()
    for field, value in expected.items():
        got = record[field]
        if isinstance(value, float):
            assert got == pytest.approx(value, abs=1e-9), f"{field}: {got} (expected {value})"
        else:
            assert got == value, f"{field}: {got!r} (expected {value!r})"


@pytest.mark.parametrize(
    ("text", "suffix", "modes"),
    [
        (dm.ackermann_car(ROS_ACKERMANN), "urdf", {"rear_left_joint": ["velocity"]}),
        (dm.tricycle(TRICYCLE), "urdf", {"front_wheel_joint": ["velocity"]}),
        (dm.two_wheel_base(KOBUKI), "urdf", {"wheel_left_joint": ["velocity"]}),
        (
            dm.two_wheel_base(JOINT_CONTROLLER + POSITION_CONTROLLER),
            "urdf",
            {"wheel_left_joint": ["velocity"], "wheel_right_joint": ["position"]},
        ),
    ],
    ids=["ackermann", "tricycle", "vendor", "joint_controllers"],
)
def test_drive_joints_get_motors_in_the_plugins_mode(
    tmp_path: Path, text: str, suffix: str, modes: dict
) -> None:
    done = _convert(tmp_path, text, suffix)
    records = json.loads(done.spec.text("control").data)
    for joint, expected in modes.items():
        assert records[joint]["modes"] == expected, f"{joint}: {records[joint]}"
    model = done.spec.compile()
    for joint in modes:
        assert model.actuator(joint).id >= 0, f"{joint} has a motor"


def test_joint_controllers_pid_gains_and_force_limit_travel_with_the_motor(tmp_path: Path) -> None:
    done = _convert(tmp_path, dm.two_wheel_base(JOINT_CONTROLLER + POSITION_CONTROLLER), "urdf")
    records = json.loads(done.spec.text("control").data)
    assert records["wheel_left_joint"]["pid"] == {"velocity": [0.5, 0.0, 0.0]}
    assert records["wheel_right_joint"]["pid"] == {"position": [30.0, 0.1, 2.0]}
    model = done.spec.compile()
    # a lone cmd_max: gz-math's PID still clamps its output below at cmd_min's default, -1000
    right = model.actuator("wheel_right_joint").id
    assert list(model.actuator_ctrlrange[right]) == [-1000.0, 4.0]


def test_ackermann_steering_joints_keep_their_own_motor(tmp_path: Path) -> None:
    """A steering joint with <limit effort> already has a motor offering every mode."""
    records = json.loads(
        _convert(tmp_path, dm.ackermann_car(ROS_ACKERMANN), "urdf").spec.text("control").data
    )
    assert "position" in records["left_steering_joint"]["modes"]
    assert records["front_left_joint"]["source"] == "passive", "front wheels roll freely"


def test_planar_move_gets_three_velocity_servos_at_the_centre_of_mass(tmp_path: Path) -> None:
    model = _convert(tmp_path, dm.planar_base(PLANAR), "urdf").spec.compile()
    names = [model.actuator(i).name for i in range(model.nu)]
    assert names == ["planar:mover:vx", "planar:mover:vy", "planar:mover:wz"]
    mass = float(model.body_subtreemass[1])
    vx = model.actuator("planar:mover:vx").id
    assert model.actuator_gainprm[vx][0] == pytest.approx(mass / PLANAR_TAU), "kv = M/τ"
    assert model.actuator_biasprm[vx][2] == pytest.approx(-mass / PLANAR_TAU)
    site = model.site("planar:mover")
    assert list(model.site_pos[site.id]) == pytest.approx([0.0, 0.0, 0.05]), "the robot's COM"


def test_vendor_plugin_is_reported_tag_by_tag(tmp_path: Path) -> None:
    report = _convert(tmp_path, dm.two_wheel_base(KOBUKI), "urdf").report
    details = [e.detail for e in report.entries if e.tag == "plugin"]
    assert any("read as a differential drive" in d for d in details), details
    for tag, says in (
        ("wheel_left_joint_name", "read as the left wheel joint"),
        ("wheel_separation", "read as the wheel separation"),
        ("wheel_diameter", "read as the wheel diameter"),
        ("torque", "read as the max wheel torque"),
        ("velocity_command_timeout", "ignored"),
        ("publish_tf", "twin serve --ros publishes odom and tf"),
    ):
        assert any(f"<{tag}>" in d and says in d for d in details), f"<{tag}>: {says}"


def test_an_unknown_plugin_is_reported_by_name_with_its_parameters(tmp_path: Path) -> None:
    plugin = (
        '<plugin name="lights" filename="libacme_blinker.so"><rate>2</rate><colour>red</colour>'
        "</plugin>"
    )
    report = _convert(tmp_path, dm.two_wheel_base(plugin), "urdf").report
    lines = [e.detail for e in report.entries if e.tag == "plugin"]
    assert (
        "<plugin> 'lights' libacme_blinker.so: not run by twin; parameters: rate=2, colour=red"
        in lines
    )


def test_a_wheel_without_a_drive_keeps_a_passive_motor(tmp_path: Path) -> None:
    done = _convert(tmp_path, dm.two_wheel_base(""), "urdf")
    records = json.loads(done.spec.text("control").data)
    for joint in ("wheel_left_joint", "wheel_right_joint"):
        assert records[joint]["source"] == "passive" and records[joint]["modes"] == [
            "effort",
            "velocity",
        ]
    assert any(e.subject == "passive joints" for e in done.report.entries)


@pytest.mark.parametrize(
    ("swap", "needle"),
    [
        (("<wheelSeparation>0.3<", "<wheelSeparation>wide<"), "wheelSeparation"),
        (("<leftRearJoint>left_rear_joint<", "<leftRearJoint>nope<"), "nope"),
        (("<torque>7<", "<torque>-1<"), "torque"),
    ],
)
def test_bad_drive_values_name_the_tag_and_the_fix(
    tmp_path: Path, swap: tuple[str, str], needle: str
) -> None:
    with pytest.raises(ConversionError, match=needle) as caught:
        _convert(tmp_path, dm.skid_steer_bot(SKID.replace(*swap)), "urdf")
    fix = "name one of its joints" if needle == "nope" else "write"
    assert fix in str(caught.value), "the message names the fix"


def test_an_ackermann_plugin_naming_a_missing_joint_is_refused(tmp_path: Path) -> None:
    text = dm.ackermann_car(ROS_ACKERMANN.replace(">rear_left_joint<", ">rear_nope<"))
    with pytest.raises(PluginJointError, match="rear_nope") as caught:
        _convert(tmp_path, text, "urdf")
    message = str(caught.value)
    assert "<rear_left_joint>" in message and "rear_right_joint" in message, "valid names"
    assert "floating_base" not in message, "only joints a plugin can name"


def test_limits_of_no_limit_are_null_in_json(tmp_path: Path) -> None:
    record = _convert(
        tmp_path, dm.sdf_diff_drive(GZ_DIFF.format(file="gz-sim-diff-drive-system")), "sdf"
    ).plugins[0]
    assert (
        math.isinf(record.max_linear_velocity) and record.to_dict()["max_linear_velocity"] is None
    )


def test_docs_list_every_plugin_and_system_twin_recognises() -> None:
    from converters.gazebo.drive_readers import READERS
    from converters.gazebo.plugins import NEEDS, SYSTEM_NAMES

    text = (Path(__file__).resolve().parents[2] / "docs" / "plugins.md").read_text()
    names = [*READERS, *NEEDS, *SYSTEM_NAMES]
    missing = [n for n in names if n not in text]
    assert not missing, f"docs/plugins.md does not name {missing}"


def test_a_known_drives_approximations_and_unused_tags_are_reported_tag_by_tag(
    tmp_path: Path,
) -> None:
    extra = (
        "<left_steering_pid_gain>1500 0 1</left_steering_pid_gain><publish_odom>true"
        "</publish_odom><steering_wheel_joint>steering_joint</steering_wheel_joint>"
        "<ros><namespace>demo</namespace></ros></plugin>"
    )
    report = _convert(tmp_path, dm.ackermann_car(ROS_ACKERMANN.replace("</plugin>", extra)), "urdf")
    notes = [e.detail for e in report.report.entries if e.outcome.name == "APPROXIMATED"]
    assert any("open differential" in n for n in notes), notes
    for tag, says in (
        ("left_steering_pid_gain", "not used by twin"),
        ("steering_wheel_joint", "not used by twin"),
        ("publish_odom", "twin serve --ros publishes odom"),
        ("ros", "twin serve --ros publishes odom"),
    ):
        assert any(f"<{tag}>" in n and says in n for n in notes), f"<{tag}>: {says}"


def test_a_tracked_vehicle_is_reported_not_run_with_each_of_its_tags(tmp_path: Path) -> None:
    plugin = (
        '<plugin filename="gz-sim-tracked-vehicle-system" name="gz::sim::systems::TrackedVehicle">'
        "<left_track><link>left_track</link></left_track><right_track><link>right_track</link>"
        "</right_track><tracks_separation>0.4</tracks_separation><steering_efficiency>0.5"
        "</steering_efficiency></plugin>"
    )
    done = _convert(tmp_path, dm.two_wheel_base(plugin), "urdf")
    (line,) = [e for e in done.report.entries if e.tag == "plugin" and "TrackedVehicle" in e.detail]
    assert line.outcome.name == "IGNORED" and "not run" in line.detail, line.detail
    for tag in ("left_track=<...>", "right_track=<...>", "tracks_separation=0.4"):
        assert tag in line.detail, f"{tag} missing from {line.detail}"
    assert "steering_efficiency=0.5" in line.detail and not done.plugins, "no drive runs"


@pytest.mark.parametrize(
    ("plugin", "tags"),
    [
        (
            GZ_DIFF.format(file="gz-sim-diff-drive-system"),
            ("min_velocity", "min_linear_velocity", "min_angular_velocity", "min_acceleration"),
        ),
        (GZ_ACKERMANN, ("min_velocity", "min_acceleration", "steer_p_gain")),
    ],
    ids=["diff_drive", "ackermann"],
)
def test_gz_limiter_tags_twin_runs_are_not_reported_unused(
    tmp_path: Path, plugin: str, tags: tuple[str, ...]
) -> None:
    """Each tag here changes what the drive does (a lower speed or acceleration bound, the
    steering gain), so the report must not call it unused; a jerk bound is not run and says so."""
    given = "".join(f"<{t}>-0.5</{t}>" if t != "steer_p_gain" else f"<{t}>2</{t}>" for t in tags)
    text = plugin.replace("</plugin>", f"{given}<max_jerk>3</max_jerk></plugin>")
    robot = dm.sdf_diff_drive(text) if "diff" in plugin else dm.sdf_ackermann(text)
    notes = [e.detail for e in _convert(tmp_path, robot, "sdf").report.entries]
    unused = [n for n in notes if "not used by twin" in n]
    assert any("<max_jerk>" in n for n in unused), notes
    assert not [n for n in unused for t in tags if f"<{t}>" in n], unused


@pytest.mark.parametrize(
    ("plugin", "idle", "read"),
    [
        (JOINT_CONTROLLER.replace("true", "false"), ("p_gain", "cmd_max"), ()),
        (JOINT_CONTROLLER, (), ("p_gain", "cmd_max")),
        (
            POSITION_CONTROLLER.replace(
                "</plugin>", "<use_velocity_commands>true</use_velocity_commands></plugin>"
            ),
            ("p_gain", "d_gain"),
            ("cmd_max",),
        ),
        (POSITION_CONTROLLER, (), ("p_gain", "d_gain", "cmd_max")),
    ],
    ids=["velocity set", "force PID", "speed set", "position PID"],
)
def test_pid_tags_gz_sim_ignores_in_a_controllers_mode_are_reported_as_such(
    tmp_path: Path, plugin: str, idle: tuple[str, ...], read: tuple[str, ...]
) -> None:
    """gz-sim's JointController uses its PID tags only with `use_force_commands`, and its
    JointPositionController only without `use_velocity_commands` (there `cmd_max` bounds the
    speed): a tag the system ignores in the mode given says so, a tag it reads is not listed."""
    notes = [e.detail for e in _convert(tmp_path, dm.two_wheel_base(plugin), "urdf").report.entries]
    for tag in idle:
        said = [n for n in notes if f"<{tag}>" in n]
        assert said and all("gz-sim uses it only" in n for n in said), (tag, notes)
    for tag in read:
        assert not [n for n in notes if f"<{tag}>:" in n], (tag, notes)
