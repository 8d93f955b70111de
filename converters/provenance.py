"""Where each generated MuJoCo element came from: identity as data, never parsed from names."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class GeomOrigin:
    """One generated geom: the URDF link it was declared on and the body it ended up in.

    `link` differs from `body` when the link was lumped into its parent by a fixed joint.
    `role` is "collision" or "visual"; `index` counts that link's <collision>/<visual> elements
    in document order; `part` numbers the convex parts of a decomposed mesh (0 when whole).
    """

    geom: str
    link: str
    body: str
    role: str
    index: int
    part: int = 0
    source_file: str | None = None


@dataclass
class Provenance:
    """Maps from generated names back to the description's names.

    `body_of_link[link]` is the body that carries that link (itself, or the parent it was lumped
    into); `lumped` lists links that became sites; `joints[mj_joint] = urdf_joint`.
    """

    geoms: list[GeomOrigin] = field(default_factory=list)
    body_of_link: dict[str, str] = field(default_factory=dict)
    lumped: list[str] = field(default_factory=list)
    joints: dict[str, str] = field(default_factory=dict)

    def geoms_of_link(self, link: str, role: str = "collision") -> list[GeomOrigin]:
        return [g for g in self.geoms if g.link == link and g.role == role]
