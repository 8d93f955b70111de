"""Adding a sensor kind as docs/architecture.md says: one module per layer, found by registries.

A copy of `converters` and `twin_cli` gets three new files and nothing else: the converter's
record and reader of `<sensor type="toy_height">` (`converters/gazebo/sensor_kinds/`), the
world's sensor and its reading (`twin_cli/sensors/kinds/`) and its ROS message, sensor_msgs/Range
(`twin_cli/record/sensor_kinds/`). A real World then spawns boxes resting on the ground that
declare one, and the sensor's reading is checked against where the physics put the box; the
topic `twin topics` lists and the messages a recording writes come from the same registries.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from source_trees import changed_files

ROOT = Path(__file__).resolve().parents[3]
CONVERTER = '''"""`<sensor type="toy_height">`: its frame's height above the ground z = 0 [m]."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from converters.description.sensors import SensorSpec
from converters.gazebo.sensors import Placement, SensorReader, sensor_kind


@dataclass(frozen=True)
class HeightSpec(SensorSpec):
    """The range [m] it reports within (`<height><min>`, `<height><max>`)."""

    min_range: float = 0.0
    max_range: float = 10.0

    def details(self) -> str:
        return f"height above z = 0 within {self.min_range:g}..{self.max_range:g} m"


@sensor_kind("toy_height", "toy_height")
def read_height(reader: SensorReader, common: dict[str, Any], placement: Placement) -> HeightSpec:
    low, high = reader.number("height/min", 0.0), reader.number("height/max", 10.0)
    return HeightSpec(**common, min_range=low, max_range=high)
'''
WORLD = '''"""The `toy_height` sensor: its site's height above z = 0 [m], clipped to its range."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from converters.gazebo.sensor_kinds.toy_height import HeightSpec
from twin_cli.sensors.frames import site_id
from twin_cli.sensors.readings import Reading
from twin_cli.sensors.registry import sensor_for


@dataclass(frozen=True)
class HeightReading(Reading):
    """sensor_msgs/Range: `range` [m] within `min_range`..`max_range`."""

    range: float
    min_range: float
    max_range: float


@sensor_for(HeightSpec, kinematic=True)
class HeightSensor:
    """One `toy_height` sensor of an entity."""

    def __init__(self, spec: HeightSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec, self.entity, self.site = spec, entity, -1

    def bind(self, model: mujoco.MjModel) -> None:
        self.site = site_id(model, self.entity, self.spec.site)

    def read(self, model: mujoco.MjModel, data: mujoco.MjData, time: float) -> HeightReading:
        s = self.spec
        height = min(max(float(data.site_xpos[self.site, 2]), s.min_range), s.max_range)
        return HeightReading(s.name, s.type, time, s.frame_id, height, s.min_range, s.max_range)
'''
RECORD = '''"""The `toy_height` sensor's message: sensor_msgs/Range."""

from __future__ import annotations

from typing import Any

from converters.gazebo.sensor_kinds.toy_height import HeightSpec
from twin_cli.record.sensor_messages import ros_message
from twin_cli.sensors.kinds.toy_height import HeightReading

RANGE = "sensor_msgs/msg/Range"
INFRARED = 1  # sensor_msgs/Range radiation_type


@ros_message(HeightSpec, HeightReading, RANGE)
def height_message(T: Any, header: Any, r: HeightReading) -> Any:
    return T[RANGE](
        header=header,
        radiation_type=INFRARED,
        field_of_view=0.0,
        min_range=r.min_range,
        max_range=r.max_range,
        range=r.range,
        variance=0.0,
    )
