"""Sweep parameters: what each one changes, applied where the matching Gazebo tag acts.

A variant never pokes compiled arrays. Robot parameters rewrite the neutral description before
the Gazebo stage runs, so the converter derives everything downstream exactly as it would from a
file carrying the changed tag: a friction value changes `<mu1>`/`<mu2>` before the min-μ
priorities are computed, a stiffness scale changes `<kp>` before the kp → solref mapping (which
also reads the link masses, so a mass scale moves solref too), a damping scale changes
`<dynamics damping>`. World parameters change the scenario's world (`<gravity>`) or the ground
plane's `<surface>` (Gazebo's `ground_plane` model).
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from converters.description import RobotDescription
    from converters.description.gazebo import Surface
    from twin_cli.validate.scenario import Scenario


@dataclass(frozen=True)
class Parameter:
    """One sweepable parameter: its unit, the Gazebo tag it stands for, and its valid range."""

    name: str
    unit: str
    tag: str
    minimum: float = 0.0
    inclusive: bool = False  # may the value equal `minimum`?


PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("ground_mu", "", "ground_plane <surface><friction><ode><mu>/<mu2>"),
        Parameter("foot_mu", "", "<gazebo reference=FOOT><mu1>/<mu2> of every foot link"),
        Parameter("foot_friction_scale", "×", "<mu1>/<mu2> of every foot link, scaled"),
        Parameter("friction_scale", "×", "<mu1>/<mu2> of every link, scaled"),
        Parameter("mass_scale", "×", "<inertial><mass> and <inertia> of every link, scaled"),
        Parameter("gravity", "m/s²", "world <gravity> magnitude (scenarios on Earth)", 0.0, True),
        Parameter("damping_scale", "×", "<dynamics damping> of every joint, scaled", 0.0, True),
        Parameter("kp_scale", "×", "contact stiffness <kp> of every link, scaled"),
    )
}
"""Every sweepable parameter by name (the NAME of `--sweep NAME=LO:HI:N`)."""

ROBOT_PARAMETERS = frozenset(
    {"foot_mu", "foot_friction_scale", "friction_scale", "mass_scale", "damping_scale", "kp_scale"}
)


def apply_to_description(
    robot: RobotDescription, values: Mapping[str, float], feet: frozenset[str]
) -> RobotDescription:
    """The description with every robot parameter of `values` applied, as its tags would be.

    Args:
        robot: the neutral description as read from the file.
        values: parameter name → value (world parameters are ignored here).
        feet: the names of the foot links (for `foot_mu`, `foot_friction_scale`).
    """
    from converters.gazebo.contact import DEFAULT_KP

    out = robot
    if "mass_scale" in values:
        out = _scale_masses(out, values["mass_scale"])
    if "damping_scale" in values:
        out = _scale_damping(out, values["damping_scale"])
    links = [link.name for link in out.links]
    edits: list[tuple[frozenset[str], object]] = []
    if "friction_scale" in values:
        edits.append((frozenset(links), _friction(lambda mu: mu * values["friction_scale"])))
    if "foot_friction_scale" in values:
        edits.append((feet, _friction(lambda mu: mu * values["foot_friction_scale"])))
    if "foot_mu" in values:
        edits.append((feet, _friction(lambda _mu: values["foot_mu"])))
    if "kp_scale" in values:
        scale = values["kp_scale"]
        edits.append(
            (frozenset(links), lambda s: dataclasses.replace(s, kp=(s.kp or DEFAULT_KP) * scale))
        )
    for chosen, edit in edits:
        out = _edit_surfaces(out, chosen, edit)
    return out


def _friction(rule):
    """A surface edit that maps μ1 and μ2 (unset: SDF's default μ = 1) through `rule`."""
    from converters.gazebo.contact import DEFAULT_MU

    def edit(surface: Surface) -> Surface:
        mu1 = DEFAULT_MU if surface.mu1 is None else surface.mu1
        mu2 = mu1 if surface.mu2 is None else surface.mu2
        return dataclasses.replace(surface, mu1=rule(mu1), mu2=rule(mu2))

    return edit


def _edit_surfaces(robot: RobotDescription, links: frozenset[str], edit) -> RobotDescription:
    """Apply a Surface → Surface edit to the `<gazebo reference>` surface of each link in
    `links`, and to the inline `<surface>` of their collisions (used with --as-written)."""
    ext = robot.gazebo
    table = dict(ext.links)
    for name in links:
        link_ext = ext.link(name)
        table[name] = dataclasses.replace(link_ext, surface=edit(link_ext.surface))
    inline = tuple(
        dataclasses.replace(s, surface=edit(s.surface)) if s.link in links else s
        for s in ext.inline_surfaces
    )
    gazebo = dataclasses.replace(ext, links=MappingProxyType(table), inline_surfaces=inline)
    return dataclasses.replace(robot, gazebo=gazebo)


def _scale_masses(robot: RobotDescription, scale: float) -> RobotDescription:
    """Every link's mass and inertia tensor times `scale` (same shape, denser material)."""
    links = tuple(
        dataclasses.replace(
            link,
            inertial=dataclasses.replace(
                link.inertial,
                mass=link.inertial.mass * scale,
                inertia=link.inertial.inertia * scale,
            ),
        )
        if link.inertial is not None
        else link
        for link in robot.links
    )
    return dataclasses.replace(robot, links=links)


def _scale_damping(robot: RobotDescription, scale: float) -> RobotDescription:
    """Every joint's `<dynamics damping>` [N m s/rad or N s/m] times `scale`."""
    joints = tuple(
        dataclasses.replace(
            j, dynamics=dataclasses.replace(j.dynamics, damping=j.dynamics.damping * scale)
        )
        if j.dynamics is not None
        else j
        for j in robot.joints
    )
    return dataclasses.replace(robot, joints=joints)


def apply_to_scenario(scenario: Scenario, values: Mapping[str, float]) -> Scenario:
    """The scenario with a swept `gravity` [m/s²]: scenarios on Earth (the default world) get
    gravity of that magnitude, straight down before the incline tilts it; scenarios that chose
    another world (moon, zero, a vector) keep theirs, since they test that world."""
    if "gravity" not in values or scenario.world.gravity != "earth":
        return scenario
    world = scenario.world.model_copy(update={"gravity": (0.0, 0.0, -values["gravity"])})
    return scenario.model_copy(update={"world": world})


@contextlib.contextmanager
def ground_friction(values: Mapping[str, float]) -> Iterator[None]:
    """Within the block, worlds build Gazebo's ground plane with the swept `ground_mu`.

    The ground plane is the `ground_plane` model's `<surface>`, built by
    `converters.gazebo.contact.add_gazebo_ground` from `GROUND_MU`; the friction checks read
    the same value for their min(μ) oracle. One variant runs at a time in a worker process,
    so the value is set for the block and restored after it.
    """
    if "ground_mu" not in values:
        yield
        return
    from converters.gazebo import contact
    from twin_cli.validate.checks import physics_friction

    saved = contact.GROUND_MU, physics_friction.GROUND_MU
    contact.GROUND_MU = physics_friction.GROUND_MU = values["ground_mu"]
    try:
        yield
    finally:
        contact.GROUND_MU, physics_friction.GROUND_MU = saved


def foot_links(spec, provenance) -> frozenset[str]:
    """Links whose collision geoms reach within 1 cm of the robot's lowest point in its home
    pose: the surfaces the robot stands on (the friction checks' rule, `foot_geoms`)."""
    import mujoco
    import numpy as np

    from twin_cli.validate.checks.model_inertia import collision_geoms

    model = spec.copy().compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    lows = {}
    for g in collision_geoms(model):
        rot = np.array(data.geom_xmat[g]).reshape(3, 3)
        centre = np.array(data.geom_xpos[g]) + rot @ model.geom_aabb[g][:3]
        lows[model.geom(g).name] = centre[2] - float(np.abs(rot[2]) @ model.geom_aabb[g][3:])
    floor = min(lows.values(), default=0.0)
    link_of = {o.geom: o.link for o in provenance.geoms if o.role == "collision"}
    return frozenset(link_of[n] for n, z in lows.items() if z <= floor + 0.01 and n in link_of)
