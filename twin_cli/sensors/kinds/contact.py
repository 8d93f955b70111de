"""Contact sensor and the gazebo_ros bumper: the contacts on a link's collision geoms.

MuJoCo lists a contact for every geom pair within their margin (0 for twin's geoms: touching or
penetrating), which is when Gazebo's contact sensor reports one. The force of each contact is
`mj_contactForce` (contact frame: normal first) turned into the world frame; MuJoCo's normal
points from geom1 to geom2 and pushes geom2 along it, so the force on the sensor's geom is
+f when it is geom2 and −f when it is geom1.
"""

from __future__ import annotations

import mujoco
import numpy as np

from converters.description.sensors import ContactSpec
from twin_cli.sensors.frames import element_id
from twin_cli.sensors.readings import ContactReading, ContactState
from twin_cli.sensors.registry import sensor_for


@sensor_for(ContactSpec)
class ContactSensor:
    """One `<sensor type="contact">` of an entity."""

    def __init__(self, spec: ContactSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.geoms: frozenset[int] = frozenset()

    def bind(self, model: mujoco.MjModel) -> None:
        kind = mujoco.mjtObj.mjOBJ_GEOM
        self.geoms = frozenset(
            element_id(model, kind, "geom", f"{self.entity}/{g}", self.entity)
            for g in self.spec.geoms
        )

    def read(self, model: mujoco.MjModel, data: mujoco.MjData, time: float) -> ContactReading:
        states = [
            self._state(model, data, i)
            for i in range(data.ncon)
            if data.contact.geom1[i] in self.geoms or data.contact.geom2[i] in self.geoms
        ]
        total = np.sum([s.force for s in states], axis=0) if states else np.zeros(3)
        return ContactReading(
            self.spec.name,
            self.spec.type,
            time,
            self.spec.frame_id,
            tuple(states),
            (float(total[0]), float(total[1]), float(total[2])),
        )

    def _state(self, model: mujoco.MjModel, data: mujoco.MjData, i: int) -> ContactState:
        contact = data.contact[i]
        mine_is_geom2 = int(contact.geom2) in self.geoms
        sign = 1.0 if mine_is_geom2 else -1.0
        local = np.zeros(6)
        mujoco.mj_contactForce(model, data, i, local)
        frame = contact.frame.reshape(3, 3)
        force = sign * (frame.T @ local[:3])
        normal = sign * frame[0]
        mine, other = (
            (contact.geom2, contact.geom1) if mine_is_geom2 else (contact.geom1, contact.geom2)
        )
        return ContactState(
            _name(model, mine),
            _name(model, other),
            _vec(force),
            _vec(contact.pos),
            _vec(normal),
            float(-contact.dist),
        )


def _name(model: mujoco.MjModel, geom: int) -> str:
    return model.geom(int(geom)).name or f"geom {int(geom)}"


def _vec(v: np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
