"""The MJCF writer: loadable scene, relative asset paths, atomic replacement, reproducible bytes."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from corpus_registry import corpus_ids

from converters.mjcf.velocity_motors import ROTOR_MASS, is_rotor
from converters.mjcf.writer import stl_bytes, write_model


def _vertices(model: object, mesh: int) -> np.ndarray:
    start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    rows = model.mesh_vert[start : start + count].astype(float)
    return rows[np.lexsort(rows.T[::-1])]


def test_written_scene_loads_and_matches_the_spec(tmp_path: Path, converted_corpus) -> None:
    done = converted_corpus("solo12")
    robot_xml = write_model(done.spec, done.report, tmp_path / "out")
    reference = done.spec.compile()
    loaded = mujoco.MjModel.from_xml_path(str(robot_xml))
    assert (loaded.nbody, loaded.ngeom, loaded.nmesh, loaded.nu) == (
        reference.nbody,
        reference.ngeom,
        reference.nmesh,
        reference.nu,
    ), "model sizes"
    assert np.allclose(loaded.body_mass, reference.body_mass), "body masses [kg]"
    for i in range(reference.nmesh):
        assert np.allclose(_vertices(loaded, i), _vertices(reference, i), atol=1e-6), (
            f"vertices [m] of mesh {reference.mesh(i).name} (float32 STL)"
        )
    assert np.allclose(loaded.geom_pos, reference.geom_pos, atol=1e-6), "geom positions [m]"
    scene = mujoco.MjModel.from_xml_path(str(robot_xml.parent / "scene.xml"))
    assert scene.nbody == reference.nbody and scene.geom("ground") is not None


def test_rewrite_replaces_the_directory_and_leaves_no_temporaries(
    tmp_path: Path, converted_corpus
) -> None:
    done = converted_corpus("robotiq_2f_85")
    out = tmp_path / "out"
    out.mkdir()
    (out / "stale.txt").write_text("old")
    write_model(done.spec, done.report, out)
    first = {p.name: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    write_model(done.spec, done.report, out)
    second = {p.name: p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    assert "stale.txt" not in first, "the old directory must be replaced"
    assert first == second, "same spec, different bytes"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"], "temporary dirs left behind"


def test_stl_bytes_round_trip_through_mujoco(tmp_path: Path) -> None:
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    (tmp_path / "t.stl").write_bytes(stl_bytes(vertices, faces))
    spec = mujoco.MjSpec()
    spec.modelfiledir = str(tmp_path)
    spec.add_mesh(name="t", file="t.stl")
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="t")
    model = spec.compile()
    assert model.mesh_vertnum[0] == 4, "tetrahedron vertices after STL de-duplication"
    assert model.nmeshface == 4, "tetrahedron faces"


def test_a_users_scene_can_include_the_robot_and_add_a_geom_only_body(tmp_path: Path) -> None:
    """The robot file must not force a global `inertiafromgeom="false"` on the user's bodies."""
    from converters import convert
    from scenarios import HUMANOID

    spec, report = convert(HUMANOID)
    robot_xml = write_model(spec, report, tmp_path / "out")
    scene = tmp_path / "out" / "my_scene.xml"
    scene.write_text(
        f'<mujoco><include file="{robot_xml.name}"/><worldbody>'
        '<body name="my_ball" pos="1 0 1"><freejoint/><geom type="sphere" size="0.1"/></body>'
        "</worldbody></mujoco>"
    )
    model = mujoco.MjModel.from_xml_path(str(scene))
    ball = model.body("my_ball")
    assert ball.mass[0] == np.float64(1000.0 * 4.0 / 3.0 * np.pi * 0.1**3), "mass from its geom"
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=100)
    assert np.isfinite(data.qpos).all(), "the combined scene steps"


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_written_mjcf_reads_back_bit_for_bit(tmp_path: Path, converted_corpus, robot_id) -> None:
    """Masses, inertias, frames, joint ranges and primitive sizes survive the file exactly. The
    file adds a velocity motor's rotor body and joint (ROTOR_MASS each) per joint whose tags
    offer velocity (`converters.mjcf.velocity_motors`); the robot's own are compared by name."""
    done = converted_corpus(robot_id)
    reference = done.spec.compile()
    loaded = mujoco.MjModel.from_xml_path(str(write_model(done.spec, done.report, tmp_path)))
    bodies = [loaded.body(reference.body(b).name).id for b in range(reference.nbody)]
    joints = [loaded.joint(reference.joint(j).name).id for j in range(reference.njnt)]
    fields = ("body_mass", "body_inertia", "body_ipos", "body_pos", "body_quat")
    for field in fields:
        expected, actual = getattr(reference, field), getattr(loaded, field)[bodies]
        assert np.array_equal(actual, expected), f"{robot_id}: {field} differs in the file"
    assert np.array_equal(loaded.jnt_range[joints], reference.jnt_range), "joint ranges"
    primitive = reference.geom_type != mujoco.mjtGeom.mjGEOM_MESH
    assert np.array_equal(loaded.geom_size[primitive], reference.geom_size[primitive]), "sizes"
    total = float(loaded.body_mass[bodies].sum())
    assert total == float(reference.body_mass.sum()), f"{robot_id}: total mass {total} kg"
    rotors = sorted(set(range(loaded.nbody)) - set(bodies))
    assert all(is_rotor(loaded.body(b).name) for b in rotors), "only rotors are added"
    assert np.all(loaded.body_mass[rotors] == ROTOR_MASS), "rotor masses [kg]"
