"""Scheme-less include URIs (`<uri>crate</uri>`) found where libsdformat and gz-sim find them.

Beside the including file first, then under each entry of GZ_SIM_RESOURCE_PATH,
IGN_GAZEBO_RESOURCE_PATH, SDF_PATH and GAZEBO_MODEL_PATH (in that order), then under the
`gazebo_model_path` that a ROS package on ROS_PACKAGE_PATH or AMENT_PREFIX_PATH exports in its
package.xml (`${prefix}` is the package's directory); `gazebo_media_path` exports serve relative
`file://` resources. Each model found is told apart by its mass and inertia, read back from the
compiled MuJoCo model.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from sdf_libsdformat_models import model_dir

from converters.errors import SDFError
from converters.pipeline import convert_full

TOL = 1e-9  # [kg], [kg m²], [m]
# Every variable whose models a scheme-less or model:// include is looked for in.
MODEL_VARIABLES = (
    "GZ_SIM_RESOURCE_PATH",
    "IGN_GAZEBO_RESOURCE_PATH",
    "SDF_PATH",
    "GAZEBO_MODEL_PATH",
)
# The variables the conversion must not inherit from the machine running the tests.
CLEARED = (*MODEL_VARIABLES, "ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH", "GAZEBO_RESOURCE_PATH")


def _crate(mass: float) -> str:
    """A crate model of `mass` [kg] with inertia diag(0.1, 0.2, 0.3)·mass [kg m²]."""
    ixx, iyy, izz = 0.1 * mass, 0.2 * mass, 0.3 * mass
    return (
        f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="crate"><link name="box">'
        f"<inertial><mass>{mass!r}</mass><inertia><ixx>{ixx!r}</ixx><iyy>{iyy!r}</iyy>"
        f"<izz>{izz!r}</izz></inertia></inertial></link></model></sdf>\n"
    )


def _holder(tmp_path: Path) -> Path:
    """A model holding `<uri>crate</uri>` at (1, 2, 3) in its frame, beside a base link."""
    path = tmp_path / "scene" / "holder.sdf"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        '<?xml version="1.0"?>\n<sdf version="1.9"><model name="holder">'
        '<link name="base"><inertial><mass>1</mass><inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz>'
        "</inertia></inertial></link>"
        "<include><uri>crate</uri><pose>1 2 3 0 0 0</pose></include>"
        '<joint name="j" type="fixed"><parent>base</parent><child>crate::box</child></joint>'
        "</model></sdf>\n"
    )
    return path


def _env(**values: Path | str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in CLEARED}
    return {**env, **{k: str(v) for k, v in values.items()}}


def _crate_found(path: Path, env: dict[str, str]) -> float:
    """The included crate's mass [kg], after checking its inertia and pose in the holder."""
    done = convert_full(path, env=env)
    model = done.spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    box = model.body("crate::box").id
    mass = float(model.body_mass[box])
    np.testing.assert_allclose(
        np.sort(model.body_inertia[box]), np.array([0.1, 0.2, 0.3]) * mass, rtol=0, atol=TOL
    )
    base = data.xpos[model.body("base").id]
    np.testing.assert_allclose(data.xpos[box] - base, [1, 2, 3], rtol=0, atol=TOL, err_msg="[m]")
    return mass


@pytest.mark.parametrize("variable", MODEL_VARIABLES)
def test_a_scheme_less_include_is_found_on_each_model_variable(tmp_path, variable) -> None:
    roots = [tmp_path / "elsewhere", model_dir(tmp_path / variable.lower(), "crate", _crate(2.5))]
    value = os.pathsep.join(str(r) for r in roots)  # the second entry of a list is searched too
    assert _crate_found(_holder(tmp_path), _env(**{variable: value})) == pytest.approx(2.5, abs=TOL)


def test_beside_the_file_wins_then_the_variables_in_gz_sims_order(tmp_path) -> None:
    path = _holder(tmp_path)
    found = {}
    for mass, variable in enumerate(MODEL_VARIABLES, start=2):
        found[variable] = model_dir(tmp_path / variable.lower(), "crate", _crate(float(mass)))
    assert _crate_found(path, _env(**found)) == pytest.approx(2.0, abs=TOL), "GZ_SIM first"
    later = {k: v for k, v in found.items() if k not in MODEL_VARIABLES[:2]}
    assert _crate_found(path, _env(**later)) == pytest.approx(4.0, abs=TOL), "then SDF_PATH"
    model_dir(path.parent, "crate", _crate(7.0))
    assert _crate_found(path, _env(**found)) == pytest.approx(7.0, abs=TOL), "beside the file"


def _package(directory: Path, name: str, export: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{name}</name><version>1.0.0</version>'
        f"<export>{export}</export></package>\n"
    )
    return directory


