"""The sensor kinds of a running world, one module each, found by `twin_cli.sensors.registry`.

Each module registers its sensor class with `@sensor_for(SpecType)`: `imu`, `ray`, `contact`,
`force_torque`, `camera`, and any module added here.
"""
