"""Every corpus robot converts (via --package and via ROS_PACKAGE_PATH), compiles and steps."""

from __future__ import annotations

import numpy as np
import pytest
from corpus_registry import (
    CORPUS,
    DANGLING,
    NON_PHYSICAL_INERTIA,
    PACKAGES_ROOT,
    corpus_ids,
    package_paths,
)

# Control drawn in ctrlrange, except where the URDF's effort is non-physical. solo12 gives
# 1000 N·m to 38 g legs (no-load ≈1.8e6 rad/s²); the free-floating base then spins at > 1000 rad/s
# within 20 ms and explicit integration of its gyroscopic terms diverges (measured: ctrl scaled
# by 0.1 diverges at 24 ms, by 0.01 runs 1 s). Its real actuators give about 2.7 N·m.
CONTROL_SCALE = {"solo12": 0.01}
STEPS = 1000  # 1 s at the 1 ms timestep


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_robot_steps_one_second_with_random_control_without_warnings(
    robot_id: str, converted_corpus
) -> None:
    import mujoco

    model = converted_corpus(robot_id).spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scale = CONTROL_SCALE.get(robot_id, 1.0)
    low, high = (model.actuator_ctrlrange * scale).T
    rng = np.random.default_rng(0)
    for _ in range(STEPS):
        data.ctrl[:] = rng.uniform(low, high)
        mujoco.mj_step(model, data)
    warnings = {
        i: data.warning[i].number for i in range(len(data.warning)) if data.warning[i].number
    }
    assert warnings == {}, f"{robot_id}: MuJoCo warnings (index: count) {warnings}"
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all(), f"{robot_id}: state"
    assert data.time == pytest.approx(1.0), f"{robot_id}: simulated time {data.time} s"


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_robot_converts_through_ros_package_path(
    robot_id: str, converted_corpus, monkeypatch
) -> None:
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert_full

    robot = CORPUS[robot_id]
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PACKAGES_ROOT))
    options = ConvertOptions(
        repair_inertia=robot_id in NON_PHYSICAL_INERTIA,
        collision=CollisionSettings(mode="mesh"),
    )
    done = convert_full(PACKAGES_ROOT / robot["entry"], args=robot["xacro_args"], options=options)
    model = done.spec.compile()
    reference = converted_corpus(robot_id).spec.compile()
    assert (model.nbody, model.njnt, model.nu, model.neq) == (
        reference.nbody,
        reference.njnt,
        reference.nu,
        reference.neq,
    ), f"{robot_id}: bodies/joints/actuators/equalities, ROS_PACKAGE_PATH vs --package"


@pytest.mark.parametrize("robot_id", corpus_ids(NON_PHYSICAL_INERTIA))
def test_non_physical_inertia_fails_with_link_named_and_converts_with_repair(
    robot_id: str, converted_corpus
) -> None:
    from converters.errors import InertiaError
    from converters.pipeline import convert_full
    from converters.report import Outcome

    robot = CORPUS[robot_id]
    with pytest.raises(InertiaError) as caught:
        convert_full(
            PACKAGES_ROOT / robot["entry"],
            args=robot["xacro_args"],
            package_paths=package_paths(robot),
        )
    assert caught.value.link in {link.name for link in converted_corpus(robot_id).description.links}
    assert f"link '{caught.value.link}'" in str(caught.value) and "--repair-inertia" in str(
        caught.value
    )
    repaired = converted_corpus(robot_id).report.of(Outcome.REPAIRED)
    assert any(caught.value.link in e.subject for e in repaired), f"{robot_id}: repair not reported"


