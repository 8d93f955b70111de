"""ROS messages of sensor kinds beyond the built-in ones: one module per kind, found by scanning.

A module here registers its builder with `@ros_message(SpecType, ReadingType, ros_type)`
(`twin_cli.record.sensor_messages`); the built-in kinds' builders are in that module.
"""
