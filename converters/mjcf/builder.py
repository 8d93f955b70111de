"""Robot description → MjSpec: bodies, joints, inertials, sites, geoms, meshes, actuators, keyframe.

Format-free: it reads only `converters.description`, so URDF and SDF robots build the same way.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from converters.collision.plan import CollisionRequest, CollisionSettings
from converters.collision.prepare import prepare_collision_meshes
from converters.description import RobotDescription
from converters.description.robot import MODEL_SITE
from converters.isolated.budget import XacroBudget
from converters.mjcf import inertia as inr
from converters.mjcf.actuators import actuated_joints, add_mimics, add_motors
from converters.mjcf.bodies import body_inertias
from converters.mjcf.control_data import add_control_data
from converters.mjcf.fixed_base import weld_base
from converters.mjcf.geometry import GeomPlan, plan_geoms
from converters.mjcf.joints import MjJointPlan, add_free_joint, add_joint_locks, add_joints
from converters.mjcf.loops import add_loop_equalities
from converters.mjcf.lumping import WORLDBODY, BodyPlan, plan_bodies
from converters.provenance import GeomOrigin, Provenance
from converters.report import Report
from converters.resources.mesh_data import MeshData

if TYPE_CHECKING:
    import mujoco

# Menagerie conventions and Gazebo's default world step (SDF physics max_step_size 0.001 s).
TIMESTEP = 0.001
VISUAL_CLASS = "visual"
COLLISION_CLASS = "collision"
VISUAL_GROUP = 2
COLLISION_GROUP = 3
HOME_KEY = "home"


@dataclass(frozen=True)
class ConvertOptions:
    """Converter choices: keep fixed joints as bodies, repair inertias, collision-mesh plan,
    `as_written`: apply what a URDF says where Gazebo's own parser drops it (inline `<surface>`,
    link surface values on named collisions) instead of simulating what Gazebo simulates,
    `strict`: refuse tags that name a missing link or joint, and visuals whose mesh is missing,
    instead of leaving them out with a warning as Gazebo does,
    `fixed_base`: weld the root link to the world (no free joint) as a `world` link does,
    and `xacro_budget`: expand xacro in a bounded child process (a server's conversions)."""

    keep_fixed: bool = False
    repair_inertia: bool = False
    collision: CollisionSettings = field(default_factory=CollisionSettings)
    as_written: bool = False
    strict: bool = False
    fixed_base: bool = False
    xacro_budget: XacroBudget | None = None  # None: xacro runs in this process, unbounded


def pose(T: np.ndarray) -> tuple[list[float], list[float]]:
    """(pos, quat w-x-y-z) of a 4×4 transform."""
    import mujoco

    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).reshape(-1))
    return T[:3, 3].tolist(), quat.tolist()


def new_spec(name: str) -> mujoco.MjSpec:
    """An empty spec with twin's compiler settings, option and default classes."""
    import mujoco

    spec = mujoco.MjSpec()
    spec.modelname = name
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    spec.option.timestep = TIMESTEP
    visual = spec.add_default(VISUAL_CLASS, spec.default)
    visual.geom.group = VISUAL_GROUP
    visual.geom.contype = 0
    visual.geom.conaffinity = 0
    visual.geom.density = 0
    collision = spec.add_default(COLLISION_CLASS, spec.default)
    collision.geom.group = COLLISION_GROUP
    return spec


@dataclass(frozen=True)
class BuildPlan:
    """What the builder works out from a description before it makes an MjSpec: the bodies,
    the geoms with their meshes read, and the inertias."""

    bodies: BodyPlan
    geoms: list[GeomPlan]
    inertias: dict[str, inr.Inertia]


def plan_build(robot: RobotDescription, options: ConvertOptions, report: Report) -> BuildPlan:
    """The body plan, geoms (meshes read) and inertias of `robot`.

    Raises:
        InertiaError, MeshError: as `build_spec`.
    """
    plan = plan_bodies(
        robot,
        preserved=robot.gazebo.preserved_joints,
        keep_fixed=options.keep_fixed,
        static=robot.gazebo.static,
    )
    if options.fixed_base:
        plan = weld_base(plan, report)
    geoms = plan_geoms(robot, plan, report)
    inertias = body_inertias(robot, plan, geoms, options.repair_inertia, report)
    return BuildPlan(plan, geoms, inertias)


def read_build_inputs(robot: RobotDescription, options: ConvertOptions, report: Report) -> None:
    """Read every file `build_spec` reads (meshes, then collision parts: hulls and CoACD) and
    stop before making an MjSpec: under `converters.isolated.replay.recording`, another
    process builds the same spec from the log."""
    planned = plan_build(robot, options, report)
    _collision_parts(planned.geoms, options.collision, report)


