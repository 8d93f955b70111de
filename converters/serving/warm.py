"""Imported once by the fork server of bounded conversions (`converters.isolated.bounded`): the
modules a conversion uses and the values it computes once per process, so that every child starts
warm.

Measured: a child that imported these itself spent ~0.1-0.3 s more on a corpus robot than the
same conversion in a warm process.
"""

from __future__ import annotations

import converters.collision.cache
import converters.description.joint_checks
import converters.description.references
import converters.gazebo.apply
import converters.gazebo.plugins
import converters.gazebo.sensor_sites
import converters.isolated.replay
import converters.mjcf.heightfields
import converters.mjcf.passive_motors
import converters.sdf
import converters.serving.served
import converters.urdf.xacro_worker
from converters.resources import mesh_store

mesh_store.loader_version()
converters.collision.cache.cache_root()
