"""Physics checks on friction: standing feet do not slide; a foot slides on a slope iff tan θ > μ.

Incline oracle (Coulomb, Gazebo's min rule): a block on a slope of angle θ sticks when
tan θ ≤ min(μ_foot, μ_ground) and otherwise slides with a = g (sin θ − μ cos θ). The robot's
feet are the collision geoms lowest in the start pose; each becomes a probe block with the
foot's own contact settings (friction, priority, solref, solimp) and bounding box, so the test
measures the robot's surfaces against Gazebo's ground, not the robot's balance.
"""

from __future__ import annotations

import math

import numpy as np

from twin_cli.validate.checks.base import (
    CheckResult,
    RobotUnderTest,
    Series,
    Status,
    bars,
    fmt_len,
    judged,
    not_applicable,
    result,
)
from twin_cli.validate.checks.model_inertia import collision_geoms
from twin_cli.validate.checks.physics_contact import skip_fixed
from twin_cli.validate.checks.sim import ScenarioRun
from twin_cli.validate.scenario import Scenario

GROUND_MU = 100.0  # Gazebo's stock ground plane (converters.gazebo.contact.GROUND_MU)
MAX_SLIDE_ANGLE = math.radians(80.0)  # steeper slopes are not tested for sliding
# [rad] a foot turned this far from level has rolled over its edge: the robot tipped, not slid.
TIPPED_OVER_RAD = 0.3
# MuJoCo's smallest friction coefficient (mjMINMU): a surface at or below it is frictionless.
FRICTIONLESS_MU = 1e-5


def foot_geoms(run: ScenarioRun, within: float = 0.01) -> list[int]:
    """Robot collision geoms whose lowest point is within `within` [m] of the robot's lowest."""
    model = run.world.model
    mine = [g for g in collision_geoms(model) if int(model.geom_bodyid[g]) in run.bodies]
    with run.world.lock:
        data = run.world.data
        lows = {}
        for g in mine:
            rot = np.array(data.geom_xmat[g]).reshape(3, 3)
            centre = np.array(data.geom_xpos[g]) + rot @ model.geom_aabb[g][:3]
            lows[g] = centre[2] - float(np.abs(rot[2]) @ model.geom_aabb[g][3:])
    floor = min(lows.values(), default=0.0)
    return [g for g, z in lows.items() if z <= floor + within]


def check_friction_standing(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Standing (posture held), the feet do not slide: horizontal slip ≤ `max_slip_m`."""
    run = ScenarioRun(robot, scenario)
    if not run.floating:
        return skip_fixed("friction_standing")
    feet = sorted({int(run.world.model.geom_bodyid[g]) for g in foot_geoms(run)})
    settle = th["settle_s"]
    run.run(settle, None, every=10)
    with run.world.lock:
        start = {b: np.array(run.world.data.xpos[b][:2]) for b in feet}
    times, slips = [0.0], {b: [0.0] for b in feet}

    def sample(r: ScenarioRun) -> None:
        times.append(r.time - settle)
        with r.world.lock:
            for b in feet:
                slips[b].append(float(np.linalg.norm(r.world.data.xpos[b][:2] - start[b])))

    run.run(scenario.duration - settle, sample, every=10)
    names = {b: run.world.model.body(b).name.removeprefix(f"{run.entity}/") for b in feet}
    worst = max(feet, key=lambda b: max(slips[b]), default=None)
    slip = max(slips[worst]) if worst is not None else 0.0
    hints = []
    tilt, tilted = _largest_foot_tilt(run, feet)
    if slip > th["max_slip_m"] and tilt > TIPPED_OVER_RAD:
        hints.append(
            f"the robot tips over ({names[tilted]} tilts {np.degrees(tilt):.0f}°): its centre "
            "of mass is outside its feet in this posture; start it balanced (-J JOINT=POS or "
            "[robot] joints in the scenario)"
        )
    elif slip > th["max_slip_m"]:
        hints.append(
            f"{names[worst]} slides {fmt_len(slip)} while standing: raise mu1/mu2 in its "
            "<gazebo> block, or check that the posture hold is not fighting a joint limit"
        )
    series = Series(
        "foot slip",
        "m",
        tuple(times),
        {names[b]: tuple(slips[b]) for b in feet},
        threshold=th["max_slip_m"],
    )
    return judged(
        "friction_standing",
        "physics",
        f"slip {fmt_len(slip)}",
        f"≤ {fmt_len(th['max_slip_m'])}",
        hints,
        value=slip,
        series=[series],
    )


def _largest_foot_tilt(run: ScenarioRun, feet: list[int]) -> tuple[float, int | None]:
    """Largest angle [rad] between a foot's z axis and the world's z axis, and that foot."""
    with run.world.lock:
        tilts = {b: float(np.arccos(np.clip(run.world.data.xmat[b][8], -1, 1))) for b in feet}
    foot = max(tilts, key=tilts.get, default=None)
    return (tilts[foot] if foot is not None else 0.0), foot


def probe_spec(model, geom: int):
    """A free flat box with a foot geom's footprint, mass and contact settings."""
    import mujoco

    spec = mujoco.MjSpec()
    spec.modelname = "probe"
    body = spec.worldbody.add_body(name="block")
    body.add_freejoint(name="free")
    # Lying flat and thin (height ≤ 1/10 of its footprint), the block tips only beyond
    # tan θ = 10, so it measures sliding alone; Coulomb friction does not depend on the area.
    a, b, c = sorted((max(float(v), 0.005) for v in model.geom_aabb[geom][3:]), reverse=True)
    half = [a, b, min(c, 0.1 * b)]
    body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=half,
        mass=float(model.body_mass[int(model.geom_bodyid[geom])]),
        friction=list(model.geom_friction[geom]),
        priority=int(model.geom_priority[geom]),
        condim=int(model.geom_condim[geom]),
        solref=list(model.geom_solref[geom]),
        solimp=list(model.geom_solimp[geom]),
        solmix=float(model.geom_solmix[geom]),
    )
    return spec