def build_spec(
    robot: RobotDescription,
    *,
    options: ConvertOptions,
    report: Report,
    provenance: Provenance,
) -> mujoco.MjSpec:
    """Build the robot's MjSpec (Gazebo tags are applied afterwards by the caller).

    Gazebo's model flags shape the bodies: `<static>` welds the base, preserveFixedJoint and
    disableFixedJointLumping keep a fixed joint's child as its own body; `fixed_base` welds
    the base as a `world` link would.

    Raises:
        InertiaError, MeshError, URDFStructureError (a mimic of a joint that cannot move).
    """
    planned = plan_build(robot, options, report)
    plan, geoms, inertias = planned.bodies, planned.geoms, planned.inertias
    spec = new_spec(robot.name)
    bodies, joints = _add_bodies(spec, plan, inertias, report, provenance)
    _add_sites(bodies, plan, robot)
    _add_geoms(spec, bodies, geoms, options.collision, report, provenance)
    actuated = actuated_joints(robot, report)
    add_motors(spec, actuated, report, frozenset(robot.actuated))
    add_control_data(spec, actuated, {a.name for a in spec.actuators}, robot, report)
    add_mimics(spec, robot, report)
    locked = add_joint_locks(spec, robot)
    spec.add_key(name=HOME_KEY, qpos=_home(joints, robot))
    _summarise(plan, inertias, geoms, report)
    report.summary.update(
        joints=len(robot.joints),
        mujoco_joints=len(joints),
        actuators=len(spec.actuators),
        mimic_equalities=len(spec.equalities) - locked,
        locked_joints=locked,
    )
    loops = add_loop_equalities(spec, robot, plan, report) if robot.loop_joints else 0
    report.summary.update(loop_equalities=loops)
    return spec


def _add_bodies(
    spec: mujoco.MjSpec,
    plan: BodyPlan,
    inertias: dict[str, inr.Inertia],
    report: Report,
    provenance: Provenance,
) -> tuple[dict[str, mujoco.MjsBody], list[MjJointPlan]]:
    bodies: dict[str, mujoco.MjsBody] = {WORLDBODY: spec.worldbody}
    joints: list[MjJointPlan] = []
    for node in plan.bodies:
        pos, quat = pose(node.T_parent_body)
        body = bodies[node.parent].add_body(name=node.name, pos=pos, quat=quat)
        bodies[node.name] = body
        _set_inertial(body, inertias[node.name])
        if node.name == plan.root_body and plan.floating:
            joints.append(add_free_joint(body, pos, quat))
        joints += add_joints(body, node.joint, report)
    for made in joints:
        if made.urdf_joint is not None:
            provenance.joints[made.name] = made.urdf_joint
    for link, placement in plan.placements.items():
        provenance.body_of_link[link] = placement.body
    provenance.lumped.extend(plan.lumped)
    return bodies, joints


def _set_inertial(body: mujoco.MjsBody, value: inr.Inertia) -> None:
    """Principal moments + axes quaternion: keeps the full tensor, off-diagonals included."""
    moments, quat = inr.principal(value)
    body.explicitinertial = True
    body.mass = value.mass
    body.ipos = value.com.tolist()
    body.iquat = quat.tolist()
    body.inertia = moments.tolist()


def _add_sites(bodies: dict[str, mujoco.MjsBody], plan: BodyPlan, robot: RobotDescription) -> None:
    """Lumped links and named frames (SDF `<frame>`) stay addressable as sites at their poses."""
    placed = [(link, plan.placements[link].T_body_link, link) for link in plan.lumped]
    for frame in robot.frames:
        placement = plan.placements[frame.link]
        placed.append((frame.name, placement.T_body_link @ frame.pose, frame.link))
    for name, T_body_site, link in placed:
        pos, quat = pose(T_body_site)
        body = bodies[plan.placements[link].body]
        body.add_site(name=name, pos=pos, quat=quat, group=VISUAL_GROUP + 3)
    if robot.model_frame_site and (plan.root_body != WORLDBODY or not plan.floating):
        T_root_model = np.linalg.inv(robot.base_pose)
        pos, quat = pose(T_root_model if plan.root_body != WORLDBODY else np.eye(4))
        bodies[plan.root_body].add_site(name=MODEL_SITE, pos=pos, quat=quat, group=VISUAL_GROUP + 3)


