"""Gazebo `<sensor>` tags → typed sensors, sites at their frames and report entries."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from corpus_registry import CORPUS, PACKAGES_ROOT, needs_corpus, package_paths
from models import write_urdf
from sensor_models import hanging_load, imu_box, lidar_post

from converters.description.sensors import (
    CameraSpec,
    ContactSpec,
    ForceTorqueSpec,
    ImuSpec,
    Noise,
    RaySpec,
)
from converters.description.transforms import pose_matrix
from converters.errors import GazeboTagError
from converters.pipeline import convert_full

LINK = """<link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
  ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry><box size="0.2 0.2 0.2"/></geometry>
  </collision></link>"""


def _robot(tmp_path: Path, sensor: str, reference: str = "base") -> object:
    text = f'<robot name="r">{LINK}<gazebo reference="{reference}">{sensor}</gazebo></robot>'
    return convert_full(write_urdf(tmp_path, text))


def _mapped(done: object) -> list[str]:
    return [
        e.detail for e in done.report.entries if e.tag == "sensor" and e.outcome.value == "mapped"
    ]


# One row per tag: the sensor element and what its record must hold.
ROWS = [
    (
        '<sensor type="imu" name="s"><update_rate>200</update_rate><imu><angular_velocity><x>'
        '<noise type="gaussian"><mean>0.1</mean><stddev>0.2</stddev><bias_mean>0.3</bias_mean>'
        "<bias_stddev>0.4</bias_stddev></noise></x></angular_velocity></imu></sensor>",
        ImuSpec,
        {
            "update_rate": 200.0,
            "angular_velocity_noise": (Noise("gaussian", 0.1, 0.2, 0.3, 0.4), Noise(), Noise()),
        },
    ),
    (
        '<sensor type="imu" name="s"><imu><noise><type>gaussian</type><rate><mean>0</mean>'
        "<stddev>2e-4</stddev></rate><accel><stddev>1.7e-2</stddev><bias_mean>0.1</bias_mean>"
        "</accel></noise></imu></sensor>",  # SDF 1.5: one model for all three axes
        ImuSpec,
        {
            "angular_velocity_noise": (Noise("gaussian", 0, 2e-4),) * 3,
            "linear_acceleration_noise": (Noise("gaussian", 0, 1.7e-2, 0.1),) * 3,
        },
    ),
    (
        '<sensor type="gpu_lidar" name="s"><topic>points</topic><lidar><scan><horizontal>'
        "<samples>100</samples><resolution>2</resolution><min_angle>-1</min_angle>"
        "<max_angle>1</max_angle></horizontal><vertical><samples>4</samples><min_angle>-0.2"
        "</min_angle><max_angle>0.2</max_angle></vertical></scan><range><min>0.1</min>"
        "<max>30</max></range></lidar></sensor>",
        RaySpec,
        {"horizontal_rays": 200, "vertical_rays": 4, "range_max": 30.0, "topic": "points"},
    ),
    (
        '<sensor type="contact" name="s"><contact><collision>base_collision</collision>'
        '</contact><plugin name="b" filename="libgazebo_ros_bumper.so"><bumperTopicName>bump'
        "</bumperTopicName><frameName>base</frameName></plugin></sensor>",
        ContactSpec,
        {"collision": "base_collision", "geoms": ("base_collision_0",), "topic": "bump"},
    ),
    (
        '<sensor type="camera" name="s"><camera><horizontal_fov>1.2</horizontal_fov><image>'
        "<width>64</width><height>48</height></image><clip><near>0.05</near><far>50</far></clip>"
        '</camera><plugin name="c" filename="libgazebo_ros_camera.so"><ros><namespace>cam'
        "</namespace><remapping>image_raw:=image</remapping></ros></plugin></sensor>",
        CameraSpec,
        {"width": 64, "height": 48, "horizontal_fov": 1.2, "far": 50.0, "topic": "/cam/image"},
    ),
]


@pytest.mark.parametrize(("sensor", "kind", "expected"), ROWS)
def test_sensor_tags_become_typed_records(tmp_path: Path, sensor, kind, expected) -> None:
    done = _robot(tmp_path, sensor)
    (found,) = done.sensors
    assert isinstance(found, kind)
    for field, value in expected.items():
        assert getattr(found, field) == value, field
    assert (found.link, found.body, found.site) == ("base", "base", "sensor:s")
    assert len(_mapped(done)) == 1


def test_sdf_defaults_apply_when_tags_are_absent(tmp_path: Path) -> None:
    (imu,) = _robot(tmp_path, '<sensor type="imu" name="s"/>').sensors
    assert (imu.update_rate, imu.always_on, imu.pose) == (0.0, False, (0.0,) * 6)
    assert imu.angular_velocity_noise == (Noise(),) * 3 and imu.enable_orientation


def test_a_sensor_on_a_lumped_link_sits_at_link_pose_times_sensor_pose(tmp_path: Path) -> None:
    text = imu_box(yaw=0.5).replace("<topic>", "<pose>0.01 0.02 0.03 0.1 0.2 0.3</pose><topic>")
    done = convert_full(write_urdf(tmp_path, text))
    (imu,) = done.sensors
    assert (imu.link, imu.body) == ("imu_link", "base"), "imu_link is lumped into base"
    model = done.spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    expected = pose_matrix((0.05, 0.02, 0.03, 0, 0, 0.5)) @ pose_matrix(imu.pose)
    site = data.site("sensor:imu")
    np.testing.assert_allclose(site.xpos, expected[:3, 3], atol=1e-12)
    np.testing.assert_allclose(site.xmat.reshape(3, 3), expected[:3, :3], atol=1e-12)


def test_force_torque_on_a_joint_knows_its_bodies_and_frame(tmp_path: Path) -> None:
    done = convert_full(write_urdf(tmp_path, hanging_load(1.0, frame="parent")))
    (ft,) = done.sensors
    assert isinstance(ft, ForceTorqueSpec)
    assert (ft.joint, ft.child_body, ft.parent_body, ft.frame) == (
        "hook",
        "load",
        "support",
        "parent",
    )
    assert ft.measure_direction == "parent_to_child"


def test_force_torque_on_a_lumped_fixed_joint_is_ignored_with_the_fix(tmp_path: Path) -> None:
    ft = '<gazebo reference="imu_joint"><sensor type="force_torque" name="ft"/></gazebo>'
    text = imu_box().replace("</robot>", ft + "</robot>")
    done = convert_full(write_urdf(tmp_path, text))
    assert [s.name for s in done.sensors] == ["imu"]
    ignored = [
        e.detail for e in done.report.entries if e.tag == "sensor" and e.outcome.value == "ignored"
    ]
    assert any("preserveFixedJoint" in d for d in ignored), ignored


def test_unknown_sensor_types_are_reported_ignored(tmp_path: Path) -> None:
    done = _robot(tmp_path, '<sensor type="sonar" name="s"/>')
    assert done.sensors == ()
    details = [e.detail for e in done.report.entries if e.tag == "sensor"]
    assert details == ["sensor type 'sonar' is not simulated"]


@pytest.mark.parametrize(
    ("sensor", "tag"),
    [
        ('<sensor type="ray" name="s"><update_rate>fast</update_rate></sensor>', "update_rate"),
        ('<sensor type="ray" name="s"><ray><range><max>x</max></range></ray></sensor>', "max"),
        ('<sensor type="imu" name="s"><pose>0 0</pose></sensor>', "pose"),
        (
            '<sensor type="depth" name="s"><camera><clip><near>5</near><far>2</far></clip>'
            "</camera></sensor>",
            "clip.*0 < near < far",
        ),
    ],
)
def test_bad_sensor_values_name_the_sensor_and_tag(tmp_path: Path, sensor: str, tag: str) -> None:
    with pytest.raises(GazeboTagError, match=rf"sensor 's'.*{tag}"):
        _robot(tmp_path, sensor)


def test_a_force_torque_frame_outside_sdfs_choices_is_refused(tmp_path: Path) -> None:
    text = hanging_load(1.0).replace("<frame>child</frame>", "<frame>world</frame>")
    with pytest.raises(GazeboTagError, match=r"sensor 'ft'.*frame.*child or parent or sensor"):
        convert_full(write_urdf(tmp_path, text))


def test_sdf_link_sensors_are_read_too(tmp_path: Path) -> None:
    sdf = """<sdf version="1.9"><model name="m"><link name="l"><inertial><mass>1</mass></inertial>
      <collision name="c"><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
      <sensor name="lidar" type="gpu_lidar"><pose>0 0 0.2 0 0 0</pose><update_rate>10</update_rate>
      <lidar><scan><horizontal><samples>32</samples><min_angle>-1</min_angle><max_angle>1</max_angle>
      </horizontal></scan><range><min>0.1</min><max>10</max></range></lidar></sensor></link>
      </model></sdf>"""
    path = tmp_path / "m.sdf"
    path.write_text(sdf)
    done = convert_full(path)
    (lidar,) = done.sensors
    assert (lidar.link, lidar.horizontal_rays, lidar.range_max) == ("l", 32, 10.0)
    model = done.spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.site("sensor:lidar").xpos - data.body("l").xpos, [0, 0, 0.2])


@needs_corpus
def test_turtlebot3_gets_its_lidar_and_imu_with_the_tags_values() -> None:
    robot = CORPUS["turtlebot3_burger"]
    done = convert_full(PACKAGES_ROOT / robot["entry"], package_paths=package_paths(robot))
    sensors = {s.name: s for s in done.sensors}
    lidar, imu = sensors["lds_lfcd_sensor"], sensors["imu"]
    assert isinstance(lidar, RaySpec) and isinstance(imu, ImuSpec)
    assert (lidar.update_rate, lidar.horizontal_rays, lidar.range_min, lidar.range_max) == (
        5.0, 360, 0.12, 3.5,
    )  # fmt: skip
    assert (lidar.horizontal_min_angle, lidar.horizontal_max_angle) == (0.0, 6.28319)
    assert lidar.noise == Noise("gaussian", 0.0, 0.01)
    assert (lidar.topic, lidar.frame_id, lidar.link) == ("scan", "base_scan", "base_scan")
    # No <update_rate>: every step; its noise is in the ROS 1 model plugin, which Gazebo's
    # libgazebo_ros_imu reads as gaussianNoise 0.0: no noise on the sensor itself.
    assert imu.update_rate == 0.0 and imu.always_on and imu.link == "imu_link"
    assert len(_mapped(done)) == 2


def test_lidar_post_model_is_static_and_its_scan_frame_is_lumped(tmp_path: Path) -> None:
    done = convert_full(write_urdf(tmp_path, lidar_post()))
    (lidar,) = done.sensors
    assert (lidar.body, lidar.topic, lidar.frame_id) == ("base", "scan", "scan")


def test_force_torque_noise_is_read_per_axis_and_reported(tmp_path: Path) -> None:
    done = convert_full(write_urdf(tmp_path, hanging_load(1.0, noise=(0.5, 0.05))))
    (ft,) = done.sensors
    assert ft.force_noise == (Noise("gaussian", stddev=0.5),) * 3
    assert ft.torque_noise == (Noise("gaussian", stddev=0.05),) * 3
    (line,) = _mapped(done)
    assert "noise stddev 0.5, 0.5, 0.5, 0.05, 0.05, 0.05" in line


def test_a_gazebo_ros_ft_plugins_gaussian_noise_applies_to_all_six_axes(tmp_path: Path) -> None:
    plugin = '<plugin name="ft" filename="libgazebo_ros_ft_sensor.so"><gaussianNoise>0.2'
    text = hanging_load(1.0).replace(
        "</force_torque>", f"</force_torque>{plugin}</gaussianNoise></plugin>"
    )
    (ft,) = convert_full(write_urdf(tmp_path, text)).sensors
    assert ft.force_noise == ft.torque_noise == (Noise("gaussian", stddev=0.2),) * 3


def test_camera_clip_planes_are_kept_and_reported(tmp_path: Path) -> None:
    sensor = (
        '<sensor type="depth" name="s"><camera><clip><near>0.3</near><far>4</far></clip>'
        "</camera></sensor>"
    )
    done = _robot(tmp_path, sensor)
    (camera,) = done.sensors
    assert (camera.near, camera.far, camera.depth) == (0.3, 4.0, True)
    assert "clip 0.3..4 m" in _mapped(done)[0]
