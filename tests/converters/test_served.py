"""A served conversion (read in a bounded child, built once from its read log) gives the same
model as one in this process, opens no description file here, and stays inside its budget."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from call_counts import converter_calls

from converters.errors import ConversionBudgetError, ResourceNotFoundError
from converters.isolated import bounded
from converters.isolated.bounded_child import READ_EVENT
from converters.isolated.budget import XacroBudget
from converters.mjcf.builder import ConvertOptions
from converters.serving.served import ConversionJob, convert_job, convert_served, read_job
from tests.corpus_registry import CORPUS, PACKAGES_ROOT, needs_corpus, package_paths

CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.1, 0.1)]
    + ["f 1 3 2", "f 2 3 4", "f 5 6 7", "f 6 8 7", "f 1 2 5", "f 2 6 5"]
    + ["f 3 7 4", "f 4 7 8", "f 1 5 3", "f 3 5 7", "f 2 4 6", "f 4 8 6"]
)
ROBOT = """<robot name="cubes">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/>
    </inertial>
    <visual><geometry><mesh filename="cube.obj" scale="1 2 1"/></geometry></visual>
    <collision><geometry><mesh filename="cube.obj"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0"
      iyz="0"/></inertial>
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="1"/>
  </joint>
</robot>"""


@pytest.fixture(autouse=True, scope="module")
def bounded_here():
    """Conversions in this module run as a world server's do (`bounded.enable`)."""
    bounded.enable()
    yield
    bounded.disable()