'''
FILES = {
    "converters/gazebo/sensor_kinds/toy_height.py": CONVERTER,
    "twin_cli/sensors/kinds/toy_height.py": WORLD,
    "twin_cli/record/sensor_kinds/toy_height.py": RECORD,
}
# A box of half-height h [m] on a link carrying the sensor `<pose>` `OFFSET` m above its centre.
BOX = """<robot name="box"><link name="b"><inertial><mass value="1"/><inertia ixx="0.01"
  iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>
  <box size="0.3 0.3 {size}"/></geometry></collision></link>
  <gazebo reference="b"><sensor type="toy_height" name="height"><update_rate>50</update_rate>
  <pose>0 0 {offset} 0 0 0</pose><topic>height</topic><height><min>0.02</min><max>{high}</max>
  </height></sensor></gazebo></robot>"""
OFFSET = 0.1  # [m]
HALF_HEIGHTS = (0.05, 0.2, 0.5)  # [m]
# [m] how far a 1 kg box at rest sinks into the ground in MuJoCo's soft contact with Gazebo's
# defaults (measured: 4e-8 m); 1e-4 m leaves room and still tells a box at rest from one on
# another face (0.15 m off) or still falling from its 5 mm drop.
SINK = 1e-4
FLOAT32 = 1e-7  # relative precision of a float32 (sensor_msgs/Range's fields), 2^-23 rounded up
RATE = 50.0  # [Hz] the sensor's `<update_rate>`
STAMP = 2e-9  # [s] a stamp is whole nanoseconds: 1 ns of rounding at each end of a period
RECORDED_STEPS = 200  # 0.2 s of 1 ms steps recorded: 10 or 11 periods of 1/RATE
PROBE = """
import json, sys
from pathlib import Path
from twin_cli.cli.commands.sensors import summary
from rosbags.highlevel import AnyReader
from twin_cli.live.catalogue import live_topics
from twin_cli.record import BagRecording, messages
from twin_cli.record.qos import SENSOR_QOS, qos_of
from twin_cli.record.sensor_messages import sensor_message, sensor_topic
from twin_cli.sensors import SensorSuite
from twin_cli.world import Pose, World

out = []
for h, high in json.loads(sys.argv[1]):
    path = Path(sys.argv[2]) / f"box{h}.urdf"
    path.write_text(sys.argv[3].format(size=2 * h, offset=sys.argv[4], high=high))
    world = World()
    world.spawn(path, name="box", pose=Pose(z=h + 0.005))
    world.step(1500)
    reading = SensorSuite(world, "box").read()["height"]
    topic = sensor_topic("box", "height", "height", reading)
    message = sensor_message(topic, reading)
    listed = [(t.name, t.type, t.rate) for t in live_topics(world) if t.sensor == "height"]
    bag = Path(sys.argv[2]) / f"box{len(out)}.mcap"
    recording = BagRecording(world, bag).start()
    for _ in range(int(sys.argv[5]) // 5):
        world.step(5)
    assert recording.stop().error is None
    with AnyReader([bag]) as bag_reader:
        wanted = [c for c in bag_reader.connections if c.topic == topic.name]
        recorded = [
            (c.msgtype, stamp.sec + stamp.nanosec * 1e-9, m.range)
            for c, _, raw in bag_reader.messages(connections=wanted)
            for m in [bag_reader.deserialize(raw, c.msgtype)]
            for stamp in [m.header.stamp]
        ]
    out.append({
        "h": h, "reading": reading.to_dict(), "z": float(world.data.body("box/b").xpos[2]),
        "topic": [topic.name, topic.type], "sensor_qos": qos_of(topic) == SENSOR_QOS,
        "decoded": messages.typestore().deserialize_cdr(
            messages.encode(message.message, topic.type), topic.type).range,
        "listed": listed,
        "summary": summary(reading.to_dict()),
        "recorded": recorded,
        "z_after": float(world.data.body("box/b").xpos[2]),
    })
print(json.dumps(out))
"""


@pytest.fixture()
def toy_tree(tmp_path: Path) -> Path:
    """A copy of `converters` and `twin_cli` with the toy kind's three modules, and only those."""
    tree = tmp_path / "tree"
    for package in ("converters", "twin_cli"):
        ignore = shutil.ignore_patterns("*.pyc", "__pycache__")
        shutil.copytree(ROOT / package, tree / package, ignore=ignore)
    for name, text in FILES.items():
        (tree / name).write_text(text)
    changed = sorted(
        f"{package}/{name}"
        for package in ("converters", "twin_cli")
        for name in changed_files(ROOT / package, tree / package)
    )
    assert changed == sorted(FILES), changed
    return tree


def test_a_toy_sensor_kind_in_three_modules_reads_a_resting_box(
    toy_tree: Path, tmp_path: Path
) -> None:
    cases = [(h, 2.0) for h in HALF_HEIGHTS] + [(0.5, 0.3)]  # the last one clips at 0.3 m
    env = {**os.environ, "PYTHONPATH": f"{toy_tree}{os.pathsep}{ROOT}"}
    args = [json.dumps(cases), str(tmp_path), BOX, str(OFFSET), str(RECORDED_STEPS)]
    done = subprocess.run(
        [sys.executable, "-c", PROBE, *args],
        cwd=toy_tree,
        env=env,
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    results = json.loads(done.stdout.splitlines()[-1])
    for (h, high), found in zip(cases, results, strict=True):
        reading = found["reading"]
        assert reading["type"] == "toy_height" and reading["frame_id"] == "b"
        # the box rests on its face: its centre is h up, less the contact's sink
        assert h - SINK < found["z"] <= h + 1e-6, found
        expected = min(found["z"] + OFFSET, high)  # the site is OFFSET above the centre
        assert reading["range"] == pytest.approx(expected, abs=1e-9), found  # same kinematics
        assert (reading["min_range"], reading["max_range"]) == (0.02, high)
        assert found["topic"] == ["/box/height", "sensor_msgs/msg/Range"], found
        assert found["listed"] == [["/box/height", "sensor_msgs/msg/Range", 50.0]], found
        assert found["sensor_qos"], "a sensor topic is offered with SensorDataQoS"
        assert found["decoded"] == pytest.approx(reading["range"], rel=FLOAT32), found
        assert found["summary"].startswith(f"range {reading['range']:.4g}  min_range 0.02")
        # a recording of the resting box: one Range a period, each where the box rests (within
        # SINK, which also covers the float32 rounding of a range below 2 m: 1.2e-7 m)
        recorded = found["recorded"]
        assert len(recorded) >= RECORDED_STEPS / 1000 * RATE, found
        stamps = [stamp for _, stamp, _ in recorded]
        steps = [b - a for a, b in zip(stamps[:-1], stamps[1:], strict=True)]
        assert all(abs(d - 1 / RATE) <= STAMP for d in steps), stamps
        assert {msgtype for msgtype, _, _ in recorded} == {"sensor_msgs/msg/Range"}
        assert h - SINK < found["z_after"] <= h + 1e-6, found
        for _, _, value in recorded:
            assert value == pytest.approx(min(found["z_after"] + OFFSET, high), abs=SINK), found
