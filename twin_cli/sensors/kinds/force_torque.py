"""Force/torque sensor: the wrench a joint transmits, at the joint's origin.

After `mj_rnePostConstraint`, `cfrc_int[child]` is the spatial force the parent exerts on the
child body (torque first), about the subtree centre of mass of the child's kinematic tree,
in world orientation. It is moved to the sensor's origin (τ_p = τ_c + (c − p) × f), negated for
Gazebo's default `child_to_parent` (what the child applies on the parent), and expressed in the
child body, parent body or sensor frame as `<frame>` says. Under a static load of mass m hanging
from the joint, `parent_to_child` reads +m·g upward.

The converter adds MuJoCo's `force` and `torque` sensors on the site (on the child body): the
same wrench, computed in C at every step, in the site frame about the site. A reading copies
those six numbers and the rotation to the asked frame (the last step's, as Gazebo reports
the last physics update); without them (or before the world stepped) it is computed here.
The tags' noise (per axis of force and torque) is added to the reading in the asked frame, as
Gazebo's F/T sensor adds it to the wrench it publishes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.description.sensors import ForceTorqueSpec
from twin_cli.sensors.frames import body_id, native_slice, site_id
from twin_cli.sensors.noise import NoiseSampler
from twin_cli.sensors.readings import WrenchReading
from twin_cli.sensors.registry import sensor_for

if TYPE_CHECKING:
    import mujoco


@sensor_for(ForceTorqueSpec)
class ForceTorqueSensor:
    """One `<sensor type="force_torque">` on a joint of an entity."""

    def __init__(self, spec: ForceTorqueSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.site = self.child = self.parent = -1
        self.native: slice | None = None
        self.sign = -1.0 if spec.measure_direction == "child_to_parent" else 1.0
        self.noise = NoiseSampler(spec.force_noise + spec.torque_noise, rng)

    def bind(self, model: mujoco.MjModel) -> None:
        self.site = site_id(model, self.entity, self.spec.site)
        self.child = body_id(model, self.entity, self.spec.child_body)
        self.parent = body_id(model, self.entity, self.spec.parent_body)
        parts = self.spec.native_parts
        self.native = native_slice(model, self.entity, self.spec.site, parts)

    def capture(self, data: mujoco.MjData) -> np.ndarray | None:
        """(force, torque) of the last step in the asked frame and direction, from MuJoCo's
        sensors; None when MuJoCo has not computed them (all zero: not stepped since built)."""
        if self.native is None:
            return None
        site_wrench = data.sensordata[self.native]
        if not site_wrench.any():
            return None
        R = self._frame(data).T @ data.site_xmat[self.site].reshape(3, 3)  # site → asked frame
        return self.sign * np.concatenate([R @ site_wrench[:3], R @ site_wrench[3:]])

    def compute(self, model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
        """What `capture` returns, computed from evaluated `data`."""
        force, torque = self.wrench_world(model, data)
        R = self._frame(data)
        return np.concatenate([R.T @ force, R.T @ torque])

    def read(self, model: mujoco.MjModel, data: mujoco.MjData, time: float) -> WrenchReading:
        values = self.capture(data)
        return self.reading(values if values is not None else self.compute(model, data), time)

    def noisy_batch(self, values: np.ndarray) -> np.ndarray:
        """Rows of `capture` values (N×6) with the tags' noise drawn for all rows at once."""
        return self.noise.apply(values)

    def reading(self, values: np.ndarray, time: float, *, noisy: bool = True) -> WrenchReading:
        """The reading of `values` (as `capture` returns them), with the tags' noise unless
        `noisy` is False (values from `noisy_batch`)."""
        if noisy:
            values = self.noise.apply_one(values)
        return WrenchReading(
            self.spec.name,
            self.spec.type,
            time,
            self.spec.frame_id,
            _vec(values[:3]),
            _vec(values[3:]),
            self.spec.frame,
            self.spec.measure_direction,
        )

    def wrench_world(
        self, model: mujoco.MjModel, data: mujoco.MjData
    ) -> tuple[np.ndarray, np.ndarray]:
        """(force [N], torque [N m] about the sensor origin), world axes, measured direction."""
        spatial = data.cfrc_int[self.child]
        torque_c, force = spatial[:3], spatial[3:]
        centre = data.subtree_com[model.body_rootid[self.child]]
        point = data.site_xpos[self.site]
        torque = torque_c + np.cross(centre - point, force)
        return self.sign * force, self.sign * torque

    def _frame(self, data: mujoco.MjData) -> np.ndarray:
        if self.spec.frame == "sensor":
            return data.site_xmat[self.site].reshape(3, 3)
        body = self.parent if self.spec.frame == "parent" else self.child
        return data.xmat[body].reshape(3, 3)


def _vec(v: np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
