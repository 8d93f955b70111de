"""Sensor kinds the converter reads, one module per kind, each found by scanning this package.

A module here registers its reader with `@sensor_kind(kind, *gazebo_types)`
(`converters.gazebo.sensors`) and, for a kind of its own, defines its `SensorSpec` subclass
beside it (the built-in kinds' records are in `converters.description.sensors`, where the
neutral description's other types are). Nothing else in the converter lists kinds. The package
is imported only when a description declares a sensor.
"""
