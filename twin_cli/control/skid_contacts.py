"""A skid steer's wheel contacts: soft while the base turns, rigid while it stands or runs straight.

In a turn a skid steer's wheels slide sideways. MuJoCo's solver then picks each sliding contact's
force by its regulariser and by the inertia each direction moves; rigid contacts (impedance d
0.999) leave the regulariser far below the wheel's inertia and lean the force away from the slip.
At d = TURN_IMPEDANCE the regulariser weighs as much as that inertia, as a tyre's compliance does,
and with the wheels' armature (`converters/gazebo/skid_wheels.py`) the base turns at the rate
Coulomb friction predicts (docs/plugins.md). A soft contact also creeps under a steady load and
gives back part of an impact, so the wheels are soft only while the drive turns the base: parked
on a slope or dropped, they are the converter's rigid contacts again.

The settings live in the world's compiled model (`geom_solimp`), which a spawn or delete
recompiles from the robots' specs: the softening is re-applied to a new model, and a restore on a
model that has been replaced since has nothing to undo.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco

if TYPE_CHECKING:
    from twin_cli.world.engine import World

TURN_IMPEDANCE = 0.5
"""Largest contact impedance d of a skid-steer wheel's collision geoms while the base turns."""


class WheelContacts:
    """Softens and restores the collision geoms of an entity's wheels.

    Args:
        world: the world (its lock held by the caller); entity: entity name; joints: the
            wheel joints (names in the robot's description).
    """

    def __init__(self, world: World, entity: str, joints: tuple[str, ...]) -> None:
        self.world, self.entity, self.joints = world, entity, joints
        self.model: mujoco.MjModel | None = None  # the model softened, None: rigid
        self.saved: dict[int, tuple[float, float]] = {}  # geom id → its (d0, d1)

    @property
    def soft(self) -> bool:
        """Whether the current model's wheel contacts are softened."""
        return self.model is not None and self.model is self.world.model

    def soften(self) -> None:
        """Wheel contacts at most TURN_IMPEDANCE (again, if the model was recompiled)."""
        if self.soft:
            return
        model = self.world.model
        self.saved = {}
        for g in self._geoms(model):
            d0, d1 = float(model.geom_solimp[g, 0]), float(model.geom_solimp[g, 1])
            self.saved[g] = (d0, d1)
            model.geom_solimp[g, 0] = min(d0, TURN_IMPEDANCE)
            model.geom_solimp[g, 1] = min(d1, TURN_IMPEDANCE)
        self.model = model

    def restore(self) -> None:
        """The converter's contacts back (a recompiled model already has them)."""
        if self.soft:
            for g, (d0, d1) in self.saved.items():
                self.world.model.geom_solimp[g, 0] = d0
                self.world.model.geom_solimp[g, 1] = d1
        self.model, self.saved = None, {}

    def _geoms(self, model: mujoco.MjModel) -> list[int]:
        found = []
        for joint in self.joints:
            j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{self.entity}/{joint}")
            if j < 0:
                continue
            body = int(model.jnt_bodyid[j])
            first, count = int(model.body_geomadr[body]), int(model.body_geomnum[body])
            found += [
                g
                for g in range(first, first + count)
                if model.geom_contype[g] or model.geom_conaffinity[g]
            ]
        return found
