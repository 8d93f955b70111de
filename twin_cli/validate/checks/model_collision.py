"""Model checks on collision geometry: mesh complexity and overlaps in the initial pose.

The start posture check (`initial_overlap`) also fails a hinge or slide that starts outside its
range: its limit throws it in at startup, as an overlap throws links apart. Physics checks that
measure the robot at rest or moving part against part are not run from such a posture
(`start_posture_problems`, used by the runner): their readings would be that push, not the
robot, and blaming twin for them misleads.

Overlap rule (Gazebo semantics): a pair that the model collides and that already penetrates at
spawn (the start posture, `-J` included) makes the robot "vibrate or explode at startup", so
it fails. A robot with selfCollide
off has no self pairs; Gazebo would not collide its links either, so overlapping links joined
by no joint are listed as a warning only (they start to fight the moment someone turns
selfCollide on). Links joined by a joint never collide in Gazebo and are not checked.
"""

from __future__ import annotations

from twin_cli.validate.checks.base import RobotUnderTest, Status, fmt_len, result
from twin_cli.validate.checks.model_inertia import collision_geoms
from twin_cli.validate.checks.posture import start_data
from twin_cli.validate.scenario import Scenario

MESH = 7  # mjtGeom mjGEOM_MESH
HINGE, SLIDE = 3, 2  # mjtJoint codes


def _mesh_sources(robot: RobotUnderTest) -> dict[str, dict]:
    """The converter's per-mesh records (`report.meshes`) keyed by link name."""
    out: dict[str, dict] = {}
    for record in robot.report.meshes:
        link = str(record.get("link", ""))
        out.setdefault(link, record)
    return out


