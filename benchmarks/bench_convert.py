"""Conversion time of each corpus robot (xacro → MjSpec → compiled model), and of the humanoid."""

from __future__ import annotations

import time
from pathlib import Path

import tomllib

REPO_ROOT = Path(__file__).resolve().parent.parent
CORPUS = REPO_ROOT.parent / "shared" / "corpus"
REPAIR = {"abb_irb2400_12_155", "anymal_c", "hyq"}
REPEATS = 3


def _time(fn: object) -> float:
    """Best of REPEATS wall times [s] (the first run also warms imports and the CoACD cache)."""
    best = float("inf")
    for _ in range(REPEATS):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


# A primitive-only robot: what `twin convert` costs with no mesh to load (target < 0.5 s wall).
PRIMITIVE = """<robot name="box"><link name="b"><inertial><mass value="1"/>
<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>"""
CLI_REPEATS = 7


def cli_wall(args: list[str], env: dict[str, str] | None = None) -> dict[str, float]:
    """Median and minimum wall time [s] of `twin ARGS` as a user runs it (a fresh process)."""
    import statistics

    times = [_once(args, env) for _ in range(CLI_REPEATS)]
    return {"median_s": round(statistics.median(times), 3), "min_s": round(min(times), 3)}


def _once(args: list[str], env: dict[str, str] | None) -> float:
    """Wall time [s] of one fresh `twin ARGS`."""
    import sys

    return _wall([sys.executable, "-m", "twin_cli", *args], env)


def _wall(command: list[str], env: dict[str, str] | None) -> float:
    """Wall time [s] of one fresh process running `command`."""
    import subprocess

    start = time.perf_counter()
    subprocess.run(command, capture_output=True, check=True, env=env)
    return round(time.perf_counter() - start, 3)


# The import floor of any conversion: a fresh interpreter importing what every build needs, as
# `twin convert` imports it (mujoco without its GL backend: a conversion never renders).
FLOOR = "import os; os.environ['MUJOCO_GL'] = 'disable'; import mujoco, numpy"
FLOOR_MARGIN_S = 0.1  # [s] a conversion may cost over the floor (or take < PRIMITIVE_TARGET_S)
PRIMITIVE_TARGET_S = 0.5


def against_floor(args: list[str], env: dict[str, str] | None = None) -> dict[str, object]:
    """Median wall [s] of `twin ARGS` beside the import floor (`FLOOR`), run alternately so both
    see the same machine load, and whether it meets the target (< PRIMITIVE_TARGET_S, or within
    FLOOR_MARGIN_S of the floor)."""
    import statistics
    import sys

    convert, floor = [], []
    for _ in range(CLI_REPEATS):
        floor.append(_wall([sys.executable, "-c", FLOOR], env))
        convert.append(_once(args, env))
    median, base = statistics.median(convert), statistics.median(floor)
    return {
        "convert_median_s": round(median, 3),
        "floor_median_s": round(base, 3),
        "over_floor_s": round(median - base, 3),
        "target_met": median < PRIMITIVE_TARGET_S or median - base <= FLOOR_MARGIN_S,
    }


def _corpus_args(package: str, args: dict[str, str]) -> list[str]:
    out = ["--package", f"{package}={CORPUS / 'packages' / package}"]
    for name, value in args.items():
        out += ["--arg", f"{name}:={value}"]
    return out


def cli_figures(tmp: Path) -> dict[str, object]:
    """`twin convert` of a primitive robot, of ur5e with its meshes and collision parts cached
    (targets < 0.5 s and < 1 s), of turtlebot3 with an empty cache (binary STL visuals read
    without trimesh, primitive collisions), and `twin validate` of the bundled humanoid (model
    checks and 10 physics scenarios); all in a fresh twin cache under `tmp`."""
    import os
    import shutil

    from scenarios import HUMANOID

    cache = tmp / "cache"
    env = {**os.environ, "TWIN_CACHE_DIR": str(cache)}
    primitive = tmp / "box.urdf"
    primitive.write_text(PRIMITIVE)
    ur = CORPUS / "packages" / "ur_description"
    config = ur / "config" / "ur5e"
    ur_args = _corpus_args("ur_description", {"robot_model": "ur5e"})
    for name, file in (
        ("joint_limit_params", "joint_limits.yaml"),
        ("kinematics_params", "default_kinematics.yaml"),
        ("physical_params", "physical_parameters.yaml"),
        ("visual_params", "visual_parameters.yaml"),
    ):
        ur_args += ["--arg", f"{name}:={config / file}"]
    mesh = ["convert", str(ur / "urdf" / "ur.xacro"), *ur_args, "-o", str(tmp / "ur")]
    turtlebot = CORPUS / "packages" / "turtlebot3_description"
    stl = [
        "convert",
        str(turtlebot / "urdf" / "turtlebot3_burger.urdf.xacro"),
        *_corpus_args("turtlebot3_description", {}),
        "-o",
        str(tmp / "tb3"),
    ]
    figures: dict[str, object] = {"load_average_before": os.getloadavg()}
    box = ["convert", str(primitive), "-o", str(tmp / "box")]
    figures["convert_primitive"] = against_floor(box, env)
    cold = []
    for _ in range(3):
        shutil.rmtree(cache, ignore_errors=True)
        cold.append(_once(stl, env))
    figures["convert_cold_stl_turtlebot3_s"] = sorted(cold)
    _once(mesh, env)  # fills the collision cache and the mesh store
    figures["convert_cached_mesh_ur5e"] = cli_wall(mesh, env)
    figures["validate_humanoid"] = cli_wall(["validate", str(HUMANOID), "--json"], env)
    figures["load_average_after"] = os.getloadavg()
    return figures


def run() -> dict[str, object]:
    """Per robot: convert [s] with hull collisions, convert with the default `auto` plan (cached
    CoACD after the first run) [s], compile [s], and mesh triangles carried in the spec."""
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert
    from scenarios import HUMANOID

    robots = tomllib.loads((CORPUS / "robots.toml").read_text())["robot"]
    entries = [("humanoid", HUMANOID, {}, [], False)] + [
        (
            r["id"],
            CORPUS / "packages" / r["entry"],
            r["xacro_args"],
            r["packages"],
            r["id"] in REPAIR,
        )
        for r in robots
    ]
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        results: dict[str, object] = {"cli": cli_figures(Path(tmp))}
    for robot_id, path, args, packages, repair in entries:
        paths = {p: CORPUS / "packages" / p for p in packages}

        def go(mode: str, path=path, args=args, paths=paths, repair=repair) -> object:
            options = ConvertOptions(repair_inertia=repair, collision=CollisionSettings(mode=mode))
            return convert(path, args=args, package_paths=paths, options=options)[0]

        spec = go("auto")
        start = time.perf_counter()
        model = spec.compile()
        compile_s = time.perf_counter() - start
        results[robot_id] = {
            "convert_hull_s": round(_time(lambda: go("hull")), 4),
            "convert_auto_cached_s": round(_time(lambda: go("auto")), 4),
            "compile_s": round(compile_s, 4),
            "nbody": model.nbody,
            "ngeom": model.ngeom,
            "mesh_faces": int(model.nmeshface),
        }
    return results
