"""A served xacro cannot freeze the world or read the server's files and environment.

xacro expands in a child process with a time budget (`TWIN_CONVERT_TIMEOUT`), the environment
the client sent, and reads limited to the robot's own folder and packages.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from twin_cli.server.client import Client
from twin_cli.server.runtime import RUNTIME_ENV

WORLD = "budget"
BOMB = """<robot name="bomb" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base${9**9**9}"/>
</robot>"""
PEEK = """<robot name="peek" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="s" value="${{xacro.load_yaml('{secret}')}}"/>
  <link name="${{s['token']}}"/>
</robot>"""
ENV_PEEK = """<robot name="envpeek" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="$(env TWIN_TEST_SECRET)"/>
</robot>"""
BUDGET_S = 4.0
BOX = (
    '<robot name="box"><link name="b"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
    'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>'
)


def _twin(runtime: Path, *args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    full = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime), **(env or {})}
    return subprocess.run(
        [sys.executable, "-m", "twin_cli", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        timeout=120,
        env=full,
    )


@pytest.fixture
def runtime(tmp_path):
    directory = tmp_path / "rt"
    directory.mkdir(mode=0o700)
    # The server starts with the budget and a secret of its own in its environment.
    started = _twin(
        directory,
        "spawn",
        "--xml",
        BOX,
        env={"TWIN_CONVERT_TIMEOUT": str(BUDGET_S), "TWIN_TEST_SECRET": "server-secret"},
    )
    assert started.returncode == 0, started.stderr
    yield directory
    _twin(directory, "stop")


def test_a_xacro_bomb_is_stopped_at_its_budget_while_the_world_answers(runtime, tmp_path):
    bomb = tmp_path / "bomb.urdf.xacro"
    bomb.write_text(BOMB)
    env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime)}
    spawn = subprocess.Popen(
        [sys.executable, "-m", "twin_cli", "spawn", str(bomb), "--world", WORLD],
        env=env,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(1.5)  # the expansion is computing 9**9**9 now
    # The world answers while the conversion runs, and keeps stepping between the answers. The
    # answers are asked for in this process: a `twin stats` process costs seconds of start-up on a
    # busy runner, and the budget would end the conversion before a second one started.
    times = []
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(RUNTIME_ENV, str(runtime))
        with Client(WORLD) as client:
            while spawn.poll() is None:
                times.append(client.stats()["sim_time"])
                time.sleep(0.2)
    assert len(times) >= 2 and times[-1] > times[0], f"answers during the conversion: {times}"
    _, err = spawn.communicate(timeout=60)
    assert spawn.returncode == 2, err
    assert f"took over {BUDGET_S:g} s" in err and "TWIN_CONVERT_TIMEOUT" in err, err


def test_stop_during_a_bomb_ends_the_server_within_5_s(tmp_path):
    runtime = tmp_path / "rt2"
    runtime.mkdir(mode=0o700)
    env = {"TWIN_CONVERT_TIMEOUT": "120"}
    started = _twin(runtime, "spawn", "--xml", BOX, env=env)
    assert started.returncode == 0, started.stderr
    bomb = tmp_path / "bomb.urdf.xacro"
    bomb.write_text(BOMB)
    spawn = subprocess.Popen(
        [sys.executable, "-m", "twin_cli", "spawn", str(bomb), "--world", WORLD],
        env={**os.environ, "TWIN_RUNTIME_DIR": str(runtime)},
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(1.5)
    start = time.monotonic()
    stop = _twin(runtime, "stop")
    took = time.monotonic() - start
    assert stop.returncode == 0 and took < 5.0, f"twin stop took {took:.1f} s: {stop.stderr}"
    _, err = spawn.communicate(timeout=30)
    assert spawn.returncode != 0 and "Traceback" not in err, err


def test_a_served_xacro_reads_no_file_outside_its_robot_and_no_server_variable(runtime, tmp_path):
    secret = tmp_path / "elsewhere" / "secret.yaml"
    secret.parent.mkdir()
    secret.write_text("token: hunter2\n")
    robot = tmp_path / "robot" / "peek.urdf.xacro"
    robot.parent.mkdir()
    robot.write_text(PEEK.format(secret=secret))
    refused = _twin(runtime, "spawn", str(robot))
    assert refused.returncode == 2 and "hunter2" not in refused.stderr, refused.stderr
    assert str(secret) in refused.stderr and "outside the robot" in refused.stderr, refused.stderr
    peek = robot.parent / "envpeek.urdf.xacro"
    peek.write_text(ENV_PEEK)
    refused = _twin(runtime, "spawn", str(peek))
    assert refused.returncode == 2 and "server-secret" not in refused.stderr, refused.stderr
    assert "TWIN_TEST_SECRET" in refused.stderr, refused.stderr


POPEN = """<robot name="pop" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="${{[l := [], l.append((x.gi_frame.f_back.f_back.f_globals['os'].popen('cat {secret}')
    .read() for x in l)), python.list(l[0])][2][0]}}"/>
</robot>"""
BESIDE = """<robot name="beside" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="s" value="${{xacro.load_yaml('{secret}')}}"/>
  <link name="${{s['token']}}"/>
</robot>"""


def _bounded(path: Path):  # noqa: ANN202
    from converters.isolated.budget import XacroBudget
    from converters.resources.packages import PackageResolver
    from converters.urdf.xacro_worker import expand_bounded

    return expand_bounded(path, {}, PackageResolver.create(path, {}, {}), XacroBudget(60, 4096))


@pytest.mark.parametrize(("payload", "said"), [(POPEN, "subprocess.Popen"), (BESIDE, "outside")])
def test_a_served_xacro_can_neither_run_a_program_nor_read_beside_its_package(
    tmp_path: Path, payload: str, said: str
) -> None:
    """A frame walk to `os.popen`, and a file next to the package folder (a robot cloned
    into ~/robot must not open ~/.kube/config)."""
    from converters.errors import XacroError

    secret = tmp_path / "secret.txt"
    secret.write_text("token: hunter2\n")
    package = tmp_path / "pkg"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>pkg</name></package>")
    robot = package / "urdf" / "r.urdf.xacro"
    robot.write_text(payload.format(secret=secret))
    with pytest.raises(XacroError) as caught:
        _bounded(robot)
    assert said in str(caught.value) and "hunter2" not in str(caught.value), str(caught.value)


def test_a_served_xacro_includes_a_sibling_folder_of_its_own_package(tmp_path: Path) -> None:
    (tmp_path / "robot" / "urdf").mkdir(parents=True)
    (tmp_path / "robot" / "package.xml").write_text("<package><name>robot</name></package>")
    (tmp_path / "robot" / "common").mkdir()
    (tmp_path / "robot" / "common" / "m.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="common_link"/></robot>'
    )
    robot = tmp_path / "robot" / "urdf" / "a.urdf.xacro"
    robot.write_text(
        '<robot name="rel" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="../common/m.xacro"/></robot>'
    )
    assert 'name="common_link"' in _bounded(robot).text