@pytest.mark.parametrize("robot_id", corpus_ids(DANGLING))
def test_a_reference_to_a_missing_link_is_left_out_with_a_warning_and_refused_when_strict(
    robot_id: str, converted_corpus
) -> None:
    from converters.errors import DanglingReferenceError
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert_full
    from converters.report import Outcome

    robot = CORPUS[robot_id]
    missing = robot["gazebo_references_to_missing_links"]
    warned = [e.subject for e in converted_corpus(robot_id).report.of(Outcome.WARNING)]
    for link in missing:
        assert f"<gazebo reference='{link}'>" in warned, f"{robot_id}: {warned}"
    with pytest.raises(DanglingReferenceError) as caught:
        convert_full(
            PACKAGES_ROOT / robot["entry"],
            args=robot["xacro_args"],
            package_paths=package_paths(robot),
            options=ConvertOptions(repair_inertia=robot_id in NON_PHYSICAL_INERTIA, strict=True),
        )
    message = str(caught.value)
    for part in [*(f"<gazebo reference='{link}'>" for link in missing), "without --strict"]:
        assert part in message, f"{robot_id}: {part!r} missing from {message!r}"


def _repair(robot_id: str):  # noqa: ANN202
    from converters.mjcf.builder import ConvertOptions

    return ConvertOptions(repair_inertia=robot_id in NON_PHYSICAL_INERTIA)


@pytest.mark.parametrize("robot_id", corpus_ids(sorted(set(CORPUS) - set(NON_PHYSICAL_INERTIA))))
def test_link_masses_and_total_mass_equal_the_urdf_after_lumping(
    robot_id: str, converted_corpus
) -> None:
    done = converted_corpus(robot_id)
    model = done.spec.compile()
    declared: dict[str, float] = {}
    for link in done.description.links:
        mass = float(link.inertial.mass) if link.inertial is not None else 0.0
        body = done.provenance.body_of_link[link.name]
        declared[body] = declared.get(body, 0.0) + mass
    for body, mass in declared.items():
        if body != "world":
            assert model.body(body).mass[0] == pytest.approx(mass, rel=1e-12, abs=1e-12), (
                f"{robot_id}: mass of body {body} [kg]"
            )
    urdf_total = sum(declared.values()) - declared.get("world", 0.0)
    assert model.body_mass.sum() == pytest.approx(urdf_total, rel=1e-12), f"{robot_id}: total [kg]"


@pytest.mark.parametrize("robot_id", corpus_ids(["aliengo", "robotiq_2f_85"]))
def test_converted_robot_compiles_after_attach_with_prefix(robot_id: str, converted_corpus) -> None:
    import mujoco

    world = mujoco.MjSpec()
    world.option.timestep = 0.001
    frame = world.worldbody.add_frame(pos=[1.0, 2.0, 0.5])
    world.attach(converted_corpus(robot_id).spec.copy(), frame=frame, prefix="r1/")
    model = world.compile()
    names = [model.body(i).name for i in range(1, model.nbody)]
    assert names and all(n.startswith("r1/") for n in names), f"{robot_id}: body names {names[:3]}"


def test_collada_unit_is_applied_like_gazebo(converted_corpus) -> None:
    """aliengo's calf.dae declares inches (<unit meter="0.0254">): 12.508 in long → 0.3177 m."""
    done = converted_corpus("aliengo")
    model = done.spec.compile()
    geom = model.geom("FR_calf_visual_0")
    start, count = model.mesh_vertadr[geom.dataid[0]], model.mesh_vertnum[geom.dataid[0]]
    vertices = model.mesh_vert[start : start + count]
    longest = float((vertices.max(axis=0) - vertices.min(axis=0)).max())
    assert longest == pytest.approx(12.50800502 * 0.0254, rel=1e-4), (
        "calf mesh length [m] (float32)"
    )


def test_open_manipulator_unprefixed_macro_calls_are_reported(converted_corpus) -> None:
    """Its <RefLink ref="link1"/> calls lack `xacro:`, so xacro 2.1.1 leaves them unexpanded."""
    from converters.report import Outcome

    warnings = converted_corpus("open_manipulator_x").report.of(Outcome.WARNING)
    calls = [e.subject for e in warnings if "RefLink" in e.subject]
    assert len(calls) >= 5 and any('ref="link1"' in c for c in calls), calls
