"""Physics checks on contact: resting on the ground, and pushed into a box without passing through.

Penetration oracle: Gazebo's contact is a spring per contact point, so a link of mass m resting
on kp sinks about m·g/kp. twin maps kp to MuJoCo's direct solref
S = (1 − d)·kp/m (converters.gazebo.contact), so kp is recovered from a compiled geom as S·m/(1 − d)
and named in the hint when a link sinks too deep.
"""

from __future__ import annotations

import numpy as np

from twin_cli.validate.checks.base import (
    CheckResult,
    RobotUnderTest,
    Series,
    fmt_len,
    judged,
    not_applicable,
)
from twin_cli.validate.checks.sim import ScenarioRun
from twin_cli.validate.scenario import Scenario

G = 9.81  # [m/s²]


def _link(run: ScenarioRun, body: int) -> str:
    return run.world.model.body(body).name.removeprefix(f"{run.entity}/")


def geom_kp(run: ScenarioRun, geom: int) -> float | None:
    """The Gazebo kp [N/m] a geom's direct solref encodes, or None for a standard solref."""
    model = run.world.model
    s = float(model.geom_solref[geom][0])
    if s >= 0:
        return None
    d = float(model.geom_solimp[geom][0])
    mass = float(model.body_mass[int(model.geom_bodyid[geom])])
    return -s * mass / max(1.0 - d, 1e-9)


def _sink_hint(run: ScenarioRun, geom: int, depth: float, limit: float) -> str:
    """How to stop a link sinking. The load on a link is often more than its own weight (a
    wheel under a chassis), so the kp asked for is what the measured sinkage says: kp·depth is
    the load, load/limit the stiffness that holds it within the limit."""
    from converters.gazebo.contact import max_contact_stiffness

    model = run.world.model
    body = int(model.geom_bodyid[geom])
    mass = float(model.body_mass[body])
    kp = geom_kp(run, geom)
    text = f"{_link(run, body)} sinks {fmt_len(depth)} (limit {fmt_len(limit)})"
    if kp is None:
        return f"{text}: the contact is too soft for {mass:.3g} kg; set <kp>/<kd> on the link"
    step = float(model.opt.timestep)
    if -float(model.geom_solref[geom][0]) >= 0.999 * max_contact_stiffness(step):
        return (
            f"{text}: its contact is already as stiff as a {step:g} s step resolves (kp "
            f"{kp:.3g} N/m on {mass:.3g} kg); a smaller step, or the load spread over more "
            "contacts, sinks less"
        )
    needed = max(mass * G, kp * depth) / limit
    return (
        f"{text}: kp {kp:.3g} N/m is too soft for the load on it; raise <kp> in its <gazebo> "
        f"block to ≥ {needed:.2g} N/m (load/kp ≤ {fmt_len(limit)})"
    )


def skip_fixed(check: str) -> CheckResult:
    """The verdict for a robot welded to the world: it cannot stand, slide or be pushed."""
    reason = "the robot is fixed to the world (no floating base): it cannot stand, slide or move"
    return not_applicable(check, "physics", "fixed base", reason)


