"""A spawn runs only the code its description needs: the modules of twin it executes, counted.

Each count is of one cold in-process `World.spawn` (xacro, conversion, build, compile, commit) in
a fresh interpreter (`footprint_probe`), which must report a conversion-cache miss: a cache hit or
a module an earlier test imported would lower the count by accident. The plugin families (drives,
wheels, multicopter, controllers) and the sensor family run only for a description that declares
a plugin or a sensor, which the control cases show the count sees.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from drive_models import SKID_STEER_ROS1, skid_steer_bot
from sensor_models import imu_box

from scenarios import HUMANOID

ROOT = Path(__file__).resolve().parents[3]
# Modules a cold spawn of the humanoid ran in, measured: 85 before plugin and sensor families
# were looked up from the description, 71 after. A new module on the path must be needed (raise
# this, saying why) or imported from what the description declares.
HUMANOID_BOUND = 71
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


PROBE = Path(__file__).with_name("footprint_probe.py")
PROBE_TIMEOUT_S = 120  # [s] a cold spawn of the humanoid takes ~3 s on 2 busy cores


def _cold_spawn(source: Path) -> set[str]:
    """The modules one spawn of `source` ran, in a fresh interpreter whose conversion cache
    missed once and never hit (so the conversion ran)."""
    paths = [str(ROOT), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    done = subprocess.run(
        [sys.executable, str(PROBE), str(source)],
        capture_output=True,
        text=True,
        env=env,
        timeout=PROBE_TIMEOUT_S,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    found = json.loads(done.stdout.splitlines()[-1])
    assert "robot" in found["entities"]
    assert (found["misses"], found["hits"]) == (1, 0), f"not a cold conversion: {found}"
    return set(found["modules"])


def test_a_humanoid_spawn_runs_a_bounded_set_of_modules_and_no_plugin_or_sensor_code() -> None:
    ran = _cold_spawn(HUMANOID)
    print(f"{len(ran)} modules:\n" + "\n".join(sorted(ran)))
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
    ran = _cold_spawn(path)
    assert expected in ran, f"{expected} did not run: {sorted(ran & family)}"
