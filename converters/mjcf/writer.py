"""MjSpec → an MJCF directory: `<robot>.xml`, `scene.xml`, STL/MSH assets; atomic, reproducible."""

from __future__ import annotations

import glob
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from converters.errors import OutputDirError
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

ASSETS = "assets"
SCENE = "scene.xml"
# Binary STL: 80-byte header, uint32 count, then per triangle normal + 3 vertices + attribute.
_STL_HEADER = b"twin binary STL".ljust(80, b" ")
_STL_DTYPE = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
# MuJoCo refuses an STL of more faces ("number of faces should be between 1 and 200000"): a
# larger mesh is written as MSH, MuJoCo's binary format, which has no such limit.
STL_MAX_FACES = 200_000


def safe_name(name: str) -> str:
    """A file-name-safe version of a robot or mesh name."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "robot"


def stl_bytes(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """A binary STL of a triangle mesh (float32, as the format stores it)."""
    triangles = np.asarray(vertices, dtype=float)[np.asarray(faces, dtype=np.int64)]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    records = np.zeros(len(triangles), dtype=_STL_DTYPE)
    records["normal"] = normals
    records["v"] = triangles
    count = np.array([len(triangles)], dtype="<u4").tobytes()
    return _STL_HEADER + count + records.tobytes()


def msh_bytes(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """MuJoCo's own binary mesh (MSH: int32 vertex, normal, texcoord and face counts, then
    float32 positions and int32 faces), for meshes past what MuJoCo reads from an STL."""
    positions = np.asarray(vertices, dtype="<f4").reshape(-1, 3)
    triangles = np.asarray(faces, dtype="<i4").reshape(-1, 3)
    counts = np.array([len(positions), 0, 0, len(triangles)], dtype="<i4")
    return counts.tobytes() + positions.tobytes() + triangles.tobytes()


def exported_spec(spec: mujoco.MjSpec) -> tuple[mujoco.MjSpec, dict[str, str]]:
    """A copy of `spec` as the exported file carries it: the world's contact rules, a `home`
    keyframe that stands a floating robot on the floor as `--on-ground` does, and the servos of
    what the robot's tags command by position or velocity (the key's ctrl holds their posture).

    Returns:
        The copy, and each joint given a servo with its mode.
    """
    from converters.mjcf.export_servos import export_servos
    from converters.mjcf.home_key import place_on_ground
    from converters.mjcf.world_rules import finish_robot_spec

    copy = spec.copy()
    finish_robot_spec(copy)  # priorities and solrefs as a world attaches the robot
    place_on_ground(copy)
    return copy, export_servos(copy)


def standalone_xml(spec: mujoco.MjSpec) -> str:
    """The exported robot's MJCF with its meshes inline: one text, no asset files."""
    from converters.mjcf.precision import restore_precision

    copy, _ = exported_spec(spec)
    return restore_precision(copy.to_xml(), copy)


def robot_xml(spec: mujoco.MjSpec, assets_dir: Path) -> str:
    """The robot's MJCF with every in-spec mesh written to `assets_dir` and referenced by file."""
    return _with_mesh_files(exported_spec(spec)[0], assets_dir)


def _with_mesh_files(copy: mujoco.MjSpec, assets_dir: Path) -> str:
    """`copy`'s MJCF, each in-spec mesh moved out to a file in `assets_dir` (changes `copy`)."""
    copy.modelfiledir = str(assets_dir.parent)  # to_xml compiles: let it find the new files
    for mesh in copy.meshes:
        if len(mesh.uservert) == 0:
            continue
        vertices = np.asarray(mesh.uservert, dtype=float).reshape(-1, 3)
        faces = np.asarray(mesh.userface, dtype=np.int64).reshape(-1, 3)
        if len(faces) <= STL_MAX_FACES:
            filename = f"{safe_name(mesh.name)}.stl"
            (assets_dir / filename).write_bytes(stl_bytes(vertices, faces))
        else:
            filename = f"{safe_name(mesh.name)}.msh"
            (assets_dir / filename).write_bytes(msh_bytes(vertices, faces))
        mesh.file = f"{ASSETS}/{filename}"
        mesh.uservert = []
        mesh.userface = []
    from converters.mjcf.precision import restore_precision

    return restore_precision(copy.to_xml(), copy)


