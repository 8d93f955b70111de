"""Collision planning: the auto rule, presets and knobs, hull caps, and a ball in a cup."""

from __future__ import annotations

import numpy as np
import pytest
from collision_models import CUP_FLOOR, CUP_INNER_R, CUP_RIM, box_mesh, cup_mesh, request
from corpus_registry import CORPUS, PACKAGES_ROOT, corpus_ids

from converters.collision import hulls
from converters.collision.plan import (
    CONVEX_RATIO,
    HEAVY_CAPS,
    HEAVY_TRIANGLES,
    PRESETS,
    TRIANGLES_ADVISED,
    TRIANGLES_MAX,
    CollisionMode,
    CollisionSettings,
    coacd_params,
    decide,
)
from converters.collision.prepare import prepare_collision_meshes
from converters.errors import CollisionSettingsError
from converters.report import Outcome, Report

BALL_RADIUS = 0.012  # [m], fits the 42 mm inner radius with room to spare
BALL_DROP_Z = 0.20  # [m] above the cup's base


@pytest.fixture(autouse=True)
def _private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))


# One row per branch of the auto rule: (triangles, convexity) -> mode.
AUTO_RULE = [
    (TRIANGLES_MAX + 1, 0.99, CollisionMode.COACD),  # too heavy, even if convex
    (500, CONVEX_RATIO - 0.01, CollisionMode.COACD),  # concave
    (500, CONVEX_RATIO, CollisionMode.HULL),  # nearly convex
    (TRIANGLES_ADVISED + 1, None, CollisionMode.COACD),  # open and over 1,000
    (TRIANGLES_ADVISED, None, CollisionMode.HULL),  # open and small
]


@pytest.mark.parametrize(("triangles", "convexity", "expected"), AUTO_RULE)
def test_auto_rule_picks_mode_from_volume_ratio_and_triangles(triangles, convexity, expected):
    decision = decide(triangles, convexity)
    assert decision.mode is expected, f"auto mode for {triangles} tris, ratio {convexity}"
    assert decision.reason, "the decision states its reason"


def test_cup_is_concave_and_box_convex_by_volume_ratio():
    cup = hulls.volumes(*cup_mesh())
    box = hulls.volumes(*box_mesh((0.1, 0.2, 0.3)))
    # Oracle: cup volume = pi (R^2 h - r^2 (h - floor)), hull = pi R^2 h.
    r_out, r_in = 0.05, 0.042
    expected = (r_out**2 * CUP_RIM - r_in**2 * (CUP_RIM - CUP_FLOOR)) / (r_out**2 * CUP_RIM)
    assert cup.convexity == pytest.approx(expected, rel=0.03), "cup volume / hull volume"
    assert box.convexity == pytest.approx(1.0, abs=1e-9), "box volume / hull volume"


def test_open_mesh_has_no_volume_and_no_convexity():
    vertices, faces = box_mesh((0.1, 0.1, 0.1))
    open_box = hulls.volumes(vertices, faces[:-2])  # drop one side
    assert open_box.mesh is None and open_box.convexity is None, "open mesh volume"
    assert open_box.hull == pytest.approx(1e-3, rel=1e-9), "hull volume of a 0.1 m cube [m^3]"


def test_threshold_in_metres_becomes_coacd_relative_threshold():
    # Longest edge 0.1 m spans 2 units inside CoACD, so 5 mm is 2 * 0.005 / 0.1 = 0.1.
    req = request("cup/0", cup_mesh())
    params = coacd_params(req, CollisionSettings(threshold_m=0.005))
    assert params.threshold == pytest.approx(0.1, rel=1e-9), "relative CoACD threshold"
    knobs = CollisionSettings(preset="fast", max_hulls=5, resolution=777, seed=3)
    params = coacd_params(req, knobs)
    assert (params.max_convex_hull, params.resolution, params.seed) == (5, 777, 3)
    assert params.mcts_iterations == PRESETS["fast"].mcts_iterations, "preset kept"


