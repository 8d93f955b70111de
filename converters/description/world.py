"""A world as Gazebo describes it: physics, gravity, lights, and the models placed in it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from converters.description.robot import RobotDescription, identity


@dataclass(frozen=True)
class PlacedModel:
    """A model of the world at its pose (4×4, model frame in the world frame)."""

    robot: RobotDescription
    pose: np.ndarray = field(default_factory=identity)


@dataclass(frozen=True)
class Light:
    """A light: kind directional | point | spot, pose in the world, direction, diffuse colour."""

    name: str
    kind: str
    pose: np.ndarray = field(default_factory=identity)
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    diffuse: tuple[float, float, float] = (0.8, 0.8, 0.8)
    cast_shadows: bool = False


@dataclass(frozen=True)
class WorldDescription:
    """One world file's content.

    Attributes:
        timestep: [s] `<physics><max_step_size>`; rate: [Hz] `<real_time_update_rate>`
            (0 = as fast as possible); real_time_factor: the target factor;
        iterations: solver iterations (`<ode><solver><iters>`);
        gravity: [m/s²]; models: in file order; lights: world-level lights;
        contact_max_correcting_vel: [m/s] ODE's cap on the speed at which contacts push
            overlapping bodies apart (`<ode><constraints>`; SDF default 100).
    """

    name: str
    source: str
    timestep: float
    rate: float
    real_time_factor: float
    iterations: int
    gravity: tuple[float, float, float]
    models: tuple[PlacedModel, ...] = ()
    lights: tuple[Light, ...] = ()
    contact_max_correcting_vel: float = 100.0
