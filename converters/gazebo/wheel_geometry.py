"""Wheel positions and radii measured on the robot itself, as gazebo_ros' Ackermann and
tricycle plugins measure them at load time (wheel base and track from the wheels' collision
centres, the radius from the wheel's cylinder or sphere).

The robot's spec is compiled once, on a copy, at its zero posture; names are the description's.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.errors import GazeboTagError, PluginJointError

if TYPE_CHECKING:
    import mujoco


class WheelGeometry:
    """Measures joints of one robot spec (compiled on first use).

    Args:
        spec: the robot's MjSpec (left unchanged); source: the description file, for messages.
    """

    def __init__(self, spec: mujoco.MjSpec, source: str) -> None:
        self.spec, self.source = spec, source
        self.plugin = ""  # the plugin being read, for messages
        self._compiled: tuple | None = None

    def _model(self) -> tuple:
        import mujoco

        if self._compiled is None:
            model = self.spec.copy().compile()
            data = mujoco.MjData(model)
            mujoco.mj_kinematics(model, data)
            self._compiled = (model, data)
        return self._compiled

    def _joint(self, joint: str, tag: str) -> int:
        import mujoco

        model, _ = self._model()
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if j < 0:
            joints = [model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] != 0]
            raise PluginJointError(self.source, self.plugin, tag, joint, joints)
        return j

    def centre(self, joint: str, tag: str) -> np.ndarray:
        """The centre [m] of the wheel `joint` turns (its child link's first collision, else
        the joint's anchor), in the robot's frame.

        Raises:
            PluginJointError: no such joint.
        """
        model, data = self._model()
        j = self._joint(joint, tag)
        geoms = _collision_geoms(model, int(model.jnt_bodyid[j]))
        if geoms:
            return np.array(data.geom_xpos[geoms[0]])
        return np.array(data.xanchor[j])

    def radius(self, joint: str, tag: str) -> float:
        """The radius [m] of the wheel `joint` turns: its cylinder's or sphere's radius, else
        half the largest extent of its first collision.

        Raises:
            PluginJointError: no such joint. GazeboTagError: its link has no collision.
        """
        import mujoco

        model, _ = self._model()
        j = self._joint(joint, tag)
        geoms = _collision_geoms(model, int(model.jnt_bodyid[j]))
        if not geoms:
            raise GazeboTagError(
                self.source, "", f"plugin/{tag}", joint, "a joint whose child link collides"
            )
        g = geoms[0]
        if model.geom_type[g] in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_SPHERE):
            return float(model.geom_size[g][0])
        return float(np.max(model.geom_aabb[g][3:]))


def _collision_geoms(model: mujoco.MjModel, body: int) -> list[int]:
    return [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == body and (model.geom_contype[g] or model.geom_conaffinity[g])
    ]