def check_ground_contact(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """On the ground: comes to rest, nothing falls through, penetration within tolerance."""
    run = ScenarioRun(robot, scenario)
    if not run.floating:
        return skip_fixed("ground_contact")
    deepest: dict[int, float] = {}
    speeds: list[float] = []
    velocities: list[np.ndarray] = []  # COM velocity [m/s] per sample
    times: list[float] = []
    depths: list[tuple[float, float]] = []  # (time [s], deepest penetration now [m]) settled
    lowest: list = [np.inf, run.root]  # the lowest link COM height [m] seen, and its body
    previous = [run.subtree_com()]
    settle = scenario.duration * 0.5

    def sample(r: ScenarioRun) -> None:
        com = r.subtree_com()
        velocities.append((com - previous[0]) / (10 * r.world.model.opt.timestep))
        speeds.append(float(np.linalg.norm(velocities[-1])))
        times.append(r.time)
        previous[0] = com
        with r.world.lock:
            z, body = min((float(r.world.data.xipos[b][2]), b) for b in r.bodies)
            if z < lowest[0]:
                lowest[:] = [z, body]
        if r.time >= settle:
            now = 0.0
            for geom, dist in r.ground_contacts():
                deepest[geom] = max(deepest.get(geom, 0.0), -dist)
                now = max(now, -dist)
            depths.append((r.time, now))

    run.run(scenario.duration, sample, every=10)
    final_speed = float(np.mean(speeds[-20:]))
    depth = max(deepest.values(), default=0.0)
    hints = [
        _sink_hint(run, g, d, th["max_penetration_m"])
        for g, d in sorted(deepest.items(), key=lambda kv: -kv[1])
        if d > th["max_penetration_m"]
    ]
    if lowest[0] < -th["max_penetration_m"]:
        hints.append(_fell_hint(run, lowest[1], lowest[0]))
    elif not deepest:
        hints.append(
            "the robot never touched the ground: check for links with gravity off "
            "(turnGravityOff) and that the links it stands on have a <collision>"
        )
    elif final_speed > th["rest_speed_m_s"]:
        hints.append(_moving_hint(np.mean(velocities[-20:], axis=0), scenario.duration))
    return judged(
        "ground_contact",
        "physics",
        f"penetration {fmt_len(depth)}, speed {final_speed:.2g} m/s",
        f"≤ {fmt_len(th['max_penetration_m'])}, ≤ {th['rest_speed_m_s']:g} m/s",
        hints,
        value=depth,
        series=_contact_plots(depths, times, speeds, th),
    )


def _contact_plots(
    depths: list[tuple[float, float]], times: list[float], speeds: list[float], th: dict
) -> list[Series]:
    """The deepest contact over the settled half, and the COM speed, against their limits."""
    return [
        Series(
            "ground penetration",
            "m",
            tuple(t for t, _ in depths),
            {"deepest contact (settled half)": tuple(d for _, d in depths)},
            threshold=th["max_penetration_m"],
        ),
        Series(
            "COM speed",
            "m/s",
            tuple(times),
            {"COM speed": tuple(speeds)},
            threshold=th["rest_speed_m_s"],
            log=True,
        ),
    ]


def _fell_hint(run: ScenarioRun, body: int, z: float) -> str:
    return (
        f"link '{_link(run, body)}': its centre of mass went {fmt_len(-z)} below the ground: it "
        "fell through; give it a <collision> or stiffen its contact"
    )


def _moving_hint(velocity: np.ndarray, duration: float) -> str:
    """Why a robot is not at rest at the end: it bounces (mostly vertical) or it slides or
    tips (mostly horizontal), with the fix of each."""
    speed = float(np.linalg.norm(velocity))
    text = f"still moving at {speed:.3g} m/s after {duration:g} s"
    if abs(float(velocity[2])) >= float(np.linalg.norm(velocity[:2])):
        return f"{text}, up and down: the contact bounces; raise <kd> on the links that touch"
    return (
        f"{text}, sideways: the robot slides or tips in this posture; start it in one it holds "
        "(-J NAME=POS or [robot] joints), or raise mu1/mu2 on its feet"
    )


def _never_reached(scenario: Scenario, beyond: float) -> CheckResult:
    """Not applicable: the push did not bring the robot to the box (its friction held it, or
    it tipped or folded on the way), so whether it passes through cannot be seen."""
    reason = (
        f"the push ({scenario.name}) never brought the robot to the box: its foremost link "
        f"centre stopped {fmt_len(-beyond)} before the near face (friction held it, or it "
        "tipped or folded under the push), so passing through cannot be judged"
    )
    return not_applicable("collision", "physics", "never reached the box", reason)


def check_collision(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Pushed towards a box, the robot touches it and does not pass through."""
    if not scenario.obstacles:
        reason = f"the scenario has no [[obstacles]] to push the robot into ({scenario.name})"
        return not_applicable("collision", "physics", "no obstacle", reason)
    run = ScenarioRun(robot, scenario)
    if not run.floating:
        return skip_fixed("collision")
    model = run.world.model
    box_body = max(b for b in range(model.nbody) if model.body(b).name.startswith("obstacle0/"))
    box_geoms = {g for g in range(model.ngeom) if int(model.geom_bodyid[g]) == box_body}
    with run.world.lock:
        far_face = float(run.world.data.xpos[box_body][0]) + scenario.obstacles[0].size[0] / 2
        near_face = far_face - scenario.obstacles[0].size[0]
    touched, furthest = [False], [-np.inf]
    times: list[float] = []
    fronts: list[float] = []  # the foremost link COM past the near face [m], per sample

    def sample(r: ScenarioRun) -> None:
        with r.world.lock:
            data = r.world.data
            front = max(float(data.xipos[b][0]) for b in r.bodies)
            furthest[0] = max(furthest[0], front)
            times.append(r.time)
            fronts.append(front - near_face)
            for i in range(data.ncon):
                if {int(data.contact[i].geom1), int(data.contact[i].geom2)} & box_geoms:
                    touched[0] = True

    run.run(scenario.duration, sample, every=5)
    beyond = furthest[0] - near_face
    hints = []
    if furthest[0] > far_face - th["max_intrusion_m"]:
        hints.append(
            f"a link's centre of mass reached {fmt_len(beyond)} past the box's near face: the "
            "robot passes through; give its links <collision> geometry (not only <visual>)"
        )
    elif not touched[0]:
        return _never_reached(scenario, beyond)
    return judged(
        "collision",
        "physics",
        f"deepest link COM {fmt_len(beyond)} past the near face",
        f"< {fmt_len(scenario.obstacles[0].size[0] - th['max_intrusion_m'])}",
        hints,
        value=beyond,
        series=[
            Series(
                "foremost link COM past the box's near face",
                "m",
                tuple(times),
                {"foremost link COM": tuple(fronts)},
                threshold=scenario.obstacles[0].size[0] - th["max_intrusion_m"],
            )
        ],
    )