def slide_on_slope(robot: RobotUnderTest, spec, scenario: Scenario, theta: float) -> float:
    """Distance [m] a probe block slides down a slope of `theta` [rad] in the scenario's time."""
    from twin_cli.validate.checks.base import RobotUnderTest as Robot

    world = scenario.world.model_copy(update={"incline_deg": math.degrees(theta)})
    start = scenario.robot.model_copy(update={"joints": {}})  # the probe has no joints
    probe_scenario = scenario.model_copy(
        update={"world": world, "robot": start, "actions": [], "hold": None}
    )
    probe = Robot("probe", "probe", spec, robot.model, robot.report)
    run = ScenarioRun(probe, probe_scenario)
    start = run.subtree_com()
    run.run(scenario.duration, None, every=50)
    return float(np.linalg.norm((run.subtree_com() - start)[:2]))


def _probe_verdicts(
    robot, scenario, geom, mu, th
) -> tuple[list[str], list[str], float, float | None]:
    """Run the stick and slide probes of one foot geom; return (hints, details, the distance
    [m] it slid on the slope where it should stick, and on the one where it should slide over
    Coulomb's distance (None: no slide probe, the slope would be too steep))."""
    spec = probe_spec(robot.model, geom)
    name = robot.model.body(int(robot.model.geom_bodyid[geom])).name
    g, t = 9.81, scenario.duration
    hints, details = [], []
    theta_stick = math.atan(th["stick_factor"] * mu)
    slid = stuck = slide_on_slope(robot, spec, scenario, theta_stick)
    details.append(f"{name}: μ={mu:.3g}, {math.degrees(theta_stick):.1f}° slides {fmt_len(slid)}")
    if slid > th["max_stick_slip_m"]:
        hints.append(
            f"{name} slides {fmt_len(slid)} on a {math.degrees(theta_stick):.1f}° slope where "
            f"μ={mu:.3g} should hold it: the contact creeps; raise <kd> or check friction priority"
        )
    hints += _scenario_slope_verdict(robot, scenario, spec, name, mu, th, details)
    theta_slide = math.atan(th["slide_factor"] * mu)
    ratio = None
    if theta_slide <= MAX_SLIDE_ANGLE:
        expected = 0.5 * g * (math.sin(theta_slide) - mu * math.cos(theta_slide)) * t * t
        slid = slide_on_slope(robot, spec, scenario, theta_slide)
        ratio = slid / expected
        details.append(f"{name}: {math.degrees(theta_slide):.1f}° slides {fmt_len(slid)}")
        if slid < th["min_slide_ratio"] * expected:
            hints.append(
                f"{name} slides {fmt_len(slid)} on a {math.degrees(theta_slide):.1f}° slope, "
                f"Coulomb with μ={mu:.3g} predicts {fmt_len(expected)}: the pair's friction is "
                "not min(μ); another surface's μ wins"
            )
    return hints, details, stuck, ratio


def _scenario_slope_verdict(robot, scenario, spec, name, mu, th, details) -> list[str]:
    """A scenario with its own `incline_deg` asks whether the feet hold on that slope: Coulomb
    says they do iff μ ≥ tan θ (what a sweep of foot μ finds). The bundled scenario is level
    and asks nothing here."""
    theta = math.radians(scenario.world.incline_deg)
    if theta <= 0.0:
        return []
    slid = slide_on_slope(robot, spec, scenario, theta)
    details.append(f"{name}: scenario slope {math.degrees(theta):.1f}° slides {fmt_len(slid)}")
    if slid <= th["max_stick_slip_m"]:
        return []
    return [
        f"{name} (μ={mu:.3g}) slides {fmt_len(slid)} on the scenario's "
        f"{math.degrees(theta):.1f}° slope: Coulomb needs μ ≥ tan θ = {math.tan(theta):.3g}; "
        "raise mu1/mu2 in its <gazebo> block"
    ]


