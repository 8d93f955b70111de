"""The product a user installs: the wheel, in a fresh virtualenv with no extras, run elsewhere.

The rest of the suite runs from the source tree with the test extras, which can hide a runtime
dependency that only a test extra pulls in, or a data file that the wheel leaves out. Here the
wheel is built from the files git tracks (as in a fresh clone), installed with plain `pip install`
into a new virtualenv, and the used-by flow runs from a directory outside the repository, with
no package or model path set.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pytest
from corpus_registry import REPO_ROOT
from mesh_models import MESH_LINKS, geom_extents, write_mesh_package

# One worker runs the module and builds and installs once per run: the fixture is session-scoped
# because a module-scoped one is torn down whenever the worker runs another module's test in
# between (it was built twice a run, 145 s each on two busy cores).
pytestmark = pytest.mark.xdist_group("installed_product")

PACKAGES = ("twin_cli", "converters", "scenarios")
INSTALL_TIMEOUT_S = 900.0  # [s] a cold pip cache downloads mujoco, scipy, matplotlib, PyAV
COMMAND_TIMEOUT_S = 120.0  # [s]
MOON_G = 1.62  # [m/s²] `twin gravity --moon`
# Variables through which twin finds packages and models: unset, as on a user's machine.
RESOLVER_ENV = (
    "ROS_PACKAGE_PATH",
    "AMENT_PREFIX_PATH",
    "GAZEBO_MODEL_PATH",
    "GZ_SIM_RESOURCE_PATH",
    "GAZEBO_RESOURCE_PATH",
    "PYTHONPATH",
    "VIRTUAL_ENV",
    "TWIN_WORLD",
)
BALL = (
    '<sdf version="1.6"><model name="ball"><link name="l"><inertial><mass>1</mass><inertia>'
    "<ixx>0.004</ixx><iyy>0.004</iyy><izz>0.004</izz></inertia></inertial>"
    '<collision name="c"><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>'
    "</link></model></sdf>"
)
STOCK_WORLD = """<?xml version="1.0"?>
<sdf version="1.6"><world name="stock">
  <include><uri>model://sun</uri></include>
  <include><uri>model://ground_plane</uri></include>