def scene_xml(robot_file: str, model_name: str, robot: mujoco.MjSpec | None = None) -> str:
    """The empty world a twin World starts from (`world_rules.world_spec`: Gazebo's ground, the
    sun, the world's options and flags) with the robot included, so plain MuJoCo runs the
    physics `twin validate` proved.

    The robot is included after the ground, as a world attaches it: the same body, geom and
    contact order gives the same trajectory as the world to rounding. `robot` (the exported
    spec) brings the `<contact>` pairs a world gives its mu1/mu2 geoms (`friction_pairs`).
    """
    from converters.gazebo.friction_pairs import contact_xml
    from converters.mjcf.precision import restore_precision
    from converters.mjcf.world_rules import world_spec

    scene = world_spec(name=f"{model_name} scene")
    contact = "" if robot is None else contact_xml(robot, list(scene.worldbody.geoms))
    text = restore_precision(scene.to_xml(), scene)
    head, sep, rest = text.rpartition("</mujoco>")
    return f'{head}  <include file="{robot_file}"/>\n{contact}{sep}{rest}'


def write_model(spec: mujoco.MjSpec, report: Report, out_dir: str | Path) -> Path:
    """Write the converted robot as an MJCF directory, replacing `out_dir` atomically.

    Layout: `OUT/<robot>.xml`, `OUT/scene.xml` (ground + light + robot), `OUT/assets/*.stl`;
    only relative paths. The same spec gives byte-identical files.

    Returns:
        The path of `<robot>.xml`.
    """
    out = Path(out_dir).resolve()
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _remove_abandoned_staging(out)
        staging = Path(tempfile.mkdtemp(prefix=_staging_prefix(out), dir=out.parent))
    except OSError as exc:
        raise OutputDirError(str(out), exc.strerror or str(exc)) from exc
    try:
        return _fill_and_replace(spec, report, staging, out)
    except OSError as exc:
        raise OutputDirError(str(out), exc.strerror or str(exc)) from exc


def _staging_prefix(out: Path) -> str:
    """`.<out>.<pid>.`: the writing process is in the name, so a later run can tell a folder
    whose writer was killed from one being written now."""
    return f".{out.name}.{os.getpid()}."


def _remove_abandoned_staging(out: Path) -> None:
    """Removes staging folders of `out` whose writing process is gone (a killed `twin convert`
    leaves its half-written model beside the target)."""
    # exactly what `_staging_prefix` and mkdtemp's 8-character suffix make: a user's own
    # `.robot.2023.bak` or another target's staging (`.robot.5.<pid>.…`) never matches
    pattern = re.compile(rf"\.{re.escape(out.name)}\.(\d+)\.(?:old\.)?[a-z0-9_]{{8}}")
    for path in out.parent.glob(f".{glob.escape(out.name)}.*"):
        match = pattern.fullmatch(path.name)
        if match and path.is_dir() and not _alive(int(match.group(1))):
            shutil.rmtree(path, ignore_errors=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _fill_and_replace(spec: mujoco.MjSpec, report: Report, staging: Path, out: Path) -> Path:
    """Writes the model into `staging` and swaps it into `out`; `staging` is gone after."""
    name = safe_name(spec.modelname or report.robot)
    try:
        (staging / ASSETS).mkdir()
        robot_file = f"{name}.xml"
        exported, servoed = exported_spec(spec)
        (staging / robot_file).write_text(_with_mesh_files(exported, staging / ASSETS))
        _report_servos(report, servoed)
        (staging / SCENE).write_text(scene_xml(robot_file, name, exported))
        os.chmod(staging, 0o755)
        _replace(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return out / robot_file


def _report_servos(report: Report, servoed: dict[str, str]) -> None:
    """One line per mode: which joints the file drives by servo instead of by torque."""
    for mode in ("position", "velocity"):
        joints = sorted(j for j, m in servoed.items() if m == mode)
        if not joints:
            continue
        names = ", ".join(f"'{j}'" for j in joints)
        report.mapped(
            f"exported {mode} servos",
            f"{len(joints)} joint(s) {names}: ctrl is the {mode} target, force within ±effort, "
            "gains from the reflected inertia at home (a twin world runs the same servos by "
            "ctrl)",
            tag="ros2_control",
        )


def _replace(staging: Path, out: Path) -> None:
    """Swap `staging` into `out` with renames, so readers never see a half-written model."""
    if not out.exists():
        staging.rename(out)
        return
    old = Path(tempfile.mkdtemp(prefix=f"{_staging_prefix(out)}old.", dir=out.parent))
    old.rmdir()
    out.rename(old)
    try:
        staging.rename(out)
    except OSError:
        old.rename(out)  # the previous model stays where it was
        raise
    shutil.rmtree(old, ignore_errors=True)