def _frictionless_links(robot: RobotUnderTest, run: ScenarioRun) -> list[str]:
    """The links whose foot geoms have no friction (each foot, not one per surface)."""
    first = min(run.robot_geoms())
    return sorted(
        {
            robot.link_of_geom(g - first)
            for g in foot_geoms(run)
            if float(robot.model.geom_friction[g - first][0]) <= FRICTIONLESS_MU
        }
    )


def _foot_surfaces(robot: RobotUnderTest, run: ScenarioRun) -> dict[tuple, int]:
    """(μ, priority) → one robot geom id (robot model) of each distinct foot surface."""
    by_surface: dict[tuple, int] = {}
    first = min(run.robot_geoms())
    for g in foot_geoms(run):
        local = g - first  # attach appends the robot's geoms in order: world id → robot id
        key = (
            round(float(robot.model.geom_friction[local][0]), 6),
            int(robot.model.geom_priority[local]),
        )
        by_surface.setdefault(key, local)
    return by_surface


def check_friction_incline(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Each foot surface sticks below tan θ = μ and slides above it, μ = min(μ_foot, μ_ground)."""
    run = ScenarioRun(robot, scenario)
    if not run.floating:
        return skip_fixed("friction_incline")
    if not run.robot_geoms():
        return _frictionless([])
    surfaces = _foot_surfaces(robot, run)
    gripping = {k: g for k, g in surfaces.items() if min(k[0], GROUND_MU) > FRICTIONLESS_MU}
    slippery = _frictionless_links(robot, run)
    if not gripping:
        return _frictionless(slippery)
    hints, details, mus, stuck, slides = [], [], [], {}, {}
    for (mu_foot, _), geom in sorted(gripping.items())[: int(th["max_probes"])]:
        mu = min(mu_foot, GROUND_MU)
        mus.append(mu)
        h, d, slid, ratio = _probe_verdicts(robot, scenario, geom, mu, th)
        hints += h
        details += d
        surface = f"{robot.model.body(int(robot.model.geom_bodyid[geom])).name} μ={mu:.3g}"
        stuck[surface] = slid
        if ratio is not None:
            slides[surface] = ratio
    if slippery:
        details.append(f"frictionless feet not probed (μ = 0 slides at any slope): {slippery}")
    return result(
        "friction_incline",
        "physics",
        Status.FAIL if hints else Status.PASS,
        f"{len(mus)} foot surface(s), μ = {', '.join(f'{m:.3g}' for m in mus)}",
        f"sticks at tan θ = {th['stick_factor']:g}μ, slides at {th['slide_factor']:g}μ",
        hints=hints,
        details=details,
        value=float(len(hints)),
        series=_incline_series(stuck, slides, th),
    )


def _frictionless(links: list[str]) -> CheckResult:
    """Not applicable: no foot has friction, so no slope holds it and there is no sticking
    angle to probe (Coulomb with μ = 0 slides at any θ > 0)."""
    if not links:
        reason = "the robot has no collision geometry at its lowest point to stand on"
        return not_applicable("friction_incline", "physics", "no feet", reason)
    reason = (
        f"every foot surface is frictionless (μ ≤ {FRICTIONLESS_MU:g} on {', '.join(links)}): "
        "it slides at any slope, so there is no angle where it should stick to test"
    )
    return not_applicable("friction_incline", "physics", "frictionless feet", reason)


def _incline_series(stuck: dict, slides: dict, th: dict[str, float]) -> list[Series]:
    """Per foot surface: the slide on the slope where it should stick (at most a distance), and
    on the slope where it should slide, over Coulomb's ½(g sin θ − μ g cos θ)t² (at least a
    ratio); surfaces too grippy for a slide probe (θ above MAX_SLIDE_ANGLE) have no bar there."""
    series = []
    if stuck:
        probe = f"probe block on a slope tan θ = {th['stick_factor']:g}μ"
        series.append(
            bars(
                "slide on the sticking slope",
                "m",
                stuck,
                th["max_stick_slip_m"],
                x_label=f"foot surface ({probe})",
            )
        )
    if slides:
        probe = f"probe block on a slope tan θ = {th['slide_factor']:g}μ"
        series.append(
            bars(
                "slide over Coulomb's",
                "1",
                slides,
                th["min_slide_ratio"],
                x_label=f"foot surface ({probe}; at least the threshold)",
            )
        )
    return series
