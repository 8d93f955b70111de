"""Gazebo's values for one robot, typed: surfaces, link and joint flags, plugins and sensors.

Part of the neutral description: a format reader fills them (URDF from `<gazebo>` blocks, SDF from
its own elements) and the Gazebo stage (`converters.gazebo.apply`) turns them into MuJoCo
settings. Names keep Gazebo's, in snake case; a value the file does not set is None.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType


@dataclass(frozen=True)
class TagSource:
    """Where one value came from: `reference` ("" for the model), the tag and its raw text."""

    reference: str
    tag: str
    value: str


@dataclass(frozen=True)
class Blob:
    """An element kept verbatim (`<plugin>`, `<sensor>`, unknown tags), with where it was written.

    `name` is its name attribute, `kind` its `type` (sensors) or `filename` (plugins); `where`
    names the file and the enclosing element, for reports and errors.
    """

    tag: str
    name: str | None
    kind: str | None
    xml: str
    where: str = ""


@dataclass(frozen=True)
class Surface:
    """Collision-level values of one link or one `<collision>` (SDF `surface`), None when unset.

    Units: kp [N/m], kd [N s/m], max_vel [m/s], min_depth [m]; mu1, mu2, torsional, restitution
    are unitless; fdir1 is a direction in the collision frame.
    """

    mu1: float | None = None
    mu2: float | None = None
    fdir1: tuple[float, float, float] | None = None
    kp: float | None = None
    kd: float | None = None
    max_vel: float | None = None
    min_depth: float | None = None
    max_contacts: int | None = None
    laser_retro: float | None = None
    torsional: float | None = None
    restitution: float | None = None
    category_bitmask: int | None = None
    collide_bitmask: int | None = None

    def overridden_by(self, other: Surface) -> Surface:
        """Return this surface with every value that `other` sets replaced by other's."""
        changes = {
            f.name: getattr(other, f.name)
            for f in dataclasses.fields(other)
            if getattr(other, f.name) is not None
        }
        return dataclasses.replace(self, **changes)

    def is_empty(self) -> bool:
        return all(getattr(self, f.name) is None for f in dataclasses.fields(self))

    @property
    def declares_bitmask(self) -> bool:
        """Whether a `category_bitmask` or `collide_bitmask` is given."""
        return self.category_bitmask is not None or self.collide_bitmask is not None


@dataclass(frozen=True)
class LinkExtension:
    """Link-level Gazebo values of one link (`<gazebo reference="link">`).

    `turn_gravity_off` keeps the tag's own sense (True = no gravity); `gravity` is the SDF
    `<gravity>` blob (False = no gravity). `damping_factor` is the fraction of velocity lost per
    Gazebo step. `visual_rgba` comes from a `<visual><material><diffuse>` block.
    """

    link: str
    surface: Surface = Surface()
    self_collide: bool | None = None
    turn_gravity_off: bool | None = None
    gravity: bool | None = None
    damping_factor: float | None = None
    material: str | None = None
    visual_rgba: tuple[float, float, float, float] | None = None
    sensors: tuple[Blob, ...] = ()
    blobs: tuple[Blob, ...] = ()
    sources: tuple[TagSource, ...] = ()

    @property
    def feels_gravity(self) -> bool:
        """False when `turnGravityOff` is true or `<gravity>` is false."""
        return not (self.turn_gravity_off is True or self.gravity is False)


@dataclass(frozen=True)
class JointExtension:
    """Joint-level Gazebo values (`<gazebo reference="joint">`); units as in SDF.

    spring_stiffness [N/m or N m/rad], spring_reference [m or rad], stop_erp and stop_cfm as ODE.
    """

    joint: str
    stop_erp: float | None = None
    stop_cfm: float | None = None
    spring_stiffness: float | None = None
    spring_reference: float | None = None
    fudge_factor: float | None = None
    provide_feedback: bool | None = None
    implicit_spring_damper: bool | None = None
    preserve_fixed_joint: bool | None = None
    disable_fixed_joint_lumping: bool | None = None
    sensors: tuple[Blob, ...] = ()
    blobs: tuple[Blob, ...] = ()
    sources: tuple[TagSource, ...] = ()


@dataclass(frozen=True)
class InlineSurface:
    """A `<surface>` written inside a URDF `<collision>`: `index` counts the link's collisions."""

    link: str
    index: int
    surface: Surface


@dataclass(frozen=True)
class GazeboExtensions:
    """Everything the `<gazebo>` tags of one robot say, typed.

    `preserved_joints` are fixed joints that must not be lumped (preserveFixedJoint or
    disableFixedJointLumping). `unresolved` lists references naming no link and no joint.

    What Gazebo's URDF parser (sdformat) drops is kept apart, so the Gazebo stage can say so:
    `dropped_surfaces` are `<surface>` blocks written inside a URDF `<collision>` (sdformat
    ignores them), `named_collisions` the (link, index) of collisions with a `name` attribute,
    which receive none of their link's `<gazebo>` surface values (sdformat matches those only
    to the collision names it generates itself).
    """

    source: str
    static: bool = False
    self_collide: bool = False
    preserved_joints: frozenset[str] = frozenset()
    links: Mapping[str, LinkExtension] = field(default_factory=lambda: MappingProxyType({}))
    joints: Mapping[str, JointExtension] = field(default_factory=lambda: MappingProxyType({}))
    inline_surfaces: tuple[InlineSurface, ...] = ()
    dropped_surfaces: tuple[InlineSurface, ...] = ()
    named_collisions: frozenset[tuple[str, int]] = frozenset()
    plugins: tuple[Blob, ...] = ()
    model_blobs: tuple[Blob, ...] = ()
    unresolved: tuple[str, ...] = ()
    sources: tuple[TagSource, ...] = ()

    @property
    def declares_sensors(self) -> bool:
        """Whether a link or joint carries a `<sensor>` (the sensor stages run only then)."""
        return any(ext.sensors for ext in (*self.links.values(), *self.joints.values()))

    def link(self, name: str) -> LinkExtension:
        """The extension of link `name` (an empty one when it has no tags)."""
        return self.links.get(name) or LinkExtension(name)

    def surface_of(self, link: str, index: int) -> Surface:
        """Surface of collision `index` of `link`: inline `<surface>`, then `<gazebo>` tags win
        (except on a named URDF collision, which Gazebo leaves without its link's values)."""
        base = Surface()
        for inline in self.inline_surfaces:
            if inline.link == link and inline.index == index:
                base = inline.surface
        if (link, index) in self.named_collisions:
            return base
        return base.overridden_by(self.link(link).surface)