def _add_geoms(
    spec: mujoco.MjSpec,
    bodies: dict[str, mujoco.MjsBody],
    geoms: list[GeomPlan],
    settings: CollisionSettings,
    report: Report,
    provenance: Provenance,
) -> None:
    import mujoco

    parts = _collision_parts(geoms, settings, report)
    meshes = _MeshAssets(spec)
    defaults = {r: spec.find_default(r) for r in (VISUAL_CLASS, COLLISION_CLASS)}
    for geom in geoms:
        pieces = parts.get(_key(geom), [geom.mesh]) if geom.role == "collision" else [geom.mesh]
        if geom.role == "collision" and geom.degenerate is not None:
            report.approximated(
                f"link '{geom.link}' collision {geom.index}",
                f"mesh {geom.mesh_file} is degenerate ({geom.degenerate}); kept out of collision",
            )
            continue
        if geom.mesh is not None and len(geom.mesh.vertices) < 4:
            report.ignored(
                f"link '{geom.link}' {geom.role} {geom.index}",
                f"mesh {geom.mesh_file} has {len(geom.mesh.vertices)} vertices",
            )
            continue
        for part, mesh in enumerate(pieces):
            name = f"{geom.link}_{geom.role}_{geom.index}" + (f"_{part}" if len(pieces) > 1 else "")
            pos, quat = pose(geom.T_body_geom)
            mj = bodies[geom.body].add_geom(defaults[geom.role], name=name, pos=pos, quat=quat)
            if mesh is None:
                mj.type = _primitive(geom.kind)
                mj.size = np.array(list(geom.size) + [0.0] * (3 - len(geom.size)))
            else:
                mj.type = mujoco.mjtGeom.mjGEOM_MESH
                mj.meshname = meshes.name_for(mesh, geom, flat=geom.degenerate is not None)
            if geom.colour is not None:
                mj.rgba = np.array(geom.colour.rgba)
                if geom.colour.texture and part == 0:
                    report.approximated(
                        f"link '{geom.link}' visual {geom.index}",
                        f"texture {geom.colour.texture} is not carried; the material colour "
                        "is used",
                    )
            provenance.geoms.append(
                GeomOrigin(name, geom.link, geom.body, geom.role, geom.index, part, geom.mesh_file)
            )


def _key(geom: GeomPlan) -> str:
    return f"{geom.link}/collision_{geom.index}"


def _collision_parts(
    geoms: list[GeomPlan], settings: CollisionSettings, report: Report
) -> dict[str, list[MeshData]]:
    """All collision meshes through `prepare_collision_meshes` in one call."""
    requests = [
        CollisionRequest(_key(g), g.link, g.mesh_file or "", g.scale, g.mesh.vertices, g.mesh.faces)
        for g in geoms
        if g.role == "collision" and g.mesh is not None and g.degenerate is None
    ]
    if not requests:
        return {}
    prepared = prepare_collision_meshes(requests, settings, report)
    by_key = {r.key: r for r in requests}
    out: dict[str, list[MeshData]] = {}
    for key, parts in prepared.items():
        whole = by_key[key]
        out[key] = [
            next(
                g.mesh
                for g in geoms
                if g.role == "collision" and g.mesh is not None and _key(g) == key
            )
            if p.vertices is whole.vertices
            else MeshData(np.asarray(p.vertices, float), np.asarray(p.faces, np.int32))
            for p in parts
        ]
    return out


class _MeshAssets:
    """Mesh assets carried inside the spec (vertex and face data, no files); one per mesh."""

    def __init__(self, spec: mujoco.MjSpec) -> None:
        self.spec = spec
        self.names: dict[int, str] = {}
        self.used: set[str] = set()

    def name_for(self, mesh: MeshData, geom: GeomPlan, flat: bool) -> str:
        import mujoco

        if id(mesh) in self.names:
            return self.names[id(mesh)]
        stem = (geom.mesh_file or geom.link).replace("\\", "/").rsplit("/", 1)[-1]
        base = stem.rsplit(".", 1)[0] if geom.mesh is mesh else f"{geom.link}_c{geom.index}"
        name, n = base, 1
        while name in self.used:
            n += 1
            name = f"{base}_{n}"
        asset = self.spec.add_mesh(
            name=name,
            uservert=mesh.vertices.reshape(-1).tolist(),
            userface=mesh.faces.reshape(-1).tolist(),
        )
        if flat:
            asset.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        self.names[id(mesh)] = name
        self.used.add(name)
        return name


def _home(joints: list[MjJointPlan], robot: RobotDescription) -> list[float]:
    """The `home` keyframe: zero (clamped into range), mimic followers consistent."""
    values = {j.name: j.home for j in joints}
    for joint in robot.joints:
        mimic = joint.mimic
        if mimic is not None and joint.name in values and mimic.joint in values:
            leader = values[mimic.joint][0]
            values[joint.name] = (mimic.offset + mimic.multiplier * leader,)
    return [v for j in joints for v in values[j.name]]


def _summarise(
    plan: BodyPlan, inertias: dict[str, inr.Inertia], geoms: list[GeomPlan], report: Report
) -> None:
    report.summary.update(
        links=len(plan.placements),
        bodies=len(plan.bodies),
        lumped_links=len(plan.lumped),
        floating_base=plan.floating,
        total_mass_kg=float(sum(v.mass for v in inertias.values())),
        visual_geoms=sum(g.role == "visual" for g in geoms),
        collision_geoms=sum(g.role == "collision" for g in geoms),
    )


def _primitive(kind: str) -> mujoco.mjtGeom:
    """The MuJoCo geom type of a primitive shape."""
    import mujoco

    return {
        "ellipsoid": mujoco.mjtGeom.mjGEOM_ELLIPSOID,
        "plane": mujoco.mjtGeom.mjGEOM_PLANE,
        "box": mujoco.mjtGeom.mjGEOM_BOX,
        "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
        "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
        "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    }[kind]
