"""Sensor kinds beyond the built-in ones: one module per kind, each found by scanning this package.

A module here defines its `SensorSpec` subclass (the values its `<sensor>` element gives) and
its reader under `@sensor_kind(kind, *gazebo_types)` (`converters.gazebo.sensors`); nothing
else in the converter lists kinds. The package is imported only when a description declares a
sensor.
"""