def mjb(spec: mujoco.MjSpec) -> bytes:
    """The compiled model's binary (MJB): equal bytes, equal models."""
    model = spec.compile()
    buffer = np.empty(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


def _robot(folder: Path, mesh: str = "cube.obj") -> Path:
    (folder / "cube.obj").write_text(CUBE_OBJ)
    robot = folder / "cubes.urdf"
    robot.write_text(ROBOT.format(mesh=mesh))
    return robot


def _job(path: Path, **options: object) -> ConversionJob:
    return ConversionJob(str(path), path=str(path), options=ConvertOptions(**options))  # type: ignore[arg-type]


def test_a_served_conversion_builds_the_same_model_and_reads_no_file_here(tmp_path, monkeypatch):
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    robot = _robot(tmp_path)
    job = _job(robot)
    here = convert_job(job)
    opened: list[str] = []
    announced: list[str] = []

    def hook(event: str, args: tuple) -> None:
        if event == "open" and isinstance(args[0], str) and args[0].startswith(str(tmp_path)):
            opened.append(args[0])
        if event == READ_EVENT:
            announced.append(os.fsdecode(args[0]))

    sys.addaudithook(hook)
    served = convert_served(job, XacroBudget(60, 4096))
    done_reading = list(opened)
    same = mjb(served.spec) == mjb(here.spec)  # not `==` in the assert: pytest would print MBs
    assert same, "the served model differs from the one built here"
    assert done_reading == [], f"the world's process opened description files: {done_reading}"
    assert {str(robot), str(tmp_path / "cube.obj")} <= set(announced), announced
    assert (
        served.report.robot == "cubes"
        and served.report.to_dict()["entries"] == (here.report.to_dict()["entries"])
    )
    assert [s.name for s in served.sensors] == [s.name for s in here.sensors]


def test_the_child_reads_without_building_and_the_caller_builds_once(tmp_path, monkeypatch):
    """The child's work (`read_job`, run here to watch it) reads the meshes and prepares the
    collision parts but makes no MjSpec; what it sends back builds the same model as a
    conversion in this process, and a served conversion makes one MjSpec here."""
    from converters.isolated import replay
    from converters.pipeline import build_description

    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    job = _job(_robot(tmp_path))
    builds = {"new_spec", "build_spec", "build_description"}
    sent: list[tuple] = []
    ran = converter_calls(lambda: sent.append(read_job(job)), builds | {"load_mesh", "compute"})
    assert {k: ran[k] for k in builds} == dict.fromkeys(builds, 0), f"the child built: {ran}"
    assert ran["load_mesh"] >= 1 and ran["compute"] == 1, f"the child did not read: {ran}"
    robot, report, reads = sent[0]
    assert {e[0] for e in reads} == {"mesh", "collision"}, sorted(reads)
    with replay.replaying(reads):
        built = build_description(robot, job.options, report)
    same = mjb(built.spec) == mjb(convert_job(job).spec)
    assert same, "the model built from what the child sent differs from one built here"
    ran = converter_calls(lambda: convert_served(job, XacroBudget(60, 4096)), {"new_spec"})
    assert ran == {"new_spec": 1}, f"a served conversion made {ran['new_spec']} MjSpecs here"


def _heightmap_terrain(folder: Path) -> Path:
    from PIL import Image

    image = np.zeros((9, 9), np.uint8)
    image[:, 5:] = 255
    Image.fromarray(image).save(folder / "terrain.png")
    path = folder / "terrain.sdf"
    path.write_text(
        '<sdf version="1.6"><model name="terrain"><static>true</static><link name="l">'
        '<collision name="c"><geometry><heightmap><uri>terrain.png</uri><size>4 4 2</size>'
        "</heightmap></geometry></collision></link></model></sdf>"
    )
    return path


def _ros2_control_base(folder: Path) -> Path:
    import drive_models as dm

    left, right = ("wheel_left_joint",), ("wheel_right_joint",)
    robot = dm.with_diff_drive_controller(dm.two_wheel_base(dm.ROS2_CONTROL), left, right, folder)
    path = folder / "base.urdf"
    path.write_text(robot)
    return path


@pytest.mark.parametrize(
    ("make", "read"),
    [(_heightmap_terrain, "terrain.png"), (_ros2_control_base, "controllers.yaml")],
    ids=["heightmap image", "controller parameter file"],
)
def test_the_builds_other_reads_come_from_the_child(tmp_path, make, read):
    """A height image and a ros2_control parameter file are read by the child too: the served
    model and drives equal this process's, and the world's process opens neither."""
    path = make(tmp_path)
    job = _job(path)
    here = convert_job(job)
    opened: list[str] = []

    def hook(event: str, args: tuple) -> None:
        if event == "open" and isinstance(args[0], str) and args[0].startswith(str(tmp_path)):
            opened.append(args[0])

    sys.addaudithook(hook)
    served = convert_served(job, XacroBudget(60, 4096))
    done_reading = list(opened)
    same = mjb(served.spec) == mjb(here.spec)
    assert same, f"{read}: the served model differs"
    assert served.plugins == here.plugins, f"{read}: the served drives differ"
    assert served.report.to_dict()["entries"] == here.report.to_dict()["entries"]
    assert done_reading == [], f"the world's process opened description files: {done_reading}"


@needs_corpus
@pytest.mark.parametrize("robot_id", ["turtlebot3_burger", "ur5e"])
def test_a_served_corpus_robot_compiles_to_the_same_model(robot_id):
    robot = CORPUS[robot_id]
    path = PACKAGES_ROOT / robot["entry"]
    job = ConversionJob(
        str(path),
        path=str(path),
        args=tuple(robot.get("xacro_args", {}).items()),
        package_paths=tuple((k, str(v)) for k, v in package_paths(robot).items()),
        options=ConvertOptions(xacro_budget=XacroBudget()),
    )
    same = mjb(convert_served(job, XacroBudget()).spec) == mjb(convert_job(job).spec)
    assert same, f"{robot_id}: the served model differs from the one built here"


def test_an_error_in_the_child_comes_back_as_its_own_class(tmp_path):
    robot = _robot(tmp_path, mesh="missing.stl")
    with pytest.raises(ResourceNotFoundError) as caught:
        convert_served(_job(robot), XacroBudget(60, 4096))
    assert "missing.stl" in str(caught.value) and "arm" in str(caught.value), str(caught.value)


def test_a_conversion_over_its_memory_budget_names_the_variable(tmp_path, monkeypatch):
    """64 MiB of address space is less than the interpreter already maps: the first large
    allocation fails, and the error says which budget and how to raise it. The mesh cache is
    empty, so the child reads the mesh itself."""
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    robot = _robot(tmp_path)
    with pytest.raises(ConversionBudgetError) as caught:
        convert_served(_job(robot), XacroBudget(60, 64))
    message = str(caught.value)
    assert "needed more than 64 MiB" in message and "TWIN_CONVERT_MEMORY" in message, message
    assert str(robot) in message and "while " in message, message


CALLER = """
import sys, threading, time
from converters.isolated import bounded
from converters.isolated.budget import XacroBudget
from converters.serving.served import ConversionJob, convert_served

if __name__ == "__main__":
    bounded.enable()

    def tell() -> None:
        while not bounded.running():
            time.sleep(0.05)
        print(bounded.running()[0].process.pid, flush=True)

    threading.Thread(target=tell, daemon=True).start()
    convert_served(ConversionJob(sys.argv[1], path=sys.argv[1]), XacroBudget(600, 4096))
"""


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_a_conversion_child_ends_with_its_killed_caller(tmp_path, monkeypatch):
    """kill -9 of the caller (a world server) while its child reads a huge mesh with a 600 s
    budget: the child and its fork server are gone within 3 s."""
    import signal
    import subprocess
    import time

    from tests.big_meshes import write_grid_obj

    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    write_grid_obj(tmp_path / "bumps.obj", 800_000)
    robot = tmp_path / "heavy.urdf"
    robot.write_text(ROBOT.replace("cube.obj", "bumps.obj").format(mesh="bumps.obj"))
    script = tmp_path / "caller.py"
    script.write_text(CALLER)
    caller = subprocess.Popen(
        [sys.executable, str(script), str(robot)], stdout=subprocess.PIPE, text=True
    )
    try:
        child = int(caller.stdout.readline())  # type: ignore[union-attr]
        server = int(Path(f"/proc/{child}/stat").read_text().rsplit(")", 1)[1].split()[1])
        time.sleep(0.5)
        assert _alive(child), "the child ended before the caller was killed"
        caller.send_signal(signal.SIGKILL)
        caller.wait(timeout=10)
        deadline = time.monotonic() + 3.0
        while (_alive(child) or _alive(server)) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(child), "the conversion child outlived its killed caller"
        assert not _alive(server), "the fork server outlived its killed caller"
    finally:
        caller.kill()