EXPORT = '<gazebo_ros gazebo_model_path="${prefix}/models" gazebo_media_path="${prefix}"/>'


def test_a_package_xml_export_on_ros_package_path_serves_models(tmp_path) -> None:
    # A catkin workspace: src/<stack>/<package>, two levels below the ROS_PACKAGE_PATH entry.
    package = _package(tmp_path / "ws" / "src" / "stack" / "crates", "crates", EXPORT)
    model_dir(package / "models", "crate", _crate(3.5))
    env = _env(ROS_PACKAGE_PATH=tmp_path / "ws" / "src")
    assert _crate_found(_holder(tmp_path), env) == pytest.approx(3.5, abs=TOL)


def test_a_package_xml_export_on_ament_prefix_path_serves_models_and_media(tmp_path) -> None:
    prefix = tmp_path / "install"
    package = _package(prefix / "share" / "crates", "crates", EXPORT)
    model_dir(package / "models", "crate", _crate(4.5))
    env = _env(AMENT_PREFIX_PATH=prefix)
    path = _holder(tmp_path)
    assert _crate_found(path, env) == pytest.approx(4.5, abs=TOL)
    # gazebo_media_path: a relative file:// mesh is found under the package's directory.
    (package / "media").mkdir()
    (package / "media" / "cube.obj").write_text(
        "".join(f"v {x} {y} {z}\n" for x in (0, 0.4) for y in (0, 0.4) for z in (0, 0.4))
        + "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n"
    )
    text = path.read_text().replace(
        '<link name="base">',
        '<link name="base"><visual name="v"><geometry><mesh><uri>file://media/cube.obj</uri>'
        "</mesh></geometry></visual>",
    )
    path.write_text(text)
    model = convert_full(path, env=env).spec.compile()
    assert model.nmesh == 1, "the exported media path's mesh"
    vertices = model.mesh_vert[: model.mesh_vertnum[0]]
    extent = vertices.max(axis=0) - vertices.min(axis=0)
    np.testing.assert_allclose(extent, [0.4, 0.4, 0.4], rtol=0, atol=1e-6, err_msg="[m], float32")


def test_a_scheme_less_include_found_nowhere_names_every_place_tried(tmp_path) -> None:
    gz = tmp_path / "gz_models"
    with pytest.raises(SDFError) as refused:
        convert_full(_holder(tmp_path), env=_env(GZ_SIM_RESOURCE_PATH=gz))
    message = str(refused.value)
    assert "holder.sdf:2: <include>: 'crate' was found neither beside the file" in message
    assert str(tmp_path / "scene" / "crate") in message and str(gz / "crate") in message
    assert "GZ_SIM_RESOURCE_PATH, IGN_GAZEBO_RESOURCE_PATH, SDF_PATH, GAZEBO_MODEL_PATH" in message
    cli = subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "convert", str(_holder(tmp_path)),
         "-o", str(tmp_path / "out")],
        env=_env(GZ_SIM_RESOURCE_PATH=gz, TWIN_RUNTIME_DIR=tmp_path / "rt"),
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert cli.returncode == 2, cli.stderr
    assert "'crate' was found neither" in cli.stderr and "Traceback" not in cli.stderr


def test_a_relative_file_uri_include_is_searched_like_a_scheme_less_one(tmp_path) -> None:
    path = _holder(tmp_path)
    path.write_text(path.read_text().replace("<uri>crate</uri>", "<uri>file://crate</uri>"))
    env = _env(SDF_PATH=model_dir(tmp_path / "sdf_path", "crate", _crate(5.5)))
    assert _crate_found(path, env) == pytest.approx(5.5, abs=TOL)


def test_twin_spawn_sends_the_shells_model_paths_to_the_world(tmp_path) -> None:
    # The world starts from a shell without SDF_PATH; a later `twin spawn` from a shell with it
    # resolves the include there, as `twin convert` in that shell does.
    path = _holder(tmp_path)
    bare = _env(TWIN_RUNTIME_DIR=tmp_path / "rt", TWIN_AUTOSAVE="0")
    with_path = {**bare, "SDF_PATH": str(model_dir(tmp_path / "sdf_path", "crate", _crate(2.0)))}

    def twin(env: dict[str, str], *args: str) -> subprocess.CompletedProcess:
        command = [sys.executable, "-m", "twin_cli.cli.app", *args]
        return subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)

    try:
        refused = twin(bare, "spawn", str(path), "--name", "first", "-z", "1")
        assert refused.returncode == 2 and "'crate' was found neither" in refused.stderr, refused
        spawned = twin(with_path, "spawn", str(path), "--name", "second", "-z", "1")
        assert spawned.returncode == 0, spawned.stderr
        links = twin(bare, "model", "second", "--json")
        assert links.returncode == 0, links.stderr
        assert "crate::box" in links.stdout, links.stdout
    finally:
        twin(bare, "stop")
