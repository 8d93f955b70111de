"""Inertial statistics of a converted robot (what `gz sdf --inertial-stats` prints) and its tree."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from converters.description import RobotDescription

if TYPE_CHECKING:
    import mujoco


@dataclass(frozen=True)
class InertialStats:
    """Whole-model mass properties at the `home` pose, in the model (root) frame.

    Attributes:
        total_mass: [kg].
        com: centre of mass (3,) [m].
        inertia: inertia tensor about the centre of mass (3, 3) [kg·m²].
        link_masses: link → mass [kg] as declared (lumped links included).
        tree: (depth, link, joint, joint type) rows, depth-first from the base link.
    """

    total_mass: float
    com: np.ndarray
    inertia: np.ndarray
    link_masses: dict[str, float]
    tree: tuple[tuple[int, str, str, str], ...]

    def to_dict(self) -> dict[str, object]:
        return {
            "total_mass_kg": self.total_mass,
            "center_of_mass_m": self.com.tolist(),
            "inertia_about_com_kg_m2": self.inertia.tolist(),
            "link_masses_kg": self.link_masses,
            "tree": [
                {"depth": d, "link": link, "joint": joint, "type": kind}
                for d, link, joint, kind in self.tree
            ],
        }


def inertial_stats(spec: mujoco.MjSpec, robot: RobotDescription) -> InertialStats:
    """Compile `spec`, pose it at qpos0 and sum every body's mass properties (parallel axis)."""
    import mujoco

    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    masses = model.body_mass
    total = float(masses.sum())
    com = (masses[:, None] * data.xipos).sum(axis=0) / total if total > 0 else np.zeros(3)
    tensor = np.zeros((3, 3))
    for body in range(1, model.nbody):
        R = data.ximat[body].reshape(3, 3)
        d = data.xipos[body] - com
        tensor += R @ np.diag(model.body_inertia[body]) @ R.T
        tensor += masses[body] * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    links = {
        link.name: link.inertial.mass if link.inertial is not None else 0.0 for link in robot.links
    }
    return InertialStats(total, com, tensor, links, link_tree(robot))


def link_tree(robot: RobotDescription) -> tuple[tuple[int, str, str, str], ...]:
    """Depth-first (depth, link, parent joint, joint type) rows from the base link."""
    return tuple(
        (depth, link, joint.name if joint else "", joint.kind if joint else "")
        for depth, link, joint in robot.walk()
    )