def check_mesh_complexity(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Collision meshes over `warn_triangles` warn; over `max_triangles` fail (not simplified)."""
    model = robot.model
    sources = _mesh_sources(robot)
    hints, details, worst = [], [], 0
    for g in collision_geoms(model):
        if int(model.geom_type[g]) != MESH:
            continue
        faces = int(model.mesh_facenum[int(model.geom_dataid[g])])
        link = robot.link_of_body(model.body(int(model.geom_bodyid[g])).name)
        worst = max(worst, faces)
        if faces > th["max_triangles"]:
            source = sources.get(link, {}).get("source", "its mesh")
            hints.append(
                f"link '{link}': collision mesh {source} has {faces} triangles "
                f"(> {th['max_triangles']:g}): use --collision auto/hull/coacd to simplify it, "
                "or a primitive collision shape"
            )
        elif faces > th["warn_triangles"]:
            details.append(f"link '{link}': collision mesh has {faces} triangles")
    status = Status.FAIL if hints else (Status.WARN if details else Status.PASS)
    return result(
        "mesh_complexity",
        "model",
        status,
        f"{worst} triangles (largest collision mesh)",
        f"≤ {th['warn_triangles']:g} (warn), ≤ {th['max_triangles']:g} (fail)",
        hints=hints,
        details=details,
        value=float(worst),
    )


def _jointed(model, b1: int, b2: int) -> bool:
    """True when one body is the other's parent (joined by a joint, or lumped into it)."""
    return int(model.body_parentid[b1]) == b2 or int(model.body_parentid[b2]) == b1


def _pair_name(robot: RobotUnderTest, b1: int, b2: int) -> str:
    names = sorted(robot.link_of_body(robot.model.body(b).name) for b in (b1, b2))
    return f"'{names[0]}' and '{names[1]}'"


def colliding_overlaps(robot: RobotUnderTest, data, tol: float) -> dict[tuple[int, int], float]:
    """Body pairs that the model collides and that penetrate deeper than `tol` [m]."""
    model = robot.model
    pairs: dict[tuple[int, int], float] = {}
    for i in range(data.ncon):
        contact = data.contact[i]
        b1, b2 = sorted(
            (int(model.geom_bodyid[contact.geom1]), int(model.geom_bodyid[contact.geom2]))
        )
        if contact.dist < -tol:
            pairs[(b1, b2)] = min(pairs.get((b1, b2), 0.0), float(contact.dist))
    return pairs


def latent_overlaps(robot: RobotUnderTest, data, tol: float, skip) -> dict[tuple[int, int], float]:
    """Overlapping pairs the model does not collide (selfCollide off), measured geometrically."""
    import mujoco

    model = robot.model
    geoms = collision_geoms(model)
    pairs: dict[tuple[int, int], float] = {}
    for i, g1 in enumerate(geoms):
        for g2 in geoms[i + 1 :]:
            b1, b2 = sorted((int(model.geom_bodyid[g1]), int(model.geom_bodyid[g2])))
            if b1 == b2 or (b1, b2) in skip or _jointed(model, b1, b2):
                continue
            if int(model.body_weldid[b1]) == int(model.body_weldid[b2]):
                continue  # rigidly joined: never moves relative to each other
            dist = mujoco.mj_geomDistance(model, data, g1, g2, 0.01, None)
            if dist < -tol:
                pairs[(b1, b2)] = min(pairs.get((b1, b2), 0.0), float(dist))
    return pairs


def outside_limits(
    robot: RobotUnderTest, data, tol: float
) -> list[tuple[str, float, float, float]]:
    """(joint, position, low, high) of each limited hinge or slide of `data` that is more than
    `tol` [rad or m] outside its range."""
    model, out = robot.model, []
    for j in range(model.njnt):
        if int(model.jnt_type[j]) not in (HINGE, SLIDE) or not model.jnt_limited[j]:
            continue
        q = float(data.qpos[model.jnt_qposadr[j]])
        low, high = (float(v) for v in model.jnt_range[j])
        if q < low - tol or q > high + tol:
            out.append((model.joint(j).name, q, low, high))
    return out


def start_posture_problems(robot: RobotUnderTest, scenario: Scenario, tol: float) -> list[str]:
    """What is wrong with the scenario's start posture: colliding pairs that overlap deeper than
    `tol` [m] and joints outside their ranges (empty: nothing)."""
    data = start_data(robot, scenario)
    overlaps = sorted(colliding_overlaps(robot, data, tol).items(), key=lambda kv: kv[1])
    problems = [
        f"links {_pair_name(robot, b1, b2)} overlap by {fmt_len(-d)}" for (b1, b2), d in overlaps
    ]
    problems += [
        f"joint '{name}' starts at {q:.4g}, outside its range [{low:.4g}, {high:.4g}]"
        for name, q, low, high in outside_limits(robot, data, tol)
    ]
    return problems


def check_initial_overlap(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Collision geometry that overlaps in the start posture (`-J` included), pair by pair, and
    joints that start outside their ranges."""
    data = start_data(robot, scenario)
    tol = th["tolerance_m"]
    live = colliding_overlaps(robot, data, tol)
    latent = latent_overlaps(robot, data, tol, set(live))
    hints = [
        f"links {_pair_name(robot, b1, b2)} overlap by {fmt_len(-d)} at spawn and collide: the "
        f"robot will jump or vibrate at startup; {_separation_fix(robot, b1, b2)}"
        for (b1, b2), d in sorted(live.items(), key=lambda kv: kv[1])
    ]
    outside = outside_limits(robot, data, tol)
    hints += [
        f"joint '{name}' starts at {q:.4g}, outside its range [{low:.4g}, {high:.4g}]: its "
        f"limit throws it in at startup; start it inside, e.g. -J {name}={(low + high) / 2:.4g}"
        for name, q, low, high in outside
    ]
    details = [
        f"links {_pair_name(robot, b1, b2)} overlap by {fmt_len(-d)} but do not collide "
        "(selfCollide off, as in Gazebo); they would fight if selfCollide were turned on"
        for (b1, b2), d in sorted(latent.items(), key=lambda kv: kv[1])
    ]
    deepest = -min(list(live.values()) + [0.0])
    status = Status.FAIL if hints else (Status.WARN if latent else Status.PASS)
    measured = f"{len(live)} colliding pair(s) overlap" + (
        f", {fmt_len(deepest)} deep" if live else ""
    )
    return result(
        "initial_overlap",
        "model",
        status,
        measured + (f"; {len(outside)} joint(s) outside their range" if outside else ""),
        f"0 pairs deeper than {fmt_len(tol)}",
        hints=hints,
        details=details,
        value=float(len(live)),
    )


def _separation_fix(robot: RobotUnderTest, b1: int, b2: int) -> str:
    """What stops this pair colliding at spawn, from what makes it collide: Gazebo collides two
    links of one model when either has selfCollide (or the model has <self_collide>)."""
    fixes = [
        "move or shrink one of their <collision>s",
        "start the robot in a posture where they are apart (-J NAME=POS, [robot] joints)",
    ]
    names = [robot.link_of_body(robot.model.body(b).name) for b in (b1, b2)]
    if not robot.described:
        pair = f"body1='{names[0]}' body2='{names[1]}'"
        fixes.append(f"exclude the pair (<contact><exclude {pair}/>)")
    elif robot.model_self_collide:
        fixes.append("drop the model's <self_collide> (it makes every pair of links collide)")
    else:
        tagged = [n for n in names if n in robot.self_collide_links]
        if tagged:
            where = " and ".join(f"'{n}'" for n in tagged)
            fixes.append(f"remove <selfCollide> from link {where}")
    return ", or ".join(fixes)