def test_presets_trade_quality_for_time():
    fast, balanced, fine = PRESETS["fast"], PRESETS["balanced"], PRESETS["fine"]
    assert fast.threshold > balanced.threshold > fine.threshold, "coarser threshold is faster"
    assert fast.mcts_iterations < balanced.mcts_iterations <= fine.mcts_iterations
    assert fast.max_convex_hull < balanced.max_convex_hull < fine.max_convex_hull


def test_heavy_mesh_gets_cheaper_coacd_search_unless_the_user_sets_knobs():
    light = request("cup/0", cup_mesh(8))  # 64 triangles
    heavy = request("cup/0", cup_mesh(HEAVY_TRIANGLES // 8 + 1))  # 8 triangles per section
    assert len(heavy.faces) > HEAVY_TRIANGLES >= len(light.faces), "fixture sizes"
    balanced = PRESETS["balanced"]
    assert coacd_params(light, CollisionSettings()) == balanced, "light mesh keeps its preset"
    sized = coacd_params(heavy, CollisionSettings())
    assert sized.threshold == HEAVY_CAPS["threshold"] > balanced.threshold, "coarser threshold"
    for name in ("max_convex_hull", "mcts_iterations", "mcts_nodes", "resolution"):
        assert getattr(sized, name) == HEAVY_CAPS[name], f"{name} capped"
    knobs = CollisionSettings(threshold=0.04, max_hulls=20, resolution=3000)
    chosen = coacd_params(heavy, knobs)
    assert (chosen.threshold, chosen.max_convex_hull, chosen.resolution) == (0.04, 20, 3000)


@pytest.mark.parametrize(
    ("settings", "option"),
    [
        (CollisionSettings(mode="convex"), "--collision"),
        (CollisionSettings(per_link={"arm": "blob"}), "--collision-link arm="),
        (CollisionSettings(preset="turbo"), "--coacd-preset"),
    ],
)
def test_unknown_setting_names_option_and_valid_values(settings, option):
    with pytest.raises(CollisionSettingsError) as info:
        prepare_collision_meshes([], settings, Report())
    message = str(info.value)
    assert option in message, f"message names the option: {message}"
    assert any(v in message for v in ("coacd", "balanced")), f"lists valid values: {message}"


def test_hull_cap_limits_vertices_and_stays_inside_full_hull():
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.1)  # 2,562 vertices
    full = hulls.convex_hull(sphere.vertices)
    capped = hulls.convex_hull(sphere.vertices, max_vertices=64)
    assert len(capped[0]) <= 64, "capped hull vertex count"
    ratio = hulls.hull_volume(capped) / hulls.hull_volume(full)
    assert 0.85 < ratio <= 1.0 + 1e-9, f"capped/full hull volume {ratio:.3f}"


def test_per_link_override_and_mesh_mode_keep_the_mesh_whole():
    cup, box = cup_mesh(8), box_mesh((0.1, 0.1, 0.1))
    settings = CollisionSettings(mode="hull", per_link={"cup": "mesh"})
    report = Report()
    requests = [request("cup/0", cup), request("box/0", box)]
    parts = prepare_collision_meshes(requests, settings, report)
    assert len(parts["cup/0"]) == 1 and np.array_equal(parts["cup/0"][0].faces, cup[1])
    rows = {row["key"]: row for row in report.meshes}
    assert (rows["cup/0"]["mode"], rows["box/0"]["mode"]) == ("mesh", "hull")
    assert len(report.of(Outcome.APPROXIMATED)) == 2, "one report line per mesh"


CUP_URDF = """<?xml version="1.0"?>
<robot name="cup_stand">
  <link name="world"/>
  <joint name="fix" type="fixed"><parent link="world"/><child link="cup"/></joint>
  <link name="cup">
    <inertial><mass value="1.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial>
    <visual><geometry><mesh filename="cup.stl"/></geometry></visual>
    <collision><geometry><mesh filename="cup.stl"/></geometry></collision>
  </link>
</robot>
"""


def _write_cup_robot(directory, sections: int = 32) -> str:
    """A static URDF whose only link is the cup mesh (an STL written here); returns its path."""
    import trimesh

    trimesh.Trimesh(*cup_mesh(sections), process=False).export(directory / "cup.stl")
    (directory / "cup.urdf").write_text(CUP_URDF)
    return str(directory / "cup.urdf")


def _drop_ball(urdf: str, settings: CollisionSettings, seconds: float):
    """Convert the cup, drop a free ball into it and step `seconds` at 1 ms.

    Returns:
        (ball centre positions (steps, 3) [m], ball speeds (steps,) [m/s], the mesh's row).
    """
    import mujoco

    from converters import ConvertOptions, convert

    spec, report = convert(urdf, options=ConvertOptions(collision=settings))
    spec.option.timestep = 0.001
    ball = spec.worldbody.add_body(name="ball", pos=[0.0, 0.0, BALL_DROP_Z])
    ball.add_freejoint(name="ball_free")
    ball.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[BALL_RADIUS, 0, 0])
    # The converted spec takes inertia from <inertial> only, so the ball states its own.
    ball.explicitinertial = True
    ball.mass = 0.01  # [kg]
    ball.inertia = [0.4 * 0.01 * BALL_RADIUS**2] * 3  # solid sphere, 2/5 m r^2 [kg m^2]
    model = spec.compile()
    data = mujoco.MjData(model)
    positions, speeds = [], []
    for _ in range(round(seconds / 0.001)):
        mujoco.mj_step(model, data)
        positions.append(data.qpos[-7:-4].copy())
        speeds.append(float(np.linalg.norm(data.qvel[-6:-3])))
    return np.array(positions), np.array(speeds), report.meshes[0]


