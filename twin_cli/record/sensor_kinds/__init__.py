"""The ROS message of each sensor kind, one module per kind, found by scanning this package.

A module here registers its builder with `@ros_message(SpecType, ReadingType, ros_type)`
(`twin_cli.record.sensor_messages`): `imu`, `ray`, `force_torque`, `contact`, `camera`, and
any module added here. Nothing else in the recorder lists kinds.
"""
