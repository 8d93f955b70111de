"""Small robots that carry Gazebo sensors, for the sensor tests (URDF text, SI units)."""

from __future__ import annotations


def _noise(stddev: float, mean: float = 0.0, bias_mean: float = 0.0) -> str:
    return (
        f'<noise type="gaussian"><mean>{mean}</mean><stddev>{stddev}</stddev>'
        f"<bias_mean>{bias_mean}</bias_mean><bias_stddev>0</bias_stddev></noise>"
    )


def _imu_noise(stddev: float, mean: float, bias_mean: float) -> str:
    axes = "".join(f"<{a}>{_noise(stddev, mean, bias_mean)}</{a}>" for a in "xyz")
    gyro = f"<angular_velocity>{axes}</angular_velocity>"
    return gyro + f"<linear_acceleration>{axes}</linear_acceleration>"


def imu_box(
    *, rate: float = 200.0, stddev: float = 0.0, mean: float = 0.0, bias_mean: float = 0.0,
    yaw: float = 0.0,
) -> str:  # fmt: skip
    """A 1 kg 0.2 m box with an IMU on a fixed child link turned by `yaw` [rad] about z."""
    noise = _imu_noise(stddev, mean, bias_mean) if stddev or mean or bias_mean else ""
    return f"""<robot name="imu_box">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.00667" iyy="0.00667" izz="0.00667"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <joint name="imu_joint" type="fixed"><parent link="base"/><child link="imu_link"/>
    <origin xyz="0.05 0.02 0.03" rpy="0 0 {yaw}"/></joint>
  <link name="imu_link"/>
  <gazebo reference="imu_link"><sensor type="imu" name="imu"><always_on>true</always_on>
    <update_rate>{rate}</update_rate><topic>imu</topic><imu>{noise}</imu></sensor></gazebo>
</robot>"""


def lidar_post(
    *, samples: int = 181, min_angle: float = -1.5708, max_angle: float = 1.5708,
    range_max: float = 3.5, stddev: float = 0.0, rate: float = 10.0,
) -> str:  # fmt: skip
    """A static post whose lidar sits 0.3 m up on a fixed link, range 0.12..`range_max` m."""
    noise = f"<noise><type>gaussian</type><mean>0</mean><stddev>{stddev}</stddev></noise>"
    return f"""<robot name="lidar_post">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.05" length="0.2"/></geometry>
    </collision></link>
  <joint name="scan_joint" type="fixed"><parent link="base"/><child link="scan"/>
    <origin xyz="0 0 0.3"/></joint>
  <link name="scan"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.04" length="0.04"/></geometry></collision></link>
  <gazebo><static>true</static></gazebo>
  <gazebo reference="scan"><sensor type="ray" name="lidar"><update_rate>{rate}</update_rate>
    <ray><scan><horizontal><samples>{samples}</samples><resolution>1</resolution>
    <min_angle>{min_angle}</min_angle><max_angle>{max_angle}</max_angle></horizontal></scan>
    <range><min>0.12</min><max>{range_max}</max><resolution>0.015</resolution></range>
    {noise if stddev else ""}</ray>
    <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
    <ros><remapping>~/out:=scan</remapping></ros><frame_name>scan</frame_name></plugin></sensor></gazebo>
</robot>"""


def hanging_load(
    mass: float,
    *,
    direction: str = "parent_to_child",
    frame: str = "child",
    rate: float = 100.0,
    noise: tuple[float, float] = (0.0, 0.0),
) -> str:
    """A load of `mass` [kg] hanging 0.3 m below a world-fixed support by a locked slider;
    `noise` is the SDF Gaussian stddev of each force [N] and torque [N m] axis (0: none)."""
    axes = "".join(
        f"<{group}>"
        + "".join(
            f'<{a}><noise type="gaussian"><stddev>{std}</stddev></noise></{a}>' for a in "xyz"
        )
        + f"</{group}>"
        for group, std in zip(("force", "torque"), noise, strict=True)
        if std > 0
    )
    return f"""<robot name="hanging">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="support"/>
    <origin xyz="0 0 1.0"/></joint>
  <link name="support"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hook" type="prismatic"><parent link="support"/><child link="load"/>
    <origin xyz="0 0 -0.3"/><axis xyz="1 0 0"/><limit lower="0" upper="0" effort="0" velocity="1"/>
  </joint>
  <link name="load"><inertial><origin xyz="0 0 -0.1"/><mass value="{mass}"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <gazebo reference="hook"><provideFeedback>true</provideFeedback>
    <sensor type="force_torque" name="ft"><update_rate>{rate}</update_rate>
    <force_torque><frame>{frame}</frame><measure_direction>{direction}</measure_direction>
    {axes}</force_torque></sensor></gazebo>
</robot>"""


def bumper_ball(radius: float = 0.05, mass: float = 0.5) -> str:
    """A ball whose contact sensor (gazebo_ros bumper) watches its one collision."""
    inertia = 0.4 * mass * radius * radius
    return f"""<robot name="bumper_ball">
  <link name="ball"><inertial><mass value="{mass}"/><inertia ixx="{inertia}" iyy="{inertia}"
    izz="{inertia}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="{radius}"/></geometry></collision></link>
  <gazebo reference="ball"><sensor type="contact" name="bumper"><update_rate>1000</update_rate>
    <contact><collision>ball_collision</collision></contact>
    <plugin name="bumper" filename="libgazebo_ros_bumper.so">
      <bumperTopicName>ball_bumper</bumperTopicName><frameName>ball</frameName></plugin>
  </sensor></gazebo>
</robot>"""