</world></sdf>
"""


@dataclass(frozen=True)
class Product:
    """The installed twin: its virtualenv, the wheel it came from and a place to work."""

    venv: Path
    wheel: Path
    work: Path
    env: dict[str, str]

    def run(self, *args: str, check: bool = True) -> subprocess.CompletedProcess:
        """Run a program of the virtualenv (`twin`, `python`, `pip`) in the work directory."""
        result = subprocess.run(
            [str(self.venv / "bin" / args[0]), *args[1:]],
            cwd=self.work,
            env=self.env,
            capture_output=True,
            text=True,
            timeout=COMMAND_TIMEOUT_S,
        )
        if check:
            assert result.returncode == 0, (
                f"{' '.join(args)}: exit {result.returncode}\n{result.stdout}\n{result.stderr}"
            )
        return result

    def twin_json(self, *args: str) -> object:
        return json.loads(self.run("twin", *args, "--json").stdout)


def _source_files() -> list[Path]:
    """The files a fresh clone has: tracked plus untracked-but-not-ignored (relative paths)."""
    if (REPO_ROOT / ".git").exists() and shutil.which("git"):
        listed = subprocess.run(
            ["git", "ls-files", "-co", "--exclude-standard", "-z"],
            cwd=REPO_ROOT,
            capture_output=True,
            check=True,
        ).stdout.decode()
        return [Path(p) for p in listed.split("\0") if p and (REPO_ROOT / p).is_file()]
    skip = {".venv", ".git", "build", "__pycache__", ".pytest_cache", ".ruff_cache"}
    return [
        p.relative_to(REPO_ROOT)
        for p in REPO_ROOT.rglob("*")
        if p.is_file() and not skip & set(p.relative_to(REPO_ROOT).parts)
    ]


def _build_wheel(destination: Path) -> Path:
    """Build the wheel from a copy of the source files, as a fresh clone would."""
    clone = destination / "clone"
    for relative in _source_files():
        target = clone / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(REPO_ROOT / relative, target)
    wheels = destination / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(wheels), str(clone)],
        check=True,
        capture_output=True,
        timeout=INSTALL_TIMEOUT_S,
    )
    (wheel,) = wheels.glob("twin-*.whl")
    return wheel


@pytest.fixture(scope="session")
def product(tmp_path_factory: pytest.TempPathFactory) -> Product:
    base = tmp_path_factory.mktemp("installed")
    wheel = _build_wheel(base)
    venv = base / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    # --no-compile: the same files a user gets, without byte-compiling every dependency at
    # install (half of the install's 43 s); Python compiles what the tests import as it loads.
    install = subprocess.run(
        [str(venv / "bin" / "python"), "-m", "pip", "install", "-q", "--no-compile", str(wheel)],
        capture_output=True,
        text=True,
        timeout=INSTALL_TIMEOUT_S,
    )
    assert install.returncode == 0, f"pip install {wheel.name}:\n{install.stderr[-3000:]}"
    work, runtime = base / "work", base / "rt"
    work.mkdir()
    runtime.mkdir(mode=0o700)
    env = {k: v for k, v in os.environ.items() if k not in RESOLVER_ENV}
    env |= {
        "PATH": f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}",
        "TWIN_RUNTIME_DIR": str(runtime),
        "TWIN_CACHE_DIR": str(base / "cache"),
    }
    return Product(venv=venv, wheel=wheel, work=work, env=env)


def test_the_wheel_ships_every_data_file_of_the_packages(product: Product) -> None:
    names = set(zipfile.ZipFile(product.wheel).namelist())
    data = [
        p.as_posix()
        for p in _source_files()
        if p.parts[0] in PACKAGES and p.suffix not in (".py", ".pyc")
    ]
    assert any(p.endswith("ground_plane/model.sdf") for p in data), "the shipped models listed"
    missing = sorted(set(data) - names)
    assert not missing, f"package data left out of {product.wheel.name}: {missing}"


def test_the_install_is_plain_and_runs_from_the_virtualenv(product: Product) -> None:
    product.run("python", "-m", "pip", "check")
    where = product.run("python", "-c", "import twin_cli; print(twin_cli.__file__)").stdout
    assert Path(where.strip()).is_relative_to(product.venv), f"twin_cli imported from {where}"
    for extra in ("pytest", "yourdfpy", "playwright"):
        found = product.run("python", "-c", f"import {extra}", check=False)
        assert found.returncode != 0, f"{extra} (a test extra) is in the plain install"


def test_convert_reads_dae_stl_and_obj_meshes_at_their_unit_and_scale(product: Product) -> None:
    import mujoco

    urdf = write_mesh_package(product.work / "src")
    package = urdf.parent.parent
    out = product.work / "mesh_robot"
    product.run(
        "twin", "convert", str(urdf), "--package", f"{package.name}={package}", "-o", str(out)
    )
    (robot_file,) = [p for p in out.glob("*.xml") if p.name != "scene.xml"]
    model = mujoco.MjModel.from_xml_path(str(robot_file))
    for mesh in MESH_LINKS:
        for kind in ("visual", "collision"):
            measured = geom_extents(model, mesh.link, kind)
            assert measured == pytest.approx(mesh.extents, rel=1e-6), (
                f"{mesh.file} ({kind}): size [m] {measured}, the box is {mesh.extents}"
            )


def test_spawn_starts_a_world_and_moon_gravity_acts_live(product: Product) -> None:
    import scenarios

    humanoid = product.run("python", "-c", "import scenarios; print(scenarios.HUMANOID)").stdout
    assert Path(humanoid.strip()).name == Path(scenarios.HUMANOID).name
    world = ("--world", "flow")
    try:
        spawned = product.run("twin", "spawn", humanoid.strip(), "-z", "1.0", *world)
        assert spawned.stdout.strip() == "humanoid" and "started world" in spawned.stderr
        stats = product.run("twin", "stats", "-d", "1", *world).stdout.splitlines()
        assert stats and all(line.startswith("Factor[") for line in stats), stats
        product.run("twin", "gravity", "--moon", *world)
        assert product.twin_json("gravity", *world) == {"gravity": [0.0, 0.0, -MOON_G]}
        # A ball dropped from rest while paused falls ½·g·t² in the Moon's gravity.
        product.run("twin", "pause", *world)
        product.run("twin", "spawn", "--xml", BALL, "--name", "ball", "-x", "3", "-z", "2", *world)
        product.run("twin", "step", "500", *world)  # 0.5 s at the default 1 ms step
        z = product.twin_json("pose", "ball", *world)["z"]
        drop = 0.5 * MOON_G * 0.5**2
        assert 2.0 - z == pytest.approx(drop, rel=0.005), f"fell {2.0 - z:.5f} m, ½gt² {drop} m"
    finally:
        product.run("twin", "stop", *world, check=False)


def test_serve_a_stock_world_finds_the_shipped_ground_plane_and_sun(product: Product) -> None:
    world_file = product.work / "stock.world"
    world_file.write_text(STOCK_WORLD)
    world = ("--world", "stock")
    server = subprocess.Popen(
        [str(product.venv / "bin" / "twin"), "serve", str(world_file), *world],
        cwd=product.work,
        env=product.env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        for _ in range(600):
            listed = product.run("twin", "list", *world, "--json", check=False)
            if listed.returncode == 0 or server.poll() is not None:
                break
            subprocess.run(["sleep", "0.1"])
        assert server.poll() is None, f"twin serve exited:\n{server.communicate()[0]}"
        names = {entity["name"] for entity in json.loads(listed.stdout)}
        assert "ground_plane" in names, f"entities {names}"
        # The shipped plane collides: a ball dropped on it rests on it at its radius.
        product.run("twin", "spawn", "--xml", BALL, "--name", "ball", "-z", "0.5", *world)
        product.run("twin", "pause", *world)
        product.run("twin", "step", "2000", *world)
        z = product.twin_json("pose", "ball", *world)["z"]
        assert z == pytest.approx(0.1, abs=0.005), f"ball centre at {z:.4f} m, radius 0.1 m"
    finally:
        product.run("twin", "stop", *world, check=False)
        server.wait(timeout=30)


def test_validate_the_bundled_robot_writes_a_passing_junit_report(product: Product) -> None:
    humanoid = product.run("python", "-c", "import scenarios; print(scenarios.HUMANOID)").stdout
    report = product.work / "report.xml"
    product.run("twin", "validate", humanoid.strip(), "--junit", str(report))
    suite = ET.parse(report).getroot().find("testsuite")
    assert suite is not None, "a <testsuite> in the report"
    counts = {key: int(suite.get(key, "0")) for key in ("tests", "failures", "errors")}
    assert counts["tests"] >= 15 and counts["failures"] == counts["errors"] == 0, counts
