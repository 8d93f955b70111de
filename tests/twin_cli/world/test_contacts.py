"""Contact stiffness follows the world's timestep: stable at any step, exact again at 1 ms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from models import ball_on_plane, write_urdf

from converters.gazebo.contact import max_contact_stiffness
from twin_cli.world import Pose, World, WorldSettings

RADIUS = 0.1  # [m], the model factory's ball


def _peak_after_first_bounce(world: World, name: str, seconds: float) -> float:
    """Highest z [m] the ball reaches after it first touches the ground."""
    steps = round(seconds / world.model.opt.timestep)
    touched, peak = False, -np.inf
    for _ in range(steps):
        world.step(1)
        z = world.get_pose(name).z
        touched = touched or z < RADIUS + 1e-3
        if touched:
            peak = max(peak, z)
    assert touched, "the ball never reached the ground"
    return peak


@pytest.mark.parametrize("step", [0.002, 0.004])
def test_stiff_contacts_stay_stable_at_a_longer_step(tmp_path: Path, step: float) -> None:
    """kp = 1e12 (SDF's default) dropped from 1 m: a damped bounce, never most of the height."""
    world = World(WorldSettings(timestep=step, rate=0.0))
    world.spawn(write_urdf(tmp_path, ball_on_plane(1.0)), name="ball", pose=Pose(z=1.0))
    stiffness = -world.model.geom_solref[world.model.geom("ball/ball_collision_0").id, 0]
    assert stiffness == pytest.approx(max_contact_stiffness(step)), "capped at 1/(16h²) [1/s²]"
    peak = _peak_after_first_bounce(world, "ball", 2.0)
    assert peak < RADIUS + 0.3 * (1.0 - RADIUS), f"bounced back to z = {peak:.3f} m"


def test_changing_the_step_recaps_from_the_converted_values(tmp_path: Path) -> None:
    world = World()
    world.spawn(write_urdf(tmp_path, ball_on_plane(1.0)), name="ball")
    geom = world.model.geom("ball/ball_collision_0").id
    converted = world.model.geom_solref[geom].copy()  # SDF's kp: the 1 ms cap, 6.25e4 s⁻²
    world.set_physics(timestep=0.004)
    S, B = -world.model.geom_solref[geom]
    assert S == pytest.approx(max_contact_stiffness(0.004)), "capped for 4 ms [1/s²]"
    ratio = B / (2.0 * np.sqrt(S))
    assert ratio == pytest.approx(-converted[1] / (2.0 * np.sqrt(-converted[0]))), "same ζ"
    world.set_physics(timestep=0.001)
    assert world.model.geom_solref[geom].tolist() == converted.tolist(), "restored exactly"