def _rest_height(urdf: str, mode: str) -> tuple[float, dict]:
    """Drop a ball into the cup converted with `mode` (fast preset) for 1.5 s; it must come to
    rest. Returns (ball height [m], the mesh's row)."""
    settings = CollisionSettings(mode=mode, preset="fast", use_cache=False)
    positions, speeds, row = _drop_ball(urdf, settings, 1.5)
    assert speeds[-1] < 0.05, f"{mode}: ball still moving at {speeds[-1]:.3f} m/s after 1.5 s"
    return float(positions[-1, 2]), row


def test_ball_rests_inside_coacd_cup_and_on_top_of_hull_cup(tmp_path):
    urdf = _write_cup_robot(tmp_path)
    inside, decomposed = _rest_height(urdf, "coacd")
    on_top, hull = _rest_height(urdf, "hull")
    assert decomposed["parts"] >= 2 and hull["parts"] == 1, "parts per mode"
    # Inside: on the floor (8 mm + radius), allowing the parts to bulge by up to 15 mm.
    assert inside < CUP_FLOOR + BALL_RADIUS + 0.015, f"coacd: ball centre at {inside:.4f} m"
    # On the hull: the hull's top is the rim plane, the ball sits one radius above it.
    assert on_top == pytest.approx(CUP_RIM + BALL_RADIUS, abs=0.002), f"hull: {on_top:.4f} m"


