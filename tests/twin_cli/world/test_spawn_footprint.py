"""A spawn runs only the code its description needs: the modules of twin it executes, counted.

`sys.setprofile` sees every Python call during one in-process `World.spawn` of the bundled
humanoid (xacro, conversion, build, compile, commit). A module counts when a function, method,
comprehension or class body of it runs; its module body alone (an import) does not. The plugin
families (drives, wheels, multicopter, controllers) and the sensor family run only for a
description that declares a plugin or a sensor, which the control cases show the count sees.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from drive_models import SKID_STEER_ROS1, skid_steer_bot
from sensor_models import imu_box

from scenarios import HUMANOID
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

ROOT = Path(__file__).resolve().parents[3]
OURS = ("twin_cli/", "converters/")
# Modules the humanoid's spawn ran in, measured: 85 before plugin and sensor families were
# looked up from the description, 70 after. A new module on the path must be needed (raise
# this, saying why) or imported from what the description declares.
HUMANOID_BOUND = 70
PLUGIN_FAMILY = {
    f"converters/gazebo/{name}.py"
    for name in (
        "plugins",
        "plugin_params",
        "drive_readers",
        "drive_records",
        "drive_motors",
        "drive_notes",
        "vendor_drive",
        "controller_yaml",
        "controller_drives",
        "trajectory_controller",
        "multicopter",
        "skid_wheels",
        "wheel_contact",
        "wheel_geometry",
    )
}
SENSOR_FAMILY = {"converters/gazebo/sensor_sites.py", "converters/gazebo/sensors.py"}


def _modules_run(action: Callable[[], object]) -> set[str]:
    """Paths (from the repository root) of twin's modules that executed code during `action`
    (module bodies, that is imports, aside)."""
    root = f"{ROOT}/"
    seen: set[str] = set()

    def profile(frame, event, arg) -> None:  # noqa: ARG001 (sys.setprofile's signature)
        code = frame.f_code
        if event == "call" and code.co_name != "<module>":
            seen.add(code.co_filename)

    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
    return {f[len(root) :] for f in seen if f.startswith(root) and f[len(root) :].startswith(OURS)}


def _spawn(world: World, source: Path, name: str) -> Callable[[], object]:
    return lambda: world.spawn(SpawnRequest(source=str(source)), name=name)


def test_a_humanoid_spawn_runs_a_bounded_set_of_modules_and_no_plugin_or_sensor_code() -> None:
    world = World()
    ran = _modules_run(_spawn(world, HUMANOID, "humanoid"))
    print(f"{len(ran)} modules:\n" + "\n".join(sorted(ran)))
    assert "humanoid" in world.entity_names()
    assert len(ran) <= HUMANOID_BOUND, f"{len(ran)} modules ran (bound {HUMANOID_BOUND})"
    families = {m for m in (PLUGIN_FAMILY | SENSOR_FAMILY) if m in ran}
    assert not families, f"a humanoid declares no plugin or sensor, yet {sorted(families)} ran"


@pytest.mark.parametrize(
    ("robot", "family", "expected"),
    [
        (skid_steer_bot(SKID_STEER_ROS1), PLUGIN_FAMILY, "converters/gazebo/skid_wheels.py"),
        (imu_box(), SENSOR_FAMILY, "converters/gazebo/sensor_sites.py"),
    ],
    ids=["skid-steer plugin", "imu sensor"],
)
def test_a_description_that_declares_a_family_runs_it(
    tmp_path: Path, robot: str, family: set[str], expected: str
) -> None:
    """The count sees a family run when the description asks for it (so the test above can fail)."""
    path = tmp_path / "robot.urdf"
    path.write_text(robot)
    world = World()
    ran = _modules_run(_spawn(world, path, "robot"))
    assert expected in ran, f"{expected} did not run: {sorted(ran & family)}"
