"""Forward kinematics of every converted corpus robot equals yourdfpy's (1e-9 m, 1e-9 rad)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from corpus_registry import corpus_ids

CONFIGURATIONS = 20
TOLERANCE = 1e-9  # [m] for positions; rotation-matrix entries likewise


def _random_configuration(urdf: object, rng: np.random.Generator) -> dict[str, float]:
    """Actuated (non-mimic) joints: inside their limits, continuous ones in [-π, π]."""
    cfg = {}
    for name in urdf.actuated_joint_names:
        joint = urdf.joint_map[name]
        limit = joint.limit
        if joint.type != "continuous" and limit is not None and limit.lower < limit.upper:
            cfg[name] = float(rng.uniform(limit.lower, limit.upper))
        else:
            cfg[name] = float(rng.uniform(-np.pi, np.pi))
    return cfg


def _with_mimics(urdf: object, cfg: dict[str, float]) -> dict[str, float]:
    """Every movable joint's value: mimic followers = offset + multiplier · leader."""
    full = dict(cfg)
    for joint in urdf.robot.joints:
        if joint.mimic is not None:
            multiplier = 1.0 if joint.mimic.multiplier is None else joint.mimic.multiplier
            offset = 0.0 if joint.mimic.offset is None else joint.mimic.offset
            full[joint.name] = offset + multiplier * full[joint.mimic.joint]
    return full


def _mujoco_frame(model: object, data: object, done: object, link: str) -> np.ndarray | None:
    """Pose (4×4, MuJoCo world) of a link: its body, or its site when it was lumped."""
    T = np.eye(4)
    if link in done.provenance.lumped:
        site = model.site(link)
        T[:3, :3] = data.site_xmat[site.id].reshape(3, 3)
        T[:3, 3] = data.site_xpos[site.id]
    elif done.provenance.body_of_link[link] == "world":
        return T
    else:
        body = model.body(link)
        T[:3, :3] = data.xmat[body.id].reshape(3, 3)
        T[:3, 3] = data.xpos[body.id]
    return T


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_forward_kinematics_matches_yourdfpy_at_random_configurations(
    robot_id: str, converted_corpus
) -> None:
    import mujoco
    import yourdfpy

    done = converted_corpus(robot_id)
    # The oracle reads the expanded URDF itself: nothing of twin's reader is shared with it.
    urdf = yourdfpy.URDF.load(
        io.BytesIO(done.description.text.encode()), build_scene_graph=True, load_meshes=False
    )
    model = done.spec.compile()
    data = mujoco.MjData(model)
    base = done.description.base_link
    rng = np.random.default_rng(7)
    for _ in range(CONFIGURATIONS):
        cfg = _random_configuration(urdf, rng)
        urdf.update_cfg(cfg)
        data.qpos[:] = model.qpos0
        for name, value in _with_mimics(urdf, cfg).items():
            data.qpos[model.joint(name).qposadr[0]] = value
        mujoco.mj_kinematics(model, data)
        T_world_base = _mujoco_frame(model, data, done, base)
        for link in urdf.link_map:
            expected = urdf.get_transform(frame_to=link, frame_from=base)
            actual = np.linalg.inv(T_world_base) @ _mujoco_frame(model, data, done, link)
            error = np.abs(actual - expected).max()
            assert error < TOLERANCE, f"{robot_id}: link {link} pose error {error:.3g} at {cfg}"