def test_ball_stays_inside_heavy_cup_decomposed_by_the_default_auto_plan(tmp_path):
    # 2,008 triangles: over HEAVY_TRIANGLES, so the cheaper CoACD search runs; the cavity must
    # stay open. Oracle: over the last second the ball's centre stays inside the cavity (below
    # the rim and within the inner wall), where the hull would hold it at rim + radius.
    # (Measured: it does not come to rest; slanted part tops and seams keep it rolling and
    # kicked at up to ~0.9 m/s, also at threshold 0.10, so rest is not asserted here.)
    urdf = _write_cup_robot(tmp_path, sections=HEAVY_TRIANGLES // 8 + 1)
    positions, _, row = _drop_ball(urdf, CollisionSettings(use_cache=False), 2.0)
    assert row["triangles_before"] > HEAVY_TRIANGLES and row["mode"] == "coacd", f"row: {row}"
    last = positions[-1000:]
    highest, widest = last[:, 2].max(), np.linalg.norm(last[:, :2], axis=1).max()
    assert highest < CUP_RIM, f"heavy cup: ball centre up to {highest:.4f} m (rim {CUP_RIM} m)"
    assert widest < CUP_INNER_R, f"heavy cup: ball centre {widest:.4f} m off the axis"


# Robots whose converted model must also step 1 s without a MuJoCo warning (MuJoCo Menagerie's
# gate for a usable model).
MESH_ROBOTS = {"booster_t1", "solo12", "anymal_c", "open_manipulator_x", "robotiq_2f_85"}
# CI keeps CoACD cold runs short: fast preset, and a mesh that needs more CPU time than this
# falls back to its hull (reported). With the heavy-mesh caps open_manipulator_x's
# 13-21k-triangle meshes need 2-14 s each, one over 20 s (chain_link1), so some fall back
# here; bench_collision measures the defaults.
CORPUS_CPU_LIMIT = 8.0  # [CPU s]


@pytest.fixture(scope="module")
def corpus_cache(tmp_path_factory):
    """One cache for the module, so robots sharing meshes (the two R2-D2s) decompose once."""
    return tmp_path_factory.mktemp("corpus_cache")


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_robot_converts_with_auto_collision(robot_id, corpus_cache, monkeypatch):
    from converters import ConvertOptions, convert

    monkeypatch.setenv("TWIN_CACHE_DIR", str(corpus_cache))
    robot, packages = CORPUS[robot_id], PACKAGES_ROOT
    settings = CollisionSettings(preset="fast", jobs=2, cpu_limit=CORPUS_CPU_LIMIT)
    # Inertia repair is the core converter's concern (anymal_c, abb need it); this test is
    # about collision meshes.
    options = ConvertOptions(repair_inertia=True, collision=settings)
    spec, report = convert(
        packages / robot["entry"],
        args=robot["xacro_args"],
        package_paths={p.name: p for p in packages.iterdir()},
        options=options,
    )
    model = spec.compile()
    for row in report.meshes:
        assert row["parts"] >= 1, f"{row['key']}: collision parts ({row['reason']})"
        assert row["mode"] in ("hull", "coacd"), f"{row['key']}: auto never keeps a raw mesh"
    if robot["id"] in MESH_ROBOTS:
        _assert_falls_onto_ground_without_warning(spec, model, robot["id"])


def _assert_falls_onto_ground_without_warning(spec, model, robot_id: str) -> None:
    """Add a ground plane 2 cm below the lowest collision geom and step 1 s at zero control.

    Zero control, because random control at full effort is the core converter's gate and
    fails for reasons outside collision (solo12: 1000 N m on 0.15 kg links, unstable with any
    collision mode, even `mesh`); here the collision parts must take the landing.
    """
    import mujoco

    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    colliding = model.geom_contype > 0
    lowest = float(np.min(data.geom_xpos[colliding, 2] - model.geom_rbound[colliding]))
    spec.worldbody.add_geom(
        name="test_ground",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[5, 5, 0.1],
        pos=[0, 0, lowest - 0.02],
    )
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=1000)
    warnings = {mujoco.mjtWarning(i).name: int(w.number) for i, w in enumerate(data.warning)}
    assert not any(warnings.values()), f"{robot_id}: MuJoCo warnings {warnings}"
    assert np.isfinite(data.qpos).all(), f"{robot_id}: finite qpos after 1 s"


def test_progress_prints_plain_lines_to_stderr_when_piped(capsys):
    boxes = [request(f"b{i}/0", box_mesh((0.1, 0.1, 0.05 * (i + 1)))) for i in range(2)]
    prepare_collision_meshes(boxes, CollisionSettings(mode="hull", progress=True), Report())
    prepare_collision_meshes(boxes, CollisionSettings(mode="hull"), Report())
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert [line.split()[1] for line in lines] == ["1/2", "2/2"], f"progress lines: {lines}"
    assert "b0/0" in lines[0] and captured.out == "", "progress names the mesh, stdout untouched"
