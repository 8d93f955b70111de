"""A spawn runs only the code its description needs: the modules of twin it executes, counted.

Each count is of one cold in-process `World.spawn` (xacro, conversion, build, compile, commit) in
a fresh interpreter (`footprint_probe`), which must report a conversion-cache miss: a cache hit or
a module an earlier test imported would lower the count by accident. The plugin families (drives,
wheels, multicopter, controllers), the sensor family and the modules in `WHEN_DECLARED` run only
for a description that declares what they handle, which the control cases show the count sees.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from drive_models import SKID_STEER_ROS1, skid_steer_bot, two_wheel_base, with_ros2_control
from sensor_models import imu_box

from scenarios import HUMANOID

ROOT = Path(__file__).resolve().parents[3]
# Modules a cold spawn of the humanoid ran in, measured: 85 before plugin and sensor families
# were looked up from the description, 71 after, 66 with `WHEN_DECLARED`, 67 when attaching an
# entity to the world's spec left world/spawn.py (499 lines) for world/attach.py. A new module on
# the path must be needed (raise this, saying why) or run only when the description declares it.
# 68 with Gazebo's velocity motor: world/velocity_motors.py (joint states and commands ask it;
# its builder, converters/mjcf/velocity_motors.py, runs only for a robot with velocity joints).
HUMANOID_BOUND = 68
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
        "wheel_contact",
        "wheel_geometry",
    )
}
SENSOR_FAMILY = {"converters/gazebo/sensor_sites.py", "converters/gazebo/sensors.py"}
# Modules for one kind of declaration each: SDF terrain, `<ros2_control>`/`<transmission>`,
# collision bitmasks; and, in a world server only, the read log of a bounded conversion and the
# background CoACD of a deferred one.
WHEN_DECLARED = {
    "converters/mjcf/heightfields.py",
    "converters/urdf/control.py",
    "converters/gazebo/collide_bits.py",
    "converters/isolated/replay.py",
    "twin_cli/world/decomposing.py",
}
BOX_LINK = (
    '<link name="b"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0"'
    ' ixz="0" iyz="0"/></inertial><collision><geometry>{shape}</geometry></collision></link>'
)


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
    declared = sorted(WHEN_DECLARED & ran)
    assert not declared, f"a humanoid declares none of what {declared} handle, yet they ran"


def _text(robot: str, name: str = "robot.urdf") -> Callable[[Path], Path]:
    def write(folder: Path) -> Path:
        path = folder / name
        path.write_text(robot)
        return path

    return write


def _terrain(folder: Path) -> Path:
    """A static SDF model whose collision is a 9×9 `<heightmap>` image."""
    import numpy as np
    from PIL import Image

    Image.fromarray(np.zeros((9, 9), np.uint8)).save(folder / "terrain.png")
    return _text(
        '<sdf version="1.6"><model name="terrain"><static>true</static><link name="l">'
        '<collision name="c"><geometry><heightmap><uri>terrain.png</uri><size>4 4 1</size>'
        "</heightmap></geometry></collision></link></model></sdf>",
        "terrain.sdf",
    )(folder)


BOX_SHAPE = '<box size="0.1 0.1 0.1"/>'
BITMASK_BOX = (
    f'<robot name="masked">{BOX_LINK.format(shape=BOX_SHAPE)}'
    '<gazebo reference="b"><collision><surface><contact><collide_bitmask>1</collide_bitmask>'
    "</contact></surface></collision></gazebo></robot>"
)
WHEELS = ("wheel_left_joint", "wheel_right_joint")


@pytest.mark.parametrize(
    ("write", "family", "expected"),
    [
        (
            _text(skid_steer_bot(SKID_STEER_ROS1)),
            PLUGIN_FAMILY,
            "converters/gazebo/drive_motors.py",
        ),
        (_text(imu_box()), SENSOR_FAMILY, "converters/gazebo/sensor_sites.py"),
        (_terrain, WHEN_DECLARED, "converters/mjcf/heightfields.py"),
        (
            _text(with_ros2_control(two_wheel_base(""), WHEELS)),
            WHEN_DECLARED,
            "converters/urdf/control.py",
        ),
        (_text(BITMASK_BOX), WHEN_DECLARED, "converters/gazebo/collide_bits.py"),
    ],
    ids=["skid-steer plugin", "imu sensor", "heightmap", "ros2_control", "bitmask"],
)
def test_a_description_that_declares_a_family_runs_it(
    tmp_path: Path, write: Callable[[Path], Path], family: set[str], expected: str
) -> None:
    """The count sees a family run when the description asks for it (so the test above can fail)."""
    ran = _cold_spawn(write(tmp_path))
    assert expected in ran, f"{expected} did not run: {sorted(ran & family)}"
